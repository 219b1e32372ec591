//! The model's free parameters: efficiency scales of each unit, the extra cost
//! of incoherent taps and of early rejection, and fixed costs per pass and per
//! copy rectangle. Fitted by `calibration`, never guessed; fitted apart for
//! profiles whose rates are peaks (spec sheets: the consoles and the sources'
//! GPUs, fitted on the published points) and profiles whose rates were
//! probed (the benchmark GPUs, fitted on their bench reports), because a peak
//! is not reached and a probe is.

use serde::{Deserialize, Serialize};

use crate::budget::profile::RateSource;

/// Number of free parameters.
pub const N_PARAMS: usize = 14;

/// One set of the model's free parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelParams {
    /// Multiplies texture time (1: the profile's rate is reached).
    pub texture_scale: f64,
    pub alu_scale: f64,
    pub fill_scale: f64,
    pub memory_scale: f64,
    /// Multiplies the time of pixels rejected one by one (stencil, at the
    /// Z-only rate).
    pub reject_scale: f64,
    /// Multiplies the time of pixels of a depth-tested pass that passes
    /// nothing (its triangle lies in front of every surface, so hierarchical
    /// Z rejects whole tiles: expected well under 1).
    pub hiz_reject_scale: f64,
    /// Extra texture-time multiplier of incoherent (per-pixel rotated) taps
    /// that land far apart (the asymptote of [`ModelParams::incoherence`]).
    pub incoherent_factor: f64,
    /// Fixed cost of every pass, in thousands of pixels at the profile's
    /// 32 bpp fill rate (pipeline ramp-up and drain, state changes).
    pub fixed_kpix_per_pass: f64,
    /// Fixed cost of every rectangle of a copy (one copy region each), in the
    /// same unit.
    pub rect_kpix: f64,
    /// Tap radius (pixels) at which incoherent taps pay half their extra
    /// cost: rotated taps well inside it land in the texels their neighbours'
    /// taps already brought into the cache.
    pub incoherent_radius_px: f64,
    /// Fixed cost of every dispatch and every transfer outside a render pass
    /// (a buffer fill), in place of `fixed_kpix_per_pass`, same unit: the
    /// H100 takes 0.012-0.014 ms for any of them, an empty indirect dispatch
    /// included (docs/perf/issue28/floors.md), four times a draw's.
    pub fixed_kpix_per_dispatch: f64,
    /// Multiplies the ALU time of dispatches (`alu_scale` is the pixel
    /// shaders'): the compute rate is the chip's published peak, which a
    /// shader of workgroup barriers and shared-memory instructions does not
    /// reach, while the pixel rate is a fitted guess of the graphics slice.
    pub compute_alu_scale: f64,
    /// `incoherent_factor` of dispatches: the compute path spreads its taps
    /// over every SM's texture cache (the H100 took the gather's rotated taps
    /// near its coherent compute rate), the pixel path over a few.
    pub compute_incoherent_factor: f64,
    /// Multiplies the shared-memory time of dispatches (their
    /// `shared_bytes` at the profile's shared-memory rate). Fitted on the
    /// one shader that stages a tile in shared memory (the separable compute
    /// blur), it is not a bandwidth efficiency: it prices the staging (store,
    /// workgroup barrier, reload) per byte staged.
    pub shared_scale: f64,
}

impl ModelParams {
    /// No efficiency losses, no fixed cost: the floor the profile's rates give.
    pub const PEAK: ModelParams = ModelParams {
        texture_scale: 1.0,
        alu_scale: 1.0,
        fill_scale: 1.0,
        memory_scale: 1.0,
        reject_scale: 1.0,
        hiz_reject_scale: 1.0,
        incoherent_factor: 1.0,
        fixed_kpix_per_pass: 0.0,
        rect_kpix: 0.0,
        incoherent_radius_px: 1.0,
        fixed_kpix_per_dispatch: 0.0,
        compute_alu_scale: 1.0,
        compute_incoherent_factor: 1.0,
        shared_scale: 1.0,
    };

    /// The texture-time multiplier of incoherent taps landing `radius_px`
    /// from their pixel: 1 (as coherent) for taps within a texel of it,
    /// rising to `incoherent_factor` as the share of a tap's bilinear
    /// texels its neighbours' taps do not share grows with the area the
    /// rotated taps sweep, `r^2 / (r^2 + r_half^2)`.
    pub fn incoherence(&self, radius_px: f64) -> f64 {
        self.incoherence_to(self.incoherent_factor, radius_px)
    }

    /// [`ModelParams::incoherence`] of a dispatch's taps: the same rise to
    /// `compute_incoherent_factor`.
    pub fn compute_incoherence(&self, radius_px: f64) -> f64 {
        self.incoherence_to(self.compute_incoherent_factor, radius_px)
    }

    fn incoherence_to(&self, factor: f64, radius_px: f64) -> f64 {
        let r2 = radius_px * radius_px;
        let h2 = self.incoherent_radius_px * self.incoherent_radius_px;
        1.0 + (factor - 1.0) * r2 / (r2 + h2)
    }

