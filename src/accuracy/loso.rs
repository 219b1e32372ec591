//! Leave-one-out: how well the model predicts a point it was not given.
//! Leave-one-scale-out: for every setting and every measured scale strictly
//! inside its range (the ends cannot be interpolated from the others), the
//! scale is dropped, its errors predicted from the remaining ones at each
//! measured light and shadow texel, and compared with what was measured
//! there. Leave-one-shadow-out does the same along the shadow texel axis.

use serde::Serialize;

use super::{AccuracyModel, Asset, Curve};

/// Absolute prediction errors of one setting (or of all: `method` "all").
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Loso {
    pub asset: String,
    pub method: String,
    pub setting: String,
    /// Predicted points (interior).
    pub points: usize,
    pub interior_mean: f64,
    pub interior_max: f64,
    /// Over the points whose silhouette was measured (not carried from a
    /// neighbouring scale).
    pub silhouette_points: usize,
    pub silhouette_mean: f64,
    pub silhouette_max: f64,
}

#[derive(Default)]
struct Acc {
    n: usize,
    sum: f64,
    max: f64,
}

impl Acc {
    fn add(&mut self, e: f64) {
        self.n += 1;
        self.sum += e;
        self.max = self.max.max(e);
    }
    fn mean(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            self.sum / self.n as f64
        }
    }
}

/// Which axis a point is left out along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    Scale,
    Shadow,
}

fn errors(c: &Curve, axis: Axis, interior: &mut Acc, silhouette: &mut Acc) {
    let n = match axis {
        Axis::Scale => c.scales.len(),
        Axis::Shadow => c.shadows.len(),
    };
    for q in 1..n.saturating_sub(1) {
        let rest = match axis {
            Axis::Scale => c.without_scale(q),
            Axis::Shadow => c.without_shadow(q),
        };
        for (k, &shadow) in c.shadows.iter().enumerate() {
            for (j, &light) in c.lights.iter().enumerate() {
                for (i, &scale) in c.scales.iter().enumerate() {
                    let left_out = match axis {
                        Axis::Scale => i == q,
                        Axis::Shadow => k == q,
                    };
                    if !left_out {
                        continue;
                    }
                    let Some(p) = rest.predict(scale, light, shadow) else {
                        continue;
                    };
                    interior.add((p.interior - c.interior[k][j][i]).abs());
                    // A silhouette carried from a neighbour is no measurement to test against.
                    if c.silhouette_measured[k][j][i] {
                        silhouette.add((p.silhouette - c.silhouette[k][j][i]).abs());
                    }
                }
            }
        }
    }
}

fn row(asset: &str, method: &str, setting: &str, i: &Acc, s: &Acc) -> Loso {
    Loso {
        asset: asset.into(),
        method: method.into(),
        setting: setting.into(),
        points: i.n,
        interior_mean: i.mean(),
        interior_max: i.max,
        silhouette_points: s.n,
        silhouette_mean: s.mean(),
        silhouette_max: s.max,
    }
}

/// One row per setting, then one per asset over its settings and a last one
/// over everything (`method` "all").
pub fn leave_one_scale_out(m: &AccuracyModel) -> Vec<Loso> {
    leave_one_out(m, Axis::Scale)
}

/// The same along the shadow texel axis (empty points where a setting has
/// fewer than three measured texels).
pub fn leave_one_shadow_out(m: &AccuracyModel) -> Vec<Loso> {
    leave_one_out(m, Axis::Shadow)
}

fn leave_one_out(m: &AccuracyModel, axis: Axis) -> Vec<Loso> {
    let mut out = Vec::new();
    let (mut all_i, mut all_s) = (Acc::default(), Acc::default());
    for asset in Asset::ALL {
        let (mut ai, mut as_) = (Acc::default(), Acc::default());
        let mut any = false;
        for c in m.curves.iter().filter(|c| c.asset == asset) {
            any = true;
            let (mut i, mut s) = (Acc::default(), Acc::default());
            errors(c, axis, &mut i, &mut s);
            errors(c, axis, &mut ai, &mut as_);
            errors(c, axis, &mut all_i, &mut all_s);
            out.push(row(asset.name(), &c.method, &c.setting, &i, &s));
        }
        if any {
            out.push(row(asset.name(), "all", "", &ai, &as_));
        }
    }
    out.push(row("all", "all", "", &all_i, &all_s));
    out
}

