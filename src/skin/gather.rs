//! The 2D gather of the exact profile (issue 28; HDRP's disk, ANCHORS.md):
//! the pure parts of `method::gather` and a CPU mirror of its shader.
//!
//! Each skin pixel estimates the convolution `M_c(x_o) = integral R_c(|x -
//! x_o|) L(x) dA` by importance sampling. The samples follow the *widest*
//! channel's radial distribution, `p(r) = 2 pi r R_w(r)` (red for both
//! profiles), truncated at its [`KEPT_MASS`] quantile (HDRP's filter radius,
//! the widest channel's 99.7% point): sample `i` of `n` takes the quantile
//! `u_i = (i + xi) / n` (stratified in radius for any `n`, `xi` a per-pixel
//! offset in `[0, 1)`) and the angle `i` golden angles on from a per-pixel
//! rotation (a Fibonacci disk, turned per pixel so that its structure
//! becomes noise). HDRP takes `xi = 1/2`; the midpoints of the quantile
//! function's strata underestimate its mean where it is convex (the tail);
//! a per-pixel offset is unbiased over pixels. Samples off the screen read
//! the edge texel (the sampler's clamp), as the separable passes do. What
//! the truncation drops, the normalisation spreads over the kept disk: red
//! moves 1.8% less light across an edge than the whole profile (`E[r]` of
//! the kept mass over the whole's: 1.100 / 1.121 mm). A sample at
//! nominal radius `r` whose pixel lies `dz` mm deeper carries the weight
//!
//! `w_c = R_c(sqrt(r^2 + dz^2)) / R_w(r)`
//!
//! (the profile at the 3D distance over the sampling density on the screen
//! plane, HDRP's depth-bilateral term) on the light filtered bilinearly at
//! the sample where its 2x2 texels are all this group's skin, else the
//! nearest texel's if it is (a bilinear tap at the skin's edge bled the
//! backdrop into the silhouette) (a tap at `d` moves a step's light by exactly `d`; the
//! nearest texel, HDRP's load, moves `round(d)`: taps under half a pixel
//! moved nothing, and green's and blue's light crossed the card's edge 3-6%
//! short),
//! and the pixel is `sum w_c L / sum
//! w_c`: dividing by the weights makes it exactly energy-preserving however
//! few samples land (uniform light in, the same light out), removes the
//! truncation's and the density's constant factors, and at a silhouette or
//! next to another group's skin (samples there are dropped) spreads what the
//! visible surface has over what it lacks, as the ground truth does.
//!
//! A sample counts only where light reaches the pixel from it through
//! tissue: the ground truth's own test (`skin::tissue::through_tissue`,
//! its module doc says why) on the view-space points of the two texels
//! (reconstructed from the linear depth at their centres, as the truth's
//! `PixelPoint` is) and the geometry pass's view-space normals. Across a
//! fold (a lip seam, an eyelid over the eye) both points lie in front of
//! each other's tangent planes and the sample is dropped like the backdrop;
//! where the two sides sit at one depth the depth weight alone cannot tell.
//! A binary test, not HDRP's (none) or a cosine `max(0, n_p . n_s)^k`: a
//! cosine also dims convex skin (a nose's sides) and the thin parts light
//! goes through, which the truth keeps whole. It costs one normal fetch a
//! sample (the nearest texel's, beside its depth) and one a pixel. The
//! normal is the shading normal (normal-mapped) where the truth takes the
//! interpolated vertex normal: the tolerance (a quarter of the distance)
//! absorbs a tilt up to asin(0.25) = 14.5 degrees on flat skin.
//!
//! Unlike the separable marginal, nothing here assumes the profile is a sum
//! of separable terms: detail small in both axes is blurred by the 2D profile
//! itself, and the narrowest Gaussians (or Burley's cusp at r = 0) are
//! sampled as densely as their share of the widest channel's mass.
//!
//! The sample count: `ceil(pi r_px^2 / PIXELS_PER_SAMPLE)` (HDRP's rule, `r_px`
//! the kept-mass radius on screen), at least [`MIN_SAMPLES`], at most the
//! budget (HDRP's low / medium / high: 20, 40, 80); a pixel whose radius is
//! under one pixel keeps its light (its whole profile lies in the pixel).

