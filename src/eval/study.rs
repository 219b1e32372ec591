//! `dermis eval` and `dermis compare` as library calls: resolve the scene set,
//! sweep every registered method against the ground truth, write the CSV, the
//! JSON and the charts; compare two render outputs.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use super::metrics::{abs_error_map, false_colour, flip_ldr, relative_rmse};
use super::{chart, pareto, sweep};
use crate::render::RenderSettings;
use crate::run::read_exr;
use crate::vk::context::Context;

/// The default head scan beside the project (never copied into it).
pub const DEFAULT_HEAD: &str = "../shared/assets/lee-perry-smith/LeePerrySmith.glb";

/// The named scene sets of `eval`.
pub fn scene_set(
    name: &str,
    head: Option<&Path>,
    base: &RenderSettings,
) -> Result<Vec<sweep::SceneSpec>> {
    let head = || -> Result<PathBuf> {
        let head = head.map_or_else(|| PathBuf::from(DEFAULT_HEAD), Path::to_path_buf);
        if !head.exists() {
            bail!("the '{name}' scene set needs the head scan: {} not found (give --scene PATH.glb, or --scenes quick)", head.display());
        }
        Ok(head)
    };
    Ok(match name {
        "thesis" => sweep::thesis_scenes(Some(head()?)),
        "dolly" => sweep::dolly_scenes(head()?),
        "quick" => vec![sweep::SceneSpec {
            distance_heads: base.distance_heads,
            ..sweep::procedural_scene()
        }],
        other => bail!("unknown scene set '{other}' (valid: thesis, dolly, quick)"),
    })
}

/// The curves of the dolly chart: one method at its default setting each.
const DOLLY_LINES: [(&str, &str); 6] = [
    ("none", "-"),
    ("separable", "17 samples"),
    ("ssg", "6 Gaussians, LOD"),
    ("ssg", "6 Gaussians, no LOD"),
    ("ss-jittered", "13 taps"),
    ("poisson", "8-32 taps"),
];

/// What `eval` wrote.
pub struct EvalOutcome {
    pub summary: Vec<pareto::EvalPoint>,
    pub files: Vec<PathBuf>,
}

/// Runs the sweep over `specs` and writes eval.csv, eval.json, chart.png/svg
/// (and for a dolly, distance.png/svg) into `out`.
pub fn eval(
    ctx: &Context,
    specs: &[sweep::SceneSpec],
    opts: &sweep::EvalOptions,
    out: &Path,
    command: &str,
    dolly: bool,
) -> Result<EvalOutcome> {
    let rows = sweep::sweep(ctx, specs, &sweep::registry(), opts)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let points: Vec<pareto::EvalPoint> = rows.iter().map(|r| r.point.clone()).collect();
    let mut files = vec![out.join("eval.csv"), out.join("eval.json")];
    pareto::write_csv(&files[0], &points)?;
    let summary = sweep::summarise(&rows);
    let report = serde_json::json!({
        "device": ctx.facts.name, "driver": ctx.facts.driver, "command": command,
        "scenes": specs, "rows": rows, "summary": summary,
        "pareto_front": pareto::pareto_front(&summary).iter().map(|&i| &summary[i]).collect::<Vec<_>>(),
    });
    std::fs::write(&files[1], serde_json::to_string_pretty(&report)?)
        .with_context(|| format!("writing {}", files[1].display()))?;
    chart::cost_error_chart(
        &summary,
        &format!(
            "SSS cost vs error ({}, {} scene(s))",
            ctx.facts.name,
            specs.len()
        ),
        "GPU ms (SSS passes, median)",
        &out.join("chart.png"),
        &out.join("chart.svg"),
    )?;
    files.extend([out.join("chart.png"), out.join("chart.svg")]);
    if dolly {
        // Error against distance: where a distance-driven switch changes the
        // image, the line steps.
        let mut series: Vec<chart::Series> = Vec::new();
        for r in &rows {
            let p = &r.point;
            if !DOLLY_LINES.contains(&(p.method.as_str(), p.setting.as_str())) {
                continue;
            }
            let Some(spec) = specs.iter().find(|s| s.name == p.scene) else {
                continue;
            };
            let label = format!("{} {}", p.method, p.setting);
            let point = (spec.distance_heads as f64, p.error);
            match series.iter_mut().find(|s| s.label == label) {
                Some(s) => s.points.push(point),
                None => series.push(chart::Series {
                    label,
                    points: vec![point],
                }),
            }
        }
        chart::series_chart(
            &series,
            &format!("SSS error along a dolly ({})", ctx.facts.name),
            "camera distance (head heights)",
            "relative RMSE against the reference",
            &out.join("distance.png"),
            &out.join("distance.svg"),
        )?;
        files.extend([out.join("distance.png"), out.join("distance.svg")]);
    }
    Ok(EvalOutcome { summary, files })
}

/// What `compare` measured.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub test: String,
    pub reference: String,
    pub skin_pixels: usize,
    pub relative_rmse: f64,
    pub flip_mean: f64,
}

/// Compares the render output in `a` with the reference output in `b` (each a
/// directory with diffuse.exr and frame.png): relative RMSE of the linear
/// diffuse over skin pixels (skin from B) and FLIP of the tone-mapped frames;
/// writes error images and compare.json into `out`.
pub fn compare(a: &Path, b: &Path, out: &Path) -> Result<Comparison> {
    let (wa, ha, da) = read_exr(&a.join("diffuse.exr"))?;
    let (wb, hb, db) = read_exr(&b.join("diffuse.exr"))?;
    if (wa, ha) != (wb, hb) {
        bail!(
            "{} is {wa}x{ha} but {} is {wb}x{hb}",
            a.display(),
            b.display()
        );
    }
    let load_png = |d: &Path| -> Result<Vec<u8>> {
        let p = d.join("frame.png");
        Ok(image::open(&p)
            .with_context(|| format!("reading {}", p.display()))?
            .to_rgba8()
            .into_raw())
    };
    let (fa, fb) = (load_png(a)?, load_png(b)?);
    let mask: Vec<bool> = db.iter().map(|p| p[3] > 0.0).collect();
    let rmse = relative_rmse(&da, &db, &mask)?;
    let flip = flip_ldr(&fa, &fb, wa, ha)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let save = |name: &str, rgba: Vec<u8>| -> Result<()> {
        let p = out.join(name);
        image::RgbaImage::from_raw(wa, ha, rgba)
            .context("error image size")?
            .save(&p)
            .with_context(|| format!("writing {}", p.display()))
    };
    /// Relative diffuse error mapped onto the colour ramp: 0..10%.
    const DIFFUSE_RAMP_MAX: f32 = 0.1;
    save(
        "error_diffuse.png",
        false_colour(&abs_error_map(&da, &db, &mask), wa, ha, DIFFUSE_RAMP_MAX),
    )?;
    save("error_flip.png", false_colour(&flip.error_map, wa, ha, 1.0))?;
    let c = Comparison {
        test: a.display().to_string(),
        reference: b.display().to_string(),
        skin_pixels: mask.iter().filter(|&&m| m).count(),
        relative_rmse: rmse,
        flip_mean: flip.mean,
    };
    let p = out.join("compare.json");
    std::fs::write(&p, serde_json::to_string_pretty(&c)?)
        .with_context(|| format!("writing {}", p.display()))?;
    Ok(c)
}
