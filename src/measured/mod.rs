//! Measured BRDFs in the formats people hold them in, so that glossmeter can read a measured material through
//! the instrument, not only analytic models. One file per format decodes its bytes or text and names its
//! source; `table.rs` is the one table/interpolation layer they all use.
//!
//! * `table.rs`: axes ([`table::TableAxis`]: clamped or periodic linear weights), N-D multilinear tables
//!   ([`table::Table`]), half/difference angles, the lobe's half width at half maximum measured from a table
//!   ([`table::specular_half_width`]) and the flat-table test ([`table::is_flat`]);
//! * `merl.rs`: MERL `.binary` (Matusik et al. 2003), isotropic, RGB ([`merl::MerlBrdf`]);
//! * `rgl.rs`: the RGL material database's `.bsdf` tensor files (Dupuy & Jakob 2018), as pbrt-v4's
//!   `MeasuredBxDF` evaluates them; isotropic and anisotropic, spectral or RGB ([`rgl::RglBrdf`] over a
//!   [`rgl::TensorFile`]);
//! * `inplane.rs`: in-plane goniometer tables f_r(θi, θo), extended off the plane by an explicit isotropy
//!   assumption ([`inplane::InPlaneBrdf`]); read from the in-plane CSV export ([`inplane::parse_csv`]);
//! * `e1392.rs`: ASTM E1392-style text tables, read into the same in-plane model ([`e1392::parse`]).
//!
//! The RGL, in-plane CSV and E1392 files are read with the tables' size limit (`crate::input::MAX_TABLE_BYTES`);
//! a MERL file is checked against its own header.
//!
//! Every reader tells the integrator the lobe's own half width at half maximum, measured from the table at
//! load (`table::specular_half_width`), as the lobe width (`Lobe::slope_width`: where the partition splits, so
//! it cannot step over the peak), and the table's angular resolution at the specular direction beside it
//! (`Tail::Table`); the kinks at the table's cells are left to the adaptive refinement, which meets the
//! tolerance the data allow far sooner than a partition split at every cell (`docs/instrument.md`
//! §Quadrature, *Measured tables*). A table that is a constant (`table::is_flat`) is a diffuse term instead.
pub(crate) mod e1392;
pub mod inplane;
pub mod merl;
pub mod rgl;
pub(crate) mod table;