use crate::shader_constants::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};
use crate::skin::burley;
use crate::skin::diffusion::Profile;
use crate::skin::tissue::through_tissue;

/// The mass of the widest channel's profile the samples cover (HDRP's 99.7%).
pub const KEPT_MASS: f64 = 0.997;
/// Screen pixels per sample of the count rule (HDRP's `SSS_PIXELS_PER_SAMPLE`).
pub const PIXELS_PER_SAMPLE: f32 = 4.0;
/// The fewest samples a blurred pixel takes: one sample would shift the image.
pub const MIN_SAMPLES: u32 = 4;
/// Intervals of the inverse-CDF table (`LUT_SIZE + 1` radii, padded to vec4s).
pub use crate::shader_constants::{GATHER_LUT_SIZE as LUT_SIZE, GATHER_LUT_VEC4S as LUT_VEC4S};
/// The budgets `samples=` takes.
pub const BUDGET_RANGE: std::ops::RangeInclusive<u32> = MIN_SAMPLES..=1000;
/// `pi (3 - sqrt 5)`, the golden angle in radians.
pub const GOLDEN_ANGLE: f32 = 2.399_963_2;

/// Index of the channel with the widest profile (the largest mean radius).
pub fn widest_channel(profile: Profile) -> usize {
    let mean = match profile {
        Profile::SixGaussian => burley::six_gaussian_mean_radius_mm(),
        Profile::Burley => profile.burley().map_or([0.0; 3], |b| b.mean_radius_mm()),
    };
    let mean = |c: usize| mean[c];
    (0..3).fold(0, |best, c| if mean(c) > mean(best) { c } else { best })
}

/// The radial CDF of channel `c`: the share of its light within `r_mm`.
pub fn radial_cdf(profile: Profile, c: usize, r_mm: f64) -> f64 {
    match profile {
        Profile::SixGaussian => (0..6)
            .map(|i| {
                let v = f64::from(SIX_GAUSSIAN_VARIANCES_MM2[i]);
                f64::from(SIX_GAUSSIAN_WEIGHTS_RGB[i][c]) * (1.0 - (-r_mm * r_mm / (2.0 * v)).exp())
            })
            .sum(),
        Profile::Burley => {
            let s = profile.burley().map_or(1.0, |b| b.s()[c]);
            burley::radial_cdf(s, r_mm)
        }
    }
}

