//! A Python callable as a [`Brdf`]: `measure_brdf(f, ...)`.
//!
//! Why: the question rendering engineers bring is "does *my* BRDF read like the real panel?", and their BRDF
//! is a Python function (NumPy, Mitsuba). `f(wi, wo)` takes two (N, 3) float64 arrays of unit directions in
//! the library's local frame (z the normal, x–z the plane of measurement, both pointing away from the
//! surface) and returns f_r in sr⁻¹ as (N,) or (N, S). The integrator calls it in batches.
//!
//! Errors: `Brdf::eval` cannot fail, so the first exception raised by f (or a bad return value: wrong shape,
//! NaN, negative) is kept, f is not called again (the integrals finish on zeros, quickly), and the
//! exception is raised, as itself, when the measurement returns.
use std::sync::Mutex;

use glossmeter::brdf::{Brdf, Hints, Lobe, Tail, Term, TermKind};
use glossmeter::colorimetry::weighting::Weighting;
use glossmeter::instrument::plan::{Plan, PlanOptions, Target};
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args::{self, type_name};
use crate::probe;
use crate::{guarded, load_geometries, readings_to_py, run_plan, to_py_err};

/// The mirror component of a Python BRDF.
enum Delta {
    /// R per spectral sample, independent of direction.
    Constant(Vec<f64>),
    /// R(wi) from a callable taking (N, 3) and returning (N,) or (N, S).
    Callable(Py<PyAny>),
}

pub struct PyBrdf {
    f: Py<PyAny>,
    delta: Option<Delta>,
    sampling: Sampling,
    terms: Vec<Term>,
    description: String,
    /// `numpy.ascontiguousarray`, to accept any array-like (float32, lists, Dr.Jit arrays) from f.
    asarray: Py<PyAny>,
    /// The first error raised by f or found in its values.
    error: Mutex<Option<PyErr>>,
}

impl std::fmt::Debug for PyBrdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PyBrdf({})", self.description)
    }
}

/// (N, 3) float64 array of directions.
fn directions<'py>(py: Python<'py>, w: &[Vec3]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = w.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    Ok(PyArray1::from_vec(py, flat).reshape([w.len(), 3])?.into_any())
}

/// Check a value array of f (or of delta) and copy it to `out` (N·S values, point-major).
fn copy_values(
    what: &str,
    asarray: &Bound<'_, PyAny>,
    result: &Bound<'_, PyAny>,
    n: usize,
    s: Option<usize>,
    out: &mut Vec<f64>,
) -> PyResult<usize> {
    let expected = format!(
        "expected f_r as an array of numbers of shape ({n},) or ({n}, S): one value (or S spectral samples) per \
         point of the batch of N = {n}"
    );
    if result.is_none() {
        return Err(PyTypeError::new_err(format!("{what} returned None (a missing `return`?); {expected}")));
    }
    let arr = asarray
        .call1((result, "float64"))
        .map_err(|_| PyTypeError::new_err(format!("{what} returned {}; {expected}", type_name(result))))?;
    let arr: PyReadonlyArrayDyn<f64> = arr
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{what} returned {}; {expected}", type_name(result))))?;
    let shape = arr.shape().to_vec();
    let got_s = match shape.as_slice() {
        [m] if *m == n => 1,
        [m, k] if *m == n && *k >= 1 => *k,
        _ => {
            let shown = shape.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ");
            let comma = if shape.len() == 1 { "," } else { "" };
            return Err(PyValueError::new_err(format!(
                "{what} returned {} of shape ({shown}{comma}); {expected} (a single number is not broadcast: \
                 return e.g. numpy.full(len(wi), x))",
                type_name(result)
            )));
        }
    };
    if let Some(s) = s {
        if got_s != s {
            return Err(PyValueError::new_err(format!(
                "{what} returned {got_s} spectral sample(s) per point, but its first call returned {s}"
            )));
        }
    }
    let slice = arr.as_slice().map_err(|e| PyValueError::new_err(e.to_string()))?;
    out.clear();
    out.extend_from_slice(slice);
    Ok(got_s)
}

/// Name the first value that is not finite or negative.
fn check_values(what: &str, values: &[f64], s: usize, at: impl Fn(usize) -> String) -> PyResult<()> {
    if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(PyValueError::new_err(format!(
            "{what} returned {} at {} (spectral sample {}); values must be finite and ≥ 0",
            values[i],
            at(i / s),
            i % s
        )));
    }
    Ok(())
}

