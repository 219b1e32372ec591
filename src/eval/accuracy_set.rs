//! The accuracy model's scene set (`dermis eval --scenes accuracy`) and what
//! the sweep over it writes: the model's data (`src/accuracy/`), err/none
//! against px/mm per setting as a chart, and the model's leave-one-scale-out
//! error.
//!
//! The axis is the scale on screen, pixels per millimetre at the head
//! centre's depth, not a distance: every view is the centre of the
//! [`REFERENCE_HEIGHT_PX`]-row frame at the run's `--fovy` (the eval's 720p
//! view) from the distance that puts the head centre at the wanted scale,
//! rendered at the run's `--height` with the field of view narrowed to match.
//! At the reference height the view is that frame itself; a smaller frame is
//! its central crop, same eye, same perspective, same px/mm, with fewer
//! pixels to render (what a close view's crop leaves out is measured in
//! docs/accuracy.md, "The accuracy model").

use std::path::{Path, PathBuf};

use super::chart;
use super::sweep::{load, AccuracyPoint, EvalRow, SceneSpec};
use crate::accuracy::data::{to_toml, Header, Row};
use crate::accuracy::loso::{leave_one_scale_out, leave_one_shadow_out, table};
use crate::accuracy::{AccuracyModel, Asset};
use crate::render::RenderSettings;
use crate::scene::light::{shadow_frame, KeyLight};
use crate::view::ViewScale;
use anyhow::{Context as _, Result};
use glam::Vec3;

/// Rows of the frame the views are crops of (the eval's 1280x720).
pub const REFERENCE_HEIGHT_PX: u32 = 720;
/// Scales measured: 8 in equal ratios from 0.1 to 10 px/mm (a character 90
/// head heights away at 720p to closer than the zoom shot's 8.6).
pub const SCALES: usize = 8;
pub const SCALE_RANGE: (f64, f64) = (0.1, 10.0);
/// Key-light azimuths (degrees round from the camera side) at 45 degrees up:
/// the thesis scene set's.
pub const AZIMUTHS: [f32; 4] = [0.0, 60.0, 110.0, 150.0];
pub const ELEVATION_DEG: f32 = 45.0;

/// The measured scales, ascending.
pub fn scales() -> Vec<f64> {
    let (lo, hi) = SCALE_RANGE;
    (0..SCALES)
        .map(|i| lo * (hi / lo).powf(i as f64 / (SCALES - 1) as f64))
        .collect()
}

/// The views of the accuracy set on each asset (`None` path: the embedded
/// procedural face), for frames of `base.height` rows at `base.fovy_deg`.
pub fn accuracy_scenes(
    assets: &[(Asset, Option<PathBuf>)],
    base: &RenderSettings,
) -> Result<Vec<SceneSpec>> {
    let tan_ref = (0.5 * base.fovy_deg.to_radians()).tan();
    // The narrowed field of view: the reference frame's central `height` rows.
    let fovy_deg =
        (2.0 * (tan_ref * base.height as f32 / REFERENCE_HEIGHT_PX as f32).atan()).to_degrees();
    let mut v = Vec::new();
    for (asset, path) in assets {
        let probe = SceneSpec {
            name: asset.name().into(),
            gltf: path.clone(),
            distance_heads: 1.0,
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
            fovy_deg: None,
            accuracy: None,
        };
        let scene = load(&probe).with_context(|| format!("loading the {} head", asset.name()))?;
        let head_units = scene.head_height_units();
        let head_mm = f64::from(head_units * scene.mm_per_unit);
        let view = ViewScale::new(base.height, fovy_deg.to_radians(), scene.mm_per_unit);
        // One head, so the shadow map is fitted to its bounds whatever the
        // view (scene::framing::frame does the same with one instance), and
        // the texel is the same at every scale and light.
        let shadow_mm = shadow_frame(Vec3::Y, Vec3::ZERO, scene.head_bounds.bounding_radius())
            .texel_mm(base.shadow_size, scene.mm_per_unit);
        for p in scales() {
            // Where the reference frame has `p` px/mm at the head centre.
            let distance_heads =
                (f64::from(REFERENCE_HEIGHT_PX) / (2.0 * f64::from(tan_ref) * p * head_mm)) as f32;
            // The scale the renderer will use (shaders/view_scale.glsl's product).
            let px_per_mm = f64::from(view.px_per_mm(distance_heads * head_units));
            for az in AZIMUTHS {
                let light = KeyLight {
                    azimuth_deg: az,
                    elevation_deg: ELEVATION_DEG,
                    ..base.light
                };
                let to_light = light.direction_to_light(scene.forward);
                let cos = f64::from(to_light.dot(scene.forward.normalize()));
                let light_deg = cos.clamp(-1.0, 1.0).acos().to_degrees();
                v.push(SceneSpec {
                    name: format!("{} {p:.3} px/mm {az:.0}deg", asset.name()),
                    gltf: path.clone(),
                    distance_heads,
                    azimuth_deg: az,
                    elevation_deg: ELEVATION_DEG,
                    fovy_deg: Some(fovy_deg),
                    accuracy: Some(AccuracyPoint {
                        asset: asset.name().into(),
                        px_per_mm,
                        light_deg,
                        shadow_mm,
                    }),
                });
            }
        }
    }
    Ok(v)
}

