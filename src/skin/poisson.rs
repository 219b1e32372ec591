//! Poisson-disk screen-space SSS (seed 003): one 2D pass of up to 32 taps
//! spread over a disk, each weighted by its distance to the centre (per
//! channel), its depth difference and its normal difference.
//!
//! Why a Poisson disk: well-spread taps with no regular structure give the
//! smoothest result for a fixed tap count, and because points are kept in
//! generation order, the first 8 or 16 are spread out too, so distant
//! (small on screen) skin can use fewer taps (the seed's "LOD").

use std::f64::consts::PI;

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

/// The orbit of `(x, y)` under quarter turns: `p`, `-p`, `p` turned by +90
/// and by -90 degrees (exact in f32: only signs and swaps).
fn quarter_turns(x: f32, y: f32) -> [[f32; 2]; 4] {
    [[x, y], [-x, -y], [-y, x], [y, -x]]
}

/// Dart throwing of quarter-turn orbits in the unit disk: returns the
/// points (`n` a multiple of 4) and the final minimum distance.
///
/// A dart is a uniform point `p` of the square `[-1, 1)^2`; darts outside
/// the unit disk (`x^2 + y^2 > 1`) are thrown again without counting. The
/// dart is accepted with its orbit ([`quarter_turns`]), as the next four
/// points, if every point of the orbit is at least the current minimum
/// distance from every accepted point and from the others of its orbit
/// (`sqrt(2) |p|` apart); checking `p` against the accepted points
/// suffices, as the accepted set is itself invariant under quarter turns.
/// A rejected dart is a failure; after [`DISK_MAX_FAILURES`] consecutive
/// failures the minimum distance shrinks by [`DISK_SHRINK`] and the count
/// restarts. Accepted points keep their generation order and stay valid
/// when the distance shrinks.
///
/// Why orbits: every prefix of 8, 16 or 32 taps (the LOD's counts) is then
/// point-symmetric, so its weighted centroid is exactly the centre for any
/// radial weight and the kernel cannot move an edge (the plain dart-thrown
/// disk's red-weighted centroid was 0.07 of the radius off centre, moving
/// edges by up to 0.25 mm). The quarter turns also make horizontal and
/// vertical edges respond alike and keep the response over all edge
/// orientations within [0.79, 1.11] of its mean; with point-symmetric
/// pairs alone green and blue hang on one pair of taps and an edge along
/// that pair barely moves (0.58 of the mean with this seed, 0.03 with
/// others).
fn dart_throw(n: usize) -> (Vec<[f32; 2]>, f32) {
    assert!(n % 4 == 0, "quarter-turn orbits");
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
        let ok = 2.0 * (x * x + y * y) >= min2
            && points.iter().all(|p| {
                let (dx, dy) = (p[0] - x, p[1] - y);
                dx * dx + dy * dy >= min2
            });
        if ok {
            points.extend(quarter_turns(x, y));
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

/// The tap counts of the LOD ([`sample_count`]), smallest first.
pub const SAMPLE_COUNTS: [u32; 3] = [8, 16, 32];

/// Index of `count` in [`SAMPLE_COUNTS`] (the falloff row it uses); the
/// shader picks it the same way: 32 -> 2, 16 -> 1, anything else -> 0.
pub fn count_index(count: u32) -> usize {
    match count {
        32 => 2,
        16 => 1,
        _ => 0,
    }
}

/// Mean distance of the light from the centre, in disk radii, of the
/// kernel made of the centre (weight 1) and the taps `disk` weighted
/// `exp(-k |q|^2)`, as the shader normalises it (flat, all skin).
///
/// Why this moment: an edge at angle theta moves `sum_j W_j (q_j.n)^+`
/// radii of light across it; averaged over edge orientations that is
/// `mean radius / pi` (the mean of `(cos)^+` is `1/pi`), the same relation
/// the profile's closed form obeys (`sigma sqrt(pi/2) / pi` per Gaussian).
pub fn kernel_mean_radius(disk: &[[f32; 2]], k: f64) -> f64 {
    let mut moment = 0.0;
    let mut total = 1.0;
    for q in disk {
        let r2 = f64::from(q[0] * q[0] + q[1] * q[1]);
        let w = (-k * r2).exp();
        moment += w * r2.sqrt();
        total += w;
    }
    moment / total
}

/// Mean distance from the centre of each channel of the six-Gaussian
/// profile (mm): `sum_i w_ic sigma_i sqrt(pi / 2)` (the mean of a Rayleigh
/// distribution).
pub fn profile_mean_radius_mm() -> [f64; 3] {
    let mut out = [0.0; 3];
    for (w, &v) in SIX_GAUSSIAN_WEIGHTS_RGB
        .iter()
        .zip(SIX_GAUSSIAN_VARIANCES_MM2.iter())
    {
        for c in 0..3 {
            out[c] += f64::from(w[c]) * f64::from(v).sqrt() * (PI / 2.0).sqrt();
        }
    }
    out
}

/// The falloff `k` at which [`kernel_mean_radius`] of `disk` equals
/// `target` (disk radii), by bisection on `log k` over [1e-4, 1e5] (the mean
/// radius falls monotonically with `k`; 0 if even a flat kernel is too
/// narrow).
fn fit_falloff(disk: &[[f32; 2]], target: f64) -> f64 {
    let (mut lo, mut hi) = (1e-4f64, 1e5f64);
    if kernel_mean_radius(disk, lo) <= target {
        return 0.0;
    }
    for _ in 0..100 {
        let mid = (lo * hi).sqrt();
        if kernel_mean_radius(disk, mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo * hi).sqrt()
}

/// Parameters of the Poisson-disk kernel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PoissonParams {
    /// Disk radius on the surface, mm.
    pub radius_mm: f32,
    /// `k` in `exp(-k |q_i|^2)` (the seed's `Radius_RGB`), with `q_i` the
    /// disk point in unit-disk coordinates: one row (R, G, B) per tap count
    /// of [`SAMPLE_COUNTS`], since the 8-, 16- and 32-tap prefixes are
    /// different kernels.
    pub falloff: [[f32; 3]; 3],
    /// `k` in `exp(-k dD^2)`, `dD` the depth difference in mm (per mm^2).
    pub depth_sensitivity: f32,
    /// `k` in `exp(-k (1 - saturate(dot(n_s, n))))`.
    pub normal_sensitivity: f32,
}

impl PoissonParams {
    /// Parameters matched to the six-Gaussian skin profile.
    ///
    /// The disk covers three standard deviations of red, the widest
    /// channel, `radius = 3 sqrt(v_red)` with `v_red = sum_i w_i v_i`
    /// (3.53 mm). Per tap count and channel the falloff is the one at which
    /// the discrete kernel (centre plus taps, as the shader weighs and
    /// normalises them) has the profile's mean radius
    /// ([`profile_mean_radius_mm`]), so that it moves the profile's light
    /// across an edge, averaged over edge orientations (see
    /// [`kernel_mean_radius`]).
    ///
    /// Why not one Gaussian of the channel's variance
    /// (`k = radius^2 / (2 v_c)`, the earlier rule): green's and blue's
    /// variances (0.068 and 0.025 mm^2) make Gaussians far narrower than
    /// the taps' spacing (about 1 mm), so their weights (`k` = 91 and 251)
    /// vanish on every tap and nothing scattered; and no single `k` fits
    /// the 8-, 16- and 32-tap prefixes at once (red needs 3.3 to 6.0).
    ///
    /// Depth: a difference of one disk radius weighs `exp(-1/2)`, i.e.
    /// `depth_sensitivity = 1 / (2 radius^2)`. Normals: 4.0, so a 90 degree
    /// turn weighs `exp(-4)` ~ 2%.
    pub fn from_profile() -> PoissonParams {
        let mut v_red = 0.0f32;
        for (w, &var) in SIX_GAUSSIAN_WEIGHTS_RGB
            .iter()
            .zip(SIX_GAUSSIAN_VARIANCES_MM2.iter())
        {
            v_red += w[0] * var;
        }
        let radius_mm = 3.0 * v_red.sqrt();
        let r2 = radius_mm * radius_mm;
        let disk = poisson_disk_32();
        let target = profile_mean_radius_mm().map(|m| m / f64::from(radius_mm));
        let falloff =
            SAMPLE_COUNTS.map(|n| target.map(|t| fit_falloff(&disk[..n as usize], t) as f32));
        PoissonParams {
            radius_mm,
            falloff,
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
    }

    #[test]
    fn every_lod_prefix_is_centred_for_any_radial_weight() {
        let disk = poisson_disk_32();
        for n in SAMPLE_COUNTS {
            for k in [0.0f32, 3.0, 40.0] {
                let (mut cx, mut cy) = (0.0f32, 0.0f32);
                for q in &disk[..n as usize] {
                    let w = (-k * (q[0] * q[0] + q[1] * q[1])).exp();
                    cx += w * q[0];
                    cy += w * q[1];
                }
                // Exact: each point's mirror has the same weight.
                assert!(
                    cx.abs() < 1e-6 && cy.abs() < 1e-6,
                    "n {n} k {k}: ({cx}, {cy})"
                );
            }
            // Invariant under a quarter turn.
            for q in &disk[..n as usize] {
                assert!(disk[..n as usize].contains(&[-q[1], q[0]]), "{q:?}");
            }
        }
    }

    #[test]
    fn params_from_profile() {
        let p = PoissonParams::from_profile();
        assert!((p.radius_mm - 3.528).abs() < 0.005, "{}", p.radius_mm);
        let disk = poisson_disk_32();
        let target = profile_mean_radius_mm();
        for (row, n) in p.falloff.iter().zip(SAMPLE_COUNTS) {
            for c in 0..3 {
                // Each count's kernel has the profile's mean radius.
                let got = kernel_mean_radius(&disk[..n as usize], f64::from(row[c]))
                    * f64::from(p.radius_mm);
                assert!((got / target[c] - 1.0).abs() < 1e-5, "n {n} c {c}: {got}");
            }
            // Red reaches furthest: the gentlest falloff; green and blue
            // scatter (their taps keep some weight) but less far.
            assert!(row[0] < row[1] && row[1] < row[2], "{row:?}");
            assert!(row[2] < 60.0, "{row:?}");
        }
        println!("falloff per count (8/16/32): {:?}", p.falloff);
        assert!((p.depth_sensitivity * 2.0 * p.radius_mm * p.radius_mm - 1.0).abs() < 1e-6);
        assert_eq!(p.normal_sensitivity, 4.0);
    }

    /// The edge energy of every count's kernel, for edges at 0..90 degrees
    /// (the quarter turns repeat the rest), stays within [0.79, 1.11] of the
    /// profile's: the mean-radius fit is exact on average over orientations.
    #[test]
    fn edge_response_over_orientations() {
        let p = PoissonParams::from_profile();
        let disk = poisson_disk_32();
        let want = profile_mean_radius_mm().map(|m| m / PI);
        for (row, n) in p.falloff.iter().zip(SAMPLE_COUNTS) {
            for c in 0..3 {
                let k = f64::from(row[c]);
                let mut range = (f64::MAX, f64::MIN);
                for step in 0..90 {
                    let t = f64::from(step).to_radians();
                    let (mut moved, mut total) = (0.0, 1.0);
                    for q in &disk[..n as usize] {
                        let (x, y) = (f64::from(q[0]), f64::from(q[1]));
                        let w = (-k * (x * x + y * y)).exp();
                        moved += w * (x * t.cos() + y * t.sin()).max(0.0);
                        total += w;
                    }
                    let ratio = moved / total * f64::from(p.radius_mm) / want[c];
                    range = (range.0.min(ratio), range.1.max(ratio));
                }
                // Measured: red 0.88..1.08, green and blue 0.79..1.11.
                assert!(range.0 > 0.78 && range.1 < 1.12, "n {n} c {c}: {range:?}");
            }
        }
    }

    #[test]
    fn kernel_mean_radius_limits() {
        let disk = poisson_disk_32();
        // k = 0: all 33 samples equal; k large: only the centre.
        let flat: f64 = disk
            .iter()
            .map(|q| f64::from(q[0].hypot(q[1])))
            .sum::<f64>()
            / 33.0;
        assert!((kernel_mean_radius(&disk, 0.0) - flat).abs() < 1e-9);
        assert!(kernel_mean_radius(&disk, 1e4) < 1e-12);
        assert_eq!(fit_falloff(&disk, 0.99), 0.0);
        // Red, green, blue: 1.12, 0.26, 0.17 mm.
        let m = profile_mean_radius_mm();
        assert!(
            (m[0] - 1.1206).abs() < 1e-3 && (m[2] - 0.1665).abs() < 1e-3,
            "{m:?}"
        );
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
