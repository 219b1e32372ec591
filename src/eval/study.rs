//! `dermis eval` and `dermis compare` as library calls: resolve the scene set,
//! sweep every registered method against the ground truth, write the CSV, the
//! JSON and the charts; compare two render outputs.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use super::bands::{bands, Band, BandErrors, BandInput};
use super::metrics::{abs_error_map, false_colour, flip_ldr, relative_rmse};
use super::{accuracy_set, chart, pareto, sweep};
use crate::accuracy::Asset;
use crate::method::lookup;
use crate::output::{read_exr, write_json, write_rgba8_png};
use crate::render::RenderSettings;
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
        // The accuracy model's sweep: both heads, or one.
        "accuracy" => accuracy_set::accuracy_scenes(
            &[(Asset::Scan, Some(head()?)), (Asset::Procedural, None)],
            base,
        )?,
        "accuracy:scan" => accuracy_set::accuracy_scenes(&[(Asset::Scan, Some(head()?))], base)?,
        "accuracy:procedural" => {
            accuracy_set::accuracy_scenes(&[(Asset::Procedural, None)], base)?
        }
        other => bail!("unknown scene set '{other}' (valid: thesis, dolly, quick, accuracy, accuracy:scan, accuracy:procedural)"),
    })
}

/// What `eval` wrote.
pub struct EvalOutcome {
    pub summary: Vec<sweep::SummaryRow>,
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
    let mut files = vec![out.join("eval.csv"), out.join("eval.json")];
    sweep::write_csv(&files[0], &rows)?;
    let summary = sweep::summarise(&rows);
    // The ranking is made on the interior: the bands are shown beside it.
    let interior: Vec<pareto::EvalPoint> =
        summary.iter().map(|r| r.point(Band::Interior)).collect();
    let report = serde_json::json!({
        "device": ctx.facts.name, "driver": ctx.facts.driver, "command": command,
        "error": "err/none over the interior band: the method's RMS error against the ground truth over the no-SSS frame's (0 perfect, 1 no better than no SSS)",
        "scenes": specs, "rows": rows, "summary": summary,
        "pareto_front": pareto::pareto_front(&interior).iter().map(|&i| &summary[i]).collect::<Vec<_>>(),
    });
    write_json(&files[1], &report)?;
    let panels: Vec<chart::Panel> = Band::ALL
        .iter()
        .map(|&band| chart::Panel {
            title: match band {
                Band::Interior => "interior (ranking, Pareto front)".into(),
                b => b.name().into(),
            },
            y_label: format!("err/none, {}", band.name()),
            points: summary
                .iter()
                .filter(|r| r.band(band).scenes > 0)
                .map(|r| r.point(band))
                .collect(),
            front: band == Band::Interior,
        })
        .filter(|p| !p.points.is_empty())
        .collect();
    chart::panel_chart(
        &panels,
        &format!(
            "SSS cost vs error relative to no SSS ({}, {} scene(s))",
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
            // The registry names the lines (`MethodEntry::dolly`).
            let drawn = lookup(&p.method).is_ok_and(|m| m.dolly.contains(&p.setting.as_str()));
            if !drawn {
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
            "err/none over the interior",
            &out.join("distance.png"),
            &out.join("distance.svg"),
        )?;
        files.extend([out.join("distance.png"), out.join("distance.svg")]);
    }
    if specs.iter().any(|s| s.accuracy.is_some()) {
        // The accuracy model's data, chart and leave-one-scale-out error.
        let header = crate::accuracy::data::Header {
            command: command.to_string(),
            device: format!("{} ({})", ctx.facts.name, ctx.facts.driver),
            frame: format!(
                "{}x{}, the centre of the {}-row frame at {} deg vertical field of view (this frame's: {:.4} deg)",
                opts.base.width,
                opts.base.height,
                accuracy_set::REFERENCE_HEIGHT_PX,
                opts.base.fovy_deg,
                specs.iter().find_map(|s| s.fovy_deg).unwrap_or(opts.base.fovy_deg)
            ),
        };
        let rows = accuracy_set::rows_of(specs, &rows)?;
        let (loso, written) = accuracy_set::write(&rows, &header, out)?;
        println!("leave-one-scale-out prediction error (absolute err/none):\n{loso}");
        files.extend(written);
    }
    Ok(EvalOutcome { summary, files })
}

/// What `compare` measured.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub test: String,
    pub reference: String,
    /// The no-SSS output err/none and the gains are relative to, if given.
    pub none: Option<String>,
    pub skin_pixels: usize,
    /// Over all skin.
    pub relative_rmse: f64,
    /// Over the whole frame.
    pub flip_mean: f64,
    /// Per band: relative RMSE, FLIP, and with a no-SSS output err/none and gain.
    pub bands: BandErrors,
}

/// A render output directory: diffuse.exr, depth.exr, frame.png, report.json.
struct Output {
    width: u32,
    height: u32,
    diffuse: Vec<[f32; 4]>,
    frame: Vec<u8>,
}

impl Output {
    fn read(d: &Path) -> Result<Self> {
        let (width, height, diffuse) = read_exr(&d.join("diffuse.exr"))?;
        let p = d.join("frame.png");
        // Its sides within the range `render` accepts for a frame's width and height.
        let frame_bound = crate::files::ImageBound::rgba8(crate::render::settings::MAX_IMAGE_SIDE);
        let frame = crate::files::read_rgba8(&p, "frame", &frame_bound)?.into_raw();
        Ok(Output {
            width,
            height,
            diffuse,
            frame,
        })
    }