/// The model's rows of a sweep over the accuracy set: `none` is 1 in both
/// bands by definition; a band without pixels has no value (the silhouette of
/// a frame that is all skin).
pub fn rows_of(specs: &[SceneSpec], rows: &[EvalRow]) -> Result<Vec<Row>> {
    let mut out = Vec::new();
    for r in rows {
        let p = &r.point;
        let Some(spec) = specs.iter().find(|s| s.name == p.scene) else {
            continue;
        };
        let Some(a) = &spec.accuracy else { continue };
        // The accuracy model predicts err/none against the six Gaussians'
        // truth (the planner's look); another profile's settings answer to
        // another truth (`sweep::six_gaussian_registry`).
        if !r.profile.is_six_gaussian() {
            continue;
        }
        let none = p.method == crate::method::none().name;
        let interior = if none {
            1.0
        } else {
            r.bands.interior.err_none.with_context(|| {
                format!(
                    "{} {} on '{}': no interior pixels",
                    p.method, p.setting, p.scene
                )
            })?
        };
        out.push(Row {
            asset: Asset::parse(&a.asset)?,
            method: p.method.clone(),
            setting: p.setting.clone(),
            px_per_mm: a.px_per_mm,
            light_deg: a.light_deg,
            shadow_mm: a.shadow_mm,
            interior,
            silhouette: if none {
                Some(1.0)
            } else {
                r.bands.silhouette.err_none
            },
        });
    }
    Ok(out)
}

/// Writes the data (one file per asset, `scan.toml`, `procedural.toml`), the
/// chart per asset (`accuracy-ASSET.png/svg`: interior err/none against px/mm,
/// the mean over the lights, one line per setting) and `loso.json`; prints and
/// returns the leave-one-scale-out table.
pub fn write(rows: &[Row], header: &Header, out: &Path) -> Result<(String, Vec<PathBuf>)> {
    let mut files = Vec::new();
    for asset in Asset::ALL {
        let mine: Vec<Row> = rows.iter().filter(|r| r.asset == asset).cloned().collect();
        if mine.is_empty() {
            continue;
        }
        let f = out.join(format!("{}.toml", asset.name()));
        std::fs::write(&f, to_toml(header, &mine)?)
            .with_context(|| format!("writing {}", f.display()))?;
        files.push(f);
    }
    let model = AccuracyModel::from_rows(rows)?;
    files.extend(charts(&model, out)?);
    let loso = leave_one_scale_out(&model);
    let f = out.join("loso.json");
    crate::output::write_json(&f, &loso)?;
    files.push(f);
    let mut text = table(&loso);
    // Along the shadow axis where it has an inner texel to leave out.
    let loss = leave_one_shadow_out(&model);
    if loss.last().is_some_and(|r| r.points > 0) {
        let f = out.join("loso-shadow.json");
        crate::output::write_json(&f, &loss)?;
        files.push(f);
        text.push_str("\nleave one shadow texel out:\n");
        text.push_str(&table(&loss));
    }
    Ok((text, files))
}

