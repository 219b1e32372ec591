//! The ground truth's pure parts: surface sampling, the grid, the profile split,
//! and an f64 CPU gather that checks the GPU one. The GPU passes are in
//! `method::reference`.
pub mod cpu;
pub mod narrow;
pub mod sampling;
pub mod tissue;
