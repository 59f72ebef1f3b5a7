//! Physical optics as small pure functions named after the physics (in the manner of pbrt-v4's
//! `scattering.h`): Fresnel equations, Kubelka–Munk layers, thin-film stacks and microfacet distributions.
//! Each function cites its source in its doc comment and in `docs/model.md`.
pub mod coat_albedo;
pub mod fresnel;
pub mod kubelka_munk;
pub mod microfacet;
pub mod tabulated;
pub mod thin_film;
