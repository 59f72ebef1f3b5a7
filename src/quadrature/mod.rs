//! Deterministic adaptive cubature with error estimates. (Being written.)