/// The radius holding the share `u` of channel `c`'s light (bisection on the
/// CDF, to 1e-12 mm; Burley's has a closed form, the six Gaussians none).
pub fn radial_quantile(profile: Profile, c: usize, u: f64) -> f64 {
    if u <= 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    while radial_cdf(profile, c, hi) < u {
        hi *= 2.0;
    }
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if radial_cdf(profile, c, mid) < u {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// What the shader needs of a profile: the widest channel, its inverse CDF
/// over `[0, KEPT_MASS]` and Burley's `s` per channel.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GatherProfile {
    pub profile: Profile,
    pub widest: usize,
    /// `LUT_SIZE + 1` radii (mm): entry `k` holds the quantile `k / LUT_SIZE x KEPT_MASS`.
    pub lut_mm: Vec<f32>,
    /// Burley's `s` (1/mm) per channel; zero for the six Gaussians.
    pub burley_s: [f32; 3],
}

impl GatherProfile {
    pub fn new(profile: Profile) -> GatherProfile {
        let widest = widest_channel(profile);
        let lut_mm = (0..=LUT_SIZE)
            .map(|k| {
                radial_quantile(profile, widest, k as f64 / LUT_SIZE as f64 * KEPT_MASS) as f32
            })
            .collect();
        let burley_s = profile
            .burley()
            .map_or([0.0; 3], |b| b.s().map(|s| s as f32));
        GatherProfile {
            profile,
            widest,
            lut_mm,
            burley_s,
        }
    }

    /// The kept-mass radius (mm): the farthest a sample lands.
    pub fn max_radius_mm(&self) -> f32 {
        self.lut_mm[LUT_SIZE]
    }

    /// The radius of quantile `u` (in `[0, 1)` of the kept mass), as the
    /// shader interpolates the table.
    pub fn radius_mm(&self, u: f32) -> f32 {
        let x = u * LUT_SIZE as f32;
        let k = (x as usize).min(LUT_SIZE - 1);
        let f = x - k as f32;
        let (a, b) = (self.lut_mm[k], self.lut_mm[k + 1]);
        a + (b - a) * f
    }

    /// The profile per channel at `r_mm` in f32, in the shader's order of
    /// operations (per mm^2; the constant factors cancel in the weights).
    pub fn eval(&self, r_mm: f32) -> [f32; 3] {
        match self.profile {
            Profile::SixGaussian => {
                let mut sum = [0.0f32; 3];
                for i in 0..6 {
                    let v = SIX_GAUSSIAN_VARIANCES_MM2[i];
                    let g = (-r_mm * r_mm / (2.0 * v)).exp() / (2.0 * std::f32::consts::PI * v);
                    for c in 0..3 {
                        sum[c] += SIX_GAUSSIAN_WEIGHTS_RGB[i][c] * g;
                    }
                }
                sum
            }
            Profile::Burley => self.burley_s.map(|s| {
                s * ((-s * r_mm).exp() + (-s * r_mm / 3.0).exp())
                    / (8.0 * std::f32::consts::PI * r_mm)
            }),
        }
    }
}

/// Samples a pixel takes for a kept-mass radius of `radius_px` on screen:
/// 0 (the pixel keeps its light) under one pixel, else HDRP's area rule
/// within `[MIN_SAMPLES, budget]`.
pub fn sample_count(radius_px: f32, budget: u32) -> u32 {
    if radius_px.is_nan() || radius_px < 1.0 {
        return 0;
    }
    let area = std::f32::consts::PI * radius_px * radius_px / PIXELS_PER_SAMPLE;
    // Saturating cast: a huge radius takes the budget.
    (area.ceil() as u32).clamp(MIN_SAMPLES, budget.max(MIN_SAMPLES))
}

/// The per-pixel rotation in `[0, 2 pi)` and offset within each radius
/// stratum in `[0, 1)` (the shader's integer hash: its low and high 16 bits).
pub fn jitter(x: u32, y: u32) -> (f32, f32) {
    let h = super::jittered::pixel_hash(x, y);
    (
        (h & 0xffff) as f32 / 65536.0 * (2.0 * std::f32::consts::PI),
        (h >> 16) as f32 / 65536.0,
    )
}

/// The images one pixel of the gather reads (row-major, `width` wide).
pub struct GatherInputs<'a> {
    pub width: usize,
    pub height: usize,
    /// RGBA: the diffuse light, alpha the SSS strength.
    pub color: &'a [[f32; 4]],
    /// Linear view depth, scene units.
    pub depth: &'a [f32],
    /// View-space unit normals (the geometry pass's normal target).
    pub normal: &'a [[f32; 3]],
    /// Whether the pixel is this group's skin.
    pub skin: &'a [bool],
    /// The view: its height in pixels, `tan(fovy / 2)` and millimetres per
    /// scene unit (pixels per mm at depth `d`: `h / (2 d tan(fovy/2) mm)`,
    /// in view_scale.glsl's order of products).
    pub height_px: f32,
    pub tan_half_fovy: f32,
    pub mm_per_unit: f32,
}

