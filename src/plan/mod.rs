//! `dermis plan` (issue 16, items 3 and 4): a method setting per character
//! under a skin-SSS budget on a hardware profile.
//!
//! Pure (no device; tests/suite/layers.rs holds them to it): [`cost`] (the
//! budget model's pass costs split per character, from the stored frames of
//! `profiles/frames/plan/`), [`character`] (what the planner knows of a
//! character, estimated from the scene's geometry), [`choose`] (the rules,
//! the accuracy model's interface, the weighted error), [`solve`] (the exact
//! branch and bound), [`dolly`] (a stand-in accuracy model from the dolly
//! sweep), [`measured`] (the measured accuracy table, what the planner uses).
//! With the registry and the stored data: [`pipeline`] (a frame planned:
//! characters, costs, the plan and its file) and [`picture`] (the schematic
//! of the plan). The checks' records, pure: [`check`] (`dermis plan-check`:
//! plans against the ground truth, its cases, record and summary) and its
//! charts [`check_chart`], scoring frames with [`score`]. docs/plan.md says
//! how it works. [`geometry`] (pure): each character's level of detail and
//! shadow casting in the plan, their triangles and triangle time. No device opens here: the commands that render (`plan-check`,
//! `plan-motion`) run in `app`.
//! Over time (issue 16 item 6, docs/plan-over-time.md): [`over_time`]
//! (pure: the walking crowd re-planned with hysteresis, switches and their
//! measure), [`fades`] (pure: cross-fading its switches), the per-frame
//! inputs [`frame_inputs`] (the characters from
//! [`skin_patches`] and their costs from [`price_grid`], both pure) and
//! [`motion`] (`dermis plan-motion`'s record and verdict) and its chart
//! [`motion_chart`].

pub mod character;
pub mod check;
pub mod check_chart;
pub mod choose;
pub mod cost;
pub mod dolly;
pub mod fades;
pub mod frame_inputs;
pub mod geometry;
pub mod log_interp;
pub mod measured;
pub mod motion;
pub mod motion_chart;
pub mod over_time;
pub mod picture;
pub mod pipeline;
pub mod price_grid;
pub mod score;
pub mod skin_patches;
pub mod solve;

/// The cost model's view of a character.
pub fn load_of(c: &character::CharacterInput) -> cost::CharacterLoad {
    cost::CharacterLoad {
        px_per_mm: c.px_per_mm,
        skin_pixels: c.skin_pixels,
        region_pixels: c.region_pixels,
        region_rects: c.region_rects,
    }
}
