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
pub const N_PARAMS: usize = 9;

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
    /// Extra texture-time multiplier of incoherent (per-pixel rotated) taps.
    pub incoherent_factor: f64,
    /// Fixed cost of every pass, in thousands of pixels at the profile's
    /// 32 bpp fill rate (pipeline ramp-up and drain, state changes).
    pub fixed_kpix_per_pass: f64,
    /// Fixed cost of every rectangle of a copy (one copy region each), in the
    /// same unit.
    pub rect_kpix: f64,
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
    };

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
        texture_scale: 1.18769,
        alu_scale: 1.07544,
        fill_scale: 1.91277,
        memory_scale: 0.55179,
        reject_scale: 1.65972,
        hiz_reject_scale: 0.29789,
        incoherent_factor: 1.40493,
        fixed_kpix_per_pass: 20.72121,
        rect_kpix: 29.63448,
    },
    probed: ModelParams {
        texture_scale: 1.14326,
        alu_scale: 0.98289,
        fill_scale: 1.05804,
        memory_scale: 1.00003,
        reject_scale: 0.14368,
        hiz_reject_scale: 0.29789,
        incoherent_factor: 1.40493,
        fixed_kpix_per_pass: 41.19397,
        rect_kpix: 29.63448,
    },
};