impl GatherInputs<'_> {
    /// The view-space point at the centre of texel `(x, y)` at linear depth
    /// `z` (gather.comp's `viewPoint`, the ground truth's reconstruction).
    pub fn view_point(&self, x: usize, y: usize, z: f32) -> [f32; 3] {
        let (w, h) = (self.width as f32, self.height as f32);
        let ndc_x = (x as f32 + 0.5) / w * 2.0 - 1.0;
        let ndc_y = (y as f32 + 0.5) / h * 2.0 - 1.0;
        let t = self.tan_half_fovy;
        [ndc_x * t * (w / h) * z, -ndc_y * t * z, -z]
    }
}

/// The CPU mirror of gather.comp for the skin pixel `(x, y)`: the same
/// samples, weights and sums in f32 (the GPU's transcendental functions may
/// differ in their last bits, and a sample on a pixel border may then land
/// one pixel over: tests compare within a tolerance, not bit for bit).
pub fn gather_pixel(
    g: &GatherProfile,
    budget: u32,
    input: &GatherInputs,
    x: usize,
    y: usize,
) -> [f32; 4] {
    let i = y * input.width + x;
    let centre = input.color[i];
    let depth = input.depth[i];
    let px_per_mm =
        input.height_px / ((2.0 * depth * input.tan_half_fovy) * input.mm_per_unit) * centre[3];
    let n = sample_count(g.max_radius_mm() * px_per_mm, budget);
    if n == 0 {
        return centre;
    }
    let xo = input.view_point(x, y, depth);
    let no = input.normal[i];
    let (theta, offset) = jitter(x as u32, y as u32);
    let mut sum = [0.0f32; 3];
    let mut wsum = [0.0f32; 3];
    for k in 0..n {
        let u = (k as f32 + offset) / n as f32;
        let r = g.radius_mm(u).max(1e-6);
        let a = theta + k as f32 * GOLDEN_ANGLE;
        let off = [a.cos() * r * px_per_mm, a.sin() * r * px_per_mm];
        // Off the screen, the edge texel (the shader's clamp).
        let clamp = |v: f32, n: usize| (v.floor().max(0.0) as usize).min(n - 1);
        let qx = clamp(x as f32 + 0.5 + off[0], input.width);
        let qy = clamp(y as f32 + 0.5 + off[1], input.height);
        let j = qy * input.width + qx;
        let (px, py) = (x as f32 + 0.5 + off[0], y as f32 + 0.5 + off[1]);
        // Bilinear where the 2x2 footprint is all this group's skin, else
        // the nearest texel if it is (the shader's stencil gather).
        let light = if footprint_is_skin(input, px, py) {
            bilinear(input, px, py)
        } else if !input.skin[j] {
            continue;
        } else {
            let c = input.color[j];
            [c[0], c[1], c[2]]
        };
        // Only through tissue (the module doc says why).
        let xq = input.view_point(qx, qy, input.depth[j]);
        if !through_tissue(xo, no, xq, input.normal[j], input.mm_per_unit) {
            continue;
        }
        let dz = (input.depth[j] - depth) * input.mm_per_unit;
        let r3 = (r * r + dz * dz).sqrt();
        let num = g.eval(r3);
        let den = g.eval(r)[g.widest];
        for c in 0..3 {
            let w = num[c] / den;
            sum[c] += w * light[c];
            wsum[c] += w;
        }
    }
    let mut out = centre;
    for c in 0..3 {
        if wsum[c] > 0.0 {
            out[c] = sum[c] / wsum[c];
        }
    }
    out
}

/// The four texels of a bilinear tap at `(px, py)`, edges clamped.
fn footprint(input: &GatherInputs, px: f32, py: f32) -> [usize; 4] {
    let (x0, y0) = ((px - 0.5).floor(), (py - 0.5).floor());
    let at = |x: f32, y: f32| {
        let xi = (x.max(0.0) as usize).min(input.width - 1);
        let yi = (y.max(0.0) as usize).min(input.height - 1);
        yi * input.width + xi
    };
    [
        at(x0, y0),
        at(x0 + 1.0, y0),
        at(x0, y0 + 1.0),
        at(x0 + 1.0, y0 + 1.0),
    ]
}

