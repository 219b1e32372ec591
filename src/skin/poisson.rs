//! Poisson-disk screen-space SSS (seed 003): one 2D pass of up to 32 taps
//! spread over a disk, each weighted by its distance to the centre (per
//! channel), its depth difference and its normal difference.
//!
//! Why a Poisson disk: well-spread taps with no regular structure give the
//! smoothest result for a fixed tap count, and because points are kept in
//! generation order, the first 8 or 16 are spread out too, so distant
//! (small on screen) skin can use fewer taps (the seed's "LOD").

use super::profile::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};

/// Seed of the dart-throwing generator (the golden-ratio constant).
const DISK_SEED: u32 = 0x9E37_79B9;
/// Minimum distance the dart throwing starts with.
const DISK_START_MIN_DISTANCE: f32 = 0.3;
/// Factor applied to the minimum distance after too many failed darts.
const DISK_SHRINK: f32 = 0.95;
/// Consecutive failed darts before the minimum distance shrinks.
const DISK_MAX_FAILURES: u32 = 1000;

/// xorshift32 (Marsaglia's 13/17/5 triple).
struct XorShift32(u32);

impl XorShift32 {
    fn next(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }

    /// Uniform in `[-1, 1)` from the top 24 bits (exact in f32).
    fn signed_unit(&mut self) -> f32 {
        (self.next() >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
    }
}

/// Dart throwing in the unit disk: returns the points and the final
/// minimum distance.
///
/// A dart is a uniform point of the square `[-1, 1)^2`; darts outside the
/// unit disk (`x^2 + y^2 > 1`) are thrown again without counting. A dart
/// closer than the current minimum distance to an accepted point is a
/// failure; after [`DISK_MAX_FAILURES`] consecutive failures the minimum
/// distance shrinks by [`DISK_SHRINK`] and the count restarts. Accepted
/// points keep their generation order and stay valid when the distance
/// shrinks.
fn dart_throw(n: usize) -> (Vec<[f32; 2]>, f32) {
    let mut rng = XorShift32(DISK_SEED);
    let mut min_dist = DISK_START_MIN_DISTANCE;
    let mut failures = 0;
    let mut points: Vec<[f32; 2]> = Vec::with_capacity(n);
    while points.len() < n {
        let x = rng.signed_unit();
        let y = rng.signed_unit();
        if x * x + y * y > 1.0 {
            continue;
        }
        let min2 = min_dist * min_dist;
        let ok = points.iter().all(|p| {
            let (dx, dy) = (p[0] - x, p[1] - y);
            dx * dx + dy * dy >= min2
        });
        if ok {
            points.push([x, y]);
            failures = 0;
        } else {
            failures += 1;
            if failures >= DISK_MAX_FAILURES {
                min_dist *= DISK_SHRINK;
                failures = 0;
            }
        }
    }
    (points, min_dist)
}

/// The 32-point Poisson disk (unit radius), deterministic.
pub fn poisson_disk_32() -> [[f32; 2]; 32] {
    let (points, _) = dart_throw(32);
    let mut out = [[0.0; 2]; 32];
    out.copy_from_slice(&points);
    out
}

/// The minimum distance the 32-point disk was generated with: every pair
/// of [`poisson_disk_32`] points is at least this far apart.
pub fn poisson_disk_32_min_distance() -> f32 {
    dart_throw(32).1
}

/// Parameters of the Poisson-disk kernel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PoissonParams {
    /// Disk radius on the surface, mm.
    pub radius_mm: f32,
    /// Per-channel `k` in `exp(-k |q_i|^2)` (the seed's `Radius_RGB`), with
    /// `q_i` the disk point in unit-disk coordinates.
    pub falloff: [f32; 3],
    /// `k` in `exp(-k dD^2)`, `dD` the depth difference in mm (per mm^2).
    pub depth_sensitivity: f32,
    /// `k` in `exp(-k (1 - saturate(dot(n_s, n))))`.
    pub normal_sensitivity: f32,
}

impl PoissonParams {
    /// Parameters matched to the six-Gaussian skin profile.
    ///
    /// Per channel the profile is replaced by one Gaussian of the same
    /// variance `v_c = sum_i w_ic v_i` (second moment preserved). The disk
    /// covers three standard deviations of red, the widest channel:
    /// `radius = 3 sqrt(v_red)`. A tap at unit-disk radius `|q|` lies
    /// `|q| radius` mm out, so the Gaussian `exp(-r^2 / (2 v_c))` becomes
    /// `exp(-falloff_c |q|^2)` with `falloff_c = radius^2 / (2 v_c)` (4.5 for
    /// red). Depth: a difference of one disk radius weighs `exp(-1/2)`,
    /// i.e. `depth_sensitivity = 1 / (2 radius^2)`. Normals: 4.0, so a 90
    /// degree turn weighs `exp(-4)` ~ 2%.
    pub fn from_profile() -> PoissonParams {
        let mut v = [0.0f32; 3];
        for (w, &var) in SIX_GAUSSIAN_WEIGHTS_RGB
            .iter()
            .zip(SIX_GAUSSIAN_VARIANCES_MM2.iter())
        {
            for c in 0..3 {
                v[c] += w[c] * var;
            }
        }
        let radius_mm = 3.0 * v[0].sqrt();
        let r2 = radius_mm * radius_mm;
        PoissonParams {
            radius_mm,
            falloff: v.map(|vc| r2 / (2.0 * vc)),
            depth_sensitivity: 1.0 / (2.0 * r2),
            normal_sensitivity: 4.0,
        }
    }
}

