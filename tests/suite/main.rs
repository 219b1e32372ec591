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
//! The modules included by `#[path]` are edited in place by their owners in
//! the same round of work; they keep their own `mod common;` (a second copy of
//! the fixtures, compiled with them) and can move here with `git mv` once
//! those edits are merged (their `mod common;` then becomes `use crate::common;`).

// Until then the fixtures are loaded once per such module (see above).
#![allow(clippy::duplicate_mod)]

#[path = "../common/mod.rs"]
mod common;

mod accuracy;
mod budget_cli;
mod harness;
mod reference;
mod region;
mod scenes;
mod screen;
mod separable;
mod stability;
mod tsd;

#[path = "../cli.rs"]
mod cli;
#[path = "../gltf_fuzz.rs"]
mod gltf_fuzz;
#[path = "../hostile.rs"]
mod hostile;
#[path = "../layers.rs"]
mod layers;
#[path = "../teardown.rs"]
mod teardown;
#[path = "../work_gpu.rs"]
mod work;
