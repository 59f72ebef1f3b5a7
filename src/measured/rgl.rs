//! The RGL material database's `.bsdf` files (Dupuy & Jakob, "An adaptive parameterization for efficient
//! material acquisition and rendering", SIGGRAPH Asia 2018; https://rgl.epfl.ch/materials), evaluated as
//! pbrt-v4's `MeasuredBxDF::f` evaluates them (`src/pbrt/bxdfs.cpp`, `PiecewiseLinear2D` in
//! `src/pbrt/util/sampling.h`), so that a measured car paint can be read through the instrument.
//!
//! The container (`tensor_file`, little-endian, as read by pbrt-v4's and Mitsuba's `Tensor` class):
//!
//! * bytes 0–11: the magic `tensor_file\0`; bytes 12–13: version 1.0; bytes 14–17: u32 number of fields;
//! * per field: u16 name length, the name, u16 rank, u8 type (1 u8, 2 i8, 3 u16, 4 i16, 5 u32, 6 i32,
//!   7 u64, 8 i64, 9 f16, 10 f32, 11 f64), u64 byte offset of the data, rank × u64 shape;
//! * the data of each field at its offset, row-major.
//!
//! The fields of a measured BRDF (shapes as pbrt-v4 checks them): `theta_i` [nθ], `phi_i` [nφ] (radians; the
//! incident directions of the acquisition), `ndf` [ny, nx] and `sigma` [ny, nx] (the microfacet distribution
//! D and the projected area σ on the unit square), `vndf` [nφ, nθ, ny, nx] (the visible-normal distribution
//! that defines the warp), `luminance` [nφ, nθ, n, n], `spectra` [nφ, nθ, nλ, n, n] with `wavelengths` [nλ]
//! (nm) — or `rgb` [nφ, nθ, 3, n, n] — the `description` (u8 text) and `jacobian` (u8 [1]). All f32 except
//! the last two. The material is isotropic when nφ ≤ 2; anisotropic files must cover the full circle
//! (pbrt-v4 refuses a symmetry reduction, and so does this reader).
//!
//! Evaluation (pbrt-v4 `MeasuredBxDF::f`): with the parameter direction ω (pbrt's ωo; here the source
//! direction ωi), the other direction ω' and the half vector m, the angles map to the unit square by
//! u_θ = √(2θ/π), u_φ = φ/(2π) + ½ (isotropic: φm − φ, wrapped to [0, 1)); the VNDF warp is inverted at
//! (u_θ(m), u_φ(m)) with the parameters (φ, θ) to a sample s; then
//! f = max(0, spectra(s; φ, θ, λ)) · ndf(u_m) / (4 σ(u_ω) cos θ'). A file whose `jacobian` is 0 stores
//! f·cos θ' itself (Mitsuba 3's `measured` plugin): f = spectra / cos θ'. Every 2-D table is bilinear on its
//! grid, every parameter linear between its values (clamped), exactly as `PiecewiseLinear2D`; the
//! arithmetic here is f64 on the files' f32 values.
use super::table::{elevation, Edge, Resolution, TableAxis};
use crate::brdf::{below_horizon, Brdf, Hints, Lobe, Term, TermKind};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// The magic bytes at the start of a tensor file.
pub(crate) const MAGIC: &[u8; 12] = b"tensor_file\0";
/// The largest number of fields or rank accepted (a guard against nonsense headers).
const MAX_FIELDS: u32 = 1024;
const MAX_RANK: u16 = 16;

/// Element types of a tensor field (pbrt-v4 `Tensor::Type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F16,
    F32,
    F64,
}

impl Dtype {
    fn from_code(c: u8) -> Option<Self> {
        use Dtype::*;
        Some(match c {
            1 => U8,
            2 => I8,
            3 => U16,
            4 => I16,
            5 => U32,
            6 => I32,
            7 => U64,
            8 => I64,
            9 => F16,
            10 => F32,
            11 => F64,
            _ => return None,
        })
    }

    pub(crate) fn size(self) -> usize {
        use Dtype::*;
        match self {
            U8 | I8 => 1,
            U16 | I16 | F16 => 2,
            U32 | I32 | F32 => 4,
            U64 | I64 | F64 => 8,
        }
    }

