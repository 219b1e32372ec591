//! The Vulkan layer: one file per concept (context, barrier table, memory,
//! shaders and reflection, pipelines, profiler, set-up uploads, the typed
//! error of the boundary, the owning guards that free a failed set-up's
//! objects).
pub mod barrier;
pub mod context;
pub mod error;
pub mod format;
pub mod guard;
pub mod memory;
pub mod pipeline;
pub mod profiler;
pub mod shader;
pub mod shader_stats;
pub mod submit;
pub mod undo;
pub mod upload;
