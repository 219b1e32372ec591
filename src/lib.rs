//! dermis: a hand-written Vulkan (ash) renderer for real-time human skin that
//! measures what every pass costs on the GPU.
//!
//! Layers, bottom up: `vk` (device, barrier table, memory, shaders, profiler),
//! `graph` (passes with declared accesses; barriers derived, never written at
//! call sites), `scene` (procedural head, glTF, camera, light), `skin` (pure
//! math: profiles, kernels, CPU references), `render` (the frame), `bench`
//! (ceilings and floors), `report` (statistics, tables, JSON).
pub mod bench;
pub mod budget;
pub mod eval;
pub mod graph;
pub mod reference;
pub mod render;
pub mod report;
pub mod run;
pub mod scene;
pub mod skin;
pub mod vk;
