//! The virtual instrument. (Being written.)
pub mod flux;
pub mod geometry;
pub mod plan;
pub mod standards;
