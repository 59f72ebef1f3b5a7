//! Measured isotropic BRDF tables in the MERL `.binary` format (Matusik, Pfister, Brand & McMillan, "A
//! data-driven reflectance model", SIGGRAPH 2003), so that glossmeter can read a measured material through
//! the instrument, not only analytic models.
//!
//! The format, as read by MERL's own `BRDFRead.cpp` and the loaders derived from it (wdas/brdf
//! `BRDFMeasuredMERL.cpp`, dj_brdf, nbonneel/pathtracer `MERLBRDFRead.h`):
//!
//! * a header of three little-endian `i32`: the table dimensions (n_θh, n_θd, n_φd) = (90, 90, 180);
//! * then 3·n little-endian `f64` (n = n_θh·n_θd·n_φd) as three channel blocks, R then G then B;
//! * the stored values are scaled on lookup by R × 1/1500, G × 1.15/1500, B × 1.66/1500 (f_r in sr⁻¹);
//! * index = φd_idx + θd_idx·n_φd + θh_idx·n_φd·n_θd, in the half/difference angles of Rusinkiewicz (1998,
//!   "A new change of variables for efficient BRDF representation");
//! * θh bins are non-linear: idx = ⌊√(θh/(π/2)·n_θh·n_θh)⌋ (finer near the specular peak); θd bins are
//!   linear over [0, π/2); φd bins are linear over [0, π), φd folded by reciprocity (φd ↦ φd + π);
//! * negative values mark cells that were not measured ("below horizon").
//!
//! Lookup: nearest bin (the bin that contains the point: MERL's `lookup_brdf_val`, the default) or trilinear
//! in (θh index coordinate, θd, φd) with the samples at the bins' lower edges and φd periodic with period π.
//! This file only decodes the bytes and chooses those coordinates; the table and its interpolation are the
//! shared layer in `table.rs`. `docs/model.md` §Measured tables (MERL) gives the details and the known limits
//! of the data.
pub(crate) use super::table::HalfDiff;
use super::table::{file_name, floor_index, reflection_half_diff, Edge, Resolution, Table, TableAxis};
pub use super::table::{fold_phi_d, half_diff};
use crate::brdf::{Brdf, Hints, Lobe, Term, TermKind};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::io::Read;
use std::path::Path;

/// The dimensions of every table in the MERL database: (n_θh, n_θd, n_φd).
pub const MERL_DIMS: [usize; 3] = [90, 90, 180];
/// The per-channel scales applied on lookup (MERL `RED_SCALE`, `GREEN_SCALE`, `BLUE_SCALE`).
pub const MERL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// Largest dimension accepted from a header (a guard against nonsense headers; MERL uses ≤ 180).
pub(crate) const MAX_DIM: usize = 4096;
/// Size of the header in bytes.
const HEADER_BYTES: usize = 12;

/// How the table is evaluated between its samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The value of the bin that contains the point (MERL's own lookup): piecewise constant.
    Nearest,
    /// Trilinear in (θh index coordinate u = n_θh·√(θh/(π/2)), θd, φd), samples at the bins' lower edges,
    /// φd periodic with period π, clamped at the upper ends of θh and θd.
    Trilinear,
}

impl Interpolation {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Interpolation::Nearest => "nearest",
            Interpolation::Trilinear => "trilinear",
        }
    }
}

/// A measured BRDF table in the MERL format, RGB.
#[derive(Clone, Debug)]
pub struct MerlBrdf {
    /// The file as given (for messages and `describe`).
    file: String,
    /// (n_θh, n_θd, n_φd).
    dims: [usize; 3],
    /// f_r in sr⁻¹ per cell (already scaled), invalid channels set to 0; axes (θh index, θd index, φd index).
    table: Table,
    /// Number of cells with at least one negative or non-finite channel.
    invalid: usize,
    interpolation: Interpolation,
    sampling: Sampling,
    /// Every cell valid and equal per channel (to `table::FLAT_RTOL`): a constant BRDF, stated as a diffuse term
    /// (`docs/instrument.md` §Quadrature, "Measured tables").
    flat: bool,
    /// The lobe's half width at half maximum as a slope, measured from the table at load
    /// ([`super::table::specular_half_width`]).
    half_width: f64,
    /// The samples the lookup reads: the table's own, or every second one (the coarse twin, [`Brdf::coarser`]).
    resolution: Resolution,
}