fn fmt_dir(w: Vec3) -> String {
    format!("({:.6}, {:.6}, {:.6})", w.x, w.y, w.z)
}

impl PyBrdf {
    fn failed(&self) -> bool {
        self.error.lock().map(|e| e.is_some()).unwrap_or(true)
    }

    fn keep(&self, e: PyErr) {
        if let Ok(mut slot) = self.error.lock() {
            if slot.is_none() {
                *slot = Some(e);
            }
        }
    }

    /// f at a batch of points; values point-major into `out` (len N·S).
    fn call_f(&self, py: Python<'_>, wi: &[Vec3], wo: &[Vec3], out: &mut Vec<f64>) -> PyResult<()> {
        let res = self.f.bind(py).call1((directions(py, wi)?, directions(py, wo)?))?;
        let s = self.sampling.len();
        copy_values("f", self.asarray.bind(py), &res, wi.len(), Some(s), out)?;
        check_values("f", out, s, |i| format!("wi = {}, wo = {}", fmt_dir(wi[i]), fmt_dir(wo[i])))
    }

    fn call_delta(&self, py: Python<'_>, g: &Py<PyAny>, wi: &[Vec3], out: &mut Vec<f64>) -> PyResult<()> {
        let res = g.bind(py).call1((directions(py, wi)?,))?;
        let s = self.sampling.len();
        copy_values("delta", self.asarray.bind(py), &res, wi.len(), Some(s), out)?;
        check_values("delta", out, s, |i| format!("wi = {}", fmt_dir(wi[i])))
    }

    /// Evaluate a batch in one call of f, keeping the first error; zeros once f has failed, and for pairs
    /// below the horizon (as `Brdf::eval_batch` requires; the instrument passes none).
    fn eval_points(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        if wi.is_empty() {
            return;
        }
        if self.failed() {
            out.fill(0.0);
            return;
        }
        let mut buf = Vec::with_capacity(out.len());
        let r = Python::attach(|py| self.call_f(py, wi, wo, &mut buf));
        match r {
            Ok(()) => {
                out.copy_from_slice(&buf);
                let n = self.sampling.len();
                for (i, o) in out.chunks_exact_mut(n).enumerate() {
                    if !(wi[i].z > 0.0 && wo[i].z > 0.0) {
                        o.fill(0.0);
                    }
                }
            }
            Err(e) => {
                self.keep(e);
                out.fill(0.0);
            }
        }
    }

    fn take_error(&self) -> Option<PyErr> {
        self.error.lock().ok().and_then(|mut e| e.take())
    }
}

impl Brdf for PyBrdf {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.eval_points(&[wi], &[wo], out);
    }

    /// One call of f per batch: the interpreter boundary is crossed once for the whole batch.
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.eval_points(wi, wo, out);
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        match &self.delta {
            None => false,
            Some(Delta::Constant(r)) => {
                out.copy_from_slice(r);
                true
            }
            Some(Delta::Callable(g)) => {
                if self.failed() {
                    out.fill(0.0);
                    return true;
                }
                let mut buf = Vec::with_capacity(out.len());
                match Python::attach(|py| self.call_delta(py, g, &[wi], &mut buf)) {
                    Ok(()) => out.copy_from_slice(&buf),
                    Err(e) => {
                        self.keep(e);
                        out.fill(0.0);
                    }
                }
                true
            }
        }
    }

    /// The terms the user stated; reciprocity is unknown for a user's function (nothing in the plan relies
    /// on it), so not claimed.
    fn hints(&self) -> Hints {
        Hints::new(self.terms.clone()).with_reciprocal(false)
    }

    fn describe(&self) -> String {
        self.description.clone()
    }
}

/// A placeholder material, only to list the angles a plan will measure at (composites pull in their parts).
#[derive(Debug)]
struct Placeholder(Sampling);

impl Brdf for Placeholder {
    fn sampling(&self) -> &Sampling {
        &self.0
    }
    fn eval(&self, _wi: Vec3, _wo: Vec3, out: &mut [f64]) {
        out.fill(0.0);
    }
    fn hints(&self) -> Hints {
        Hints::new(vec![Term { label: "placeholder".into(), kind: TermKind::Diffuse }])
    }
    fn describe(&self) -> String {
        "placeholder".into()
    }
}

