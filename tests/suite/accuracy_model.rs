//! The accuracy model's data (`profiles/accuracy/`, measured by `dermis eval
//! --scenes accuracy`): it loads, covers every registered method's eval
//! settings on both heads over the measured scales, gives back what was
//! measured, and says what no SSS is by definition. No device.

use dermis::accuracy::{AccuracyModel, Asset};
use dermis::eval::accuracy_set::{scales, SCALE_RANGE};
use dermis::eval::sweep::six_gaussian_registry as registry;

#[test]
fn the_projects_data_covers_every_registered_setting_on_both_heads() {
    let m = AccuracyModel::load_default().expect("profiles/accuracy/ loads");
    for asset in Asset::ALL {
        let listed = m.settings(asset);
        for c in registry() {
            let (method, setting) = (c.method.name, c.setting.label);
            assert!(
                listed.iter().any(|(a, b)| a == method && b == setting),
                "{} lacks {method} '{setting}'",
                asset.name()
            );
            // Measured from 0.1 to 10 px/mm (f32 scales: within 1e-6).
            let (lo, hi) = m.range(asset, method, setting).unwrap();
            assert!((lo / SCALE_RANGE.0 - 1.0).abs() < 1e-6, "{lo}");
            assert!((hi / SCALE_RANGE.1 - 1.0).abs() < 1e-6, "{hi}");
            let curve = m.curve(asset, method, setting).unwrap();
            assert_eq!(curve.scales.len(), scales().len());
            assert_eq!(curve.lights.len(), 4);
            // One head's own 2048 shadow map and 512, 128 and 32: texels in
            // ratios of 4.
            assert_eq!(curve.shadows.len(), 4, "{:?}", curve.shadows);
            for w in curve.shadows.windows(2) {
                assert!((w[1] / w[0] - 4.0).abs() < 1e-6, "{:?}", curve.shadows);
            }
            let (fine, wide) = (curve.shadows[0], curve.shadows[3]);
            // Inside the range a prediction at every light and texel; outside none.
            for light in [0.0, 45.0, 90.0, 135.0, 180.0] {
                for sh in [fine * 0.5, fine, (fine * wide).sqrt(), wide] {
                    let p = m.predict(asset, method, setting, 1.0, light, sh).unwrap();
                    assert!(p.interior.is_finite() && p.interior >= 0.0);
                    assert!(p.silhouette.is_finite() && p.silhouette >= 0.0);
                }
            }
            assert!(m
                .predict(asset, method, setting, lo * 0.99, 60.0, fine)
                .is_none());
            assert!(m
                .predict(asset, method, setting, hi * 1.01, 60.0, fine)
                .is_none());
            assert!(m
                .predict(asset, method, setting, 1.0, 60.0, wide * 1.01)
                .is_none());
        }
        // Nothing measured that the registry does not name.
        assert_eq!(listed.len(), registry().len(), "{listed:?}");
        // No SSS is no better than no SSS, by definition.
        let none = m.predict(asset, "none", "-", 2.0, 70.0, 1.0).unwrap();
        assert_eq!((none.interior, none.silhouette), (1.0, 1.0));
    }
    // The data's command regenerates it.
    assert!(m
        .headers
        .iter()
        .all(|h| h.command.contains("eval") && h.command.contains("--scenes accuracy")));
}

// The model gives back each measured point exactly, against the file's text
// read here by plain TOML (not through the model's loader).
#[test]
fn the_model_returns_the_measured_points_of_the_file() {
    let dir = dermis::accuracy::default_dir();
    let m = AccuracyModel::load_default().unwrap();
    // scan.toml (one head's own shadow map) and scan-sN.toml (an N-texel map).
    let mut rows = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let f = e.unwrap().path();
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with("scan") && name.ends_with(".toml") {
            let t: toml::Table = std::fs::read_to_string(&f).unwrap().parse().unwrap();
            rows.extend(t["rows"].as_array().unwrap().iter().cloned());
        }
    }
    assert!(rows.len() >= registry().len() * 32 * 4);
    for r in rows.iter().step_by(37) {
        let s = |k: &str| r[k].as_str().unwrap();
        let f = |k: &str| r[k].as_float().unwrap();
        let p = m
            .predict(
                Asset::Scan,
                s("method"),
                s("setting"),
                f("px_per_mm"),
                f("light_deg"),
                f("shadow_mm"),
            )
            .unwrap();
        assert_eq!(p.interior, f("interior"), "{r:?}");
        if let Some(v) = r.get("silhouette") {
            assert_eq!(p.silhouette, v.as_float().unwrap());
        }
    }
}

// The data's shadow texels are those of the sweep's own frames: one head's
// shadow map fitted to it at 2048, 512, 128 and 32 texels, computed here from
// each head's scene the way the sweep places it.
#[test]
fn the_datas_shadow_texels_are_the_sweeps_frames() {
    let mut base = dermis::render::RenderSettings::study();
    let mut frames = Vec::new();
    for (asset, path) in [
        (Asset::Procedural, None),
        (Asset::Scan, crate::common::lps_path()),
    ] {
        if asset == Asset::Scan && path.is_none() {
            continue;
        }
        for (k, size) in [2048u32, 512, 128, 32].into_iter().enumerate() {
            base.shadow_size = size;
            let specs =
                dermis::eval::accuracy_set::accuracy_scenes(&[(asset, path.clone())], &base)
                    .unwrap();
            let sh = specs[0].accuracy.as_ref().unwrap().shadow_mm;
            println!("{} at {size}: shadow texel {sh:?} mm", asset.name());
            frames.push((asset, k, size, sh));
        }
    }
    let m = AccuracyModel::load_default().unwrap();
    for (asset, k, size, sh) in frames {
        let curve = m.curve(asset, "none", "-").unwrap();
        // Within 1e-6: the face's eyes (issue 29) carved its lids open, and
        // that moved its bounds by 5e-7 of their radius; the data is of the
        // face before its eyes (docs/accuracy.md).
        assert!(
            (curve.shadows[k] / sh - 1.0).abs() < 1e-6,
            "{} at {size}: data {} against the frame's {sh}",
            asset.name(),
            curve.shadows[k]
        );
    }
}

// The model's own prediction error on the project's data, along both
// interpolated axes (printed; docs/accuracy.md quotes these tables): leaving
// a scale out, and leaving a shadow texel out (512 and 128, predicted from
// their neighbours four times finer and coarser).
#[test]
fn leave_one_out_on_the_projects_data() {
    use dermis::accuracy::loso::{leave_one_scale_out, leave_one_shadow_out, table};
    let m = AccuracyModel::load_default().unwrap();
    let scale = leave_one_scale_out(&m);
    let shadow = leave_one_shadow_out(&m);
    println!("leave one scale out:\n{}", table(&scale));
    println!("leave one shadow texel out:\n{}", table(&shadow));
    let all = |v: &[dermis::accuracy::loso::Loso]| v.last().unwrap().clone();
    // 16 settings x 4 lights x 4 texels x 6 inner scales x 2 heads.
    assert_eq!(all(&scale).points, 16 * 4 * 4 * 6 * 2);
    // ... and x 2 inner texels x 8 scales.
    assert_eq!(all(&shadow).points, 16 * 4 * 2 * 8 * 2);
    assert!(all(&scale).interior_mean < 0.1, "{:?}", all(&scale));
    assert!(all(&shadow).interior_mean < 0.1, "{:?}", all(&shadow));
}