/// Whether the four texels of a bilinear tap at `(px, py)` are all skin.
fn footprint_is_skin(input: &GatherInputs, px: f32, py: f32) -> bool {
    footprint(input, px, py).iter().all(|&i| input.skin[i])
}

/// The light filtered bilinearly at `(px, py)` (pixels, centres at `+ 0.5`),
/// edges clamped, as the shader's sampler filters it.
fn bilinear(input: &GatherInputs, px: f32, py: f32) -> [f32; 3] {
    let (fx, fy) = (px - 0.5, py - 0.5);
    let (tx, ty) = (fx - fx.floor(), fy - fy.floor());
    let [a, b, c, d] = footprint(input, px, py).map(|i| input.color[i]);
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * tx;
        let bottom = c[k] + (d[k] - c[k]) * tx;
        top + (bottom - top) * ty
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn red_is_the_widest_channel_of_both_profiles() {
        for p in Profile::ALL {
            assert_eq!(widest_channel(p), 0, "{}", p.name());
        }
    }

    #[test]
    fn the_table_inverts_the_cdf() {
        for p in Profile::ALL {
            let g = GatherProfile::new(p);
            assert_eq!(g.lut_mm.len(), LUT_SIZE + 1);
            assert_eq!(g.lut_mm[0], 0.0);
            for k in 1..=LUT_SIZE {
                assert!(
                    g.lut_mm[k] > g.lut_mm[k - 1],
                    "{} not increasing at {k}",
                    p.name()
                );
                let u = k as f64 / LUT_SIZE as f64 * KEPT_MASS;
                let back = radial_cdf(p, 0, f64::from(g.lut_mm[k]));
                assert!((back - u).abs() < 1e-5, "{} k {k}: {back} vs {u}", p.name());
            }
            // Burley's quantile against its closed-form inverse (an independent formula).
            if let Some(b) = p.burley() {
                let exact = burley::radial_inverse_cdf(b.s()[0], KEPT_MASS);
                assert!((f64::from(g.max_radius_mm()) / exact - 1.0).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn stratified_quantiles_follow_the_sampling_distribution() {
        // Kolmogorov-Smirnov distance of the n radii against the truncated
        // CDF: stratified samples sit within 1/(2n) plus the table's error.
        for p in Profile::ALL {
            let g = GatherProfile::new(p);
            let n = 40;
            let mut d = 0.0f64;
            for k in 0..n {
                let r = g.radius_mm((k as f32 + 0.5) / n as f32);
                let f = radial_cdf(p, 0, f64::from(r)) / KEPT_MASS;
                d = d.max((f - (k as f64 + 0.5) / n as f64).abs());
            }
            assert!(d < 2e-3, "{}: KS distance {d}", p.name());
        }
    }

    #[test]
    fn the_count_rule_is_hdrps() {
        assert_eq!(sample_count(0.9, 40), 0);
        assert_eq!(sample_count(f32::NAN, 40), 0);
        assert_eq!(sample_count(1.0, 40), MIN_SAMPLES);
        // pi 5^2 / 4 = 19.6 -> 20.
        assert_eq!(sample_count(5.0, 40), 20);
        assert_eq!(sample_count(50.0, 40), 40);
        assert_eq!(sample_count(1e30, 80), 80);
    }

    #[test]
    fn weights_estimate_the_channel_profiles() {
        // The importance weights integrate each channel's profile: the mean
        // of w_c over the sampling distribution is F_c(r_max) / F_w(r_max),
        // against the CDFs (no weights of ours): within 1% with 4096 samples.
        for p in Profile::ALL {
            let g = GatherProfile::new(p);
            let n = 4096;
            let mut mean = [0.0f64; 3];
            for k in 0..n {
                let r = g.radius_mm((k as f32 + 0.5) / n as f32).max(1e-6);
                let (num, den) = (g.eval(r), g.eval(r)[g.widest]);
                for c in 0..3 {
                    mean[c] += f64::from(num[c] / den) / n as f64;
                }
            }
            let rmax = f64::from(g.max_radius_mm());
            for (c, m) in mean.iter().enumerate() {
                let expect = radial_cdf(p, c, rmax) / KEPT_MASS;
                assert!(
                    (m / expect - 1.0).abs() < 0.01,
                    "{} c {c}: {m} vs {expect}",
                    p.name()
                );
            }
        }
    }

    #[test]
    fn the_tissue_test_stops_light_at_a_fold_and_not_at_a_ridge() {
        // Two half-planes meeting at x = 20 at 30 degrees to the screen, the
        // seam deepest (a fold) or nearest (a ridge): equal depths at equal
        // distances from the seam, so only the normals tell them apart. A
        // pixel 4 px right of the seam, all the red on the left: at the fold
        // no tap across the seam counts (the red it gets comes from bilinear
        // taps straddling the seam only), at the ridge all do.
        let (w, h) = (40, 30);
        let color: Vec<[f32; 4]> = (0..w * h)
            .map(|i| [if i % w < 20 { 1.0 } else { 0.0 }, 0.0, 0.0, 1.0])
            .collect();
        let skin = vec![true; w * h];
        let (t, hp, z0) = (0.2f32, 30.0f32, 2.0f32);
        let step = 2.0 * z0 * t / hp * 30f32.to_radians().tan();
        let red_at = |fold: bool| {
            let sign = if fold { -1.0 } else { 1.0 };
            let depth: Vec<f32> = (0..w * h)
                .map(|i| z0 + sign * ((i % w) as f32 + 0.5 - 20.0).abs() * step)
                .collect();
            // The surfaces' normals: +-30 degrees about the view axis, the
            // fold's sides facing each other, the ridge's facing apart.
            let (s30, c30) = (0.5f32, 0.75f32.sqrt());
            let normal: Vec<[f32; 3]> = (0..w * h)
                .map(|i| {
                    let left = if i % w < 20 { 1.0 } else { -1.0 };
                    [left * -sign * s30, 0.0, c30]
                })
                .collect();
            let input = GatherInputs {
                width: w,
                height: h,
                color: &color,
                depth: &depth,
                normal: &normal,
                skin: &skin,
                height_px: hp,
                tan_half_fovy: t,
                mm_per_unit: 2.0,
            };
            let g = GatherProfile::new(Profile::SixGaussian);
            gather_pixel(&g, 80, &input, 24, 15)[0]
        };
        let (fold, ridge) = (red_at(true), red_at(false));
        println!("fold {fold}, ridge {ridge}");
        assert!(ridge > 0.05, "ridge {ridge}");
        assert!(fold < 0.2 * ridge, "fold {fold} vs ridge {ridge}");
    }

    #[test]
    fn uniform_light_stays_uniform_and_a_lone_pixel_keeps_its_light() {
        let (w, h) = (40, 30);
        let color = vec![[0.5, 0.4, 0.3, 1.0]; w * h];
        let depth = vec![2.0; w * h];
        let skin = vec![true; w * h];
        let normal = vec![[0.0, 0.0, 1.0]; w * h];
        let input = GatherInputs {
            width: w,
            height: h,
            color: &color,
            depth: &depth,
            normal: &normal,
            skin: &skin,
            height_px: 400.0,
            tan_half_fovy: 0.2,
            mm_per_unit: 10.0,
        };
        for p in Profile::ALL {
            let g = GatherProfile::new(p);
            for (x, y) in [(0, 0), (20, 15), (39, 29)] {
                let o = gather_pixel(&g, 40, &input, x, y);
                for c in 0..3 {
                    assert!((o[c] - color[0][c]).abs() < 1e-6, "{o:?}");
                }
            }
        }
    }
}
