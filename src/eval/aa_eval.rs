//! `dermis aa-eval`: every anti-aliasing mode scored against a supersampled
//! frame (issue 17 item 6). For each scene of the set, the frame is rendered
//! once at N x N its size with the same camera, SSS method and settings and
//! box-filtered down (`supersample`), then once per AA mode at its size, timed
//! like every frame; each mode's frame is scored against the filtered one over
//! the edge pixels and the whole frame. Writes aa-eval.json, aa-eval.csv and
//! the cost/error chart (chart.png, chart.svg), and per scene the filtered
//! reference and the edge mask as PNGs.
//!
//! The SSS kernels keep their size in millimetres at N x N the pixels: every
//! method converts millimetres to pixels through `view::ViewScale`, whose
//! `px_per_mm` grows with the frame's height, so the N-times-larger frame blurs
//! over N times the pixels. The SSS region's tiles are scaled by N too, so
//! they cover the same part of the picture. The shadow map keeps its size: it
//! is the same scene input at both resolutions.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use super::supersample::{box_filter_srgb8, check_supersampled, edge_mask, score, AaError};
use super::{chart, pareto};
use crate::output::{write_json, write_rgba8_png};
use crate::post::AaMode;
use crate::render::settings::{check_msaa, MSAA_COUNTS};
use crate::render::RenderSettings;
use crate::run::{run, RunOptions};
use crate::scene::camera::Camera;
use crate::scene::gltf_load::TextureOverrides;
use crate::scene::{builtin, load_gltf_scene, Scene, MAX_IMAGE_SIDE};
use crate::vk::context::Context;

/// The scene groups `--scenes` takes, comma-separated.
pub const SCENE_GROUPS: [&str; 3] = ["head", "crowd", "lines"];
/// Characters in the crowd when `--heads` is left at 1.
pub const DEFAULT_CROWD: u32 = 9;

/// One view of the set.
#[derive(Clone, Debug, Serialize)]
pub struct AaScene {
    pub name: String,
    /// `builtin:NAME` or a glTF path.
    pub source: String,
    pub distance_heads: f32,
    pub heads: u32,
}

/// The views of `groups` (a comma-separated subset of [`SCENE_GROUPS`]): the
/// procedural head close and far (and the scan `head`, when given, the
/// same), a crowd of `crowd` procedural heads, and the lines card at one,
/// two and four close-up distances.
pub fn scene_set(
    groups: &str,
    head: Option<&Path>,
    crowd: u32,
    fovy_deg: f32,
) -> Result<Vec<AaScene>> {
    let close = Camera::close_up_distance_heads(fovy_deg);
    let view = |name: String, source: String, d: f32, heads: u32| AaScene {
        name,
        source,
        distance_heads: d,
        heads,
    };
    let mut v = Vec::new();
    for g in groups.split(',').map(str::trim).filter(|g| !g.is_empty()) {
        match g {
            "head" => {
                let mut heads = vec![("face".to_string(), "builtin:face".to_string())];
                if let Some(p) = head {
                    heads.push(("scan".into(), p.display().to_string()));
                }
                for (who, src) in heads {
                    v.push(view(format!("{who} close"), src.clone(), close, 1));
                    v.push(view(format!("{who} far"), src, 5.0 * close, 1));
                }
            }
            "crowd" => v.push(view(
                format!("crowd of {crowd}"),
                "builtin:face".into(),
                2.0 * close,
                crowd,
            )),
            "lines" => {
                for k in [1.0f32, 2.0, 4.0] {
                    v.push(view(
                        format!("lines {k}x"),
                        "builtin:lines".into(),
                        k * close,
                        1,
                    ));
                }
            }
            other => bail!(
                "unknown aa-eval scene group '{other}' (valid: {})",
                SCENE_GROUPS.join(", ")
            ),
        }
    }
    if v.is_empty() {
        bail!(
            "--scenes names no scene (valid: {})",
            SCENE_GROUPS.join(", ")
        );
    }
    Ok(v)
}

fn load(s: &AaScene) -> Result<Scene> {
    match s.source.strip_prefix("builtin:") {
        Some(name) => builtin(name),
        None => load_gltf_scene(Path::new(&s.source), &TextureOverrides::default(), None),
    }
}

