//! `dermis aa-eval`: every anti-aliasing mode (and every MSAA count the
//! device renders) against a supersampled frame of the same view; what is
//! scored and recorded is `eval::aa_eval`'s. Every view's every frame is a
//! `FrameRequest` checked before the first renders; `--aa-edges` and
//! `--smaa-preset` apply to the modes that take them.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};

use super::cli::AaEvalArgs;
use super::request::{self, Given};
use crate::eval::aa_eval::{
    aa_pass_ms, csv, msaa_label, scene_set, score_view, slug, table, AaEvalReport, AaRow, AaScene,
    ModeFrame, PassTimes, ViewFrames, DEFAULT_CROWD,
};
use crate::eval::supersample::{box_filter_srgb8, check_supersampled, EDGE_THRESHOLD};
use crate::eval::{chart, pareto};
use crate::header::{command_line, RunHeader};
use crate::output::paths::{OutputPaths, Owned};
use crate::output::{write_json, write_rgba8_png};
use crate::post::AaMode;
use crate::render::request::CheckedSettings;
use crate::render::settings::{check_msaa, MSAA_COUNTS};
use crate::render::{FrameRequest, RenderSettings};
use crate::report::device_header;
use crate::run::{run_request, FrameCounts, RunOptions};
use crate::scene::source::SceneSource;
use crate::scene::{Scene, MAX_IMAGE_SIDE};
use crate::vk::context::Context;

/// The files aa-eval writes into its folder, and its per-view pictures.
const FILES: [&str; 4] = ["aa-eval.json", "aa-eval.csv", "chart.png", "chart.svg"];
const VIEWS: Owned = Owned {
    sub: "views",
    suffix: "",
};

/// One view's frames, each checked.
pub struct ViewPlan<'s> {
    pub view: &'s AaScene,
    /// The supersampled frame (N x N the size, no AA, one sample).
    pub reference: FrameRequest<'s>,
    /// Every post mode, in `AaMode::ALL` order (`none` first).
    pub modes: Vec<(AaMode, FrameRequest<'s>)>,
    /// Every MSAA count above 1 the method accepts (`--aa none`); the device
    /// renders some of them.
    pub msaa: Vec<(u32, FrameRequest<'s>)>,
    /// Samples per pixel per axis of the reference.
    pub factor: u32,
}

impl ViewPlan<'_> {
    /// The view's frame size (the reference's over the factor).
    pub fn size(&self) -> (u32, u32) {
        let s = self.modes[0].1.settings();
        (s.width, s.height)
    }
}

/// The frames of every view, checked (one line naming the view and the
/// frame), before any renders.
pub fn plan<'s>(
    views: &'s [AaScene],
    scenes: &'s [(String, Scene)],
    base: &RenderSettings,
    factor: u32,
) -> Result<Vec<ViewPlan<'s>>> {
    views
        .iter()
        .map(|v| {
            let scene = &scenes
                .iter()
                .find(|(s, _)| *s == v.source)
                .context("a view's scene was not loaded")?
                .1;
            plan_view(v, scene, base, factor)
        })
        .collect()
}

/// One view's frames, checked: its supersampled reference at `factor` x
/// `factor` the size, every post mode (`--aa-edges` and `--smaa-preset`
/// where they apply) and every MSAA count the method accepts.
pub fn plan_view<'s>(
    v: &'s AaScene,
    scene: &'s Scene,
    base: &RenderSettings,
    factor: u32,
) -> Result<ViewPlan<'s>> {
    let (w, h) = check_supersampled(base.width, base.height, factor, MAX_IMAGE_SIDE)?;
    let s = RenderSettings {
        distance_heads: v.distance_heads,
        heads: v.heads,
        // The post modes run on the single-sample frame; MSAA has rows of its own.
        msaa: 1,
        ..base.clone()
    };
    let frame = |s: RenderSettings, what: String| {
        FrameRequest::new(scene, s).with_context(|| format!("{what} on '{}'", v.name))
    };
    let reference = frame(
        RenderSettings {
            width: w,
            height: h,
            sss_region_tile: (s.sss_region_tile * factor).min(1024),
            aa: AaMode::None,
            post: s.post.for_mode(AaMode::None),
            ..s.clone()
        },
        format!("the {factor}x{factor} supersampled reference ({w}x{h})"),
    )?;
    let modes = AaMode::ALL
        .iter()
        .map(|&mode| {
            let m = RenderSettings {
                aa: mode,
                post: s.post.for_mode(mode),
                ..s.clone()
            };
            Ok((mode, frame(m, format!("--aa {mode}"))?))
        })
        .collect::<Result<_>>()?;
    let msaa = MSAA_COUNTS
        .into_iter()
        .filter(|&n| n > 1 && check_msaa(n, Some(s.method)).is_ok())
        .map(|n| {
            let m = RenderSettings {
                msaa: n,
                aa: AaMode::None,
                post: s.post.for_mode(AaMode::None),
                ..s.clone()
            };
            Ok((n, frame(m, format!("--msaa {n}"))?))
        })
        .collect::<Result<_>>()?;
    Ok(ViewPlan {
        view: v,
        reference,
        modes,
        msaa,
        factor,
    })
}

