//! Measured BRDFs in the formats people hold them in, so that glossmeter can read a measured material through
//! the instrument, not only analytic models. One file per format decodes its bytes or text and names its
//! source; `table.rs` is the one table/interpolation layer they all use.
//!
//! * `merl.rs`: MERL `.binary` (Matusik et al. 2003), isotropic, RGB.
//! * `rgl.rs`: the RGL material database's `.bsdf` tensor files (Dupuy & Jakob 2018), as pbrt-v4's
//!   `MeasuredBxDF` evaluates them; isotropic and anisotropic, spectral or RGB.
//! * `inplane.rs`: in-plane goniometer tables f_r(θi, θo), extended off the plane by an explicit isotropy
//!   assumption; read from the in-plane CSV export and from ASTM E1392-style text tables (`e1392.rs`).
//!
//! Every reader tells the integrator the table's angular resolution as the lobe width (`Lobe::slope_width`),
//! so the adaptive cubature splits at the table's finest structure and cannot step over its peak, and the
//! lobe's own half width at half maximum, measured from the table at load (`Tail::Table`,
//! `table::specular_half_width`); a table that is a constant (`table::is_flat`) is a diffuse term instead.
pub mod e1392;
pub mod inplane;
pub mod merl;
pub mod rgl;
pub mod table;
