//! Separable subsurface-scattering kernel (Jimenez's thesis, eq. 6.1).
//!
//! `s(w, t, f)[x] = p[x * w / (0.001 + f)] * t + delta(x) * (1 - t)`, where
//! `p` is the red channel of d'Eon's six-Gaussian skin profile, `t` the
//! per-channel strength and `f` the per-channel falloff.
//!
//! # Project definition of "width in mm"
//!
//! * `width_mm` is the kernel's half-extent on the surface: sample offsets
//!   span `[-width_mm, +width_mm]` millimetres.
//! * Sample positions: `t_k = -1 + 2k/(n-1)`, `x_k = width_mm * sign(t_k) * t_k^2`,
//!   denser near the centre (the thesis samples the error more densely
//!   there, where the profile carries most of its energy).
//! * Per channel `c` the reshaped profile along the line is
//!   `shape_c(x) = red_profile(|3x| / (width_mm * (0.001 + f_c)))`: the kernel
//!   edge maps to `3 / (0.001 + f_c)` mm of d'Eon's red profile (the original
//!   HLSL divides the step by 3 "as the kernels range from -3 to 3").
//! * Weight of sample k = exact integral of `shape_c` over its cell; cells
//!   are bounded by midpoints between neighbouring positions and the outer
//!   cells end at `+-width_mm` (the extreme samples themselves). Exact
//!   integration handles the 0.0064 mm^2 Gaussian, which point sampling would
//!   miss or over-weight.
//! * Each channel is normalised to sum 1, then strength is applied:
//!   centre `= (1 - t) + t * w_centre`, others `*= t`. The sum stays 1.
//! * `width_mm == 0` yields the identity kernel (centre 1, others 0, all
//!   offsets 0).
//! * Output order: centre first, then the others by increasing offset.
//!
//! # The physical preset
//!
//! Eq. 6.1 slices the 2D profile through its centre: along a line the
//! slice weighs Gaussian `i` by `w_i / sqrt(2 pi v_i)` (its line integral),
//! so the narrowest Gaussian takes 72% of red, and Table 6.1's falloffs
//! and strengths narrow it further (red variance 0.06 mm^2 against the
//! profile's 1.38). That is an artist's look, kept as published.
//! [`Preset::Physical`] instead samples each channel's *marginal*, the 2D
//! profile integrated across the line, `sum_i w_ic N(x; 0, v_i)`
//! ([`KernelShape::Marginal`]), at the same tap positions but with weights
//! that keep the mass and first moment of every interval between taps
//! (see `build`), so its edge response is exact for any tap count. Why the marginal rather than the best
//! rank-1 (least-squares) separable approximation of the 2D kernel: for
//! anything that varies along one axis only (an albedo or shadow edge, the
//! flat card of [`super::card`]) one pass is a no-op and the other applies
//! the marginal, so the response is exact, energy moved across the edge
//! included; the rank-1 fit minimises the pointwise 2D error, which the
//! 0.08 mm spike dominates, and comes out far narrower (it moves about 0.4x
//! the exact red energy across an edge; see the tests). No separable kernel
//! reproduces the 2D profile exactly (a product of two Gaussian mixtures is
//! not a radial mixture), so the choice is which error to keep: the
//! marginal keeps edges exact and errs only at features small in both axes.
//!
//! # The Burley preset
//!
//! [`Preset::Burley`] ([`KernelShape::Burley`]) is the same construction
//! on Burley's normalized diffusion instead of the six Gaussians: each
//! channel's marginal `s / (4 pi) [K0(s|x|) + K0(s|x|/3)]` (see
//! [`super::burley`]), with `s` matched to the six-Gaussian skin by the
//! mean radius ([`burley_profile`]), the same tap positions and the same
//! mass- and first-moment-keeping weights. Its half-extent is where the
//! widest channel's (red's) marginal keeps 99.7% of its mass, 5.97 mm (HDRP
//! sizes its filter by the 99.7% point). Burley's tail is exponential, not
//! Gaussian: the 0.3% beyond that point carries 3% of red's edge energy,
//! which dropping it would lose. So the tail `[w, inf)` is assigned like
//! any interval, linearly between two taps, here the centre and the
//! outermost one (`T - G / w` and `G / w`, for tail mass `T` and first
//! moment `G`): mass and edge energy stay exact for any width and tap
//! count, the centre tap gives up a little weight to pay for it. Like the
//! physical preset it is exact only for what varies along one axis: a
//! separable product of a radial profile's marginals is not the radial
//! profile.
//!
//! Over 800 lines because its tests (about 500 lines: the kernel against the
//! profile's closed forms, the presets, the rank-1 study) sit beside the 380
//! lines of code they check.

use std::str::FromStr;

use anyhow::{bail, Context, Result};

use super::burley::{self, BurleyParams, SFit};
use super::profile::{
    marginal_first_moment, marginal_integral, red_profile_line_integral, SIX_GAUSSIAN_VARIANCES_MM2,
};

/// Millimetres per "demo unit".
///
/// Assumption: the original SSS demo's head is about one unit from chin to
/// crown, and a human head is about 230 mm, so one demo unit is ~230 mm.
/// This converts the thesis' widths (given in demo units) to millimetres.
pub const DEMO_UNIT_MM: f32 = 230.0;

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// Half-extent of the physical kernel in standard deviations of the
/// profile's widest Gaussian (red's `v_6 = 7.41 mm^2`, sigma 2.72 mm): the
/// 3-sigma tail beyond holds 0.27% of that Gaussian's mass, 0.02% of red's.
pub const PHYSICAL_WIDTH_SIGMAS: f32 = 3.0;