/// The distinct specimen angles of the plan for these geometries.
fn specimen_angles(geos: &[glossmeter::instrument::standards::StandardGeometry]) -> PyResult<Vec<f64>> {
    let plan = Plan::compile(std::sync::Arc::new(Placeholder(Sampling::grey())), geos.to_vec(), PlanOptions::default())
        .map_err(to_py_err)?;
    let mut out: Vec<f64> = Vec::new();
    for j in &plan.jobs {
        if j.method.aperture.target == Target::Specimen
            && !out.iter().any(|t| t.to_bits() == j.method.aperture.theta.to_bits())
        {
            out.push(j.method.aperture.theta);
        }
    }
    Ok(out)
}

/// `lobes=`: a list of slope widths or of dicts {"slope": m, "tail": "heavy"|"gaussian", "eta": 1.0,
/// "label": str}.
fn parse_lobes(lobes: &Bound<'_, PyAny>) -> PyResult<Vec<Lobe>> {
    let mut out = Vec::new();
    let bad = |i: usize, m: String| PyValueError::new_err(format!("lobes[{i}]: {m}"));
    let items = match lobes.try_iter() {
        Ok(items) if !lobes.is_instance_of::<pyo3::types::PyString>() && !lobes.is_instance_of::<PyDict>() => items,
        _ => {
            return Err(PyTypeError::new_err(format!(
                "lobes: expected None (probe f), [] (f is smooth) or a list of slope widths or dicts {{\"slope\": m, \
                 \"tail\": \"heavy\" | \"gaussian\", \"eta\": 1.0, \"label\": str}}, got {}",
                type_name(lobes)
            )))
        }
    };
    for (i, item) in items.enumerate() {
        let item = item?;
        let number =
            |key: &str, v: &Bound<'_, PyAny>, allowed: &str| args::real(&format!("lobes[{i}][\"{key}\"]"), v, allowed);
        let (slope, heavy, eta, label) = if let Ok(d) = item.cast::<PyDict>() {
            for k in d.keys() {
                let k: String = k.extract()?;
                if !["slope", "tail", "eta", "label"].contains(&k.as_str()) {
                    return Err(bad(
                        i,
                        format!("unknown key \"{k}\"; allowed: \"slope\", \"tail\", \"eta\", \"label\""),
                    ));
                }
            }
            let slope: f64 = match d.get_item("slope")? {
                Some(v) => number("slope", &v, "the facet slope width, Beckmann m or GGX α, in (0, 10]")?,
                None => return Err(bad(i, "missing \"slope\" (the facet slope width, Beckmann m or GGX α)".into())),
            };
            let heavy = match d.get_item("tail")? {
                None => true,
                Some(v) => match v.extract::<String>().as_deref() {
                    Ok("heavy") => true,
                    Ok("gaussian") => false,
                    Ok(other) => {
                        return Err(bad(i, format!("\"tail\" is \"{other}\"; allowed: \"heavy\", \"gaussian\"")))
                    }
                    Err(_) => {
                        return Err(PyTypeError::new_err(format!(
                            "lobes[{i}][\"tail\"]: expected \"heavy\" or \"gaussian\", got {}",
                            type_name(&v)
                        )))
                    }
                },
            };
            let eta: f64 = match d.get_item("eta")? {
                Some(v) => number("eta", &v, "the index of the medium the lobe forms in, in [1, 4]")?,
                None => 1.0,
            };
            let label: String = match d.get_item("label")? {
                Some(v) => v.extract().map_err(|_| {
                    PyTypeError::new_err(format!("lobes[{i}][\"label\"]: expected a str, got {}", type_name(&v)))
                })?,
                None => format!("lobe {i} of f (hinted)"),
            };
            (slope, heavy, eta, label)
        } else {
            let slope = args::real(
                &format!("lobes[{i}]"),
                &item,
                "a slope width in (0, 10], or a dict {\"slope\": m, \"tail\": ..., \"eta\": ..., \"label\": ...}",
            )?;
            (slope, true, 1.0, format!("lobe {i} of f (hinted)"))
        };
        if !(slope.is_finite() && slope > 0.0 && slope <= 10.0) {
            return Err(bad(i, format!("slope width {} is outside (0, 10]", glossmeter::error::given(slope))));
        }
        if !(eta.is_finite() && (1.0..=4.0).contains(&eta)) {
            return Err(bad(i, format!("eta {} is outside [1, 4]", glossmeter::error::given(eta))));
        }
        // A heavy tail of a user's function has no stated shape: `Tail::Unknown` (split out to the range ends).
        let tail = if heavy { Tail::Unknown } else { Tail::Gaussian };
        out.push(Lobe { slope_width: slope, medium_eta: eta, label, tail });
    }
    Ok(out)
}