impl MerlBrdf {
    /// Read a MERL `.binary` file. Errors (`Error::Io` for a file that cannot be read, `Error::Input` for a
    /// wrong header or size) name the file; nothing here panics on bad data.
    pub fn load(path: &Path, interpolation: Interpolation) -> Result<Self> {
        let file = path.display().to_string();
        let io = |source| Error::Io { file: file.clone(), source };
        let mut f = std::fs::File::open(path).map_err(io)?;
        let size = f.metadata().map_err(io)?.len();
        let mut header = [0u8; HEADER_BYTES];
        if size < HEADER_BYTES as u64 {
            return Err(Error::input(
                &file,
                "",
                format!(
                    "{size} bytes: too short for a MERL table (a 12-byte header of 3 × i32 dimensions, then 3·n f64)"
                ),
            ));
        }
        f.read_exact(&mut header).map_err(io)?;
        let dims = parse_dims(&header, &file)?;
        let n = dims[0] * dims[1] * dims[2];
        check_size(size, n, dims, &file)?;
        let mut body = Vec::with_capacity(3 * n * 8);
        f.read_to_end(&mut body).map_err(io)?;
        // The file may have changed between the size check and the read.
        check_size((HEADER_BYTES + body.len()) as u64, n, dims, &file)?;
        Ok(Self::from_parts(file, dims, &body, interpolation))
    }

    /// Parse a whole MERL file held in memory; `file` names it in messages.
    pub fn from_bytes(bytes: &[u8], file: &str, interpolation: Interpolation) -> Result<Self> {
        if bytes.len() < HEADER_BYTES {
            return Err(Error::input(file, "", format!("{} bytes: too short for a MERL table", bytes.len())));
        }
        let dims = parse_dims(&bytes[..HEADER_BYTES], file)?;
        let n = dims[0] * dims[1] * dims[2];
        check_size(bytes.len() as u64, n, dims, file)?;
        Ok(Self::from_parts(file.to_string(), dims, &bytes[HEADER_BYTES..], interpolation))
    }

    /// A MERL-format table (dims n_θh × n_θd × n_φd) of a grey model's BRDF (its first sample, in all three
    /// channels), sampled where this reader places its samples (the bins' lower edges: θh = (π/2)(i/n_θh)²,
    /// θd = (π/2)(j/n_θd), φd = π(k/n_φd)), written in the MERL byte layout and read back as a file would be;
    /// directions below the horizon get MERL's invalid marker. For tests and benches of the table path: a
    /// table whose analytic original is known (docs/accuracy.md §Data uncertainty of measured tables).
    pub fn tabulate(model: &dyn Brdf, dims: [usize; 3], interpolation: Interpolation) -> Result<Self> {
        let [nh, nd, np] = dims;
        let n = nh * nd * np;
        let mut vals = vec![0.0; n];
        let mut f = vec![0.0; model.sampling().len()];
        for ih in 0..nh {
            let th = FRAC_PI_2 * (ih as f64 / nh as f64).powi(2);
            let h = Vec3::new(th.sin(), 0.0, th.cos());
            for id in 0..nd {
                let td = id as f64 / nd as f64 * FRAC_PI_2;
                for ip in 0..np {
                    let pd = ip as f64 / np as f64 * PI;
                    let d = Vec3::new(td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos());
                    // ωi: the difference vector rotated from the half-vector frame (φh = 0) to the surface's.
                    let wi = Vec3::new(d.x * th.cos() + d.z * th.sin(), d.y, -d.x * th.sin() + d.z * th.cos());
                    let wo = 2.0 * wi.dot(h) * h - wi;
                    vals[ip + id * np + ih * np * nd] = if wi.z > 1e-9 && wo.z > 1e-9 {
                        model.eval(wi, wo, &mut f);
                        f[0]
                    } else {
                        -1.0
                    };
                }
            }
        }
        let mut bytes = Vec::with_capacity(HEADER_BYTES + 24 * n);
        for d in dims {
            bytes.extend_from_slice(&(d as i32).to_le_bytes());
        }
        for s in MERL_SCALE {
            for v in &vals {
                bytes.extend_from_slice(&(if *v < 0.0 { -1.0 } else { v / s }).to_le_bytes());
            }
        }
        Self::from_bytes(&bytes, "tabulated.binary", interpolation)
    }

