//! The virtual instrument. (Being written.)
pub mod geometry;
pub mod standards;
