//! Physical optics as small pure functions named after the physics (in the manner of pbrt-v4's
//! `scattering.h`): Fresnel equations, Kubelka–Munk layers, thin-film stacks and microfacet distributions.
//! Each function cites its source in its doc comment and in `docs/model.md`.
//!
//! The folder (`thin_film.rs` builds on `fresnel.rs`; `coat_albedo.rs` on `fresnel.rs`, `microfacet.rs`,
//! `tabulated.rs` and the quadrature's Gauss–Legendre rule; `slope_mixture.rs` on `microfacet.rs`; the others only
//! the crate's `Vec3`):
//! * `fresnel.rs`: dielectric and conducting interfaces, the decaying-wave branch, refraction into a coat and
//!   the critical angles ([`fresnel::fresnel_dielectric`], [`fresnel::fr_dielectric`],
//!   [`fresnel::fresnel_conductor`], [`fresnel::fr_conductor`], [`fresnel::amplitudes`],
//!   [`fresnel::refract_into`], [`fresnel::critical_cosine`]);
//! * `kubelka_munk.rs`: two-flux layers: [`kubelka_munk::r_infinity`], a layer over a background
//!   ([`kubelka_munk::layer`] → [`kubelka_munk::Layer`]), [`kubelka_munk::mix`],
//!   [`kubelka_munk::invert_white_black`];
//! * `thin_film.rs`: coherent and incoherent layer stacks, the pearlescent flake ([`thin_film::stack`],
//!   [`thin_film::stack_spectrum`] (one angle, several wavelengths),
//!   [`thin_film::FilmLayer`], [`thin_film::StackResult`]);
//! * `microfacet.rs`: Beckmann and GGX distributions with Smith and V-cavity masking
//!   ([`microfacet::Microfacet`], [`microfacet::Distribution`], [`microfacet::Shadowing`]);
//! * `slope_mixture.rs` (on `microfacet.rs`): a mixture of slope populations, D = Σ wᵢ Dᵢ with the Smith
//!   masking of the mixture, Λ = Σ wᵢ Λᵢ ([`slope_mixture::SlopeMixture`]);
//! * `slope_table.rs` (on `microfacet.rs`): a measured slope distribution (a topography's cells) smoothed into
//!   a normalised density, its D and the Gaussian-equivalent Smith Λ ([`slope_table::SlopeTable`]);
//! * `scatter.rs`: smooth-surface (Rayleigh–Rice) scatter from a surface PSD, K-correlation or Gaussian
//!   ([`scatter::Psd`], [`scatter::rayleigh_rice`], [`scatter::polarisation_factor`]);
//! * `levelling.rs` (on the quadrature's Gauss–Legendre rule): the levelling of an applied texture by surface tension
//!   as the film dries, Orchard's rate integrated over a rising viscosity and a thinning film, and the cured
//!   PSD's transfer ([`levelling::Application`], [`levelling::psd_transfer`]);
//! * `tabulated.rs`: piecewise Chebyshev tables of smooth functions of one variable, accepted only with their
//!   error verified when built ([`tabulated::ChebTable`]; the node and basis helpers the coat-albedo table uses);
//! * `kirchhoff.rs` (on `fresnel.rs` and the Gauss–Legendre rule): the scalar Beckmann–Kirchhoff far field of a
//!   height map by one FFT and the flux it sends into a receptor stop, with its validity refusals
//!   ([`kirchhoff::KirchhoffMap`], [`kirchhoff::Edge`], [`kirchhoff::Refusal`]; docs/optics.md §11);
//! * `coat_albedo.rs`: the directional albedo E(μ) of a rough coat's lobe and its mean Ē
//!   ([`coat_albedo::CoatAlbedo`], read from the shipped table `assets/coat-albedo-table.bin` or computed by
//!   the module's reference rule; [`coat_albedo::lobe_albedo`]).
pub mod coat_albedo;
pub mod fresnel;
pub mod kirchhoff;
pub mod kubelka_munk;
pub mod levelling;
pub mod microfacet;
pub mod scatter;
pub mod slope_mixture;
pub mod slope_table;
pub mod tabulated;
pub mod thin_film;
