//! The frame on a profile: every pass's unit times (`units`, with the eDRAM
//! transfers of `transfers`) combined by the stated rule with the fitted
//! parameters of the profile's rate source (`params`), shares of the frame and
//! of the skin budget, and what could not be priced: the JSON-ready result of
//! `dermis budget` ([`FrameBudget`]).

use serde::Serialize;

use crate::budget::input::{FrameInput, RESCALE_RULE};
use crate::budget::params::{ModelParams, ParamSet};
use crate::budget::profile::{Profile, RateSource};
use crate::budget::transfers::price_units;
use crate::budget::units::{Bound, EdramUse, PassUnits, Substitution, UnitTimes};
use crate::work::PassRole;

/// The combining rule, written out for reports.
pub const COMBINING_RULE: &str = "t = fixed + k_rect rects + k_fill T_clear + max(k_tex (T_tex + \
f_inc T_tex_incoherent), k_alu T_alu, k_fill T_fill, k_mem T_mem, k_shared T_shared) + k_rej T_reject + \
k_hiz T_reject_hiz + T_geometry + T_resolve + T_restore; a dispatch or a fill outside a render \
pass takes its own fixed cost, k_alu and f_inc, and T_shared its shared-memory bytes at the \
profile's rate; the k's, f_inc and the fixed costs fitted per rate source (peak: the published \
points; probed: the benchmark GPUs' passes)";

/// Per-pass result, ready for JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassBudget {
    pub name: String,
    pub role: PassRole,
    pub modelled_ms: Option<f64>,
    pub measured_ms: Option<f64>,
    pub bound: Option<Bound>,
    /// Each term of the combining rule, parameters applied (ms).
    pub terms_ms: UnitTimes,
    pub edram: Option<EdramUse>,
    pub substitutions: Vec<Substitution>,
    pub unpriced: Vec<String>,
    pub overruns: Vec<String>,
    pub share_of_frame: Option<f64>,
    /// For SSS passes: share of the profile's skin-SSS budget.
    pub share_of_skin_budget: Option<f64>,
}

/// Time of one role against its budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CategoryBudget {
    pub role: PassRole,
    pub modelled_ms: f64,
    pub budget_ms: f64,
    pub over: bool,
}

/// The whole frame on one profile.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameBudget {
    pub profile: String,
    pub label: String,
    /// Size of the run the counts come from.
    pub run_size: [u32; 2],
    /// Size the frame was priced at.
    pub priced_size: [u32; 2],
    pub rescale_rule: Option<String>,
    pub combining_rule: String,
    pub rates: RateSource,
    pub params: ModelParams,
    pub passes: Vec<PassBudget>,
    /// Sum over priced frame-cost passes.
    pub total_ms: f64,
    pub measured_total_ms: Option<f64>,
    pub frame_ms: f64,
    pub over_frame: bool,
    pub skin_budget_ms: f64,
    pub sss_ms: f64,
    pub over_skin_budget: bool,
    /// Resolve and restore time of the SSS passes (eDRAM profiles).
    pub sss_transfer_ms: f64,
    pub categories: Vec<CategoryBudget>,
    pub unpriced_passes: Vec<String>,
    pub substitutions: usize,
    pub overruns: Vec<String>,
}

/// At which resolution to price.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rescale {
    /// The run's own resolution.
    AsRun,
    /// The profile's target resolution (see `input::RESCALE_RULE`).
    ToProfile,
}

fn role_share(prof: &Profile, r: PassRole) -> f64 {
    match r {
        PassRole::Shadow => prof.budget.shadow_share,
        PassRole::Geometry => prof.budget.geometry_share,
        PassRole::Sss => prof.budget.sss_share,
        PassRole::Post => prof.budget.post_share,
        _ => 0.0,
    }
}

