//! Evaluation building blocks: how far a real-time SSS method's frame is from the
//! brute-force ground truth, and what that accuracy costs.
//!
//! Kept apart from the renderer so that the numbers a comparison reports come from
//! plain, unit-tested CPU code that never touches Vulkan:
//! - `bands`: where on the skin an error is (interior, silhouette, depth steps)
//!   and the per-band err/none, gain and FLIP;
//! - `metrics`: image error measures (energy-normalised relative RMSE on linear
//!   radiance, NVIDIA FLIP on the tone-mapped sRGB frame, per-pixel error maps and
//!   their false-colour visualisation, masked energy for halo/leak checks);
//! - `pareto`: cost/error points, their Pareto front and CSV export;
//! - `chart`: the cost-versus-error chart (PNG and SVG) a report shows;
//! - `sweep`: what the sweep of every registered method and setting over a
//!   scene set records (its views, rows, summary and eval.json's schema);
//! - `accuracy_set`: the accuracy model's scene set (scales x lights on both
//!   heads) and what it writes: the model's data, its chart and its
//!   leave-one-scale-out error;
//! - `supersample`: the anti-aliasing evaluation's supersampled reference
//!   (the box filter in display-linear light), edge mask and scores;
//! - `aa_eval`: what `dermis aa-eval` scores and records (every AA mode
//!   against that reference);
//! - `compare`: `dermis compare`, two render outputs against each other.
//!
//! The commands that render (`eval`, `aa-eval`) run in `app`.
pub mod aa_eval;
pub mod accuracy_set;
pub mod bands;
pub mod chart;
pub mod compare;
pub mod metrics;
pub mod pareto;
pub mod supersample;
pub mod sweep;