    pub(crate) fn name(self) -> &'static str {
        use Dtype::*;
        match self {
            U8 => "uint8",
            I8 => "int8",
            U16 => "uint16",
            I16 => "int16",
            U32 => "uint32",
            I32 => "int32",
            U64 => "uint64",
            I64 => "int64",
            F16 => "float16",
            F32 => "float32",
            F64 => "float64",
        }
    }
}

/// One field of a tensor file.
#[derive(Clone, Debug)]
pub struct Field {
    pub name: String,
    pub dtype: Dtype,
    pub shape: Vec<usize>,
    /// Byte offset of the data in the file.
    pub offset: usize,
    /// The raw little-endian bytes.
    pub bytes: Vec<u8>,
}

impl Field {
    /// The values of an f32 field.
    pub(crate) fn f32s(&self) -> Vec<f64> {
        self.bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64).collect()
    }
}

/// A parsed tensor file: its fields in file order.
#[derive(Clone, Debug)]
pub struct TensorFile {
    pub fields: Vec<Field>,
}

/// Reads the header with the offset of every value, so that an error can say where the file went wrong.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    file: &'a str,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8]> {
        if self.bytes.len() - self.pos < n {
            return Err(Error::input(
                self.file,
                "",
                format!(
                    "truncated at byte offset {}: {what} needs {n} bytes, the file has {} bytes in all",
                    self.pos,
                    self.bytes.len()
                ),
            ));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.take(1, what)?[0])
    }
    fn u16(&mut self, what: &str) -> Result<u16> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }
    fn u64(&mut self, what: &str) -> Result<u64> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

impl TensorFile {
    /// Parse a whole tensor file held in memory; `file` names it in messages.
    pub fn parse(bytes: &[u8], file: &str) -> Result<Self> {
        let mut c = Cursor { bytes, pos: 0, file };
        let magic = c.take(12, "the magic `tensor_file\\0`")?;
        if magic != MAGIC {
            return Err(Error::input(
                file,
                "",
                format!(
                    "wrong magic at byte offset 0: {:?}, expected \"tensor_file\\0\" (is this an RGL .bsdf file?)",
                    String::from_utf8_lossy(magic)
                ),
            ));
        }
        let at = c.pos;
        let version = c.take(2, "the version")?;
        if version != [1, 0] {
            return Err(Error::input(
                file,
                "",
                format!("unknown tensor_file version {}.{} at byte offset {at}; allowed: 1.0", version[0], version[1]),
            ));
        }
        let at = c.pos;
        let n = c.u32("the number of fields")?;
        if n > MAX_FIELDS {
            return Err(Error::input(file, "", format!("{n} fields (byte offset {at}); at most {MAX_FIELDS}")));
        }
        let mut fields = Vec::new();
        for k in 0..n {
            let len = c.u16(&format!("the name length of field {k}"))? as usize;
            let name_bytes = c.take(len, &format!("the name of field {k}"))?;
            let name = String::from_utf8_lossy(name_bytes).into_owned();
            // The name is the file's text, not ours: an error names it escaped (a newline or a backquote in
            // it cannot end or fake a line of the message); plain names print unchanged.
            let shown = name.escape_debug().to_string();
            let at = c.pos;
            let rank = c.u16(&format!("the rank of field {name:?}"))?;
            if rank > MAX_RANK {
                return Err(Error::input(file, shown, format!("rank {rank} at byte offset {at}; at most {MAX_RANK}")));
            }
            let at = c.pos;
            let code = c.u8(&format!("the type of field {name:?}"))?;
            let dtype = Dtype::from_code(code).ok_or_else(|| {
                Error::input(
                    file,
                    shown.clone(),
                    format!("unknown element type {code} at byte offset {at}; allowed 1–11"),
                )
            })?;
            let offset = c.u64(&format!("the data offset of field {name:?}"))?;
            let mut shape = Vec::with_capacity(rank as usize);
            let mut count: u128 = 1;
            for j in 0..rank {
                let d = c.u64(&format!("dimension {j} of field {name:?}"))?;
                count = count.saturating_mul(d as u128);
                shape.push(d as usize);
            }
            let need = count.saturating_mul(dtype.size() as u128);
            let end = (offset as u128).saturating_add(need);
            if end > bytes.len() as u128 {
                return Err(Error::input(
                    file,
                    shown,
                    format!(
                        "truncated or mis-sized: the data of shape {shape:?} ({}) at byte offset {offset} needs {need} bytes, \
                         but the file ends at byte {}",
                        dtype.name(),
                        bytes.len()
                    ),
                ));
            }
            let data = bytes[offset as usize..end as usize].to_vec();
            fields.push(Field { name, dtype, shape, offset: offset as usize, bytes: data });
        }
        Ok(TensorFile { fields })
    }

    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }
}