/// Taps for a kernel of radius `r_px` pixels: 32 from 16 px up, 16 from
/// 8 px, else 8 (small kernels cannot resolve more taps).
pub fn sample_count(r_px: f32) -> u32 {
    if r_px >= 16.0 {
        32
    } else if r_px >= 8.0 {
        16
    } else {
        8
    }
}

/// Mip level to sample for a kernel of radius `r_px` pixels:
/// `clamp(floor(log2(max(r_px, 1) / 16)), 0, max_level)`.
///
/// Why: 32 taps spread over a disk of radius 16 px are about one level-0
/// texel apart; every doubling of the radius doubles the spacing, so one
/// level coarser keeps the taps covering (not skipping) texels and keeps
/// the texture cache warm (the seed's measurements). NaN gives level 0.
pub fn mip_level(r_px: f32, max_level: u32) -> u32 {
    let l = (r_px.max(1.0) / 16.0).log2().floor();
    // `as i64` saturates (+inf -> i64::MAX, NaN -> 0).
    (l as i64).clamp(0, i64::from(max_level)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disk_points_are_inside_and_spread() {
        let disk = poisson_disk_32();
        let min_dist = poisson_disk_32_min_distance();
        assert!(
            min_dist > 0.15 && min_dist <= 0.3,
            "min distance {min_dist}"
        );
        for (i, p) in disk.iter().enumerate() {
            assert!(p[0] * p[0] + p[1] * p[1] <= 1.0, "point {i} outside");
            for q in &disk[..i] {
                let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
                // Acceptance compared squared distances; allow 1 ulp-ish.
                assert!(d >= min_dist * (1.0 - 1e-6), "{p:?} {q:?}: {d}");
            }
        }
        assert_eq!(disk, poisson_disk_32());
    }

    #[test]
    fn disk_prefixes_cover_the_disk() {
        // The first 8 points already reach into every quadrant.
        let disk = poisson_disk_32();
        for (sx, sy) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
            assert!(
                disk[..8]
                    .iter()
                    .any(|p| p[0] * sx >= 0.0 && p[1] * sy >= 0.0),
                "quadrant ({sx}, {sy}) empty"
            );
        }
        // Centroid of the full disk near the origin.
        let (cx, cy) = disk
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p[0] / 32.0, b + p[1] / 32.0));
        assert!(cx.abs() < 0.2 && cy.abs() < 0.2, "centroid ({cx}, {cy})");
    }

    #[test]
    fn params_from_profile() {
        let p = PoissonParams::from_profile();
        assert!((p.radius_mm - 3.528).abs() < 0.005, "{}", p.radius_mm);
        assert!((p.falloff[0] - 4.5).abs() < 1e-4);
        // Green and blue are much narrower: steeper falloff.
        assert!(p.falloff[1] > 80.0 && p.falloff[2] > p.falloff[1]);
        assert!((p.depth_sensitivity * 2.0 * p.radius_mm * p.radius_mm - 1.0).abs() < 1e-6);
        assert_eq!(p.normal_sensitivity, 4.0);
    }

    #[test]
    fn sample_count_thresholds() {
        assert_eq!(sample_count(0.0), 8);
        assert_eq!(sample_count(7.999), 8);
        assert_eq!(sample_count(8.0), 16);
        assert_eq!(sample_count(15.99), 16);
        assert_eq!(sample_count(16.0), 32);
        assert_eq!(sample_count(1e6), 32);
    }

    #[test]
    fn mip_level_thresholds() {
        assert_eq!(mip_level(0.0, 5), 0);
        assert_eq!(mip_level(31.9, 5), 0);
        assert_eq!(mip_level(32.0, 5), 1);
        assert_eq!(mip_level(64.0, 5), 2);
        assert_eq!(mip_level(127.0, 5), 2);
        assert_eq!(mip_level(1e9, 5), 5);
        assert_eq!(mip_level(1e9, 0), 0);
        assert_eq!(mip_level(f32::INFINITY, 3), 3);
        assert_eq!(mip_level(f32::NAN, 3), 0);
    }
}
