//! The virtual instrument. (Being written.)
pub mod convergence;
pub mod flux;
pub mod geometry;
pub mod plan;
pub mod reference;
pub mod sheet;
pub mod standards;