/// pbrt-v4's `PiecewiseLinear2D<D>`: a bilinear function on an nx × ny grid over the unit square, one slice
/// per combination of D parameters (linear between their values), optionally normalised with its marginal and
/// conditional CDFs for the warp's inverse.
#[derive(Clone, Debug)]
struct Warp2D {
    nx: usize,
    ny: usize,
    params: Vec<TableAxis>,
    /// Slice stride of each parameter (0 for a parameter of one value).
    strides: Vec<usize>,
    data: Vec<f64>,
    marginal: Vec<f64>,
    conditional: Vec<f64>,
}

impl Warp2D {
    /// `data` is slices × ny × nx (x fastest). With `normalize`, every slice is divided by its integral
    /// (trapezoid sums in grid units, as pbrt) and the CDFs are built.
    fn new(data: &[f64], nx: usize, ny: usize, params: Vec<Vec<f64>>, normalize: bool) -> Self {
        let mut strides = vec![0; params.len()];
        let mut slices = 1;
        for k in (0..params.len()).rev() {
            strides[k] = if params[k].len() > 1 { slices } else { 0 };
            slices *= params[k].len();
        }
        assert!(params.len() <= 3, "at most 3 parameters");
        let params: Vec<TableAxis> = params.into_iter().map(TableAxis::values).collect();
        let n = nx * ny;
        let mut out = data.to_vec();
        let (mut marginal, mut conditional) = (Vec::new(), Vec::new());
        if normalize {
            marginal = vec![0.0; slices * ny];
            conditional = vec![0.0; slices * n];
            for s in 0..slices {
                let d = &data[s * n..(s + 1) * n];
                let cond = &mut conditional[s * n..(s + 1) * n];
                for y in 0..ny {
                    let mut sum = 0.0;
                    for x in 0..nx - 1 {
                        let i = y * nx + x;
                        sum += 0.5 * (d[i] + d[i + 1]);
                        cond[i + 1] = sum;
                    }
                }
                let marg = &mut marginal[s * ny..(s + 1) * ny];
                let mut sum = 0.0;
                for y in 0..ny - 1 {
                    sum += 0.5 * (cond[(y + 1) * nx - 1] + cond[(y + 2) * nx - 1]);
                    marg[y + 1] = sum;
                }
                let norm = if sum > 0.0 { 1.0 / sum } else { 0.0 };
                cond.iter_mut().for_each(|v| *v *= norm);
                marg.iter_mut().for_each(|v| *v *= norm);
                out[s * n..(s + 1) * n].iter_mut().for_each(|v| *v *= norm);
            }
        }
        Warp2D { nx, ny, params, strides, data: out, marginal, conditional }
    }

    /// The slices and weights of a parameter point (2^D corners, D ≤ 3; pbrt's `lookup`). At
    /// `Resolution::Coarse` the incident directions' parameters (φi, θi: the first two) are read on every
    /// second node; a third parameter (the spectral axis) never is.
    fn corners(&self, param: &[f64], res: Resolution) -> Corners {
        let mut c = Corners { n: 1, at: [(0, 1.0); 8] };
        for (k, a) in self.params.iter().enumerate() {
            let (i0, i1, t) = a.linear_at(param[k], if k < 2 { res } else { Resolution::Own });
            let n = c.n;
            for j in (0..n).rev() {
                let (s, w) = c.at[j];
                c.at[2 * j] = (s + i0 * self.strides[k], w * (1.0 - t));
                c.at[2 * j + 1] = (s + i1 * self.strides[k], w * t);
            }
            c.n = 2 * n;
        }
        c
    }

    fn lookup(corners: &Corners, arr: &[f64], i: usize, size: usize) -> f64 {
        corners.at[..corners.n].iter().map(|&(s, w)| if w == 0.0 { 0.0 } else { w * arr[s * size + i] }).sum()
    }

