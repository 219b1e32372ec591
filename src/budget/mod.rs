//! Console budget model (issue 10): what the frame dermis renders would cost on
//! a target GPU (Xbox 360, PS3, Switch, Steam Deck, the GPUs of the sources, the
//! benchmark GPUs), pass by pass, from the passes' declared work and the counts
//! of a run, calibrated against published timings and bench reports.
//!
//! Pure (no device): [`profile`] (hardware profiles, `profiles/*.toml`, strict
//! parsing), [`format`] (the formats profiles name, substitutes), [`input`] (the model's input and the rescaling rule), [`record`]
//! (a run's report read back, the fragments and fetch-count rules), [`edram`]
//! (tiles, resolves), [`msaa`] (MSAA colour and Z compression), [`units`] (unit times of a pass and the combining rule),
//! [`transfers`] (eDRAM resolves and restores over a frame), [`params`] (the
//! fitted parameters), [`model`] (the priced frame), [`frames`] (stored
//! frames, the pairing of bench reports with them, the transformations into
//! the implementations the sources timed, first-principles frames),
//! [`points`] (the published and benchmark points), [`calibration`] (fit,
//! held-out scores), [`porting`] (docs/budget.md's tables), [`table`] (the
//! printed table), [`table91`] (thesis Table 9.1 as data and its games' line).
//!
//! The chart: [`chart`] (the stacked-bar chart). The command that runs a
//! frame on a device and prices it is `app::budget`.

pub mod calibration;
pub mod chart;
pub mod edram;
pub mod format;
pub mod frames;
pub mod input;
pub mod model;
pub mod msaa;
pub mod params;
pub mod points;
pub mod porting;
pub mod profile;
pub mod record;
pub mod table;
pub mod table91;
pub mod transfers;
pub mod unit_times;
pub mod units;

pub use input::{FrameInput, PassInput};
pub use model::{price_frame, FrameBudget, PassBudget, Rescale};
pub use params::{ModelParams, ParamSet};
pub use profile::Profile;
pub use units::Bound;
