//! dermis: a hand-written Vulkan (ash) renderer for real-time human skin that
//! measures what every pass costs on the GPU.
//!
//! Layers, bottom up (a module uses only the ones before it):
//! `files` (the one door every user-supplied file is read through: regular
//! files only, sizes and decoded image sizes bounded; pure) ->
//! `vk` (device, barrier table, memory, shaders and their statistics, uploads,
//! profiler) -> `graph` (declared images, passes with their role, work and
//! accesses; barriers and usages derived, never written at call sites) ->
//! `scene`, `skin`, `reference` (pure CPU: meshes, framing, profiles, kernels,
//! CPU references, the ground truth's sampling) -> `method` (the SSS methods,
//! one module each behind one trait, and their registry) -> `render` (the frame
//! around a method) -> `report`, `bench`, `run`, `budget`, `plot` (runs, statistics, floors,
//! the console budget model, the chart writer) ->
//! `eval` (ground-truth comparisons, charts). `main.rs` parses arguments only.
pub mod bench;
pub mod budget;
pub mod eval;
pub mod files;
pub mod graph;
pub mod method;
pub mod plot;
pub mod reference;
pub mod render;
pub mod report;
pub mod run;
pub mod scene;
pub mod skin;
pub mod vk;
