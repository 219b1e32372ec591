//! What `dermis aa-eval` scores and records (no device: the renders are
//! `app::aa_eval`'s): its views, the scoring of a view's frames, the rows,
//! the table, the CSV and aa-eval.json's schema (read back typed).
//!
//! Every anti-aliasing mode is scored against a supersampled frame (issue 17
//! item 6). For each scene of the set, the frame is rendered
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

use std::path::Path;

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

use super::supersample::{edge_mask, score, AaError};
use crate::header::RunHeader;
use crate::post::AaMode;
use crate::render::settings::ShotPreset;

/// The scene groups `--scenes` takes, comma-separated.
pub const SCENE_GROUPS: [&str; 3] = ["head", "crowd", "lines"];
/// Characters in the crowd when `--heads` is left at 1.
pub const DEFAULT_CROWD: u32 = 9;

/// One view of the set.
#[derive(Clone, Debug, Serialize, Deserialize)]
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
    let (close, far) = (
        ShotPreset::Close.distance_heads(fovy_deg),
        ShotPreset::Far.distance_heads(fovy_deg),
    );
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
                    v.push(view(format!("{who} far"), src, far, 1));
                }
            }
            "crowd" => v.push(view(
                format!("crowd of {crowd}"),
                "builtin:face".into(),
                ShotPreset::Mid.distance_heads(fovy_deg),
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

/// One (scene, mode) result.
#[derive(Clone, Debug, Serialize, Deserialize)]
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

/// The filtered reference of one view and the 1x frames of every mode.
pub struct ViewFrames {
    pub reference: Vec<u8>,
    /// `(mode, sRGB8 frame, AA ms, frame ms)`, in `AaMode::ALL` order, then
    /// the MSAA rows (`mode_frames`).
    pub modes: Vec<ModeFrame>,
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
pub fn slug(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
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

/// aa-eval.json: the run, how the reference and the errors are made, the
/// views and a row per (view, mode); written by `dermis aa-eval`, read back
/// typed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AaEvalReport {
    #[serde(flatten)]
    pub run: RunHeader,
    pub method: String,
    pub factor: u32,
    pub reference: String,
    pub space: String,
    pub edge_pixels: String,
    pub scenes: Vec<AaScene>,
    pub rows: Vec<AaRow>,
}

/// The CSV's header and a row's fields.
pub fn csv(rows: &[AaRow]) -> (&'static [&'static str], Vec<Vec<String>>) {
    (&CSV_HEADER[..], rows.iter().map(csv_fields).collect())
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