/// What the sweep needs besides the scenes.
pub struct AaEvalOptions {
    /// The frame every view starts from (size, method, lights...); its `aa`,
    /// distance and head count are set per run.
    pub base: RenderSettings,
    /// Samples per pixel per axis of the reference.
    pub factor: u32,
    pub warmup: usize,
    pub measured: usize,
    pub progress: bool,
    /// Where to write the per-scene PNGs (`None`: nowhere).
    pub images: Option<PathBuf>,
}

/// One (scene, mode) result.
#[derive(Clone, Debug, Serialize)]
pub struct AaRow {
    pub scene: String,
    pub mode: String,
    /// GPU ms of the AA stage's passes (those the `none` frame does not
    /// run, `aa_pass_ms`), median over the measured frames; 0 for `none`.
    pub aa_ms: f64,
    /// GPU ms of the whole frame, median.
    pub frame_ms: f64,
    pub edge_pixels: usize,
    pub pixels: usize,
    #[serde(flatten)]
    pub error: AaError,
    /// Edge-pixel relative RMSE over `none`'s on the same view (1: no better).
    pub rmse_edges_vs_none: Option<f64>,
    /// Edge-pixel FLIP over `none`'s.
    pub flip_edges_vs_none: Option<f64>,
}

/// Each pass of a frame: its name and median GPU ms.
pub type PassTimes = Vec<(String, f64)>;
/// One mode's frame of a view: `(mode, sRGB8 frame, AA ms, frame ms)`.
pub type ModeFrame = (String, Vec<u8>, f64, f64);

/// The label of the row of `--msaa n` (with `--aa none`).
pub fn msaa_label(n: u32) -> String {
    format!("msaa{n}x")
}

/// The MSAA counts above 1 scored beside the post modes: those the device
/// renders and the settings' method accepts (none in a frame of several,
/// whose groups are checked only once they are known).
pub fn msaa_counts(ctx: &Context, settings: &RenderSettings) -> Vec<u32> {
    if settings.assignment.is_some() {
        return Vec::new();
    }
    MSAA_COUNTS
        .into_iter()
        .filter(|&n| n > 1 && ctx.facts.framebuffer_sample_counts.contains(&n))
        .filter(|&n| check_msaa(n, Some(settings.method)).is_ok())
        .collect()
}

/// The filtered reference of one view and the 1x frames of every mode.
pub struct ViewFrames {
    pub reference: Vec<u8>,
    /// `(mode, sRGB8 frame, AA ms, frame ms)`, in `AaMode::ALL` order, then
    /// the MSAA rows (`mode_frames`).
    pub modes: Vec<ModeFrame>,
}

/// Renders the supersampled reference of `settings` and box-filters it.
pub fn reference(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    n: u32,
) -> Result<Vec<u8>> {
    let max_side = ctx.facts.max_image_dimension_2d.min(MAX_IMAGE_SIDE);
    let (w, h) = check_supersampled(settings.width, settings.height, n, max_side)?;
    let big = RenderSettings {
        width: w,
        height: h,
        sss_region_tile: (settings.sss_region_tile * n).min(1024),
        aa: AaMode::None,
        // The reference is supersampled, not multisampled.
        msaa: 1,
        ..settings.clone()
    };
    let out = run(
        ctx,
        scene,
        &big,
        &RunOptions::capture_once("aa-eval reference"),
    )
    .with_context(|| format!("the {n}x{n} supersampled reference ({w}x{h})"))?;
    let cap = out.capture.context("reference capture")?;
    box_filter_srgb8(&cap.ldr, settings.width, settings.height, n)
}

/// The AA stage's GPU ms: the summed median ms of the passes of a frame with
/// the stage (`passes`, name and ms) that the same frame without it
/// (`none`) does not run. The chain adds the stage's passes after the tone
/// map and changes nothing else, so this is the stage, found without naming
/// any pass.
pub fn aa_pass_ms(passes: &[(String, f64)], none: &[(String, f64)]) -> f64 {
    passes
        .iter()
        .filter(|(name, _)| !none.iter().any(|(n, _)| n == name))
        // A fold from +0: `sum` of no pass is -0.0.
        .fold(0.0, |a, (_, ms)| a + ms)
}

