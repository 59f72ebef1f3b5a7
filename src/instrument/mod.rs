//! The virtual instrument: what a glossmeter, haze meter or DOI meter would read on a BRDF.
//!
//! `geometry` states the instrument model (axes, field stops, tangent coordinates); `reading` what a geometry
//! reads (the reading specs and the scale they are on); `standards` holds the shipped geometries as data with
//! the provenance of every number; `aperture` answers questions about one aperture integral (charts, split
//! points, clipping, mirror overlap, kinks); `method` is one integral designed as plain data, its executor and
//! its result (the flux); `plan` compiles (material, geometries) into the cheapest set of methods and combines
//! their fluxes into readings; `reference` gives independent closed forms to check them against; `convergence`
//! measures error against run time. The contract is
//! written out in `docs/instrument.md`.
pub mod aperture;
pub mod convergence;
pub mod envelope;
pub mod geometry;
pub mod method;
pub mod plan;
pub mod profile;
pub mod reading;
pub mod reference;
pub mod sphere;
pub mod standards;
