//! Thesis Table 9.1 as data, and what its ten games say on their own
//! (issue 17 item 7; docs/aa.md, "Table 9.1 re-scored").
//!
//! The table times Jimenez's MLAA at 1280x720 on five screenshots of each of
//! ten games, on the Xbox 360 and on a GeForce 9800 GTX+. The screenshots'
//! edge shares are unknown, but each game's two columns come from the same
//! screenshots. So a straight line through the ten (9800 GTX+, Xbox 360) pairs
//! separates what grows with the content (its slope: the Xbox 360's cost of
//! the 9800's per unit of content-dependent work) from what does not (its
//! intercept: the Xbox 360's cost the 9800's content-independent work does not
//! explain). No dermis code produced these numbers: they check the budget
//! model from outside.
//!
//! Pure: the table, a least-squares line with its standard errors, and where a
//! modelled cost line meets a published time.

/// One row of Table 9.1 (thesis 000, ch. 9.6): average and standard
/// deviation over five screenshots, in ms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Game {
    pub name: &'static str,
    pub xbox360_ms: f64,
    pub xbox360_sd_ms: f64,
    pub g92_ms: f64,
    pub g92_sd_ms: f64,
}

const fn game(name: &'static str, x: f64, xs: f64, g: f64, gs: f64) -> Game {
    Game {
        name,
        xbox360_ms: x,
        xbox360_sd_ms: xs,
        g92_ms: g,
        g92_sd_ms: gs,
    }
}

/// The table's ten games, in its order (the names as printed).
pub const TABLE_9_1: [Game; 10] = [
    game("Assasin's Creed", 4.37, 0.61, 0.55, 0.13),
    game("Bioshock", 3.44, 0.09, 0.37, 0.00),
    game("Crysis", 3.92, 0.10, 0.44, 0.02),
    game("Dead Space", 3.65, 0.45, 0.39, 0.03),
    game("Devil May Cry 4", 3.46, 0.34, 0.39, 0.04),
    game("GTA IV", 4.11, 0.23, 0.47, 0.04),
    game("Modern Warfare 2", 4.38, 0.80, 0.57, 0.17),
    game("NFS Shift", 3.54, 0.35, 0.42, 0.04),
    game("Split/Second", 3.85, 0.27, 0.46, 0.05),
    game("S.T.A.L.K.E.R.", 3.18, 0.05, 0.36, 0.01),
];

/// The table's grand averages (Xbox 360, 9800 GTX+), ms.
pub const GRAND_AVERAGE_MS: (f64, f64) = (3.79, 0.44);

/// Published bilinear texel rates, GTexel/s (../shared/docs/HARDWARE.md:
/// Xenos 16 filtering units at 500 MHz; the 9800 GTX+'s 47.2), the same
/// numbers `profiles/xbox360.toml` and `profiles/geforce-9800-gtx-plus.toml`
/// hold (a test checks).
pub const TEXEL_GTEXELS: (f64, f64) = (8.0, 47.2);

/// A least-squares line `y = intercept + slope x` with its correlation and
/// the standard errors of its two coefficients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub slope: f64,
    pub intercept: f64,
    pub r: f64,
    pub slope_se: f64,
    pub intercept_se: f64,
}

impl Line {
    /// `y` at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }

    /// The `x` at which the line reaches `y`; `None` for a flat line, or
    /// where that `x` is negative (the line starts above `y`).
    pub fn reaches(&self, y: f64) -> Option<f64> {
        if self.slope == 0.0 {
            return None;
        }
        let x = (y - self.intercept) / self.slope;
        (x >= 0.0).then_some(x)
    }
}

/// Ordinary least squares through `(x, y)` points; `None` with fewer than
/// three points or no spread in `x` (no standard error without a residual
/// degree of freedom).
pub fn fit_line(points: &[(f64, f64)]) -> Option<Line> {
    let n = points.len();
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = points.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let r = if syy > 0.0 {
        sxy / (sxx * syy).sqrt()
    } else {
        1.0
    };
    let ss_res: f64 = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    let s2 = ss_res / (nf - 2.0);
    Some(Line {
        slope,
        intercept,
        r,
        slope_se: (s2 / sxx).sqrt(),
        intercept_se: (s2 * (1.0 / nf + mx * mx / sxx)).sqrt(),
    })
}

