//! Recipes: JSON descriptions of materials, validated into BRDFs. (Being written.)
pub mod fields;
pub mod paint;
