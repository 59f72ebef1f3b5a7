//! Arguments from Python, converted with refusals that name the argument and what it allows
//! (docs/python.md §Errors): a value of the wrong type is a `TypeError`, a value out of range a `ValueError`,
//! each saying `name: expected ..., got ...` instead of PyO3's generic conversion messages.
use glossmeter::request::{MeasureRequest, PlanRequest};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyString};

/// The Python type name of a value, for messages (`int`, `str`, `NoneType`).
pub fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "an unknown type".into())
}

/// A real number (int, float, or anything with `__float__`, e.g. a NumPy scalar); a bool or a str is refused.
pub fn real(name: &str, v: &Bound<'_, PyAny>, allowed: &str) -> PyResult<f64> {
    let refuse = || PyTypeError::new_err(format!("{name}: expected a number ({allowed}), got {}", type_name(v)));
    if v.is_instance_of::<PyBool>() || v.is_instance_of::<PyString>() {
        return Err(refuse());
    }
    v.extract::<f64>().map_err(|_| refuse())
}

/// The keywords of a measurement (`measure`, `measure_brdf`) as the library's request
/// ([`MeasureRequest`]), in this one place, as the command line converts its flags and the server its body: the
/// request owns the defaults (10⁻⁶; for a measured table, without `rtol`, the tolerance its data uncertainty
/// allows, docs/accuracy.md §Data uncertainty of measured tables; a given `rtol` is used as given) and the
/// checks, whose messages name each keyword ([`keyword`]). Here only the types are checked.
pub fn measure_request(
    rtol: Option<&Bound<'_, PyAny>>,
    max_evals: Option<&Bound<'_, PyAny>>,
    max_seconds: Option<&Bound<'_, PyAny>>,
    illuminant: Option<&Bound<'_, PyAny>>,
    observer: Option<&Bound<'_, PyAny>>,
) -> PyResult<MeasureRequest> {
    Ok(MeasureRequest {
        plan: plan_request(rtol, max_evals, illuminant, observer)?,
        max_seconds: opt_real("max_seconds", max_seconds, "a wall-clock limit in seconds, ≥ 0 (0: none)")?
            .unwrap_or(0.0),
    })
}

/// The keywords of a plan (`rtol`, `max_evals`, `illuminant`, `observer`) as the library's [`PlanRequest`],
/// shared by every function that runs plans; only their types are checked here.
pub fn plan_request(
    rtol: Option<&Bound<'_, PyAny>>,
    max_evals: Option<&Bound<'_, PyAny>>,
    illuminant: Option<&Bound<'_, PyAny>>,
    observer: Option<&Bound<'_, PyAny>>,
) -> PyResult<PlanRequest> {
    let max_evals = opt_count("max_evals", max_evals, "the evaluation budget of each aperture integral, ≥ 1")?;
    Ok(PlanRequest {
        rtol: opt_real("rtol", rtol, "the relative tolerance of the integrals, in (0, 1), e.g. 1e-6")?,
        max_evals: max_evals.map(|n| usize::try_from(n).unwrap_or(usize::MAX)),
        illuminant: opt_string("illuminant", illuminant, "\"D65\", \"D50\", \"A\" or \"C\"")?,
        observer: opt_string("observer", observer, "\"10\" or \"2\"")?,
    })
}

/// A flag: True or False (a NumPy bool too); None is `default`. An int is refused (0 and 1 are not flags).
pub fn flag(name: &str, v: Option<&Bound<'_, PyAny>>, default: bool) -> PyResult<bool> {
    match v {
        None => Ok(default),
        Some(v) if v.is_none() => Ok(default),
        Some(v) => v
            .extract::<bool>()
            .map_err(|_| PyTypeError::new_err(format!("{name}: expected True or False, got {}", type_name(v)))),
    }
}