    fn same_size(&self, other: &Output, a: &Path, b: &Path) -> Result<()> {
        if (self.width, self.height) != (other.width, other.height) {
            bail!(
                "{} is {}x{} but {} is {}x{}",
                a.display(),
                self.width,
                self.height,
                b.display(),
                other.width,
                other.height
            );
        }
        Ok(())
    }
}

/// The bands of the reference output in `b`: its skin (diffuse alpha), its
/// depth.exr and its report's field of view and scale.
fn reference_bands(b: &Path, r: &Output, mask: &[bool]) -> Result<Vec<Option<Band>>> {
    let (w, h, depth) = read_exr(&b.join("depth.exr"))?;
    if (w, h) != (r.width, r.height) {
        bail!(
            "{}: depth.exr is {w}x{h}, diffuse.exr {}x{}",
            b.display(),
            r.width,
            r.height
        );
    }
    let report = crate::report::load(&b.join("report.json"))?;
    let depth: Vec<f32> = depth.iter().map(|d| d[0]).collect();
    Ok(bands(&BandInput::for_view(
        (w as usize, h as usize),
        mask,
        &depth,
        report.fovy_deg,
        report.mm_per_unit,
    )))
}

/// Compares the render output in `a` with the reference output in `b` (each a
/// directory with diffuse.exr, depth.exr, frame.png and report.json): relative
/// RMSE of the linear diffuse over skin pixels (skin from B), FLIP of the
/// tone-mapped frames, and both per band (interior, silhouette, depth step);
/// with `none` (the no-SSS output) also err/none and the per-channel gain per
/// band. Writes error images and compare.json into `out`.
pub fn compare(a: &Path, b: &Path, none: Option<&Path>, out: &Path) -> Result<Comparison> {
    let (ta, rb) = (Output::read(a)?, Output::read(b)?);
    ta.same_size(&rb, a, b)?;
    let zero = none.map(Output::read).transpose()?;
    if let (Some(z), Some(n)) = (&zero, none) {
        z.same_size(&rb, n, b)?;
    }
    let (wa, ha) = (ta.width, ta.height);
    let mask: Vec<bool> = rb.diffuse.iter().map(|p| p[3] > 0.0).collect();
    let rmse = relative_rmse(&ta.diffuse, &rb.diffuse, &mask)?;
    let flip = flip_ldr(&ta.frame, &rb.frame, wa, ha)?;
    let band_of = reference_bands(b, &rb, &mask)?;
    let band_errors = BandErrors::of(
        &ta.diffuse,
        &rb.diffuse,
        zero.as_ref().map(|z| z.diffuse.as_slice()),
        &flip.error_map,
        &band_of,
    );
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let save = |name: &str, rgba: Vec<u8>| write_rgba8_png(&out.join(name), wa, ha, rgba);
    /// Relative diffuse error mapped onto the colour ramp: 0..10%.
    const DIFFUSE_RAMP_MAX: f32 = 0.1;
    save(
        "error_diffuse.png",
        false_colour(
            &abs_error_map(&ta.diffuse, &rb.diffuse, &mask),
            wa,
            ha,
            DIFFUSE_RAMP_MAX,
        ),
    )?;
    save("error_flip.png", false_colour(&flip.error_map, wa, ha, 1.0))?;
    save("bands.png", band_picture(&band_of))?;
    let c = Comparison {
        test: a.display().to_string(),
        reference: b.display().to_string(),
        none: none.map(|n| n.display().to_string()),
        skin_pixels: mask.iter().filter(|&&m| m).count(),
        relative_rmse: rmse,
        flip_mean: flip.mean,
        bands: band_errors,
    };
    write_json(&out.join("compare.json"), &c)?;
    Ok(c)
}

/// The bands as a picture: interior grey, silhouette orange, depth steps blue,
/// off skin black.
fn band_picture(band_of: &[Option<Band>]) -> Vec<u8> {
    band_of
        .iter()
        .flat_map(|b| match b {
            None => [0, 0, 0, 255],
            Some(Band::Interior) => [150, 150, 150, 255],
            Some(Band::Silhouette) => [230, 159, 0, 255],
            Some(Band::DepthStep) => [0, 114, 178, 255],
        })
        .collect()
}

/// The comparison as the CLI prints it.
pub fn comparison_table(c: &Comparison) -> String {
    let mut s = format!(
        "skin pixels {}: relative RMSE {:.4e}, FLIP (frame) {:.4}\n",
        c.skin_pixels, c.relative_rmse, c.flip_mean
    );
    s.push_str(&format!(
        "{:<11} {:>8} {:>10} {:>8} {:>9} {:>17}\n",
        "band", "pixels", "rel. RMSE", "FLIP", "err/none", "gain R/G/B"
    ));
    for band in Band::ALL {
        let e = c.bands.get(band);
        let err_none = e.err_none.map_or("-".into(), |v| format!("{v:.3}"));
        let gain = e.gain.map_or("-".into(), |g| {
            format!("{:.2}/{:.2}/{:.2}", g[0], g[1], g[2])
        });
        s.push_str(&format!(
            "{:<11} {:>8} {:>10.4e} {:>8.4} {:>9} {:>17}\n",
            band.name(),
            e.pixels,
            e.rel_rmse,
            e.flip,
            err_none,
            gain
        ));
    }
    s
}
