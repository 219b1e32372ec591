//! The Vulkan layer: one file per concept (the instance, the physical
//! device's choice and facts, the logical device, the validation messenger,
//! the set-up test hook, and the context that owns them all; the barrier
//! table, the format table's Vulkan names, memory, shaders and reflection,
//! pipelines, profiler, set-up uploads, the typed error of the boundary, the
//! owning guards that free a failed set-up's objects).
pub mod barrier;
pub mod context;
pub mod device;
pub mod error;
pub mod fault;
pub mod format;
pub mod guard;
pub mod instance;
pub mod memory;
pub mod messenger;
pub mod physical_device;
pub mod pipeline;
pub mod profiler;
pub mod shader;
pub mod shader_stats;
pub mod submit;
pub mod undo;
pub mod upload;