/// A list of numbers (any iterable of numbers but a str); `name[i]` names a bad element.
pub fn reals(name: &str, v: &Bound<'_, PyAny>, allowed: &str) -> PyResult<Vec<f64>> {
    let refuse =
        || PyTypeError::new_err(format!("{name}: expected a list of numbers ({allowed}), got {}", type_name(v)));
    if v.is_instance_of::<PyString>() {
        return Err(refuse());
    }
    let items = v.try_iter().map_err(|_| refuse())?;
    let mut out = Vec::new();
    for (i, x) in items.enumerate() {
        out.push(real(&format!("{name}[{i}]"), &x?, allowed)?);
    }
    Ok(out)
}

/// The keyword of an argument that a library error names ([`glossmeter::error::Words`]): the library says
/// `target`, Python's `fit` takes `targets=` (as the command line writes `--target`); every other argument is
/// its keyword.
pub fn keyword(argument: &'static str) -> String {
    match argument {
        "target" => "`targets`".into(),
        name => format!("`{name}`"),
    }
}

pub(crate) fn given<'py>(v: Option<&Bound<'py, PyAny>>) -> Option<Bound<'py, PyAny>> {
    v.filter(|v| !v.is_none()).cloned()
}

/// An optional real number (None: the default).
pub fn opt_real(name: &str, v: Option<&Bound<'_, PyAny>>, allowed: &str) -> PyResult<Option<f64>> {
    given(v).map(|v| real(name, &v, allowed)).transpose()
}

/// An optional whole number ≥ 0 (an int, or anything with `__index__`, e.g. a NumPy integer; a bool or a float
/// is refused); a negative one is a `ValueError`.
pub fn opt_count(name: &str, v: Option<&Bound<'_, PyAny>>, allowed: &str) -> PyResult<Option<u64>> {
    let Some(v) = given(v) else { return Ok(None) };
    let refuse = || PyTypeError::new_err(format!("{name}: expected a whole number ({allowed}), got {}", type_name(&v)));
    if v.is_instance_of::<PyBool>() || v.is_instance_of::<pyo3::types::PyFloat>() || v.is_instance_of::<PyString>() {
        return Err(refuse());
    }
    let i: i128 = v.extract().map_err(|_| refuse())?;
    u64::try_from(i)
        .map(Some)
        .map_err(|_| PyValueError::new_err(format!("{name}: expected a whole number ({allowed}), got {i}")))
}

/// An optional str.
pub fn opt_string(name: &str, v: Option<&Bound<'_, PyAny>>, allowed: &str) -> PyResult<Option<String>> {
    let Some(v) = given(v) else { return Ok(None) };
    match v.cast::<PyString>() {
        Ok(s) => Ok(Some(s.to_cow()?.into_owned())),
        Err(_) => Err(PyTypeError::new_err(format!("{name}: expected a str ({allowed}), got {}", type_name(&v)))),
    }
}

/// Strings: None (none), one str, or any iterable of str; `name[i]` names a bad element.
pub fn strings(name: &str, v: Option<&Bound<'_, PyAny>>, allowed: &str) -> PyResult<Vec<String>> {
    let Some(v) = given(v) else { return Ok(vec![]) };
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(vec![s.to_cow()?.into_owned()]);
    }
    let refuse =
        || PyTypeError::new_err(format!("{name}: expected a str or a list of str ({allowed}), got {}", type_name(&v)));
    if v.is_instance_of::<pyo3::types::PyDict>() {
        return Err(refuse());
    }
    let items = v.try_iter().map_err(|_| refuse())?;
    let mut out = Vec::new();
    for (i, x) in items.enumerate() {
        let x = x?;
        match x.cast::<PyString>() {
            Ok(s) => out.push(s.to_cow()?.into_owned()),
            Err(_) => {
                return Err(PyTypeError::new_err(format!(
                    "{name}[{i}]: expected a str ({allowed}), got {}",
                    type_name(&x)
                )))
            }
        }
    }
    Ok(out)
}