    /// Cell and fractions of a point of the unit square (pbrt clamps the cell to the last patch).
    fn cell(&self, p: [f64; 2]) -> (usize, usize, f64, f64) {
        let sx = p[0].max(0.0) * (self.nx - 1) as f64;
        let sy = p[1].max(0.0) * (self.ny - 1) as f64;
        let px = (sx as usize).min(self.nx - 2);
        let py = (sy as usize).min(self.ny - 2);
        (px, py, sx - px as f64, sy - py as f64)
    }

    /// The bilinear value at p (pbrt `Evaluate`, for an unnormalised table: the stored values themselves). At
    /// `Resolution::Coarse` on every second node of the grid and of the incident directions' parameters.
    fn eval(&self, p: [f64; 2], param: &[f64], res: Resolution) -> f64 {
        let corners = self.corners(param, res);
        let (nx, size) = (self.nx, self.nx * self.ny);
        let ((x0, x1, fx), (y0, y1, fy)) = match res {
            Resolution::Own => {
                let (px, py, fx, fy) = self.cell(p);
                ((px, px + 1, fx), (py, py + 1, fy))
            }
            Resolution::Coarse | Resolution::Shifted => {
                let at =
                    |u: f64, n: usize| TableAxis::index(n, Edge::Clamp).linear_at(u.max(0.0) * (n - 1) as f64, res);
                (at(p[0], self.nx), at(p[1], self.ny))
            }
        };
        let v = |x: usize, y: usize| Self::lookup(&corners, &self.data, x + y * nx, size);
        let (v00, v10, v01, v11) = (v(x0, y0), v(x1, y0), v(x0, y1), v(x1, y1));
        (1.0 - fy) * ((1.0 - fx) * v00 + fx * v10) + fy * ((1.0 - fx) * v01 + fx * v11)
    }

    /// The inverse of the warp (pbrt `Invert`): the sample of the unit square that the warp maps to p. The warp
    /// is the tables' parameterisation, not a measured value: its grid is read in full at either resolution,
    /// its parameters (φi, θi) at `res`, as the spectra's are.
    fn invert(&self, p: [f64; 2], param: &[f64], res: Resolution) -> [f64; 2] {
        let corners = self.corners(param, res);
        let (px, py, fx, fy) = self.cell(p);
        let (nx, ny, size) = (self.nx, self.ny, self.nx * self.ny);
        let off = px + py * nx;
        let d = |j: usize| Self::lookup(&corners, &self.data, j, size);
        let cc = |j: usize| Self::lookup(&corners, &self.conditional, j, size);
        let (v00, v10, v01, v11) = (d(off), d(off + 1), d(off + nx), d(off + nx + 1));
        let c0 = (1.0 - fy) * v00 + fy * v01;
        let c1 = (1.0 - fy) * v10 + fy * v11;
        let mut x = fx * (c0 + 0.5 * fx * (c1 - c0));
        x += (1.0 - fy) * cc(off) + fy * cc(off + nx);
        let roff = py * nx;
        let (r0, r1) = (cc(roff + nx - 1), cc(roff + 2 * nx - 1));
        let row = (1.0 - fy) * r0 + fy * r1;
        x = if row > 0.0 { x / row } else { 0.0 };
        let mut y = fy * (r0 + 0.5 * fy * (r1 - r0));
        y += Self::lookup(&corners, &self.marginal, py, ny);
        [x, y]
    }
}

/// Up to 8 (slice, weight) pairs.
struct Corners {
    n: usize,
    at: [(usize, f64); 8],
}

/// pbrt-v4 `MeasuredBxDF::theta2u`.
pub(crate) fn theta2u(theta: f64) -> f64 {
    (theta * (2.0 / PI)).max(0.0).sqrt()
}

/// pbrt-v4 `MeasuredBxDF::phi2u`.
pub(crate) fn phi2u(phi: f64) -> f64 {
    phi * (1.0 / (2.0 * PI)) + 0.5
}

/// A measured BRDF from the RGL database.
#[derive(Clone, Debug)]
pub struct RglBrdf {
    file: String,
    description: String,
    isotropic: bool,
    jacobian: bool,
    /// (nφ, nθ) of the acquisition, n × n of the spectral tables, ny × nx of the NDF.
    shape: [usize; 5],
    ndf: Warp2D,
    sigma: Warp2D,
    vndf: Warp2D,
    spectra: Warp2D,
    /// The index along the file's spectral axis of each of our samples.
    channels: Vec<f64>,
    /// Wavelengths of the file not used (outside the CIE tables).
    dropped: usize,
    sampling: Sampling,
    /// The lobe's half width at half maximum as a slope, measured from the table at load
    /// ([`super::table::specular_half_width`]).
    half_width: f64,
    /// The samples the lookups read: the file's own, or every second one of the NDF, σ and spectral grids and
    /// of the incident directions (the coarse twin, [`Brdf::coarser`]).
    resolution: Resolution,
}