/// Share of the widest channel's marginal mass within the Burley kernel's
/// half-extent (HDRP's 99.7% point).
pub const BURLEY_KEPT_MASS: f64 = 0.997;

/// The Burley profile [`KernelShape::Burley`] samples: matched to the
/// six-Gaussian skin by the mean radius (and so the edge spread), with the
/// default fit (which sets only the mean free path, not the shape).
pub fn burley_profile() -> BurleyParams {
    BurleyParams::matching_six_gaussians(SFit::default())
}

/// Which 1D profile the kernel's cells integrate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum KernelShape {
    /// Eq. 6.1: the red profile's slice through its centre, reshaped per
    /// channel by the falloff (the sources' presets).
    #[default]
    RedSlice,
    /// The per-channel marginal of the 2D profile, at its true scale; the
    /// falloff does not apply (it must be 0). See the module docs.
    Marginal,
    /// The per-channel marginal of Burley's profile ([`burley_profile`]);
    /// the falloff must be 0. See the module docs.
    Burley,
}

impl KernelShape {
    /// Eq. 6.1's shape is left out of serialised parameters, so reports of
    /// the sources' presets keep their layout.
    fn is_red_slice(&self) -> bool {
        *self == KernelShape::RedSlice
    }
}

/// Parameters of eq. 6.1, with the width already converted to millimetres.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SssParams {
    /// Half-extent of the kernel on the surface, in mm (see module docs).
    pub width_mm: f32,
    /// Per-channel fraction of diffuse light that scatters (`t`, in [0, 1]).
    pub strength: [f32; 3],
    /// Per-channel falloff of the gradients (`f`, >= 0).
    pub falloff: [f32; 3],
    /// The profile the cells integrate.
    #[serde(skip_serializing_if = "KernelShape::is_red_slice")]
    pub shape: KernelShape,
}

/// Named parameter sets (`dermis kernel --preset` takes them by name).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// Table 6.1 of the thesis: width 0.014 demo units (3.22 mm),
    /// strength (0.78, 0.70, 0.75), falloff (0.57, 0.13, 0.08).
    #[value(name = "table6.1", alias = "table61")]
    Table61,
    /// The look of the original demo: width 0.012 demo units (2.76 mm),
    /// strength (0.48, 0.41, 0.28), falloff (1.0, 0.37, 0.3).
    Demo,
    /// Fitted to the profile rather than an artist's look: each channel's
    /// marginal of d'Eon's six-Gaussian profile (Table 4.2), half-extent 3
    /// sigma of the widest Gaussian (8.17 mm), strength 1 (the profile's
    /// own narrow Gaussians are the light that barely moves). Beyond the
    /// sources; see the module docs.
    Physical,
    /// Burley's normalized diffusion matched to the same skin (same total
    /// reflectance and mean radius per channel), its per-channel marginal,
    /// half-extent where red's keeps 99.7% of its mass (5.97 mm), strength
    /// 1. See the module docs.
    Burley,
}

impl Preset {
    /// Every preset, for listings and exhaustive tests.
    pub const ALL: [Preset; 4] = [
        Preset::Table61,
        Preset::Demo,
        Preset::Physical,
        Preset::Burley,
    ];

    /// Canonical name, accepted back by `FromStr`.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Table61 => "table6.1",
            Preset::Demo => "demo",
            Preset::Physical => "physical",
            Preset::Burley => "burley",
        }
    }

    /// The preset's parameters (widths converted with [`DEMO_UNIT_MM`]).
    pub fn params(self) -> SssParams {
        match self {
            Preset::Table61 => SssParams {
                width_mm: 0.014 * DEMO_UNIT_MM,
                strength: [0.78, 0.70, 0.75],
                falloff: [0.57, 0.13, 0.08],
                shape: KernelShape::RedSlice,
            },
            Preset::Demo => SssParams {
                width_mm: 0.012 * DEMO_UNIT_MM,
                strength: [0.48, 0.41, 0.28],
                falloff: [1.0, 0.37, 0.3],
                shape: KernelShape::RedSlice,
            },
            Preset::Physical => SssParams {
                width_mm: PHYSICAL_WIDTH_SIGMAS * SIX_GAUSSIAN_VARIANCES_MM2[5].sqrt(),
                strength: [1.0; 3],
                falloff: [0.0; 3],
                shape: KernelShape::Marginal,
            },
            Preset::Burley => {
                let s = burley_profile().s();
                let width = s
                    .iter()
                    .map(|&s| burley::marginal_quantile_half_width(s, BURLEY_KEPT_MASS))
                    .fold(0.0, f64::max);
                SssParams {
                    width_mm: width as f32,
                    strength: [1.0; 3],
                    falloff: [0.0; 3],
                    shape: KernelShape::Burley,
                }
            }
        }
    }
}

impl FromStr for Preset {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "table6.1" | "table61" => Ok(Preset::Table61),
            "demo" => Ok(Preset::Demo),
            "physical" => Ok(Preset::Physical),
            "burley" => Ok(Preset::Burley),
            _ => bail!(
                "unknown SSS preset {s:?}; valid presets: table6.1 (or table61), demo, physical, \
                 burley"
            ),
        }
    }
}

impl SssParams {
    /// Largest accepted width: anything wider than a metre is a unit mistake.
    pub const MAX_WIDTH_MM: f32 = 1000.0;
    /// Largest accepted falloff. Eq. 6.1 stretches the red profile by
    /// 1 / (0.001 + f): past f = 40 its narrowest Gaussian (0.08 mm) spans the
    /// whole kernel, which is then a box; at 1e30 the weights underflow to 0/0.
    pub const MAX_FALLOFF: f32 = 100.0;