/// `dermis aa-eval`.
pub fn run(a: &AaEvalArgs, given: &Given) -> Result<()> {
    let counts = FrameCounts::new(a.frames.warmup, a.frames.frames)?;
    let (source, settings) = request::frame_settings(&a.frame, given)?;
    let base = RenderSettings {
        assignment: None,
        ..settings
    };
    for n in super::notes::foreign(&base) {
        eprintln!("note: {n}");
    }
    // The base frame's numbers before any scene loads.
    CheckedSettings::new(base.clone())?;
    // A glTF --scene is the scan the head views add; a built-in one adds nothing.
    let head = source.gltf();
    let crowd = if base.heads > 1 {
        base.heads
    } else {
        DEFAULT_CROWD
    };
    let views = scene_set(&a.scenes, head, crowd, base.fovy_deg)?;
    let scenes = load_scenes(&views, &source)?;
    let plan = plan(&views, &scenes, &base, a.factor)?;
    OutputPaths::new()
        .folder("--out", &a.out, &FILES, &[VIEWS])
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let result = sweep(&ctx, &plan, counts, Some(&a.out.join(VIEWS.sub)), true).and_then(|rows| {
        let files = write(&ctx, &rows, &views, (&base, a.factor, counts), &a.out)?;
        Ok((rows, files))
    });
    let (rows, files) = ctx.finish_with(result)?;
    print!("{}", table(&rows));
    let names: Vec<String> = files
        .iter()
        .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    println!(
        "wrote {} and views/ in {}",
        names.join(", "),
        a.out.display()
    );
    Ok(())
}

/// Each distinct scene of the views, loaded once (the scan with the given
/// textures and scale).
fn load_scenes(views: &[AaScene], given: &SceneSource) -> Result<Vec<(String, Scene)>> {
    let mut scenes: Vec<(String, Scene)> = Vec::new();
    for v in views {
        if scenes.iter().any(|(s, _)| *s == v.source) {
            continue;
        }
        let source = match v.source.strip_prefix(crate::scene::source::BUILTIN_PREFIX) {
            Some(name) => SceneSource::builtin_named(name),
            None => SceneSource {
                scene: Some(PathBuf::from(&v.source)),
                ..given.clone()
            },
        };
        let scene =
            request::load_scene(&source).with_context(|| format!("loading scene '{}'", v.name))?;
        scenes.push((v.source.clone(), scene));
    }
    Ok(scenes)
}

