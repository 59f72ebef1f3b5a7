//! The virtual instrument. (Being written.)
pub mod flux;
pub mod geometry;
// pub mod plan; (enabled once standards.rs lands)
pub mod standards;