    /// Checks ranges so that kernel construction never produces NaN.
    pub fn validate(&self) -> Result<()> {
        let w = self.width_mm;
        if !w.is_finite() {
            bail!("SSS width_mm must be finite, got {w}");
        }
        if !(0.0..=Self::MAX_WIDTH_MM).contains(&w) {
            bail!(
                "SSS width_mm must be in [0, {}] mm, got {w}",
                Self::MAX_WIDTH_MM
            );
        }
        for (name, &t) in CHANNELS.iter().zip(&self.strength) {
            if !t.is_finite() || !(0.0..=1.0).contains(&t) {
                bail!("SSS strength ({name}) must be a finite value in [0, 1], got {t}");
            }
        }
        for (name, &f) in CHANNELS.iter().zip(&self.falloff) {
            if !f.is_finite() || !(0.0..=Self::MAX_FALLOFF).contains(&f) {
                bail!(
                    "SSS falloff ({name}) must be within 0..={}, got {f}",
                    Self::MAX_FALLOFF
                );
            }
            if self.shape != KernelShape::RedSlice && f != 0.0 {
                bail!(
                    "SSS falloff ({name}) reshapes eq. 6.1's red slice and must be 0 for the \
                     marginal kernels (physical, burley), got {f}"
                );
            }
        }
        Ok(())
    }
}

/// One kernel tap: surface offset in mm and per-channel weight.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct KernelSample {
    pub offset_mm: f32,
    pub weight: [f32; 3],
}

/// A built 1D kernel; `samples[0]` is the centre (offset 0).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SeparableKernel {
    pub params: SssParams,
    pub samples: Vec<KernelSample>,
}

/// Weights of the non-negative taps `offsets` (from 0 up) for a symmetric
/// density given by its `mass(a, b)` and `first(a, b)` (first moment) over
/// intervals: each interval's mass goes to its two taps linearly, so that
/// the mass and the first moment of every interval stay exact. Tap 0 gets
/// only its `[0, x_1]` share (the caller doubles it for `[-x_1, x_1]`).
fn moment_keeping_weights(
    offsets: &[f64],
    mass: impl Fn(f64, f64) -> f64,
    first: impl Fn(f64, f64) -> f64,
) -> Vec<f64> {
    let mut raw = vec![0.0; offsets.len()];
    for j in 0..offsets.len() - 1 {
        let (a, b) = (offsets[j], offsets[j + 1]);
        let (m, f) = (mass(a, b), first(a, b));
        raw[j] += (b * m - f) / (b - a);
        raw[j + 1] += (f - a * m) / (b - a);
    }
    raw
}

impl SeparableKernel {
    /// Upper bound on taps (the shader's fixed-size uniform array, sized from
    /// the same constant).
    pub const MAX_SAMPLES: usize = crate::shader_constants::SEPARABLE_MAX_SAMPLES;

    /// Builds the kernel with `n_samples` taps (odd, 3..=63).
    pub fn build(params: SssParams, n_samples: usize) -> Result<Self> {
        params.validate().context("invalid SSS kernel parameters")?;
        if !(3..=Self::MAX_SAMPLES).contains(&n_samples) || n_samples % 2 == 0 {
            bail!(
                "SSS kernel sample count must be odd and in 3..={}, got {n_samples}",
                Self::MAX_SAMPLES
            );
        }
        let half = (n_samples - 1) / 2;
        let width = f64::from(params.width_mm);
        if width == 0.0 {
            let mut samples = vec![
                KernelSample {
                    offset_mm: 0.0,
                    weight: [0.0; 3],
                };
                n_samples
            ];
            samples[0].weight = [1.0; 3];
            return Ok(Self { params, samples });
        }

        // Non-negative half only (j = 0..=half); the kernel is mirrored so
        // that symmetry is exact rather than up to rounding.
        let offsets: Vec<f64> = (0..=half)
            .map(|j| {
                let t = j as f64 / half as f64;
                width * t * t
            })
            .collect();
        let cell = |j: usize| -> (f64, f64) {
            let lo = if j == 0 {
                0.0
            } else {
                0.5 * (offsets[j - 1] + offsets[j])
            };
            let hi = if j == half {
                width
            } else {
                0.5 * (offsets[j] + offsets[j + 1])
            };
            (lo, hi)
        };

        // half_weights[j][c]: normalised, strength-applied weight of tap +j.
        let mut half_weights = vec![[0.0f64; 3]; half + 1];
        let channels = params.falloff.iter().zip(&params.strength);
        for (c, (&falloff, &strength)) in channels.enumerate() {
            let mut raw: Vec<f64> = match params.shape {
                KernelShape::RedSlice => {
                    // Change of variable u = s x maps the kernel edge to
                    // 3 / (0.001 + f) mm of the red profile; the 1/s
                    // Jacobian is common to all cells and cancels in the
                    // normalisation.
                    let s = 3.0 / (width * (0.001 + f64::from(falloff)));
                    (0..=half)
                        .map(|j| {
                            let (lo, hi) = cell(j);
                            red_profile_line_integral(s * lo, s * hi)
                        })
                        .collect()
                }
                // True millimetres. Each interval between neighbouring taps
                // splits its mass between its two taps so that the mass and
                // the first moment stay exact (linear, "cloud in cell"
                // assignment): then sum_k W_k |x_k| is the marginal's mean
                // |x|, the moment an edge's response measures, for any tap
                // count. Cell integrals instead lump the 0.08 and 0.22 mm
                // Gaussians on the centre tap and lose 3% (red) to 13%
                // (blue) of the edge energy at 17 taps. The mass beyond
                // +-width (0.02% of red at 3 sigma) is dropped by the
                // normalisation below.
                KernelShape::Marginal => moment_keeping_weights(
                    &offsets,
                    |a, b| marginal_integral(c, a, b),
                    |a, b| marginal_first_moment(c, a, b),
                ),
                // The same on Burley's marginal, plus its tail beyond the
                // outermost tap (see the module docs).
                KernelShape::Burley => {
                    let s = burley_profile().s()[c];
                    let mut raw = moment_keeping_weights(
                        &offsets,
                        |a, b| burley::marginal_integral(s, a, b),
                        |a, b| burley::marginal_first_moment(s, a, b),
                    );
                    let tail_mass = burley::marginal_tail(s, width);
                    let tail_first = burley::marginal_first_moment(s, width, f64::INFINITY);
                    raw[half] += tail_first / width;
                    raw[0] += tail_mass - tail_first / width;
                    raw
                }
            };
            // The centre cell spans [-m, m]; only [0, m] was integrated.
            raw[0] *= 2.0;
            let total = raw[0] + 2.0 * raw[1..].iter().sum::<f64>();
            let t = f64::from(strength);
            for (j, r) in raw.iter().enumerate() {
                let w = r / total;
                half_weights[j][c] = if j == 0 { (1.0 - t) + t * w } else { t * w };
            }
        }

        let to_f32 = |w: [f64; 3]| [w[0] as f32, w[1] as f32, w[2] as f32];
        let tap = |j: usize, sign: f64| KernelSample {
            offset_mm: (sign * offsets[j]) as f32,
            weight: to_f32(half_weights[j]),
        };
        let mut samples = Vec::with_capacity(n_samples);
        samples.push(tap(0, 1.0));
        samples.extend((1..=half).rev().map(|j| tap(j, -1.0)));
        samples.extend((1..=half).map(|j| tap(j, 1.0)));
        // The checked ranges keep every weight finite; a weight that is not
        // would put NaN in every skin pixel.
        anyhow::ensure!(
            samples
                .iter()
                .all(|s| s.weight.iter().all(|w| w.is_finite())),
            "SSS kernel weights are not finite for {params:?}"
        );
        Ok(Self { params, samples })
    }

