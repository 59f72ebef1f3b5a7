//! The virtual instrument: what a glossmeter, haze meter, DOI meter or colour meter would read on a BRDF. The
//! contract is written out in `docs/instrument.md`.
//!
//! The folder, floor by floor from the ground up (a file imports only files below it;
//! `docs/architecture.md` §Floors):
//! * `reading.rs`: what a geometry reads ([`reading::ReadingSpec`], [`reading::ColourQuantity`]), the spectral
//!   weighting each reading needs ([`reading::ReadingSpec::weighting`]) and the scale it is on
//!   ([`reading::Scale`]: the gloss standard and its assigned value);
//! * `geometry.rs`: the instrument model: [`geometry::Axes`], field stops in tangent coordinates
//!   ([`geometry::Stop`]), [`geometry::solid_angle_density`], a compiled [`geometry::Geometry`] and its
//!   [`geometry::Integral`]s (aperture, sphere hemisphere, specular port);
//! * `aperture.rs`: questions about one aperture integral: [`aperture::clip`], [`aperture::mirror_overlap`],
//!   the [`aperture::Chart`] ([`aperture::choose_chart`]), [`aperture::lobe_widths_uv`], a material's lobes at
//!   one angle with their widths there ([`aperture::LobesAt`]),
//!   [`aperture::seen_widths`], [`aperture::lobe_splits`], [`aperture::lobe_boxes`], the kinks that cross the stops
//!   ([`aperture::delta_kinks`], [`aperture::regular_kinks`], [`aperture::regular_kinks_between`],
//!   [`aperture::kinked_position`]) and
//!   [`aperture::DELTA_SHARE`];
//! * `reference.rs`: independent references that share no code with the quadrature
//!   ([`reference::projected_solid_angle`], [`reference::lambertian_flux_reference`],
//!   [`reference::mirror_flux_reference`]);
//! * `sphere.rs`: a d/8 sphere's two integrals per sample ([`sphere::hemisphere_reflectance`],
//!   [`sphere::port_reflectance`]);
//! * [`standards`]: the geometry files as data, with the provenance of every number, and their one catalogue
//!   ([`standards::find`], [`standards::StandardGeometry`]);
//! * [`method`]: one integral designed as plain data ([`method::Method`]), its executor and its result
//!   ([`method::Flux`]);
//! * [`plan`]: (material, geometries) compiled into the cheapest set of methods ([`plan::Planner`],
//!   [`plan::Plan`]), executed, and their fluxes combined into readings ([`plan::Reading`]);
//! * studies that run plans: `profile.rs` (a goniophotometric profile, [`profile::measure`]), `envelope.rs`
//!   (the readings' extremes over the tolerances the geometry files give, [`envelope::read`]) and
//!   `convergence.rs` (error against run time, [`convergence::sweep`]).
pub mod aperture;
pub mod convergence;
pub mod envelope;
pub mod geometry;
pub mod method;
pub mod plan;
pub mod profile;
pub mod reading;
pub mod reference;
pub(crate) mod sphere;
pub mod standards;