fn shape_err(file: &str, f: &Field, what: String) -> Error {
    Error::input(
        file,
        f.name.clone(),
        format!(
            "{what} (the field has shape {:?}, type {}, data at byte offset {})",
            f.shape,
            f.dtype.name(),
            f.offset
        ),
    )
}

impl RglBrdf {
    pub fn load(path: &Path) -> Result<Self> {
        let file = path.display().to_string();
        let bytes = crate::input::read_bytes_limited(path, "table", crate::input::MAX_TABLE_BYTES)?;
        Self::from_bytes(&bytes, &file)
    }

    /// Parse and check a whole `.bsdf` file held in memory; `file` names it in messages.
    pub(crate) fn from_bytes(bytes: &[u8], file: &str) -> Result<Self> {
        let tf = TensorFile::parse(bytes, file)?;
        let get = |name: &str, dtype: Dtype, rank: usize| -> Result<&Field> {
            let f = tf.field(name).ok_or_else(|| {
                Error::input(file, name, "missing: an RGL .bsdf file has the fields theta_i, phi_i, ndf, sigma, vndf, luminance, spectra + wavelengths (or rgb), description, jacobian")
            })?;
            if f.dtype != dtype || f.shape.len() != rank {
                return Err(shape_err(file, f, format!("expected a rank-{rank} {} field", dtype.name())));
            }
            Ok(f)
        };
        let theta_i = get("theta_i", Dtype::F32, 1)?;
        let phi_i = get("phi_i", Dtype::F32, 1)?;
        let ndf = get("ndf", Dtype::F32, 2)?;
        let sigma = get("sigma", Dtype::F32, 2)?;
        let vndf = get("vndf", Dtype::F32, 4)?;
        let luminance = get("luminance", Dtype::F32, 4)?;
        let description = get("description", Dtype::U8, 1)?;
        let jacobian = get("jacobian", Dtype::U8, 1)?;
        let (spectra, wavelengths) = match tf.field("spectra") {
            Some(_) => (get("spectra", Dtype::F32, 5)?, Some(get("wavelengths", Dtype::F32, 1)?)),
            None => (
                get("rgb", Dtype::F32, 5).map_err(|_| {
                    Error::input(
                        file,
                        "spectra",
                        "missing: neither `spectra` (with `wavelengths`) nor `rgb` is in the file",
                    )
                })?,
                None,
            ),
        };
        let (nphi, ntheta) = (phi_i.shape[0], theta_i.shape[0]);
        if nphi == 0 || ntheta == 0 {
            return Err(shape_err(file, if nphi == 0 { phi_i } else { theta_i }, "no values".into()));
        }
        let thetas = theta_i.f32s();
        let phis = phi_i.f32s();
        for (f, v) in [(theta_i, &thetas), (phi_i, &phis)] {
            if v.iter().any(|x| !x.is_finite()) || v.windows(2).any(|w| !(w[1] > w[0])) {
                return Err(shape_err(file, f, "values must be finite and strictly increasing".into()));
            }
        }
        if thetas[0] < 0.0 || thetas[ntheta - 1] > FRAC_PI_2 + 1e-6 {
            return Err(shape_err(file, theta_i, "values must lie in [0, π/2] (radians)".into()));
        }
        for f in [ndf, sigma] {
            if f.shape[0] < 2 || f.shape[1] < 2 {
                return Err(shape_err(file, f, "expected at least 2 × 2 samples".into()));
            }
        }
        if vndf.shape[0] != nphi || vndf.shape[1] != ntheta || vndf.shape[2] < 2 || vndf.shape[3] < 2 {
            return Err(shape_err(file, vndf, format!("expected [{nphi} (phi_i), {ntheta} (theta_i), ≥ 2, ≥ 2]")));
        }
        let n = spectra.shape[3];
        if luminance.shape[0] != nphi
            || luminance.shape[1] != ntheta
            || luminance.shape[2] != n
            || luminance.shape[3] != n
        {
            return Err(shape_err(file, luminance, format!("expected [{nphi}, {ntheta}, {n}, {n}] (as spectra)")));
        }
        let nl = spectra.shape[2];
        let expect_l = match wavelengths {
            Some(w) => w.shape[0],
            None => 3,
        };
        if spectra.shape[0] != nphi || spectra.shape[1] != ntheta || nl != expect_l || spectra.shape[4] != n || n < 2 {
            return Err(shape_err(
                file,
                spectra,
                format!("expected [{nphi} (phi_i), {ntheta} (theta_i), {expect_l} (wavelengths), n, n] with n ≥ 2"),
            ));
        }
        if jacobian.shape[0] != 1 {
            return Err(shape_err(file, jacobian, "expected one value".into()));
        }
        let isotropic = nphi <= 2;
        if !isotropic {
            let reduction = (2.0 * PI / (phis[nphi - 1] - phis[0])).round();
            if reduction != 1.0 {
                return Err(shape_err(
                    file,
                    phi_i,
                    format!(
                        "phi_i spans 2π/{reduction}: a symmetry reduction, which pbrt-v4 does not support either; \
                         expected phi_i to cover the full circle"
                    ),
                ));
            }
        }
        let mut wl_axis: Vec<f64> = (0..nl).map(|k| k as f64).collect();
        let (sampling, channels, dropped) = match wavelengths {
            None => (Sampling::rgb(), vec![0.0, 1.0, 2.0], 0),
            Some(w) => {
                let lam = w.f32s();
                if lam.iter().any(|x| !x.is_finite()) || lam.windows(2).any(|p| !(p[1] > p[0])) {
                    return Err(shape_err(file, w, "wavelengths must be finite and strictly increasing (nm)".into()));
                }
                wl_axis = lam.clone();
                let keep: Vec<f64> = lam.iter().copied().filter(|l| (360.0..=830.0).contains(l)).collect();
                if keep.is_empty() {
                    return Err(shape_err(file, w, "no wavelength within 360–830 nm (the CIE tables)".into()));
                }
                let s = Sampling::spectral(&keep).map_err(|e| shape_err(file, w, e.to_string()))?;
                (s, keep.clone(), lam.len() - keep.len())
            }
        };
        let ndf_w = Warp2D::new(&ndf.f32s(), ndf.shape[1], ndf.shape[0], vec![], false);
        let sigma_w = Warp2D::new(&sigma.f32s(), sigma.shape[1], sigma.shape[0], vec![], false);
        let vndf_w = Warp2D::new(&vndf.f32s(), vndf.shape[3], vndf.shape[2], vec![phis.clone(), thetas.clone()], true);
        let spectra_w = Warp2D::new(&spectra.f32s(), n, n, vec![phis, thetas, wl_axis], false);
        let mut brdf = RglBrdf {
            file: file.to_string(),
            description: String::from_utf8_lossy(&description.bytes).trim_end_matches('\0').trim().to_string(),
            isotropic,
            jacobian: jacobian.bytes[0] != 0,
            shape: [nphi, ntheta, n, ndf.shape[0], ndf.shape[1]],
            ndf: ndf_w,
            sigma: sigma_w,
            vndf: vndf_w,
            spectra: spectra_w,
            channels,
            dropped,
            sampling,
            half_width: f64::INFINITY,
            resolution: Resolution::Own,
        };
        let n = brdf.sampling.len();
        brdf.half_width = super::table::specular_half_width(|wi, wo, out| brdf.eval(wi, wo, out), n);
        Ok(brdf)
    }

