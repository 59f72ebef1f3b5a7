//! The MERL reader moved to [`crate::measured::merl`] (with the other measured formats and the shared table
//! layer); this path is kept so that existing code keeps compiling.
pub use crate::measured::merl::*;
