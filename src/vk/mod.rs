//! The Vulkan layer: one file per concept (context, barrier table, memory,
//! shaders and reflection, pipelines, profiler).
pub mod barrier;
pub mod context;
pub mod memory;
pub mod pipeline;
pub mod profiler;
pub mod shader;
