//! Console budget model (issue 10): what the frame dermis renders would cost on
//! a target GPU (Xbox 360, PS3, Switch, Steam Deck, the GPUs of the sources, the
//! benchmark GPU), pass by pass, from the passes' declared work and the counts
//! of a run, calibrated against published timings.
//!
//! - [`profile`]: hardware profiles (`profiles/*.toml`), strict parsing.
//! - [`input`]: the model's input ([`FrameInput`], [`PassInput`]) and the
//!   rescaling rule to a profile's resolution.
//! - [`edram`]: tiles, predicated tiling, resolves.
//! - [`model`]: per-unit times, the combining rule, format substitution, the
//!   JSON-ready results ([`FrameBudget`]).
//! - [`calibration`]: the published points as data, frames for them, the fit
//!   of the model's free parameters and its held-out scores.
//!
//! The CLI's call: `Profile::load(name)?`, a `FrameInput` from a run, then
//! [`model::price_frame`] with [`model::ModelParams::fitted`].

pub mod calibration;
pub mod edram;
pub mod frames;
pub mod input;
pub mod model;
pub mod profile;

pub use input::{ClearInput, FrameInput, PassInput};
pub use model::{price_frame, Bound, FrameBudget, ModelParams, PassBudget, Rescale};
pub use profile::Profile;
