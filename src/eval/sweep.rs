//! `dermis eval`: every registered method and quality setting, on a scene set,
//! timed by the same run's timestamps and scored against the ground truth.
//!
//! A method joins the chart by adding its settings to [`registry`].

use std::path::PathBuf;

use anyhow::{Context as _, Result};
use serde::Serialize;

use super::metrics::relative_rmse;
use super::pareto::EvalPoint;
use crate::method::{ground_truth, EvalSetting, MethodEntry, METHODS};
use crate::render::RenderSettings;
use crate::run::{run, RunOptions};
use crate::scene::gltf_load::TextureOverrides;
use crate::scene::{default_scene, load_gltf_scene, Scene};
use crate::vk::context::Context;

/// One point of the sweep: a method at one quality setting.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    pub method: &'static MethodEntry,
    pub setting: &'static EvalSetting,
}

/// Every method's eval settings, in registry order (the ground truth is what
/// they are scored against, not a point).
pub fn registry() -> Vec<Config> {
    METHODS
        .iter()
        .filter(|m| !m.ground_truth)
        .flat_map(|m| {
            m.eval.iter().map(move |s| Config {
                method: m,
                setting: s,
            })
        })
        .collect()
}

/// A view of the scene set.
#[derive(Clone, Debug, Serialize)]
pub struct SceneSpec {
    pub name: String,
    /// `None`: the embedded procedural head.
    pub gltf: Option<PathBuf>,
    pub distance_heads: f32,
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
}

/// The thesis' perceptual study (section 4.3.2): zoom, near and far (28, 50 and
/// 132 units for a 27-unit head, so 1.04, 1.85 and 4.89 head heights) x light at
/// 0, 60, 110 and 150 degrees azimuth, 45 elevation, on the given head, plus the
/// procedural default scene.
pub fn thesis_scenes(head: Option<PathBuf>) -> Vec<SceneSpec> {
    let mut v = Vec::new();
    if let Some(h) = head {
        for (shot, d) in [
            ("zoom", 28.0 / 27.0),
            ("near", 50.0 / 27.0),
            ("far", 132.0 / 27.0),
        ] {
            for az in [0.0, 60.0, 110.0, 150.0] {
                v.push(SceneSpec {
                    name: format!("head {shot} {az:.0}deg"),
                    gltf: Some(h.clone()),
                    distance_heads: d,
                    azimuth_deg: az,
                    elevation_deg: 45.0,
                });
            }
        }
    }
    v.push(procedural_scene());
    v
}

/// A camera dolly on the given head from a close-up (1 head height) to a far
/// shot (24), in 12 steps of equal ratio, light at 60 degrees azimuth and 45
/// elevation: each method's error along it shows where a distance-driven
/// switch (Gaussian LOD, poisson's sample count) changes the image.
pub fn dolly_scenes(head: PathBuf) -> Vec<SceneSpec> {
    const STEPS: usize = 12;
    let (near, far) = (1.0f32, 24.0f32);
    (0..STEPS)
        .map(|i| {
            let d = near * (far / near).powf(i as f32 / (STEPS - 1) as f32);
            SceneSpec {
                name: format!("head dolly {d:.2}"),
                gltf: Some(head.clone()),
                distance_heads: d,
                azimuth_deg: 60.0,
                elevation_deg: 45.0,
            }
        })
        .collect()
}

/// The embedded scene at its default view.
pub fn procedural_scene() -> SceneSpec {
    let d = RenderSettings::default();
    SceneSpec {
        name: "procedural".into(),
        gltf: None,
        distance_heads: d.distance_heads,
        azimuth_deg: d.light.azimuth_deg,
        elevation_deg: d.light.elevation_deg,
    }
}

/// One row of the detailed report.
#[derive(Clone, Debug, Serialize)]
pub struct EvalRow {
    #[serde(flatten)]
    pub point: EvalPoint,
    pub skin_pixels: usize,
    pub frame_ms: f64,
}

pub struct EvalOptions {
    pub base: RenderSettings,
    pub warmup: usize,
    pub measured: usize,
    pub progress: bool,
}

fn load(spec: &SceneSpec) -> Result<Scene> {
    match &spec.gltf {
        None => Ok(default_scene()),
        Some(p) => load_gltf_scene(p, &TextureOverrides::default(), None),
    }
}

