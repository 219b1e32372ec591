//! The ground truth's pure parts: surface sampling, the grid, the chunk plan,
//! the profile split, the tissue test, and an f64 CPU mirror of the GPU passes
//! (`mirror`). The GPU passes are in `method::reference`.
pub mod burley;
pub mod chunks;
pub mod mirror;
pub mod narrow;
pub mod sampling;
