//! dermis's integration tests: one binary, one module per area (the catalogue
//! is docs/tests.md). One binary because each integration binary links the
//! whole crate and its dependencies (there were sixteen).
//!
//! Every test here runs on lavapipe (or DERMIS_TEST_DEVICE) with the Khronos
//! validation layer and synchronization validation on, any message failing
//! it: in this process through `common::ctx()`, or in a `dermis` child process
//! started with `--validate`. The tests that need no device (the layer rule,
//! the fuzzer's loading half) run here too: a binary of their own would cost
//! another link of the crate for a few seconds of work.
//!
//! Not here: `tests/soak.rs`, which measures this process's resident memory, so
//! nothing may run beside it (its own binary, see Cargo.toml).
//!
//! `tests/teardown.rs` stays where issue 11 left it (its path), included
//! by `#[path]` with its own `mod common;` (a second copy of the fixtures).

// teardown.rs's own `mod common;` (see above).
#![allow(clippy::duplicate_mod)]

#[path = "../common/mod.rs"]
mod common;

mod aa;
mod aa_edges;
mod aa_eval;
mod accuracy;
mod accuracy_model;
mod bloom;
mod budget_cli;
mod casters;
mod compute;
mod fade;
mod gather;
mod harness;
mod lod;
mod materials;
mod mix;
mod motion;
mod msaa;
mod plan;
mod plan_motion;
mod reference;
mod region;
mod request;
mod scenes;
mod screen;
mod separable;
mod stability;
mod stepping;
mod texel_params;
mod texturing;
mod tsd;
mod wrinkles;

mod cli;
mod gltf_fuzz;
mod hostile;
mod hostile_output;
mod layers;
mod trace;
mod work;

// Unchanged since issue 11 (it proves every failed set-up step cleans up):
// included where it lies, with its own `mod common;`.
#[path = "../teardown.rs"]
mod teardown;
