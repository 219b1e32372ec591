//! A stand-in accuracy model until the per-setting model of issue 16's item 2
//! (`src/accuracy/`) is wired in: err/none of every setting measured by
//! `dermis eval --scenes dolly` (the Lee Perry-Smith head from 1 to 24 head
//! heights, one key light; `docs/perf/h100/dolly/eval.json`, on the H100),
//! interpolated in ln(px/mm) between the measured distances and `None`
//! outside them. The dolly scores the whole skin, not its bands: interior and
//! silhouette are both that number; its one light is not a range of angles,
//! so the light angle is not read. Pure: the rows are given.

use super::choose::Accuracy;

/// One measured point.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub method: String,
    pub setting: String,
    pub px_per_mm: f64,
    pub err_over_none: f64,
}

/// The measured points, by setting.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct DollyTable {
    pub points: Vec<Point>,
    /// Where the points come from (for the plan's notes).
    pub source: String,
}

impl Accuracy for DollyTable {
    fn predict(
        &self,
        method: &str,
        setting: &str,
        px_per_mm: f64,
        _light: f64,
        _shadow_mm: f64,
    ) -> Option<(f64, f64)> {
        let mut pts: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| p.method == method && p.setting == setting)
            .map(|p| (p.px_per_mm, p.err_over_none))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (lo, hi) = (pts.first()?.0, pts.last()?.0);
        if !(px_per_mm >= lo * (1.0 - 1e-9) && px_per_mm <= hi * (1.0 + 1e-9)) {
            return None;
        }
        let j = pts
            .iter()
            .position(|p| p.0 >= px_per_mm)
            .unwrap_or(pts.len() - 1);
        let e = if j == 0 || pts[j].0 == pts[j - 1].0 {
            pts[j].1
        } else {
            let (a, b) = (pts[j - 1], pts[j]);
            let t = (px_per_mm.ln() - a.0.ln()) / (b.0.ln() - a.0.ln());
            a.1 + (b.1 - a.1) * t
        };
        Some((e, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_inside_and_refuses_outside() {
        let p = |x: f64, e: f64| Point {
            method: "m".into(),
            setting: "s".into(),
            px_per_mm: x,
            err_over_none: e,
        };
        let t = DollyTable {
            points: vec![p(1.0, 0.2), p(4.0, 0.6)],
            source: String::new(),
        };
        let (e, _) = t.predict("m", "s", 2.0, 0.0, 0.2).unwrap();
        assert!((e - 0.4).abs() < 1e-12, "{e}");
        assert_eq!(t.predict("m", "s", 0.5, 0.0, 0.2), None);
        assert_eq!(t.predict("m", "s", 4.5, 0.0, 0.2), None);
        assert_eq!(t.predict("m", "x", 2.0, 0.0, 0.2), None);
    }
}