/// One pass's result.
fn pass_budget(pu: &PassUnits, params: &ModelParams, frame_ms: f64, skin_ms: f64) -> PassBudget {
    let modelled = pu.modelled_ms(params);
    let cost = pu.role.is_frame_cost();
    PassBudget {
        name: pu.name.clone(),
        role: pu.role,
        modelled_ms: modelled,
        measured_ms: pu.measured_ms,
        bound: modelled.map(|_| pu.units.bound(params)),
        terms_ms: pu.units.scaled(params),
        edram: pu.edram.clone(),
        substitutions: pu.substitutions.clone(),
        unpriced: pu.unpriced.clone(),
        overruns: pu.overruns.clone(),
        share_of_frame: modelled.filter(|_| cost).map(|m| m / frame_ms),
        // A profile may give skin SSS no share of the frame (0): then no pass
        // has a share of it, rather than an infinite one.
        share_of_skin_budget: modelled
            .filter(|_| pu.role == PassRole::Sss && skin_ms > 0.0)
            .map(|m| m / skin_ms),
    }
}

/// Prices a frame on a profile with the parameters of its rate source: the
/// call behind `dermis budget`.
pub fn price_frame(
    prof: &Profile,
    frame: &FrameInput,
    set: &ParamSet,
    rescale: Rescale,
) -> FrameBudget {
    let params = *set.get(prof.profile.rates);
    let (w, h) = (prof.target.width_px, prof.target.height_px);
    let scaled;
    let (priced, rule) = match rescale {
        Rescale::ToProfile if (w, h) != (frame.width, frame.height) => {
            scaled = frame.rescaled(w, h);
            (&scaled, Some(RESCALE_RULE.to_string()))
        }
        _ => (frame, None),
    };
    let frame_ms = prof.target.frame_ms;
    let skin_budget_ms = prof.share_ms(prof.budget.sss_share);
    let units = price_units(prof, priced);
    let passes: Vec<PassBudget> = units
        .iter()
        .map(|pu| pass_budget(pu, &params, frame_ms, skin_budget_ms))
        .collect();
    let costed = || passes.iter().filter(|p| p.role.is_frame_cost());
    // Folds from +0 (an empty f64 sum is -0, printed "-0.000").
    let total: f64 = costed()
        .filter_map(|p| p.modelled_ms)
        .fold(0.0, |a, m| a + m);
    let measured: Option<f64> = costed().map(|p| p.measured_ms).sum();
    // A measured total is comparable only at the size it was measured at.
    let measured_total_ms = measured.filter(|_| rule.is_none());
    let mut categories: Vec<CategoryBudget> = Vec::new();
    for p in costed() {
        let m = p.modelled_ms.unwrap_or(0.0);
        match categories.iter_mut().find(|c| c.role == p.role) {
            Some(c) => c.modelled_ms += m,
            None => categories.push(CategoryBudget {
                role: p.role,
                modelled_ms: m,
                budget_ms: prof.share_ms(role_share(prof, p.role)),
                over: false,
            }),
        }
    }
    for c in &mut categories {
        c.over = c.modelled_ms > c.budget_ms;
    }
    let sss = || passes.iter().filter(|p| p.role == PassRole::Sss);
    let sss_ms: f64 = sss().filter_map(|p| p.modelled_ms).fold(0.0, |a, m| a + m);
    let sss_transfer_ms = sss()
        .map(|p| p.terms_ms.resolve + p.terms_ms.restore)
        .fold(0.0, |a, m| a + m);
    FrameBudget {
        profile: prof.profile.name.clone(),
        label: frame.label.clone(),
        run_size: [frame.width, frame.height],
        priced_size: [priced.width, priced.height],
        rescale_rule: rule,
        combining_rule: COMBINING_RULE.to_string(),
        rates: prof.profile.rates,
        params,
        total_ms: total,
        measured_total_ms,
        frame_ms,
        over_frame: total > frame_ms,
        skin_budget_ms,
        sss_ms,
        over_skin_budget: sss_ms > skin_budget_ms,
        sss_transfer_ms,
        categories,
        unpriced_passes: costed()
            .filter(|p| p.modelled_ms.is_none())
            .map(|p| format!("{}: needs {}", p.name, p.unpriced.join(", ")))
            .collect(),
        substitutions: passes.iter().map(|p| p.substitutions.len()).sum(),
        overruns: passes
            .iter()
            .flat_map(|p| p.overruns.iter().map(move |o| format!("{}: {o}", p.name)))
            .collect(),
        passes,
    }
}

#[cfg(test)]
#[path = "model_tests.rs"]
mod tests;
