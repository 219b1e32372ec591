//! The accuracy model's data (`profiles/accuracy/`, measured by `dermis eval
//! --scenes accuracy`): it loads, covers every registered method's eval
//! settings on both heads over the measured scales, gives back what was
//! measured, and says what no SSS is by definition. No device.

use dermis::accuracy::{AccuracyModel, Asset};
use dermis::eval::accuracy_set::{scales, SCALE_RANGE};
use dermis::eval::sweep::registry;

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
            // Inside the range a prediction at every light; outside none.
            for light in [0.0, 45.0, 90.0, 135.0, 180.0] {
                let p = m.predict(asset, method, setting, 1.0, light).unwrap();
                assert!(p.interior.is_finite() && p.interior >= 0.0);
                assert!(p.silhouette.is_finite() && p.silhouette >= 0.0);
            }
            assert!(m.predict(asset, method, setting, lo * 0.99, 60.0).is_none());
            assert!(m.predict(asset, method, setting, hi * 1.01, 60.0).is_none());
        }
        // Nothing measured that the registry does not name.
        assert_eq!(listed.len(), registry().len(), "{listed:?}");
        // No SSS is no better than no SSS, by definition.
        let none = m.predict(asset, "none", "-", 2.0, 70.0).unwrap();
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
    let text = std::fs::read_to_string(dir.join("scan.toml")).unwrap();
    let t: toml::Table = text.parse().unwrap();
    let rows = t["rows"].as_array().unwrap();
    assert!(rows.len() >= registry().len() * 32);
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
            )
            .unwrap();
        assert_eq!(p.interior, f("interior"), "{r:?}");
        if let Some(v) = r.get("silhouette") {
            assert_eq!(p.silhouette, v.as_float().unwrap());
        }
    }
}
