//! Command-line layer. (Being written.)