    /// Uniform-buffer layout: per sample `[wr, wg, wb, offset_mm]`, centre
    /// first (the HLSL kernel stores the offset in `.a` the same way).
    pub fn gpu_data(&self) -> Vec<[f32; 4]> {
        self.samples
            .iter()
            .map(|s| [s.weight[0], s.weight[1], s.weight[2], s.offset_mm])
            .collect()
    }

    /// `sum_i w_i * f(offset_i)` per channel: the kernel applied to a 1D
    /// signal sampled at the tap offsets (mm). Used to test the quadrature.
    pub fn apply_1d(&self, f: impl Fn(f64) -> [f64; 3]) -> [f64; 3] {
        let mut acc = [0.0; 3];
        for s in &self.samples {
            let v = f(f64::from(s.offset_mm));
            for c in 0..3 {
                acc[c] += f64::from(s.weight[c]) * v[c];
            }
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::super::profile::{profile_variance_mm2, red_profile, SIX_GAUSSIAN_WEIGHTS_RGB};
    use super::*;

    const COUNTS: [usize; 3] = [9, 17, 33];

    fn build(p: Preset, n: usize) -> SeparableKernel {
        SeparableKernel::build(p.params(), n).expect("preset kernel builds")
    }

    #[test]
    fn preset_names_round_trip_and_widths() {
        for p in Preset::ALL {
            assert_eq!(p.name().parse::<Preset>().unwrap(), p);
            p.params().validate().unwrap();
        }
        assert_eq!("table61".parse::<Preset>().unwrap(), Preset::Table61);
        assert_eq!(" Demo ".parse::<Preset>().unwrap(), Preset::Demo);
        let err = "skin".parse::<Preset>().unwrap_err().to_string();
        assert!(
            err.contains("table6.1")
                && err.contains("demo")
                && err.contains("physical")
                && err.contains("burley"),
            "{err}"
        );
        assert!((Preset::Table61.params().width_mm - 3.22).abs() < 1e-5);
        assert!((Preset::Demo.params().width_mm - 2.76).abs() < 1e-5);
        // 3 sigma of red's widest Gaussian: 3 sqrt(7.41).
        assert!((Preset::Physical.params().width_mm - 8.1664).abs() < 1e-4);
    }

    #[test]
    fn channels_are_normalised() {
        for p in Preset::ALL {
            for n in COUNTS {
                let k = build(p, n);
                assert_eq!(k.samples.len(), n);
                for c in 0..3 {
                    let s: f64 = k.samples.iter().map(|s| f64::from(s.weight[c])).sum();
                    assert!((s - 1.0).abs() < 1e-6, "{p:?} n={n} c={c}: sum {s}");
                }
                assert!(k.samples.iter().all(|s| s.weight.iter().all(|w| *w >= 0.0)));
            }
        }
    }

    #[test]
    fn centre_first_and_strength_lerp() {
        let base = Preset::Table61.params();
        let full = SeparableKernel::build(
            SssParams {
                strength: [1.0; 3],
                ..base
            },
            17,
        )
        .unwrap();
        let part = SeparableKernel::build(base, 17).unwrap();
        assert_eq!(part.samples[0].offset_mm, 0.0);
        for (i, (a, b)) in part.samples.iter().zip(&full.samples).enumerate() {
            assert_eq!(a.offset_mm, b.offset_mm);
            for c in 0..3 {
                let t = base.strength[c];
                let want = if i == 0 {
                    (1.0 - t) + t * b.weight[c]
                } else {
                    t * b.weight[c]
                };
                assert!((a.weight[c] - want).abs() < 1e-6, "tap {i} c {c}");
            }
        }
        // Remaining taps are ordered by increasing offset and exclude 0.
        let offs: Vec<f32> = part.samples[1..].iter().map(|s| s.offset_mm).collect();
        assert!(offs.windows(2).all(|w| w[0] < w[1]));
        assert!(offs.iter().all(|&o| o != 0.0));
        let w = base.width_mm;
        assert!((offs[0] + w).abs() < 1e-6 && (offs[offs.len() - 1] - w).abs() < 1e-6);
    }

    #[test]
    fn taps_are_symmetric() {
        for p in Preset::ALL {
            for n in COUNTS {
                let k = build(p, n);
                for i in 1..n {
                    let (a, b) = (k.samples[i], k.samples[n - i]);
                    assert_eq!(a.offset_mm, -b.offset_mm, "{p:?} n={n} i={i}");
                    for c in 0..3 {
                        assert!((a.weight[c] - b.weight[c]).abs() < 1e-7);
                    }
                }
            }
        }
    }

    #[test]
    fn zero_width_is_identity() {
        let params = SssParams {
            width_mm: 0.0,
            ..Preset::Demo.params()
        };
        let k = SeparableKernel::build(params, 9).unwrap();
        assert_eq!(k.samples[0].weight, [1.0; 3]);
        assert!(k.samples.iter().all(|s| s.offset_mm == 0.0));
        assert!(k.samples[1..].iter().all(|s| s.weight == [0.0; 3]));
        let g = k.apply_1d(|x| [x + 2.0, 3.0, -1.0]);
        assert_eq!(g, [2.0, 3.0, -1.0]);
    }

    #[test]
    fn gpu_data_layout() {
        let k = build(Preset::Table61, 9);
        let d = k.gpu_data();
        assert_eq!(d.len(), 9);
        for (row, s) in d.iter().zip(&k.samples) {
            assert_eq!(*row, [s.weight[0], s.weight[1], s.weight[2], s.offset_mm]);
        }
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let ok = Preset::Table61.params();
        let bad = [
            (
                SssParams {
                    width_mm: f32::NAN,
                    ..ok
                },
                "width_mm",
            ),
            (
                SssParams {
                    width_mm: -1.0,
                    ..ok
                },
                "width_mm",
            ),
            (
                SssParams {
                    width_mm: 1e4,
                    ..ok
                },
                "width_mm",
            ),
            (
                SssParams {
                    strength: [0.5, 1.5, 0.5],
                    ..ok
                },
                "strength (green)",
            ),
            (
                SssParams {
                    strength: [f32::NAN, 0.5, 0.5],
                    ..ok
                },
                "strength (red)",
            ),
            (
                SssParams {
                    falloff: [0.5, 0.5, -0.1],
                    ..ok
                },
                "falloff (blue)",
            ),
            (
                SssParams {
                    falloff: [f32::INFINITY, 0.5, 0.1],
                    ..ok
                },
                "falloff (red)",
            ),
            // Issue 11: --falloff 1e30 gave NaN pixels.
            (
                SssParams {
                    falloff: [1e30, 0.5, 0.1],
                    ..ok
                },
                "falloff (red)",
            ),
        ];
        for (p, field) in bad {
            let msg = format!("{:#}", SeparableKernel::build(p, 17).unwrap_err());
            assert!(msg.contains(field), "{msg}");
        }
        for n in [0, 1, 2, 8, 16, 64, 65] {
            assert!(SeparableKernel::build(ok, n).is_err(), "n={n} accepted");
        }
        assert!(SeparableKernel::build(ok, 3).is_ok());
        assert!(SeparableKernel::build(ok, 63).is_ok());
    }

    /// Composite Simpson rule with `n` (even) intervals.
    fn simpson(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
        let h = (b - a) / n as f64;
        let mut s = f(a) + f(b);
        for i in 1..n {
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
        }
        s * h / 3.0
    }

    /// Max over channels and evaluation points of |kernel - continuous|.
    ///
    /// Both test signals are odd about 0 (sin, tanh), for which any symmetric
    /// kernel is trivially exact at x0 = 0; so the convolution is evaluated
    /// at several shifted points x0 (i.e. the signal g(x + x0) is used).
    /// The continuous 1D shape channel `c` of `params` samples (unnormalised).
    fn continuous_shape(params: SssParams, c: usize) -> impl Fn(f64) -> f64 {
        let w = f64::from(params.width_mm);
        let s = 3.0 / (w * (0.001 + f64::from(params.falloff[c])));
        move |x: f64| match params.shape {
            KernelShape::RedSlice => red_profile((s * x).abs()),
            KernelShape::Marginal => marginal_density(c, x),
            KernelShape::Burley => unreachable!("see burley_reference"),
        }
    }

    /// Burley's marginal for channel `c` as a fine kernel: taps at `k h`,
    /// `k = 0..=20000`, out to `40 / s` (the tail beyond holds ~1e-7), with
    /// the moment-keeping weights (the log singularity at 0 rules out
    /// Simpson there). Halves `(offset, weight)`, the centre's weight
    /// already doubled. Computed once.
    fn burley_reference(c: usize) -> &'static [(f64, f64)] {
        static FINE: std::sync::OnceLock<[Vec<(f64, f64)>; 3]> = std::sync::OnceLock::new();
        &FINE.get_or_init(|| {
            let s = burley_profile().s();
            [0, 1, 2].map(|c| {
                let n = 20_000;
                let h = 40.0 / s[c] / n as f64;
                let x: Vec<f64> = (0..=n).map(|k| k as f64 * h).collect();
                let mut w = moment_keeping_weights(
                    &x,
                    |a, b| burley::marginal_integral(s[c], a, b),
                    |a, b| burley::marginal_first_moment(s[c], a, b),
                );
                w[0] *= 2.0;
                x.into_iter().zip(w).collect()
            })
        })[c]
    }

    /// The continuous convolution `integral shape(x) g(x + x0) dx` over the
    /// shape's mass, with the preset's strength: the exact kernel, truncated
    /// to the preset's width for the six-Gaussian shapes (which drop the
    /// rest), the whole line for Burley's (which keeps it).
    fn continuous_convolution(params: SssParams, c: usize, g: &dyn Fn(f64) -> f64, x0: f64) -> f64 {
        let w = f64::from(params.width_mm);
        let (num, den) = match params.shape {
            KernelShape::Burley => {
                burley_reference(c)
                    .iter()
                    .fold((0.0, 0.0), |(num, den), &(x, wt)| {
                        let (v, m) = if x == 0.0 {
                            (g(x0), 1.0)
                        } else {
                            (g(x0 + x) + g(x0 - x), 2.0)
                        };
                        (num + wt * v, den + wt * m)
                    })
            }
            _ => {
                let shape = continuous_shape(params, c);
                let num = simpson(-w, w, 40_000, |x| shape(x) * g(x + x0));
                (num, simpson(-w, w, 40_000, shape))
            }
        };
        let t = f64::from(params.strength[c]);
        (1.0 - t) * g(x0) + t * num / den
    }

    /// `sum_i w_ic N(x; 0, v_i)`.
    fn marginal_density(c: usize, x: f64) -> f64 {
        SIX_GAUSSIAN_VARIANCES_MM2
            .iter()
            .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
            .map(|(&v, w)| {
                let v = f64::from(v);
                f64::from(w[c]) * (-x * x / (2.0 * v)).exp() / (2.0 * PI * v).sqrt()
            })
            .sum()
    }

    fn convolution_error(p: Preset, n: usize, g: &dyn Fn(f64) -> f64) -> f64 {
        let k = build(p, n);
        let params = p.params();
        let w = f64::from(params.width_mm);
        let mut worst: f64 = 0.0;
        for frac in [0.07, 0.23, 0.41, 0.6] {
            let x0 = frac * w;
            let got = k.apply_1d(|x| [g(x + x0); 3]);
            for (c, &got_c) in got.iter().enumerate() {
                let want = continuous_convolution(params, c, g, x0);
                worst = worst.max((got_c - want).abs());
            }
        }
        worst
    }

    /// Bounds for 9/17/33 taps, measured with both presets and both signals
    /// (worst observed: 7.8e-3, 2.4e-3, 3.6e-4 for Table 6.1 with tanh;
    /// signal amplitude ~1), with ~30% head-room.
    const ERROR_BOUNDS: [f64; 3] = [1e-2, 3.2e-3, 5e-4];

    /// The physical kernel is 2.5x wider with the same taps, so the 0.3 mm
    /// tanh step is coarser for it (worst observed 5.6e-2, 1.3e-2, 2.9e-3).
    const PHYSICAL_ERROR_BOUNDS: [f64; 3] = [7e-2, 1.7e-2, 4e-3];

    /// Burley's kernel, 5.97 mm wide, against the whole line (its tail is
    /// folded onto the outer taps, not dropped): worst observed 4.4e-2,
    /// 7.9e-3, 2.1e-3 (tanh).
    const BURLEY_ERROR_BOUNDS: [f64; 3] = [6e-2, 1.1e-2, 2.8e-3];

    #[test]
    fn matches_continuous_convolution() {
        for p in Preset::ALL {
            let w = f64::from(p.params().width_mm);
            let sine = move |x: f64| 1.0 + 0.5 * (2.0 * std::f64::consts::PI * x / (0.8 * w)).sin();
            let step = |x: f64| (x / 0.3).tanh();
            let signals: [(&str, &dyn Fn(f64) -> f64); 2] = [("sine", &sine), ("tanh", &step)];
            for (name, g) in signals {
                let errs: Vec<f64> = COUNTS.iter().map(|&n| convolution_error(p, n, g)).collect();
                println!(
                    "{} {name}: err9 {:.3e} err17 {:.3e} err33 {:.3e}",
                    p.name(),
                    errs[0],
                    errs[1],
                    errs[2]
                );
                assert!(
                    errs[2] < errs[1] && errs[1] < errs[0],
                    "{p:?} {name}: no convergence {errs:?}"
                );
                let bounds = match p {
                    Preset::Physical => PHYSICAL_ERROR_BOUNDS,
                    Preset::Burley => BURLEY_ERROR_BOUNDS,
                    _ => ERROR_BOUNDS,
                };
                for (err, bound) in errs.iter().zip(bounds) {
                    assert!(*err < bound, "{p:?} {name}: {errs:?} vs {bounds:?}");
                }
            }
        }
    }

    /// `(variance, sum_k W_k max(x_k, 0))` of channel `c` of a built kernel:
    /// the second moment and the energy a step of unit contrast moves.
    fn moments(k: &SeparableKernel, c: usize) -> (f64, f64) {
        let mut var = 0.0;
        let mut plus = 0.0;
        for s in &k.samples {
            let (x, w) = (f64::from(s.offset_mm), f64::from(s.weight[c]));
            var += w * x * x;
            plus += w * x.max(0.0);
        }
        (var, plus)
    }

    #[test]
    fn physical_kernel_matches_the_profile_moments() {
        let var = profile_variance_mm2();
        let spread = crate::skin::card::edge_spread_mm();
        // Worst relative errors over R, G, B of the variance and of the
        // edge energy at 9/17/33/63 taps (measured; bounds with head-room).
        let bounds = [(1.5, 3e-3), (0.35, 3e-3), (0.1, 3e-3), (0.03, 3e-3)];
        for (n, (var_bound, edge_bound)) in [9, 17, 33, 63].into_iter().zip(bounds) {
            let k = build(Preset::Physical, n);
            let mut line = format!("physical n={n}:");
            for c in 0..3 {
                let (v, plus) = moments(&k, c);
                let (ev, ee) = (v / var[c] - 1.0, plus / spread[c] - 1.0);
                line += &format!(
                    " {}: var {v:.4} (profile {:.4}, {ev:+.4}) edge {:+.4};",
                    CHANNELS[c], var[c], ee
                );
                assert!(ev.abs() < var_bound && ee.abs() < edge_bound, "{line}");
            }
            println!("{line}");
        }
        // The sources' presets, for comparison: far narrower.
        for p in [Preset::Table61, Preset::Demo] {
            let k = build(p, 17);
            let (v, plus) = moments(&k, 0);
            println!(
                "{} n=17 red: var {v:.4} (profile {:.4}) edge {:.3}x",
                p.name(),
                var[0],
                plus / spread[0]
            );
        }
    }

    /// The Burley kernel against its profile's closed forms: the energy a
    /// step moves (the card's edge spread, `2.5 / (pi s)`) and the mass, at
    /// every tap count; the variance only converges (the tail folded onto
    /// the outermost tap carries less of it). Also what dropping the tail,
    /// as the physical kernel does, would cost at this width.
    #[test]
    fn burley_kernel_matches_its_edge_spread() {
        let profile = burley_profile();
        let (spread, var) = (profile.edge_spread_mm(), profile.marginal_variance_mm2());
        // Same-mean-radius match: the six Gaussians' edge spread (to the
        // f32 weights' sum, 1 only to ~1e-7, which the match divides out).
        let six = crate::skin::card::edge_spread_mm();
        for c in 0..3 {
            assert!(
                (spread[c] / six[c] - 1.0).abs() < 1e-6,
                "{spread:?} {six:?}"
            );
        }
        let width = f64::from(Preset::Burley.params().width_mm);
        assert!((width - 5.9671).abs() < 1e-4, "{width}");
        for n in [9, 17, 33, 63] {
            let k = build(Preset::Burley, n);
            let mut line = format!("burley n={n}:");
            for c in 0..3 {
                let (v, plus) = moments(&k, c);
                let ee = plus / spread[c] - 1.0;
                line += &format!(
                    " {}: var {v:.4} (profile {:.4}) edge {ee:+.2e};",
                    CHANNELS[c], var[c]
                );
                // f32 weights: exact to rounding.
                assert!(ee.abs() < 1e-5, "{line}");
            }
            println!("{line}");
        }
        // Dropping the tail beyond the width instead: red's edge energy
        // short by the tail's first moment, less the renormalisation.
        let s = profile.s()[0];
        let (tail, first) = (
            burley::marginal_tail(s, width),
            burley::marginal_first_moment(s, width, f64::INFINITY),
        );
        let dropped = (spread[0] - first) / (1.0 - 2.0 * tail) / spread[0] - 1.0;
        println!("burley red without the tail: edge {dropped:+.4} (tail mass {tail:.2e} a side)");
        assert!(dropped < -0.02, "{dropped}");
    }

    #[test]
    fn marginal_shape_rejects_a_falloff() {
        for preset in [Preset::Physical, Preset::Burley] {
            let p = SssParams {
                falloff: [0.0, 0.2, 0.0],
                ..preset.params()
            };
            let msg = format!("{:#}", SeparableKernel::build(p, 17).unwrap_err());
            assert!(msg.contains("falloff (green)"), "{msg}");
        }
    }

    #[test]
    fn physical_params_serialise_their_shape_and_sources_do_not() {
        let t = serde_json::to_value(Preset::Table61.params()).unwrap();
        assert!(t.get("shape").is_none(), "{t}");
        let p = serde_json::to_value(Preset::Physical.params()).unwrap();
        assert_eq!(p["shape"], "Marginal");
        let b = serde_json::to_value(Preset::Burley.params()).unwrap();
        assert_eq!(b["shape"], "Burley");
    }

    /// Why the marginal and not the rank-1 least-squares fit: both as 1D
    /// kernels on a 0.02 mm grid (red), compared with the 2D profile on an
    /// edge (energy moved), as a point response (relative L2 error of the
    /// separable product against the 2D profile) and by the energy a point
    /// light leaves within 1 and 3 mm.
    #[test]
    fn marginal_versus_rank_one() {
        let h = 0.02;
        let n = 1001; // -10..=10 mm
        let x: Vec<f64> = (0..n).map(|i| (i as f64 - 500.0) * h).collect();
        let p: Vec<f64> = (0..n * n)
            .map(|k| red_profile(x[k / n].hypot(x[k % n])))
            .collect();
        // Marginal: the row sums of the 2D profile, normalised.
        let mut marginal: Vec<f64> = (0..n)
            .map(|i| p[i * n..(i + 1) * n].iter().sum::<f64>())
            .collect();
        // Rank 1: the leading eigenvector of the (symmetric, positive) P.
        let mut u = vec![1.0; n];
        for _ in 0..200 {
            let next: Vec<f64> = (0..n)
                .map(|i| {
                    p[i * n..(i + 1) * n]
                        .iter()
                        .zip(&u)
                        .map(|(a, b)| a * b)
                        .sum()
                })
                .collect();
            let norm = next.iter().map(|v| v * v).sum::<f64>().sqrt();
            u = next.iter().map(|v| v / norm).collect();
        }
        let p_norm = p.iter().map(|v| v * v).sum::<f64>().sqrt();
        // The least-squares fit itself, lambda u u^T (|u| = 1): its error
        // and the share of the light it keeps.
        let lambda: f64 = (0..n)
            .map(|i| u[i] * (0..n).map(|j| p[i * n + j] * u[j]).sum::<f64>())
            .sum();
        let ls_err = (0..n * n)
            .map(|m| (lambda * u[m / n] * u[m % n] - p[m]).powi(2))
            .sum::<f64>()
            .sqrt()
            / p_norm;
        let ls_energy = lambda * u.iter().sum::<f64>().powi(2) * h * h;
        println!(
            "rank-1 least squares: 2D L2 error {ls_err:.3}, keeps {ls_energy:.3} of the light"
        );
        // As kernels, both normalised to conserve light (each pass sums to 1).
        for k in [&mut marginal, &mut u] {
            let s: f64 = k.iter().sum();
            k.iter_mut().for_each(|v| *v /= s);
        }
        let p_total: f64 = p.iter().sum();
        let exact_edge = crate::skin::card::edge_spread_mm()[0];
        let within = |k: Option<&[f64]>, r: f64| -> f64 {
            let mut e = 0.0;
            for i in 0..n {
                for j in 0..n {
                    if x[i].hypot(x[j]) <= r {
                        e += match k {
                            Some(k) => k[i] * k[j],
                            None => p[i * n + j] / p_total,
                        };
                    }
                }
            }
            e
        };
        let mut stats = Vec::new();
        for (name, k) in [("marginal", &marginal), ("rank-1", &u)] {
            let edge: f64 = k.iter().zip(&x).map(|(w, x)| w * x.max(0.0)).sum();
            let var: f64 = k.iter().zip(&x).map(|(w, x)| w * x * x).sum();
            // Densities: k_i k_j / h^2 against P.
            let err = (0..n * n)
                .map(|m| (k[m / n] * k[m % n] / (h * h) - p[m]).powi(2))
                .sum::<f64>()
                .sqrt()
                / p_norm;
            let (e1, e3) = (within(Some(k), 1.0), within(Some(k), 3.0));
            println!(
                "{name}: edge {:.3}x exact, variance {var:.3} mm^2, 2D L2 error {err:.3}, \
                 within 1 mm {e1:.3}, within 3 mm {e3:.3}",
                edge / exact_edge
            );
            stats.push((edge / exact_edge, err));
        }
        println!(
            "2D profile: variance {:.3}, within 1 mm {:.3}, within 3 mm {:.3}",
            profile_variance_mm2()[0],
            within(None, 1.0),
            within(None, 3.0)
        );
        let (marginal_edge, marginal_err) = stats[0];
        let (rank1_edge, rank1_err) = stats[1];
        assert!((marginal_edge - 1.0).abs() < 2e-3, "{marginal_edge}");
        assert!(ls_err < marginal_err, "{ls_err} vs {marginal_err}");
        assert!(rank1_err > marginal_err, "{rank1_err} vs {marginal_err}");
        assert!(rank1_edge < 0.5, "{rank1_edge}");
    }

    /// FNV-1a over the f32 bits of every tap (offset and weights).
    fn kernel_hash(k: &SeparableKernel) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for row in k.gpu_data() {
            for v in row {
                for b in v.to_bits().to_le_bytes() {
                    h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
                }
            }
        }
        h
    }

