//! The planner's accuracy source: the measured table of `profiles/accuracy/`
//! (`crate::accuracy`, the sweep of issue 16 item 2) for the head the scene
//! is: the scan's table for a loaded model, the procedural face's for the
//! built-in scenes.

use anyhow::Result;

use super::choose::Accuracy;
use crate::accuracy::{AccuracyModel, Asset};

/// The measured accuracy model of one head.
pub struct Measured {
    pub model: AccuracyModel,
    pub asset: Asset,
}

impl Measured {
    /// The project's table for `asset`.
    pub fn load_default(asset: Asset) -> Result<Measured> {
        Ok(Measured {
            model: AccuracyModel::load_default()?,
            asset,
        })
    }

    /// The head a scene is: a loaded model is taken for a scan (the only scan
    /// the table holds), a built-in scene for the procedural face.
    pub fn asset_of(scene_path: Option<&std::path::Path>) -> Asset {
        match scene_path {
            Some(p) if !p.to_string_lossy().starts_with("builtin:") => Asset::Scan,
            _ => Asset::Procedural,
        }
    }

    /// Where the predictions come from, for the plan's notes.
    pub fn source(&self) -> String {
        format!(
            "the measured accuracy table of profiles/accuracy/ ({} head)",
            self.asset.name()
        )
    }
}

impl Accuracy for Measured {
    fn predict(
        &self,
        method: &str,
        setting: &str,
        px_per_mm: f64,
        light_deg: f64,
        shadow_mm: f64,
    ) -> Option<(f64, f64)> {
        self.model
            .predict(self.asset, method, setting, px_per_mm, light_deg, shadow_mm)
            .map(|p| (p.interior, p.silhouette))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_project_table_answers_for_every_registered_setting_in_its_range() {
        for asset in Asset::ALL {
            let m = Measured::load_default(asset).unwrap();
            for r in super::super::pipeline::registered() {
                let (lo, hi) = m
                    .model
                    .range(asset, r.method, r.eval)
                    .unwrap_or_else(|| panic!("{} {} not measured", r.method, r.eval));
                let mid = (lo * hi).sqrt();
                let widest = m.model.widest_shadow_mm(asset, r.method, r.eval).unwrap();
                let (i, s) = m.predict(r.method, r.eval, mid, 60.0, widest).unwrap();
                assert!(i.is_finite() && i >= 0.0 && s.is_finite() && s >= 0.0);
                assert!(m
                    .predict(r.method, r.eval, hi * 1.5, 60.0, widest)
                    .is_none());
                assert!(m
                    .predict(r.method, r.eval, mid, 60.0, widest * 1.01)
                    .is_none());
            }
        }
        assert_eq!(Measured::asset_of(None), Asset::Procedural);
        assert_eq!(
            Measured::asset_of(Some(std::path::Path::new("head.glb"))),
            Asset::Scan
        );
    }
}
