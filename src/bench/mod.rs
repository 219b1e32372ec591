//! Device ceilings (measured by micro-passes in the same run) and the per-pass
//! floors computed from them.
pub mod ceilings;
pub mod floor;