/// The table as the command prints it.
pub fn table(rows: &[Loso]) -> String {
    let mut s = format!(
        "{:<11} {:<12} {:<26} {:>6} {:>9} {:>9} {:>6} {:>9} {:>9}\n",
        "asset",
        "method",
        "setting",
        "points",
        "int. mean",
        "int. max",
        "sil. n",
        "sil. mean",
        "sil. max"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<11} {:<12} {:<26} {:>6} {:>9.4} {:>9.4} {:>6} {:>9.4} {:>9.4}\n",
            r.asset,
            r.method,
            r.setting,
            r.points,
            r.interior_mean,
            r.interior_max,
            r.silhouette_points,
            r.silhouette_mean,
            r.silhouette_max
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::super::Row;
    use super::*;

    fn model(f: impl Fn(f64) -> f64) -> AccuracyModel {
        let rows: Vec<Row> = [0.5, 1.0, 2.0, 4.0]
            .into_iter()
            .map(|p| Row {
                asset: Asset::Scan,
                method: "m".into(),
                setting: "s".into(),
                px_per_mm: p,
                light_deg: 60.0,
                shadow_mm: 0.2,
                interior: f(p),
                silhouette: Some(f(p) * 2.0),
            })
            .collect();
        AccuracyModel::from_rows(&rows).unwrap()
    }

    #[test]
    fn a_curve_linear_in_log_scale_is_predicted_exactly() {
        let r = leave_one_scale_out(&model(|p: f64| 0.3 + 0.1 * p.log2()));
        // The two inner scales, one light.
        assert_eq!(r[0].points, 2);
        assert!(r[0].interior_max < 1e-12, "{r:?}");
        assert!(r[0].silhouette_max < 1e-12);
        assert_eq!(r.last().unwrap().method, "all");
    }

    #[test]
    fn a_kink_shows_as_the_error_at_the_dropped_scale() {
        // 0, 0, 1, 1 at 0.5, 1, 2, 4: dropping 1 px/mm predicts 0.5 from 0.5
        // and 2 (halfway in log), dropping 2 predicts 0.5 from 1 and 4.
        let r = leave_one_scale_out(&model(|p| if p < 1.5 { 0.0 } else { 1.0 }));
        assert!((r[0].interior_mean - 0.5).abs() < 1e-12, "{r:?}");
        assert!((r[0].interior_max - 0.5).abs() < 1e-12);
        assert!((r[0].silhouette_max - 1.0).abs() < 1e-12);
        assert!(table(&r).contains("0.5000"));
    }

    #[test]
    fn the_shadow_axis_is_left_out_alone() {
        // Linear in log texel at three texels: the middle one is predicted exactly.
        let rows: Vec<Row> = [0.2, 0.4, 0.8]
            .into_iter()
            .flat_map(|sh: f64| {
                [1.0, 2.0].into_iter().map(move |p| Row {
                    asset: Asset::Scan,
                    method: "m".into(),
                    setting: "s".into(),
                    px_per_mm: p,
                    light_deg: 60.0,
                    shadow_mm: sh,
                    interior: 0.5 + 0.1 * sh.log2(),
                    silhouette: Some(1.0 + sh.log2()),
                })
            })
            .collect();
        let m = AccuracyModel::from_rows(&rows).unwrap();
        let r = leave_one_shadow_out(&m);
        // The middle texel at both scales.
        assert_eq!(r[0].points, 2);
        assert!(
            r[0].interior_max < 1e-12 && r[0].silhouette_max < 1e-12,
            "{r:?}"
        );
        // Two scales: no inner scale to leave out.
        assert_eq!(leave_one_scale_out(&m)[0].points, 0);
    }
}