/// One frame measured and captured: (sRGB8, each pass's name and median GPU
/// ms, the frame's median GPU ms).
pub fn mode_frame(
    ctx: &Context,
    frame: &FrameRequest,
    counts: FrameCounts,
) -> Result<(Vec<u8>, PassTimes, f64)> {
    let o = RunOptions {
        frames: counts,
        ..RunOptions::capture_once("aa-eval")
    };
    let out = run_request(ctx, frame, &o)?;
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

/// The supersampled reference of a view, box-filtered to the view's size.
pub fn reference(ctx: &Context, p: &ViewPlan) -> Result<Vec<u8>> {
    let (factor, (w, h)) = (p.factor, p.size());
    let out = run_request(
        ctx,
        &p.reference,
        &RunOptions::capture_once("aa-eval reference"),
    )
    .with_context(|| format!("the {factor}x{factor} supersampled reference"))?;
    let cap = out.capture.context("reference capture")?;
    box_filter_srgb8(&cap.ldr, w, h, factor)
}

/// Every mode's frame of one view, in `AaMode::ALL` order (`none` first, whose
/// passes the others' AA ms are told from), then one frame per MSAA count the
/// device renders: `(label, sRGB8, AA ms, frame ms)`. An MSAA row's AA ms is
/// its frame's median GPU ms over `none`'s (the overhead Table 10.1 gives for
/// MSAA; 0 when the measurement noise makes it negative). `on_mode` is called
/// with each label before its run and `done` after it.
pub fn mode_frames(
    ctx: &Context,
    p: &ViewPlan,
    counts: FrameCounts,
    on_mode: &dyn Fn(&str),
    done: &dyn Fn(),
) -> Result<Vec<ModeFrame>> {
    let mut none_passes: PassTimes = Vec::new();
    let mut none_ms = 0.0;
    let mut out = Vec::new();
    for (mode, f) in &p.modes {
        on_mode(mode.name());
        let (frame, passes, frame_ms) =
            mode_frame(ctx, f, counts).with_context(|| format!("--aa {mode}"))?;
        if *mode == AaMode::None {
            none_passes = passes.clone();
            none_ms = frame_ms;
        }
        let aa = aa_pass_ms(&passes, &none_passes);
        out.push((mode.name().to_string(), frame, aa, frame_ms));
        done();
    }
    for (n, f) in p.msaa.iter().filter(|(n, _)| renders(ctx, *n)) {
        let label = msaa_label(*n);
        on_mode(&label);
        let (frame, _, frame_ms) =
            mode_frame(ctx, f, counts).with_context(|| format!("--msaa {n}"))?;
        out.push((label, frame, (frame_ms - none_ms).max(0.0), frame_ms));
        done();
    }
    Ok(out)
}

/// Whether the device renders `n` samples per pixel.
fn renders(ctx: &Context, n: u32) -> bool {
    ctx.facts.framebuffer_sample_counts.contains(&n)
}

/// Renders every view; one row per (view, mode). With `images`, each view's
/// reference, edge mask and frames as PNGs under `images/VIEW/`.
pub fn sweep(
    ctx: &Context,
    plan: &[ViewPlan],
    counts: FrameCounts,
    images: Option<&Path>,
    progress: bool,
) -> Result<Vec<AaRow>> {
    let per_view: usize = plan
        .iter()
        .map(|p| 1 + p.modes.len() + p.msaa.iter().filter(|(n, _)| renders(ctx, *n)).count())
        .sum();
    let bar = progress.then(|| {
        let b = indicatif::ProgressBar::new(per_view as u64);
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
    let mut rows = Vec::new();
    for p in plan {
        let v = p.view;
        let (w, h) = p.size();
        let factor = p.factor;
        step(format!("{}: {factor}x{factor} reference", v.name));
        let reference = reference(ctx, p).with_context(|| format!("on '{}'", v.name))?;
        tick();
        let modes = mode_frames(
            ctx,
            p,
            counts,
            &|mode| step(format!("{}: {mode}", v.name)),
            &tick,
        )
        .with_context(|| format!("on '{}'", v.name))?;
        let frames = ViewFrames { reference, modes };
        let (view_rows, mask) = score_view(&v.name, &frames, w, h)?;
        if let Some(dir) = images {
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

/// Writes aa-eval.json, aa-eval.csv, chart.png and chart.svg into `out`;
/// returns the paths.
pub fn write(
    ctx: &Context,
    rows: &[AaRow],
    views: &[AaScene],
    (base, factor, counts): (&RenderSettings, u32, FrameCounts),
    out: &Path,
) -> Result<Vec<PathBuf>> {
    let files: Vec<PathBuf> = FILES.iter().map(|f| out.join(f)).collect();
    let n = factor;
    let report = AaEvalReport {
        run: RunHeader::new(
            &command_line(),
            device_header(ctx),
            (base.width, base.height),
            (counts.warmup(), counts.measured()),
        ),
        method: base.method.name.to_string(),
        factor,
        reference: format!("{n}x{n} samples per pixel: the frame rendered at {n} times the size (same camera, SSS method and settings), tone-mapped, then each {n}x{n} block decoded from sRGB, averaged in display-linear light and re-encoded"),
        space: "relative RMSE on the display-linear RGB of the sRGB frames (the space the AA modes blend in), FLIP on the sRGB bytes".into(),
        edge_pixels: format!("pixels where the filtered reference and the 1x --aa none frame differ by >= {EDGE_THRESHOLD}/255 in a channel"),
        scenes: views.to_vec(),
        rows: rows.to_vec(),
    };
    write_json(&files[0], &report)?;
    let (header, table) = csv(rows);
    pareto::write_table(&files[1], header, &table)?;
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
            views.len(),
        ),
        "GPU ms (AA passes, median)",
        &files[2],
        &files[3],
    )?;
    Ok(files)
}