    /// `body` holds exactly 3·n·8 bytes (checked by the callers).
    fn from_parts(file: String, dims: [usize; 3], body: &[u8], interpolation: Interpolation) -> Self {
        let n = dims[0] * dims[1] * dims[2];
        let mut table = vec![[0.0; 3]; n];
        let mut bad = vec![false; n];
        for (c, block) in body.chunks_exact(8 * n).take(3).enumerate() {
            for (i, b) in block.chunks_exact(8).enumerate() {
                let raw = f64::from_le_bytes(b.try_into().expect("chunks of 8 bytes"));
                if raw.is_finite() && raw >= 0.0 {
                    table[i][c] = raw * MERL_SCALE[c];
                } else {
                    bad[i] = true;
                }
            }
        }
        let invalid = bad.iter().filter(|b| **b).count();
        let [nh, nd, np] = dims;
        let axes = vec![
            TableAxis::index(nh, Edge::Clamp),
            TableAxis::index(nd, Edge::Clamp),
            TableAxis::index(np, Edge::Periodic),
        ];
        let flat = invalid == 0 && (0..3).all(|c| super::table::is_flat(table.iter().map(|v| v[c])));
        let table = Table::new(axes, 3, table.into_iter().flatten().collect());
        let mut m = MerlBrdf {
            file,
            dims,
            table,
            invalid,
            interpolation,
            sampling: Sampling::rgb(),
            flat,
            half_width: f64::INFINITY,
            resolution: Resolution::Own,
        };
        m.half_width = super::table::specular_half_width(|wi, wo, out| m.eval(wi, wo, out), 3);
        m
    }

    /// Whether every cell is valid and the same per channel, to `table::FLAT_RTOL` (a constant BRDF: [`Hints::terms`] then states a
    /// diffuse term, so the plan integrates it in the plain chart instead of splitting at the resolution).
    pub fn is_flat(&self) -> bool {
        self.flat
    }

    /// The lobe's half width at half maximum about the specular direction, as a slope, measured from the
    /// table when it was loaded (`Tail::Table`).
    pub fn half_width(&self) -> f64 {
        self.half_width
    }

    /// (n_θh, n_θd, n_φd).
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Number of cells with a negative (unmeasured) or non-finite value in at least one channel; those
    /// channels read as 0.
    pub fn invalid_entries(&self) -> usize {
        self.invalid
    }

    /// The scaled value (sr⁻¹, R G B) of cell (θh index, θd index, φd index); None outside the table.
    pub fn cell(&self, ih: usize, id: usize, ip: usize) -> Option<[f64; 3]> {
        let [nh, nd, np] = self.dims;
        (ih < nh && id < nd && ip < np).then(|| {
            let c = self.table.cell(&[ih, id, ip]);
            [c[0], c[1], c[2]]
        })
    }

    /// The cell MERL's nearest-bin lookup uses for these angles (φd already folded or not: it is folded
    /// here). The same arithmetic as MERL's `theta_half_index`, `theta_diff_index`, `phi_diff_index`.
    pub fn bin(&self, theta_h: f64, theta_d: f64, phi_d: f64) -> (usize, usize, usize) {
        let [nh, nd, np] = self.dims;
        let ih =
            if theta_h <= 0.0 { 0 } else { floor_index(((theta_h / FRAC_PI_2) * nh as f64 * nh as f64).sqrt(), nh) };
        let id = floor_index(theta_d / FRAC_PI_2 * nd as f64, nd);
        let ip = floor_index(fold_phi_d(phi_d) / PI * np as f64, np);
        (ih, id, ip)
    }

