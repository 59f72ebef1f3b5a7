//! Measured BRDFs in the formats people hold them in, so that glossmeter can read a measured material through
//! the instrument, not only analytic models. One file per format decodes its bytes or text and names its
//! source; `table.rs` is the one table/interpolation layer they all use.
//!
//! * `merl.rs`: MERL `.binary` (Matusik et al. 2003), isotropic, RGB.
//! * `table.rs`: sample axes, linear weights (clamped or periodic), N-dimensional tables and the
//!   Rusinkiewicz half/difference angles, shared by every format.
//!
//! Every reader tells the integrator the table's angular resolution as the lobe width (`Lobe::slope_width`),
//! so the adaptive cubature splits at the table's finest structure and cannot step over its peak.
pub mod merl;
pub mod table;