    /// The sources' presets stay bit for bit what they were before the
    /// physical preset was added (hashes recorded then, checked against
    /// `dermis kernel` output of the earlier build).
    #[test]
    fn source_presets_are_unchanged() {
        let mut got = Vec::new();
        for p in [Preset::Table61, Preset::Demo] {
            for n in [9, 17, 33] {
                got.push(kernel_hash(&build(p, n)));
            }
        }
        assert_eq!(got, PINNED_HASHES, "{got:#x?}");
    }

    /// table6.1 at 9/17/33 taps, then demo.
    const PINNED_HASHES: [u64; 6] = [
        0xdc04_4989_c876_780b,
        0x0b82_c020_8b53_7b9c,
        0xe479_dd1e_e3b7_0a4c,
        0x1ecd_1b9a_f488_227e,
        0xee34_9daf_4b08_b388,
        0xa572_d77a_9a6c_66ea,
    ];

    // Every corner of the accepted ranges gives finite weights summing to 1
    // per channel (issue 11: out-of-range falloffs gave NaN).
    #[test]
    fn the_accepted_ranges_give_finite_normalised_kernels() {
        for width in [0.0, 1e-6, 1e-3, 3.0, SssParams::MAX_WIDTH_MM] {
            for f in [0.0, 1e-6, 1.0, 40.0, SssParams::MAX_FALLOFF] {
                for t in [0.0, 0.5, 1.0] {
                    for n in [3, 17, SeparableKernel::MAX_SAMPLES] {
                        let p = SssParams {
                            width_mm: width,
                            strength: [t; 3],
                            falloff: [f; 3],
                            shape: KernelShape::RedSlice,
                        };
                        let k = SeparableKernel::build(p, n).unwrap();
                        for c in 0..3 {
                            let sum: f32 = k.samples.iter().map(|s| s.weight[c]).sum();
                            assert!((sum - 1.0).abs() < 1e-4, "{p:?} n={n}: {sum}");
                        }
                    }
                }
            }
        }
    }
}