/// Runs the sweep; returns one row per (scene, config).
pub fn sweep(
    ctx: &Context,
    scenes: &[SceneSpec],
    configs: &[Config],
    opts: &EvalOptions,
) -> Result<Vec<EvalRow>> {
    let total = (scenes.len() * (configs.len() + 1)) as u64;
    let bar = opts.progress.then(|| {
        let b = indicatif::ProgressBar::new(total);
        b.set_style(
            indicatif::ProgressStyle::with_template("{msg:<40} [{bar:30}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let mut rows = Vec::new();
    for spec in scenes {
        let scene = load(spec).with_context(|| format!("loading scene '{}'", spec.name))?;
        let mut base = opts.base.clone();
        base.distance_heads = spec.distance_heads;
        base.light.azimuth_deg = spec.azimuth_deg;
        base.light.elevation_deg = spec.elevation_deg;
        let once = RunOptions::capture_once("eval");
        if let Some(b) = &bar {
            b.set_message(format!("{}: reference", spec.name));
        }
        let reference = run(
            ctx,
            &scene,
            &RenderSettings {
                method: ground_truth(),
                ..base.clone()
            },
            &once,
        )?;
        let ref_diffuse = reference.capture.context("reference capture")?.diffuse;
        let mask: Vec<bool> = ref_diffuse.iter().map(|p| p[3] > 0.0).collect();
        let skin = mask.iter().filter(|&&m| m).count();
        if let Some(b) = &bar {
            b.inc(1);
        }
        for c in configs {
            if let Some(b) = &bar {
                b.set_message(format!(
                    "{}: {} {}",
                    spec.name, c.method.name, c.setting.label
                ));
            }
            let s = base.clone().with(c.method, c.setting.options);
            let o = RunOptions {
                warmup: opts.warmup,
                measured: opts.measured,
                capture: true,
                ..once.clone()
            };
            let out = run(ctx, &scene, &s, &o).with_context(|| {
                format!("{} {} on '{}'", c.method.name, c.setting.label, spec.name)
            })?;
            let diffuse = out.capture.context("capture")?.diffuse;
            // With no skin in view there is nothing to score.
            let error = if skin > 0 {
                relative_rmse(&diffuse, &ref_diffuse, &mask)?
            } else {
                0.0
            };
            rows.push(EvalRow {
                point: EvalPoint {
                    method: c.method.name.to_string(),
                    setting: c.setting.label.to_string(),
                    scene: spec.name.clone(),
                    gpu_ms: out.report.sss_total_ms.map_or(0.0, |s| s.median),
                    error,
                },
                skin_pixels: skin,
                frame_ms: out.report.frame.map_or(0.0, |f| f.gpu_ms.median),
            });
            if let Some(b) = &bar {
                b.inc(1);
            }
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok(rows)
}

/// The summary as the CLI prints it.
pub fn summary_table(summary: &[EvalPoint]) -> String {
    let mut s = format!(
        "{:<12} {:<26} {:>10} {:>12}\n",
        "method", "setting", "SSS ms", "rel. RMSE"
    );
    for p in summary {
        s.push_str(&format!(
            "{:<12} {:<26} {:>10.4} {:>12.4e}\n",
            p.method, p.setting, p.gpu_ms, p.error
        ));
    }
    s
}

/// Mean cost and error of each (method, setting) over the scenes, for the chart.
pub fn summarise(rows: &[EvalRow]) -> Vec<EvalPoint> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in rows {
        let k = (r.point.method.clone(), r.point.setting.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(method, setting)| {
            let sel: Vec<&EvalRow> = rows
                .iter()
                .filter(|r| r.point.method == method && r.point.setting == setting)
                .collect();
            let n = sel.len() as f64;
            EvalPoint {
                gpu_ms: sel.iter().map(|r| r.point.gpu_ms).sum::<f64>() / n,
                error: sel.iter().map(|r| r.point.error).sum::<f64>() / n,
                scene: "mean over scenes".into(),
                method,
                setting,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_covers_every_method_but_the_ground_truth() {
        let r = registry();
        for m in METHODS {
            assert_eq!(
                r.iter().any(|c| c.method == *m),
                !m.ground_truth,
                "{}",
                m.name
            );
        }
        // The separable sample counts of the thesis are all there.
        for n in ["9", "17", "33"] {
            let c = r
                .iter()
                .find(|c| c.setting.label == format!("{n} samples"))
                .unwrap();
            let s = RenderSettings::default().with(c.method, c.setting.options);
            assert_eq!(s.method.opts(&s.options).raw("samples"), n);
        }
    }

    #[test]
    fn dolly_goes_from_one_to_twenty_four_head_heights_in_equal_ratios() {
        let d = dolly_scenes(PathBuf::from("head.glb"));
        assert_eq!(d.len(), 12);
        assert!((d[0].distance_heads - 1.0).abs() < 1e-6);
        assert!((d[11].distance_heads - 24.0).abs() < 1e-3);
        let r = d[1].distance_heads / d[0].distance_heads;
        for w in d.windows(2) {
            assert!((w[1].distance_heads / w[0].distance_heads - r).abs() < 1e-4);
        }
        let mut names: Vec<&str> = d.iter().map(|s| s.name.as_str()).collect();
        names.dedup();
        assert_eq!(
            names.len(),
            12,
            "scene names must be unique: rows are matched by name"
        );
    }

    #[test]
    fn thesis_scene_set_is_three_distances_by_four_lights_plus_default() {
        let s = thesis_scenes(Some(PathBuf::from("head.glb")));
        assert_eq!(s.len(), 13);
        assert!((s[0].distance_heads - 28.0 / 27.0).abs() < 1e-6);
        assert_eq!(s.iter().filter(|x| x.azimuth_deg == 110.0).count(), 3);
        assert!(s.iter().all(|x| x.gltf.is_some() || x.name == "procedural"));
        assert_eq!(thesis_scenes(None).len(), 1);
    }

    #[test]
    fn summary_averages_per_setting() {
        let row = |scene: &str, ms: f64, e: f64| EvalRow {
            point: EvalPoint {
                method: "m".into(),
                setting: "s".into(),
                scene: scene.into(),
                gpu_ms: ms,
                error: e,
            },
            skin_pixels: 1,
            frame_ms: 0.0,
        };
        let s = summarise(&[row("a", 1.0, 0.1), row("b", 3.0, 0.3)]);
        assert_eq!(s.len(), 1);
        assert!((s[0].gpu_ms - 2.0).abs() < 1e-12 && (s[0].error - 0.2).abs() < 1e-12);
    }
}
