//! Deterministic adaptive cubature with error estimates, written for the aperture integrals.
//!
//! Why our own: the instrument integral is 4-D and vector-valued, its mass sits on thin ridges that the
//! caller knows in advance, and it must be reproducible bit for bit. What it needs from an integrator is
//! (a) an initial partition supplied by the caller (the splits at lobe centres, widths and kinks that keep
//! a near-specular lobe from being silently missed: an automatic rule sampling a box at a few points cannot
//! see a peak between them, Lyness & Kaganove, "Comments on the nature of automatic quadrature routines",
//! ACM TOMS 2 (1976) 65–81; `benches/integrators/` B3 shows it on the raw box), (b) one
//! global absolute/relative tolerance across all pieces, (c) vector values with a stated error norm, and
//! (d) a fixed, single-threaded order of work. The Rust crates looked at (bilby 0.3: scalar only, no initial
//! split; scirs2-integrate: very heavy) offer none of (a)–(c) together, so the rule is implemented here
//! (`genz_malik.rs`, tested against closed forms in its own test module).
//!
//! The rule is Genz & Malik's degree-7 rule with an embedded degree-5 rule (A. C. Genz, A. A. Malik,
//! "An adaptive algorithm for numerical integration over an n-dimensional rectangular region",
//! J. Comput. Appl. Math. 6 (1980) 295–302), as used by Johnson's `hcubature`; the worst region is bisected
//! along the axis with the largest fourth difference. The error of a region is not hcubature's |I₇ − I₅| (the
//! error of the degree-5 rule, 100–1000× above the actual error of the reported I₇ on smooth integrands) but
//! a DCUHRE-style calibration from three successive null rules on the same points (`genz_malik::calibrated`,
//! `docs/accuracy.md` §5), on a smooth integrand also checked against the refinement (a bisected box's
//! children against their parent, `genz_malik::child_scale`, §5.1).
//!
//! The folder (the items of its private files are re-exported here):
//! * `genz_malik.rs`: the cubature: [`integrate`] over boxes, [`integrate_partition`] over a caller's partition
//!   of [`Cell`]s, adaptive or frozen ([`Refine`]), [`pointwise`], its [`Options`] and [`Estimate`], the rule's
//!   points and weights ([`GenzMalikRule`]) and the calibration's limits ([`MAX_SHRINK`], [`MAX_SHRINK_LOBE`], [`MAX_SHRINK_PLAIN`]);
//! * `gauss.rs`: the crate's one Gauss–Legendre rule ([`gauss_legendre`], per-process tables up to
//!   [`TABLE_MAX_ORDER`]: [`gauss_legendre_table`]) and the adaptive Gauss–Kronrod G7/K15
//!   ([`gauss_kronrod_adaptive`]);
//! * `hermite.rs`: the Gauss–Hermite rules of narrow Gaussian lobes ([`gauss_hermite`], [`gauss_hermite_table`]);
//! * `polar.rs`: the polar (ρ = tan β) and mapped (σ = 1/x, y = c·tan γ) Gauss–Legendre rules of narrow
//!   heavy-tailed lobes ([`polar_rectangle`], [`mapped_legendre`] with its [`Map`], [`legendre_on`], each with
//!   an `_into` form that fills caller buffers, [`PolarBuffers`]);
//! * [`tensor`]: the anisotropic tensor Gauss–Legendre rule with per-axis p-refinement of smooth integrands
//!   ([`tensor::integrate`], [`tensor::ORDERS`], [`tensor::Path`]).
mod gauss;
mod genz_malik;
mod hermite;
mod polar;
pub mod tensor;

pub(crate) use gauss::gauss_legendre_table;
pub(crate) use gauss::{adaptive as gauss_kronrod_adaptive, gauss_legendre};
pub(crate) use hermite::gauss_hermite_table;
pub use polar::{legendre_on, mapped_legendre, polar_rectangle, Map};
pub(crate) use polar::{legendre_on_into, mapped_legendre_into, polar_rectangle_into, PolarBuffers};

pub use genz_malik::{
    integrate, integrate_partition, pointwise, Cell, Estimate, Options, Refine, DEFAULT_RTOL, MAX_SHRINK_LOBE,
};
pub(crate) use genz_malik::{MAX_SHRINK, MAX_SHRINK_PLAIN};