/// `delta=`: None, a mirror reflectance R in [0, 1] (a number, or a list of `s` numbers, one per spectral sample),
/// or a callable R(wi).
fn parse_delta(delta: Option<&Bound<'_, PyAny>>, s: usize) -> PyResult<Option<Delta>> {
    Ok(match delta {
        None => None,
        Some(d) if d.is_callable() => Some(Delta::Callable(d.clone().unbind())),
        Some(d) => {
            let allowed = "the mirror reflectance R in [0, 1]: a number, a list of S numbers, or a callable R(wi)";
            let r: Vec<f64> = match args::real("delta", d, allowed) {
                Ok(x) => vec![x; s],
                Err(_) => args::reals("delta", d, allowed)
                    .map_err(|_| PyTypeError::new_err(format!("delta: expected {allowed}, got {}", type_name(d))))?,
            };
            if r.len() != s {
                return Err(PyValueError::new_err(format!(
                    "delta: {} values, but f returns {s} spectral sample(s) per point (one R per sample)",
                    r.len()
                )));
            }
            if let Some(x) = r.iter().find(|x| !(x.is_finite() && **x >= 0.0 && **x <= 1.0)) {
                return Err(PyValueError::new_err(format!(
                    "delta: reflectance {} is outside [0, 1]",
                    glossmeter::error::given(*x)
                )));
            }
            Some(Delta::Constant(r))
        }
    })
}

/// measure_brdf(f, geometries=None, rtol=None, lobes=None, delta=None, wavelengths=None, timing=True, *,
/// max_evals=None, max_seconds=None)
///
/// Read a Python BRDF through instrument geometries. `f(wi, wo)` takes two (N, 3) float64 arrays (local
/// frame, z the normal) and returns f_r in sr⁻¹, shape (N,) or (N, S), S spectral samples (1: grey, 3: linear
/// RGB with BT.709 luminance weights, otherwise give `wavelengths` in nm). It is called in batches.
/// `lobes`: hints of the lobe widths, a list of slope widths or dicts {"slope", "tail", "eta", "label"};
/// None probes f around the specular direction (and says so in each reading's "note"); [] declares f
/// smooth. `delta`: a mirror component, R as a number, a list of S numbers, or a callable R(wi) → (N,) or
/// (N, S). `rtol`, `max_evals` and `max_seconds` are `measure`'s ([`args::measure_request`]). An exception
/// raised in f propagates as itself.
#[pyfunction]
#[pyo3(signature = (f, geometries=None, rtol=None, lobes=None, delta=None, wavelengths=None, timing=None, *,
    max_evals=None, max_seconds=None))]
#[pyo3(text_signature = "(f, geometries=None, rtol=None, lobes=None, delta=None, wavelengths=None, timing=True, \
    *, max_evals=None, max_seconds=None)")]