    /// The parameters as a vector (for fitting) and back.
    pub fn to_vec(self) -> [f64; N_PARAMS] {
        [
            self.texture_scale,
            self.alu_scale,
            self.fill_scale,
            self.memory_scale,
            self.reject_scale,
            self.hiz_reject_scale,
            self.incoherent_factor,
            self.fixed_kpix_per_pass,
            self.rect_kpix,
            self.incoherent_radius_px,
            self.fixed_kpix_per_dispatch,
            self.compute_alu_scale,
            self.compute_incoherent_factor,
            self.shared_scale,
        ]
    }

    pub fn from_vec(v: [f64; N_PARAMS]) -> ModelParams {
        ModelParams {
            texture_scale: v[0],
            alu_scale: v[1],
            fill_scale: v[2],
            memory_scale: v[3],
            reject_scale: v[4],
            hiz_reject_scale: v[5],
            incoherent_factor: v[6],
            fixed_kpix_per_pass: v[7],
            rect_kpix: v[8],
            incoherent_radius_px: v[9],
            fixed_kpix_per_dispatch: v[10],
            compute_alu_scale: v[11],
            compute_incoherent_factor: v[12],
            shared_scale: v[13],
        }
    }
}

/// The parameters of both rate sources.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamSet {
    pub peak: ModelParams,
    pub probed: ModelParams,
}

impl ParamSet {
    /// The same parameters for both sources.
    pub const fn both(p: ModelParams) -> ParamSet {
        ParamSet { peak: p, probed: p }
    }

    pub fn get(&self, rates: RateSource) -> &ModelParams {
        match rates {
            RateSource::Peak => &self.peak,
            RateSource::Probed => &self.probed,
        }
    }

    /// The parameters fitted on every calibration point (`calibration::fit_all`;
    /// docs/budget-calibration.md lists them and the held-out errors);
    /// `calibration`'s tests check they are what the fit gives.
    pub fn fitted() -> ParamSet {
        FITTED
    }
}

/// See [`ParamSet::fitted`].
pub const FITTED: ParamSet = ParamSet {
    peak: ModelParams {
        texture_scale: 1.15983,
        alu_scale: 1.06743,
        fill_scale: 2.09130,
        memory_scale: 0.54768,
        reject_scale: 1.64821,
        hiz_reject_scale: 0.13733,
        incoherent_factor: 2.67479,
        fixed_kpix_per_pass: 20.27306,
        rect_kpix: 34.76759,
        incoherent_radius_px: 8.22099,
        fixed_kpix_per_dispatch: 179.97864,
        compute_alu_scale: 0.99952,
        compute_incoherent_factor: 1.18741,
        shared_scale: 25.39211,
    },
    probed: ModelParams {
        texture_scale: 1.14078,
        alu_scale: 0.98076,
        fill_scale: 0.98252,
        memory_scale: 1.63252,
        reject_scale: 0.07979,
        hiz_reject_scale: 0.13733,
        incoherent_factor: 2.67479,
        fixed_kpix_per_pass: 46.02980,
        rect_kpix: 34.76759,
        incoherent_radius_px: 8.22099,
        fixed_kpix_per_dispatch: 179.97864,
        compute_alu_scale: 0.99952,
        compute_incoherent_factor: 1.18741,
        shared_scale: 25.39211,
    },
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn incoherence_rises_from_one_to_the_factor() {
        for p in [FITTED.peak, FITTED.probed] {
            assert!((p.incoherence(0.0) - 1.0).abs() < 1e-12);
            let half = p.incoherence(p.incoherent_radius_px);
            assert!((half - (1.0 + p.incoherent_factor) / 2.0).abs() < 1e-12);
            assert!((p.incoherence(1e6) - p.incoherent_factor).abs() < 1e-6);
            let mut last = 1.0;
            for r in [0.5, 1.0, 2.0, 4.0, 8.0, 16.0] {
                let f = p.incoherence(r);
                assert!(f > last, "not rising at {r}");
                last = f;
            }
        }
    }

    #[test]
    fn a_dispatch_s_incoherence_rises_to_its_own_factor() {
        let p = ModelParams {
            incoherent_factor: 3.0,
            compute_incoherent_factor: 1.5,
            incoherent_radius_px: 4.0,
            ..ModelParams::PEAK
        };
        // At the half radius: 1 + (1.5 - 1) / 2 for a dispatch, 1 + (3 - 1) / 2 for a draw.
        assert!((p.compute_incoherence(4.0) - 1.25).abs() < 1e-12);
        assert!((p.incoherence(4.0) - 2.0).abs() < 1e-12);
        // 12 px: 144 / (144 + 16) = 0.9 of the way.
        assert!((p.compute_incoherence(12.0) - 1.45).abs() < 1e-12);
        assert!((p.compute_incoherence(0.0) - 1.0).abs() < 1e-12);
    }
}