/// One chart per asset and measured shadow texel: each setting's interior
/// err/none, averaged over the measured lights, against px/mm (log). The
/// finest texel's is `accuracy-ASSET.png/svg` (one head's own shadow map),
/// each wider one `accuracy-ASSET-shadow-MMmm.png/svg`.
pub fn charts(model: &AccuracyModel, out: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for asset in Asset::ALL {
        let Some(first) = model.curves.iter().find(|c| c.asset == asset) else {
            continue;
        };
        for (k, &shadow_mm) in first.shadows.iter().enumerate() {
            let series: Vec<chart::Series> = model
                .curves
                .iter()
                .filter(|c| c.asset == asset)
                .filter_map(|c| {
                    let grid = c.interior.get(k)?;
                    Some(chart::Series {
                        label: format!("{} {}", c.method, c.setting),
                        points: c
                            .scales
                            .iter()
                            .enumerate()
                            .map(|(i, &p)| {
                                let n = c.lights.len() as f64;
                                (p, grid.iter().map(|l| l[i]).sum::<f64>() / n)
                            })
                            .collect(),
                    })
                })
                .collect();
            let stem = if k == 0 {
                format!("accuracy-{}", asset.name())
            } else {
                format!("accuracy-{}-shadow-{shadow_mm:.2}mm", asset.name())
            };
            let (png, svg) = (
                out.join(format!("{stem}.png")),
                out.join(format!("{stem}.svg")),
            );
            chart::series_chart(
                &series,
                &format!(
                    "err/none against scale, {}, shadow texel {shadow_mm:.2} mm (mean over {} lights)",
                    asset.name(),
                    first.lights.len()
                ),
                "pixels per mm at the head centre",
                "err/none over the interior",
                &png,
                &svg,
            )?;
            files.extend([png, svg]);
        }
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_span_a_hundredfold_in_equal_ratios() {
        let s = scales();
        assert_eq!(s.len(), 8);
        assert!((s[0] - 0.1).abs() < 1e-12 && (s[7] - 10.0).abs() < 1e-9);
        let r = s[1] / s[0];
        for w in s.windows(2) {
            assert!((w[1] / w[0] - r).abs() < 1e-9);
        }
    }

    // The views hold their scale: at the reference height the frame is the
    // eval's own view, in a smaller frame the same px/mm from the same eye.
    #[test]
    fn every_view_has_its_scale_and_light() {
        let mut base = RenderSettings::study();
        let full = accuracy_scenes(&[(Asset::Procedural, None)], &base).unwrap();
        base.height = 180;
        let crop = accuracy_scenes(&[(Asset::Procedural, None)], &base).unwrap();
        assert_eq!(full.len(), SCALES * AZIMUTHS.len());
        for (f, c) in full.iter().zip(&crop) {
            let (fa, ca) = (f.accuracy.as_ref().unwrap(), c.accuracy.as_ref().unwrap());
            assert_eq!(f.distance_heads, c.distance_heads);
            assert!(
                (fa.px_per_mm / ca.px_per_mm - 1.0).abs() < 1e-5,
                "{fa:?} {ca:?}"
            );
            assert!((f.fovy_deg.unwrap() - 20.0).abs() < 1e-5);
            assert!(c.fovy_deg.unwrap() < 5.1);
        }
        // One head's shadow map at 2048: a texel of its fitted extent over 2048,
        // the same in every view, and 4x as wide at 512.
        let sh = full[0].accuracy.as_ref().unwrap().shadow_mm;
        assert!(sh > 0.05 && sh < 0.5, "{sh}");
        assert!(full
            .iter()
            .all(|f| f.accuracy.as_ref().unwrap().shadow_mm == sh));
        base.shadow_size = 512;
        let wide = accuracy_scenes(&[(Asset::Procedural, None)], &base).unwrap();
        let sw = wide[0].accuracy.as_ref().unwrap().shadow_mm;
        assert!((sw / sh - 4.0).abs() < 1e-9, "{sw} {sh}");
        let want = scales();
        for (i, p) in want.iter().enumerate() {
            let a = full[i * AZIMUTHS.len()].accuracy.as_ref().unwrap();
            assert!(
                (a.px_per_mm / p - 1.0).abs() < 1e-5,
                "{} vs {p}",
                a.px_per_mm
            );
        }
        // Light 60 round and 45 up: acos(cos 60 cos 45) = 69.3 degrees from the camera.
        let a = full[1].accuracy.as_ref().unwrap();
        assert!((a.light_deg - 69.295).abs() < 1e-3, "{}", a.light_deg);
        let mut names: Vec<&str> = full.iter().map(|s| s.name.as_str()).collect();
        names.dedup();
        assert_eq!(names.len(), full.len());
    }
}