#[allow(clippy::too_many_arguments)]
pub fn measure_brdf<'py>(
    py: Python<'py>,
    f: &Bound<'py, PyAny>,
    geometries: Option<&Bound<'py, PyAny>>,
    rtol: Option<&Bound<'py, PyAny>>,
    lobes: Option<&Bound<'py, PyAny>>,
    delta: Option<&Bound<'py, PyAny>>,
    wavelengths: Option<&Bound<'py, PyAny>>,
    timing: Option<&Bound<'py, PyAny>>,
    max_evals: Option<&Bound<'py, PyAny>>,
    max_seconds: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    if !f.is_callable() {
        return Err(PyTypeError::new_err(format!(
            "f: expected a callable f(wi, wo) taking two (N, 3) float64 arrays and returning f_r as (N,) or (N, S), \
             got {}",
            type_name(f)
        )));
    }
    // The measurement's request (the library's defaults and checks, as `measure`'s); colour readings need
    // a recipe's spectral data, so a Python BRDF's plan keeps the default conditions.
    let request = args::measure_request(rtol, max_evals, max_seconds, None, None)?;
    let options = guarded(|| request.options().map_err(to_py_err))?;
    let timing = args::flag("timing", timing, true)?;
    let wavelengths = match wavelengths {
        None => None,
        Some(w) if w.is_none() => None,
        Some(w) => Some(args::reals("wavelengths", w, "the wavelength of each spectral sample of f, in nm")?),
    };
    let geos = guarded(|| load_geometries(py, geometries))?;
    let hinted = match lobes {
        None => None,
        Some(l) => Some(guarded(|| parse_lobes(l))?),
    };
    let angles = guarded(|| specimen_angles(&geos))?;
    let asarray = py.import("numpy")?.getattr("ascontiguousarray")?;

    // One call up front on the probe points of every angle: learns S, checks f, and feeds the probe.
    let pts: Vec<(Vec3, Vec3)> = angles.iter().flat_map(|t| probe::points(*t)).collect();
    let (wi, wo): (Vec<Vec3>, Vec<Vec3>) = pts.iter().copied().unzip();
    let res = f.call1((directions(py, &wi)?, directions(py, &wo)?))?;
    let mut values = Vec::new();
    let s = copy_values("f", &asarray, &res, wi.len(), None, &mut values)?;
    check_values("f", &values, s, |i| format!("wi = {}, wo = {}", fmt_dir(wi[i]), fmt_dir(wo[i])))?;
    let sampling = match (&wavelengths, s) {
        (Some(w), _) if w.len() != s => {
            return Err(PyValueError::new_err(format!(
                "wavelengths: {} entries, but f returns {s} spectral sample(s) per point (one wavelength in nm per \
                 sample)",
                w.len()
            )))
        }
        (Some(w), _) => Sampling::spectral(w).map_err(to_py_err)?,
        (None, 1) => Sampling::grey(),
        (None, 3) => Sampling::rgb(),
        (None, _) => {
            return Err(PyValueError::new_err(format!(
                "wavelengths: f returns {s} spectral samples per point: give their wavelengths (nm) as \
                 wavelengths=[...] (1 sample is grey, 3 are linear RGB)"
            )))
        }
    };

    let (lobes, probe_note) = match hinted {
        Some(l) => (l, None),
        None => {
            let per = probe::points(0.0).len();
            let lum = Weighting::luminous(&sampling).map_err(to_py_err)?;
            let found: Vec<(f64, probe::Found)> = angles
                .iter()
                .enumerate()
                .map(|(a, t)| {
                    let lum: Vec<f64> =
                        (0..per).map(|i| lum.component(0, &values[(a * per + i) * s..(a * per + i + 1) * s])).collect();
                    (*t, probe::analyse(*t, &lum))
                })
                .collect();
            let (l, note) = probe::conclude(&found);
            (l, Some(note))
        }
    };

    let delta = parse_delta(delta, s)?;

    let mut terms = Vec::new();
    if delta.is_some() {
        terms.push(Term { label: "mirror component (delta=)".into(), kind: TermKind::Delta });
    }
    if lobes.is_empty() {
        terms.push(Term { label: "f (smooth)".into(), kind: TermKind::Diffuse });
    }
    for l in &lobes {
        terms.push(Term { label: l.label.clone(), kind: TermKind::Lobe(l.clone()) });
    }
    let name: String = f
        .getattr("__qualname__")
        .or_else(|_| f.getattr("__name__"))
        .and_then(|n| n.extract())
        .unwrap_or_else(|_| "f".to_string());
    let description = format!(
        "Python BRDF {name} ({}; {})",
        sampling.describe(),
        if lobes.is_empty() {
            "smooth".to_string()
        } else {
            lobes.iter().map(|l| format!("lobe slope {:.3e}", l.slope_width)).collect::<Vec<_>>().join(", ")
        }
    );
    let brdf = std::sync::Arc::new(PyBrdf {
        f: f.clone().unbind(),
        delta,
        sampling,
        terms,
        description,
        asarray: asarray.unbind(),
        error: Mutex::new(None),
    });
    let readings = run_plan(py, brdf.clone(), geos, options, true)?;
    if let Some(e) = brdf.take_error() {
        return Err(e);
    }
    let list = guarded(|| readings_to_py(py, &readings, timing))?;
    if let Some(note) = probe_note {
        for d in list.iter() {
            let note = match d.get_item("note") {
                Ok(existing) => format!("{}; {note}", existing.extract::<String>()?),
                Err(_) => note.clone(),
            };
            d.set_item("note", note)?;
        }
    }
    Ok(list)
}