/// One frame with `mode`, measured and captured: (sRGB8, each pass's name
/// and median GPU ms, the frame's median GPU ms).
pub fn mode_frame(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    mode: AaMode,
    warmup: usize,
    measured: usize,
) -> Result<(Vec<u8>, PassTimes, f64)> {
    let s = RenderSettings {
        aa: mode,
        ..settings.clone()
    };
    let o = RunOptions {
        warmup,
        measured,
        ..RunOptions::capture_once("aa-eval")
    };
    let out = run(ctx, scene, &s, &o).with_context(|| format!("--aa {mode}"))?;
    let cap = out.capture.context("capture")?;
    let frame_ms = out.report.frame.as_ref().map_or(0.0, |f| f.gpu_ms.median);
    let passes = out
        .report
        .passes
        .iter()
        .map(|p| (p.name.clone(), p.gpu_ms.median))
        .collect();
    Ok((cap.ldr, passes, frame_ms))
}

/// Every mode's frame of one view, in `AaMode::ALL` order (`none` first, whose
/// passes the others' AA ms are told from), then one frame per count of
/// [`msaa_counts`] with `--aa none`: `(label, sRGB8, AA ms, frame ms)`. An
/// MSAA row's AA ms is its frame's median GPU ms over `none`'s (the overhead
/// Table 10.1 gives for MSAA; 0 when the measurement noise makes it
/// negative). `on_mode` is called with each label before its run and `done`
/// after it.
pub fn mode_frames(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    (warmup, measured): (usize, usize),
    on_mode: &dyn Fn(&str),
    done: &dyn Fn(),
) -> Result<Vec<ModeFrame>> {
    // The post modes run on the single-sample frame; MSAA has rows of its own.
    let settings = &RenderSettings {
        msaa: 1,
        ..settings.clone()
    };
    let mut none_passes: PassTimes = Vec::new();
    let mut none_ms = 0.0;
    let mut out = Vec::new();
    for mode in AaMode::ALL {
        on_mode(mode.name());
        let (frame, passes, frame_ms) = mode_frame(ctx, scene, settings, mode, warmup, measured)?;
        if mode == AaMode::None {
            none_passes = passes.clone();
            none_ms = frame_ms;
        }
        let aa = aa_pass_ms(&passes, &none_passes);
        out.push((mode.name().to_string(), frame, aa, frame_ms));
        done();
    }
    for n in msaa_counts(ctx, settings) {
        let label = msaa_label(n);
        on_mode(&label);
        let s = RenderSettings {
            msaa: n,
            ..settings.clone()
        };
        let (frame, _, frame_ms) = mode_frame(ctx, scene, &s, AaMode::None, warmup, measured)
            .with_context(|| format!("--msaa {n}"))?;
        out.push((label, frame, (frame_ms - none_ms).max(0.0), frame_ms));
        done();
    }
    Ok(out)
}

/// The rows of one view: every mode scored against the reference over the
/// edge mask the reference and `none`'s frame define.
pub fn score_view(
    name: &str,
    f: &ViewFrames,
    width: u32,
    height: u32,
) -> Result<(Vec<AaRow>, Vec<bool>)> {
    let none = f
        .modes
        .iter()
        .find(|m| m.0 == AaMode::None.name())
        .context("the no-AA frame")?;
    let mask = edge_mask(&f.reference, &none.1)?;
    let edges = mask.iter().filter(|&&m| m).count();
    let mut rows = Vec::new();
    for (mode, frame, aa, frame_ms) in &f.modes {
        let error = score(frame, &f.reference, &mask, width, height)
            .with_context(|| format!("scoring {mode} on '{name}'"))?;
        rows.push(AaRow {
            scene: name.to_string(),
            mode: mode.clone(),
            aa_ms: *aa,
            frame_ms: *frame_ms,
            edge_pixels: edges,
            pixels: mask.len(),
            error,
            rmse_edges_vs_none: None,
            flip_edges_vs_none: None,
        });
    }
    let base = rows[0].error;
    for r in &mut rows {
        let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if b > 0.0 => Some(a / b),
            _ => None,
        };
        r.rmse_edges_vs_none = ratio(r.error.rmse_edges, base.rmse_edges);
        r.flip_edges_vs_none = ratio(r.error.flip_edges, base.flip_edges);
    }
    Ok((rows, mask))
}

/// A file-name-safe form of a scene name.
fn slug(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
}