    /// The resolution stated with the lobe (`Tail::Table`): tan of the polar angle of the first node off the pole of the
    /// finer of the NDF and VNDF grids, θ = (π/2)/(n − 1)² (u_θ = √(2θ/π) puts the nodes densest there).
    pub(crate) fn resolution_slope(&self) -> f64 {
        let n = self.ndf.nx.max(self.vndf.nx) as f64;
        (FRAC_PI_2 / ((n - 1.0) * (n - 1.0))).tan()
    }
}

impl Brdf for RglBrdf {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        out.fill(0.0);
        // pbrt's ωo (the table's parameter direction) is our source direction ωi.
        let wm = wi + wo;
        if !(wm.length_squared() > 0.0) {
            return;
        }
        let wm = wm.normalize();
        let (theta_p, phi_p) = (elevation(wi), wi.y.atan2(wi.x));
        let (theta_m, phi_m) = (elevation(wm), wm.y.atan2(wm.x));
        let u_p = [theta2u(theta_p), phi2u(phi_p)];
        let mut u_m = [theta2u(theta_m), phi2u(if self.isotropic { phi_m - phi_p } else { phi_m })];
        u_m[1] -= u_m[1].floor();
        let params = [phi_p, theta_p];
        let res = self.resolution;
        let s = self.vndf.invert(u_m, &params, res);
        let scale = if self.jacobian {
            self.ndf.eval(u_m, &[], res) / (4.0 * self.sigma.eval(u_p, &[], res) * wo.z)
        } else {
            1.0 / wo.z
        };
        if !scale.is_finite() {
            return;
        }
        for (o, &ch) in out.iter_mut().zip(&self.channels) {
            *o = self.spectra.eval(s, &[phi_p, theta_p, ch], res).max(0.0) * scale;
        }
    }

    /// Not reciprocal: the evaluation singles out the parameter direction, and the data need not be.
    fn hints(&self) -> Hints {
        Hints::new(vec![Term {
            label: "measured table (RGL .bsdf, pbrt-v4 evaluation)".into(),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.half_width,
                medium_eta: 1.0,
                label: "measured (RGL)".into(),
                tail: crate::brdf::Tail::Table { half_width: self.half_width, resolution: self.resolution_slope() },
            }),
        }])
        .with_reciprocal(false)
    }

    fn coarser(&self) -> Vec<std::sync::Arc<dyn Brdf>> {
        self.resolution.twins(|resolution| std::sync::Arc::new(RglBrdf { resolution, ..self.clone() }) as _)
    }

    fn describe(&self) -> String {
        let name = super::table::file_name(&self.file);
        let [np, nt, n, ny, nx] = self.shape;
        let dropped = if self.dropped > 0 {
            format!(", {} wavelengths outside 360–830 nm not used", self.dropped)
        } else {
            String::new()
        };
        format!(
            "measured RGL table {name} {:?} ({}, {np} × {nt} incident directions, {n} × {n} spectral grid, NDF {ny} × {nx}, {}{dropped}{})",
            self.description,
            if self.isotropic { "isotropic" } else { "anisotropic" },
            self.sampling.describe(),
            if self.resolution != Resolution::Own { "; a coarse twin, read on about every second sample" } else { "" }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_warp_inverts_to_the_identity() {
        let w = Warp2D::new(&[2.0; 12], 4, 3, vec![], true);
        for p in [[0.1, 0.2], [0.5, 0.5], [0.97, 0.03]] {
            let s = w.invert(p, &[], Resolution::Own);
            assert!((s[0] - p[0]).abs() < 1e-14 && (s[1] - p[1]).abs() < 1e-14, "{s:?} vs {p:?}");
        }
    }

    #[test]
    fn inverse_is_a_cdf() {
        // A sloped density: the inverse is monotone and maps the corners to the corners.
        let data: Vec<f64> = (0..20).map(|i| 1.0 + (i % 5) as f64 + 0.5 * (i / 5) as f64).collect();
        let w = Warp2D::new(&data, 5, 4, vec![], true);
        assert!(w.invert([0.0, 0.0], &[], Resolution::Own).iter().all(|v| v.abs() < 1e-14));
        let top = w.invert([1.0, 1.0], &[], Resolution::Own);
        assert!((top[0] - 1.0).abs() < 1e-12 && (top[1] - 1.0).abs() < 1e-12, "{top:?}");
        let mut last = -1.0;
        for k in 0..50 {
            let s = w.invert([k as f64 / 49.0, 0.3], &[], Resolution::Own);
            assert!(s[0] >= last);
            last = s[0];
        }
    }

    #[test]
    fn header_errors_name_offset() {
        let e = TensorFile::parse(b"tensor_filX\0\x01\x00\0\0\0\0", "x.bsdf").unwrap_err().to_string();
        assert!(e.contains("wrong magic at byte offset 0"), "{e}");
        let e = TensorFile::parse(b"tensor_file\0\x01\x00\x01\0", "x.bsdf").unwrap_err().to_string();
        assert!(e.contains("truncated at byte offset 14"), "{e}");
    }
}
