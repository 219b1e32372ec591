//! dermis: a hand-written Vulkan (ash) renderer for real-time human skin that
//! measures what every pass costs on the GPU.
//!
//! Layers, bottom up (a module uses only the ones before it; tests/suite/layers.rs
//! checks it on every path the code names):
//! the pure core, `files`, `format`, `shader_constants`, `work`, `view`, `scene`, `skin`,
//! `reference`, `accuracy`, `aa` (no Vulkan: the one door every user-supplied file is read
//! through, regular files only and sizes bounded; the numbers shared with the shaders, the
//! vocabulary of a pass's work, the view's scale and the SSS region, meshes and
//! framing, profiles, kernels and the CPU mirrors of the passes, the ground
//! truth's sampling and chunk plan, the measured accuracy model, the MLAA and
//! SMAA lookup tables and edge references) -> `vk` (device, barrier table, memory,
//! shaders and their statistics, uploads, profiler) -> `graph` (declared images,
//! passes with their role, work and accesses; barriers and usages derived, never
//! written at call sites) -> `method` (the SSS methods, one module each behind
//! one trait, and their registry; `post`, the anti-aliasing stages after the
//! tone map) -> `render` (the frame around a method) ->
//! `report`, `bench`, `run`, `output`, `trace`, `budget`, `plot` (report.json's
//! schema and statistics, floors, runs, the file writers, the timeline, the
//! console budget model, the chart writer) -> `eval` (ground-truth comparisons,
//! charts). `main.rs` parses arguments only.
//!
//! The pure core and, above it, `eval::metrics` and `budget::model` name
//! neither `ash`, `crate::vk` nor `crate::graph`, nor reach them through any
//! file they lead to (tests/suite/layers.rs).
pub mod aa;
pub mod accuracy;
pub mod bench;
pub mod budget;
pub mod eval;
pub mod files;
pub mod format;
pub mod graph;
pub mod method;
pub mod mix;
pub mod output;
pub mod plan;
pub mod plot;
pub mod post;
pub mod reference;
pub mod render;
pub mod report;
pub mod run;
pub mod scene;
pub mod shader_constants;
pub mod skin;
pub mod trace;
pub mod view;
pub mod vk;
pub mod work;