/// Runs the set; one row per (view, mode).
pub fn sweep(ctx: &Context, scenes: &[AaScene], o: &AaEvalOptions) -> Result<Vec<AaRow>> {
    let per_view = 1 + (AaMode::ALL.len() + msaa_counts(ctx, &o.base).len()) as u64;
    let bar = o.progress.then(|| {
        let b = indicatif::ProgressBar::new(scenes.len() as u64 * per_view);
        b.set_style(
            indicatif::ProgressStyle::with_template("{msg:<40} [{bar:30}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let step = |msg: String| {
        if let Some(b) = &bar {
            b.set_message(msg);
        }
    };
    let tick = || {
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let (w, h) = (o.base.width, o.base.height);
    let mut rows = Vec::new();
    for v in scenes {
        let scene = load(v).with_context(|| format!("loading scene '{}'", v.name))?;
        let s = RenderSettings {
            distance_heads: v.distance_heads,
            heads: v.heads,
            ..o.base.clone()
        };
        step(format!("{}: {n}x{n} reference", v.name, n = o.factor));
        let reference =
            reference(ctx, &scene, &s, o.factor).with_context(|| format!("on '{}'", v.name))?;
        tick();
        let modes = mode_frames(
            ctx,
            &scene,
            &s,
            (o.warmup, o.measured),
            &|mode| step(format!("{}: {mode}", v.name)),
            &tick,
        )
        .with_context(|| format!("on '{}'", v.name))?;
        let frames = ViewFrames { reference, modes };
        let (view_rows, mask) = score_view(&v.name, &frames, w, h)?;
        if let Some(dir) = &o.images {
            let dir = dir.join(slug(&v.name));
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            write_rgba8_png(&dir.join("reference.png"), w, h, frames.reference.clone())?;
            let m: Vec<u8> = mask
                .iter()
                .flat_map(|&e| {
                    if e {
                        [255, 255, 255, 255]
                    } else {
                        [0, 0, 0, 255]
                    }
                })
                .collect();
            write_rgba8_png(&dir.join("edges.png"), w, h, m)?;
            for (mode, frame, ..) in frames.modes {
                write_rgba8_png(&dir.join(format!("{mode}.png")), w, h, frame)?;
            }
        }
        rows.extend(view_rows);
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok(rows)
}

const CSV_HEADER: [&str; 12] = [
    "scene",
    "mode",
    "aa_ms",
    "frame_ms",
    "edge_pixels",
    "pixels",
    "rmse_edges",
    "rmse_frame",
    "flip_edges",
    "flip_frame",
    "rmse_edges_vs_none",
    "flip_edges_vs_none",
];

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| format!("{v:.6}"))
}

fn csv_fields(r: &AaRow) -> Vec<String> {
    vec![
        r.scene.clone(),
        r.mode.clone(),
        format!("{:.6}", r.aa_ms),
        format!("{:.6}", r.frame_ms),
        r.edge_pixels.to_string(),
        r.pixels.to_string(),
        opt(r.error.rmse_edges),
        format!("{:.6}", r.error.rmse_frame),
        opt(r.error.flip_edges),
        format!("{:.6}", r.error.flip_frame),
        opt(r.rmse_edges_vs_none),
        opt(r.flip_edges_vs_none),
    ]
}

/// The table the CLI prints.
pub fn table(rows: &[AaRow]) -> String {
    let f = |v: Option<f64>| v.map_or_else(|| "-".to_string(), |v| format!("{v:.4}"));
    let mut s = format!(
        "{:<16} {:<5} {:>8} {:>8} {:>10} {:>10} {:>10} {:>10} {:>9}\n",
        "scene",
        "aa",
        "AA ms",
        "edge px",
        "rRMSE edge",
        "FLIP edge",
        "rRMSE all",
        "FLIP all",
        "edge/none"
    );
    for r in rows {
        s += &format!(
            "{:<16} {:<5} {:>8.3} {:>8} {:>10} {:>10} {:>10.4} {:>10.4} {:>9}\n",
            r.scene,
            r.mode,
            r.aa_ms,
            r.edge_pixels,
            f(r.error.rmse_edges),
            f(r.error.flip_edges),
            r.error.rmse_frame,
            r.error.flip_frame,
            f(r.rmse_edges_vs_none),
        );
    }
    s
}

/// Writes aa-eval.json, aa-eval.csv, chart.png and chart.svg into `out`;
/// returns the paths.
pub fn write(
    ctx: &Context,
    rows: &[AaRow],
    scenes: &[AaScene],
    o: &AaEvalOptions,
    command: &str,
    out: &Path,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let files = vec![
        out.join("aa-eval.json"),
        out.join("aa-eval.csv"),
        out.join("chart.png"),
        out.join("chart.svg"),
    ];
    write_json(
        &files[0],
        &serde_json::json!({
            "device": ctx.facts.name, "driver": ctx.facts.driver, "command": command,
            "width": o.base.width, "height": o.base.height, "method": o.base.method.name,
            "factor": o.factor,
            "reference": format!("{n}x{n} samples per pixel: the frame rendered at {n} times the size (same camera, SSS method and settings), tone-mapped, then each {n}x{n} block decoded from sRGB, averaged in display-linear light and re-encoded", n = o.factor),
            "space": "relative RMSE on the display-linear RGB of the sRGB frames (the space the AA modes blend in), FLIP on the sRGB bytes",
            "edge_pixels": format!("pixels where the filtered reference and the 1x --aa none frame differ by >= {}/255 in a channel", super::supersample::EDGE_THRESHOLD),
            "scenes": scenes, "rows": rows,
        }),
    )?;
    let table: Vec<Vec<String>> = rows.iter().map(csv_fields).collect();
    pareto::write_table(&files[1], &CSV_HEADER[..], &table)?;
    type Pick = fn(&AaRow) -> Option<f64>;
    let metrics: [(&str, Pick); 5] = [
        ("edge relative RMSE over no AA's", |r| r.rmse_edges_vs_none),
        ("relative RMSE, edge pixels", |r| r.error.rmse_edges),
        ("FLIP, edge pixels", |r| r.error.flip_edges),
        ("relative RMSE, whole frame", |r| Some(r.error.rmse_frame)),
        ("FLIP, whole frame", |r| Some(r.error.flip_frame)),
    ];
    let panels: Vec<chart::Panel> = metrics
        .iter()
        .map(|(title, pick)| chart::Panel {
            title: (*title).into(),
            y_label: format!("{title} against the supersampled frame"),
            points: rows
                .iter()
                .filter_map(|r| {
                    pick(r).map(|e| pareto::EvalPoint {
                        method: r.mode.clone(),
                        setting: String::new(),
                        scene: r.scene.clone(),
                        gpu_ms: r.aa_ms,
                        error: e,
                    })
                })
                .collect(),
            front: false,
        })
        .filter(|p| !p.points.is_empty())
        .collect();
    chart::panel_chart(
        &panels,
        &format!(
            "AA cost vs error to the {n}x{n} supersampled frame ({}, {} view(s))",
            ctx.facts.name,
            scenes.len(),
            n = o.factor
        ),
        "GPU ms (AA passes, median)",
        &files[2],
        &files[3],
    )?;
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_set_has_every_group() {
        let all = scene_set("head,crowd,lines", None, 9, 30.0).unwrap();
        let names: Vec<&str> = all.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "face close",
                "face far",
                "crowd of 9",
                "lines 1x",
                "lines 2x",
                "lines 4x"
            ]
        );
        let with_scan = scene_set("head", Some(Path::new("x.glb")), 9, 30.0).unwrap();
        assert_eq!(with_scan.len(), 4);
        assert_eq!(with_scan[2].source, "x.glb");
        assert!(scene_set("heads", None, 9, 30.0)
            .unwrap_err()
            .to_string()
            .contains("valid: head, crowd, lines"));
        assert!(scene_set(",", None, 9, 30.0).is_err());
    }

    #[test]
    fn aa_ms_is_the_passes_none_does_not_run() {
        let p = |v: &[(&str, f64)]| -> Vec<(String, f64)> {
            v.iter().map(|(n, m)| (n.to_string(), *m)).collect()
        };
        let none = p(&[("geometry", 2.0), ("composite", 1.0), ("tonemap", 0.5)]);
        let mlaa = p(&[
            ("geometry", 2.1),
            ("composite", 1.0),
            ("tonemap", 0.5),
            ("mlaa edges", 0.25),
            ("mlaa blend", 0.5),
        ]);
        assert_eq!(aa_pass_ms(&mlaa, &none), 0.75);
        let z = aa_pass_ms(&none, &none);
        assert!(z == 0.0 && z.is_sign_positive());
    }

    #[test]
    fn csv_has_every_column() {
        let r = AaRow {
            scene: "s".into(),
            mode: "fxaa".into(),
            aa_ms: 0.1,
            frame_ms: 1.0,
            edge_pixels: 3,
            pixels: 9,
            error: AaError::default(),
            rmse_edges_vs_none: None,
            flip_edges_vs_none: Some(0.5),
        };
        assert_eq!(csv_fields(&r).len(), CSV_HEADER.len());
        assert!(table(&[r]).contains("fxaa"));
    }
}