/// The ten games' line: Xbox 360 ms against 9800 GTX+ ms.
pub fn games_line() -> Line {
    let pts: Vec<(f64, f64)> = TABLE_9_1.iter().map(|g| (g.g92_ms, g.xbox360_ms)).collect();
    // Ten points with spread in x: the fit always exists.
    fit_line(&pts).expect("Table 9.1 has ten games")
}

/// The least the 9800 GTX+'s content-independent work can cost: no game ran
/// faster than it, and every game's screenshots hold some edges. The
/// smallest average, ms.
pub fn g92_floor_bound_ms() -> f64 {
    TABLE_9_1
        .iter()
        .map(|g| g.g92_ms)
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transcribed_rows_give_the_printed_grand_averages() {
        let n = TABLE_9_1.len() as f64;
        let x = TABLE_9_1.iter().map(|g| g.xbox360_ms).sum::<f64>() / n;
        let g = TABLE_9_1.iter().map(|g| g.g92_ms).sum::<f64>() / n;
        // The table prints its averages to two decimals.
        assert!((x - GRAND_AVERAGE_MS.0).abs() < 0.005, "{x}");
        assert!((g - GRAND_AVERAGE_MS.1).abs() < 0.005, "{g}");
        let sd = TABLE_9_1.iter().map(|g| g.xbox360_sd_ms).sum::<f64>() / n;
        assert!((sd - 0.33).abs() < 0.005, "{sd}");
    }

    #[test]
    fn a_line_through_exact_points_is_exact() {
        let l = fit_line(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0), (4.0, 9.0)]).unwrap();
        assert!((l.slope - 2.0).abs() < 1e-12 && (l.intercept - 1.0).abs() < 1e-12);
        assert!((l.r - 1.0).abs() < 1e-12 && l.slope_se < 1e-9 && l.intercept_se < 1e-9);
        assert_eq!(l.reaches(9.0), Some(4.0));
        assert_eq!(l.reaches(0.0), None);
        assert!(fit_line(&[(1.0, 1.0), (1.0, 2.0), (1.0, 3.0)]).is_none());
        assert!(fit_line(&[(1.0, 1.0), (2.0, 2.0)]).is_none());
    }

    #[test]
    fn the_games_scale_like_the_texel_rates_with_a_fixed_xbox_360_cost() {
        let l = games_line();
        // Computed by hand from the ten rows: 5.39, 1.41 ms, r 0.956.
        assert!((l.slope - 5.390).abs() < 0.005, "{l:?}");
        assert!((l.intercept - 1.408).abs() < 0.005, "{l:?}");
        assert!((l.r - 0.956).abs() < 0.001, "{l:?}");
        // The texel-rate ratio (5.9) lies within one standard error of the
        // slope; the ALU (1.96), fill (2.95) and bandwidth (3.14) ratios of
        // the same two GPUs (HARDWARE.md) lie more than three away.
        let texel = TEXEL_GTEXELS.1 / TEXEL_GTEXELS.0;
        assert!((texel - l.slope).abs() < l.slope_se, "{texel} {l:?}");
        for other in [470.0 / 240.0, 11.8 / 4.0, 70.4 / 22.4] {
            assert!((l.slope - other) > 3.0 * l.slope_se, "{other} {l:?}");
        }
        // The intercept is positive beyond doubt: a cost the Xbox 360 pays
        // that the 9800's times do not scale into.
        assert!(l.intercept > 2.0 * l.intercept_se, "{l:?}");
        assert!((g92_floor_bound_ms() - 0.36).abs() < 1e-12);
    }

    #[test]
    fn the_profiles_hold_the_published_texel_rates() {
        use crate::budget::profile::Profile;
        let x = Profile::load("xbox360").unwrap();
        let g = Profile::load("geforce-9800-gtx-plus").unwrap();
        assert_eq!(x.texture.bilinear_gtexels.value(), Some(TEXEL_GTEXELS.0));
        assert_eq!(g.texture.bilinear_gtexels.value(), Some(TEXEL_GTEXELS.1));
    }
}
