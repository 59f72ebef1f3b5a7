//! glossmeter: a virtual gloss, haze and distinctness-of-image meter.
//!
//! The crate is a stack of small layers, each with one job (see `docs/architecture.md`):
//!
//! * [`optics`]: pure functions of physical optics (Fresnel, Kubelka–Munk, thin films, microfacets).
//! * [`brdf`]: the [`brdf::Brdf`] trait and the reflectance models built from the optics, including the
//!   paint model of Ďurikovič & Ágošton (2007).
//! * [`recipe`]: JSON recipes → validated BRDFs, with errors that name the file and the field.
//! * [`input`]: input files read as text with a size limit.
//! * [`fit`]: the inverse problem (recipe parameters from readings) with standard errors and an
//!   identifiability verdict.
//! * [`registry`]: every recipe parameter's JSON Pointer, type, unit, range and meaning, shared by the
//!   validator, the schema, the docs and the fitter.
//! * [`spectrum`]: spectral sampling and the luminous (CIE illuminant C × V(λ)) weighting.
//! * [`colorimetry`]: CIE tristimulus weights (CIE 15 / ASTM E308), CIELAB and CIEDE2000.
//! * [`quadrature`]: the deterministic adaptive cubature with error estimates.
//! * [`instrument`]: aperture geometry, the standards as data, the measurement plan and the readings.
//! * [`api`]: the one-call API ([`measure`], the default panel, geometry resolution).
//! * [`batch`], [`sweep`]: many recipes at once, and sweeps over a template's JSON Pointer paths (streamed, sharded).
//! * [`request`]: the front door: one typed request per action, owning its defaults and validation; the
//!   command line, the server and Python only convert into them.
//! * [`report`]: the readings as documents (JSON, JSON lines, CSV) and the JSON Schemas of the outputs.
//! * [`topography`]: measured surface topographies (X3P, SDF, GSF, text matrices) read, levelled and described
//!   (ISO 25178-2 parameters, slopes, PSD).
//! * [`comparison`]: predictions beside instrument sheets: statistics, verdicts, many samples, baselines.
//! * `cli` (feature `cli`, on by default): the thin command-line layer. The library builds and works without
//!   it and its dependencies (clap, plotters): `cargo build --lib --no-default-features`.
#![forbid(unsafe_code)]
// Items the command line or the server alone use are `pub(crate)` (the public surface is what programs use,
// docs/architecture.md §The public surface), so a build without either front end leaves some of them unused.
#![cfg_attr(not(all(feature = "cli", feature = "serve")), allow(dead_code))]

pub mod api;
pub mod batch;
pub mod brdf;
#[cfg(feature = "cli")]
pub mod cli;
pub mod colorimetry;
pub mod comparison;
pub mod error;
pub mod fit;
pub mod input;
pub mod instrument;
pub mod measured;
pub mod optics;
pub mod quadrature;
pub mod recipe;
pub mod registry;
pub mod report;
pub mod request;
#[cfg(feature = "serve")]
pub mod serve;
pub mod spectrum;
pub mod sweep;
pub mod topography;

pub use api::{measure, measure_file, resolve_geometries, resolve_geometries_or, DEFAULT_PANEL};
pub use error::{Error, Result};
pub use instrument::plan::{PlanOptions, Reading, DEFAULT_RTOL};

/// Double-precision 3-vector used for directions. Local shading frame: z is the specimen normal,
/// x–z is the plane of measurement, and every direction points away from the surface.
pub type Vec3 = glam::DVec3;