    /// The resolution stated with the lobe (`Tail::Table`): the tangent of the first θh bin edge, (π/2)/n_θh², the
    /// table's angular resolution at the specular direction (≈ 1.94e-4 for 90 bins).
    pub fn resolution_slope(&self) -> f64 {
        let nh = self.dims[0] as f64;
        (FRAC_PI_2 / (nh * nh)).tan()
    }

    fn nearest(&self, hd: &HalfDiff) -> [f64; 3] {
        let (ih, id, ip) = self.bin(hd.theta_h, hd.theta_d, hd.phi_d);
        let r = self.resolution;
        let c = self.table.cell(&[r.floor(ih), r.floor(id), r.floor(ip)]);
        [c[0], c[1], c[2]]
    }

    fn trilinear(&self, hd: &HalfDiff) -> [f64; 3] {
        let [nh, nd, np] = self.dims;
        let uh = nh as f64 * (hd.theta_h.max(0.0) / FRAC_PI_2).sqrt();
        let ud = hd.theta_d.max(0.0) / FRAC_PI_2 * nd as f64;
        let up = fold_phi_d(hd.phi_d) / PI * np as f64;
        let mut out = [0.0; 3];
        self.table.linear_at(&[uh, ud, up], self.resolution, &mut out);
        out
    }
}

fn parse_dims(header: &[u8], file: &str) -> Result<[usize; 3]> {
    let mut raw = [0i32; 3];
    for (k, r) in raw.iter_mut().enumerate() {
        *r = i32::from_le_bytes(header[4 * k..4 * k + 4].try_into().expect("4 bytes"));
    }
    if raw.iter().any(|&d| d < 1 || d as usize > MAX_DIM) {
        return Err(Error::input(
            file,
            "",
            format!(
                "header dimensions {} × {} × {} (θh × θd × φd) are not a MERL table: each must be 1 – {MAX_DIM} \
                 (MERL: 90 × 90 × 180); is this a MERL .binary file?",
                raw[0], raw[1], raw[2]
            ),
        ));
    }
    Ok([raw[0] as usize, raw[1] as usize, raw[2] as usize])
}

fn check_size(size: u64, n: usize, dims: [usize; 3], file: &str) -> Result<()> {
    let expected = HEADER_BYTES as u64 + 3 * 8 * n as u64;
    if size != expected {
        let what = if size < expected { "truncated" } else { "trailing data" };
        return Err(Error::input(
            file,
            "",
            format!(
                "{size} bytes, but a MERL table of {} × {} × {} needs 12 + 3·{n}·8 = {expected} bytes ({what})",
                dims[0], dims[1], dims[2]
            ),
        ));
    }
    Ok(())
}

impl Brdf for MerlBrdf {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let Some(hd) = reflection_half_diff(wi, wo, out) else { return };
        let v = match self.interpolation {
            Interpolation::Nearest => self.nearest(&hd),
            Interpolation::Trilinear => self.trilinear(&hd),
        };
        out.copy_from_slice(&v);
    }

    fn hints(&self) -> Hints {
        let lookup = self.interpolation.name();
        if self.flat {
            return Hints::new(vec![Term {
                label: format!(
                    "measured table (MERL, {lookup} lookup): every cell the same value per channel (to 1e-9)"
                ),
                kind: TermKind::Diffuse,
            }]);
        }
        Hints::new(vec![Term {
            label: format!("measured table (MERL, {lookup} lookup)"),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.half_width,
                medium_eta: 1.0,
                label: "measured (MERL)".to_string(),
                tail: crate::brdf::Tail::Table { half_width: self.half_width, resolution: self.resolution_slope() },
            }),
        }])
    }

    fn coarser(&self) -> Vec<std::sync::Arc<dyn Brdf>> {
        self.resolution.twins(|resolution| std::sync::Arc::new(MerlBrdf { resolution, ..self.clone() }) as _)
    }

    fn describe(&self) -> String {
        let name = file_name(&self.file);
        let [nh, nd, np] = self.dims;
        format!(
            "measured MERL table {name} ({nh} × {nd} × {np} θh × θd × φd, {} lookup, {} invalid entries read as 0{})",
            self.interpolation.name(),
            self.invalid,
            if self.resolution != Resolution::Own { "; a coarse twin, read on about every second sample" } else { "" }
        )
    }
}
