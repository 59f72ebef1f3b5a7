//! Deterministic adaptive cubature with error estimates, written for the aperture integrals.
//!
//! Why our own: the instrument integral is 4-D and vector-valued, its mass sits on thin ridges that the
//! caller knows in advance, and it must be reproducible bit for bit. What it needs from an integrator is
//! (a) an initial partition supplied by the caller (the splits at lobe centres, widths and kinks that keep
//! a near-specular lobe from being silently missed: an automatic rule sampling a box at a few points cannot
//! see a peak between them, Lyness & Kaganove, "Comments on the nature of automatic quadrature routines",
//! ACM TOMS 2 (1976) 65–81; `benches/integrators.rs` B3 shows it on the raw box), (b) one
//! global absolute/relative tolerance across all pieces, (c) vector values with a stated error norm, and
//! (d) a fixed, single-threaded order of work. The Rust crates looked at (bilby 0.3: scalar only, no initial
//! split; scirs2-integrate: very heavy) offer none of (a)–(c) together, so the rule is implemented here
//! (`genz_malik.rs`, tested against closed forms in its own test module). `gauss.rs` holds the crate's
//! one-dimensional Gauss–Legendre and Gauss–Kronrod rules, `hermite.rs` the Gauss–Hermite rules of narrow lobes, `polar.rs` the polar (ρ = tan β) and
//! box product rules of narrow heavy-tailed lobes, `tensor.rs` the anisotropic tensor Gauss–Legendre rules with
//! per-axis p-refinement of smooth integrands.
//!
//! The rule is Genz & Malik's degree-7 rule with an embedded degree-5 rule (A. C. Genz, A. A. Malik,
//! "An adaptive algorithm for numerical integration over an n-dimensional rectangular region",
//! J. Comput. Appl. Math. 6 (1980) 295–302), as used by Johnson's `hcubature`; the worst region is bisected
//! along the axis with the largest fourth difference. The error of a region is not hcubature's |I₇ − I₅| (the
//! error of the degree-5 rule, 100–1000× above the actual error of the reported I₇ on smooth integrands) but
//! a DCUHRE-style calibration from three successive null rules on the same points (`genz_malik::calibrated`,
//! `docs/accuracy.md` §5), on a smooth integrand also checked against the refinement (a bisected box's
//! children against their parent, `genz_malik::child_scale`, §5.1).
mod gauss;
mod genz_malik;
mod hermite;
mod polar;
pub mod tensor;

pub use gauss::{adaptive as gauss_kronrod_adaptive, gauss_legendre, gauss_legendre_table, TABLE_MAX_ORDER};
pub use hermite::{gauss_hermite, gauss_hermite_table, HERMITE_TABLE_MAX_ORDER};
pub use polar::{
    legendre_on, legendre_on_into, mapped_legendre, mapped_legendre_into, polar_rectangle, polar_rectangle_into, Map,
    PolarBuffers,
};

pub use genz_malik::{
    integrate, integrate_partition, pointwise, Cell, Estimate, GenzMalikRule, Options, Refine, MAX_SHRINK,
    MAX_SHRINK_LOBE,
};
