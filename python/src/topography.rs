//! Height maps from Python (docs/python.md §Topography): a 2-D NumPy array of heights with its pixel spacing,
//! or a topography file, as the library's [`HeightMap`], converted in this one place with the library's own
//! checks (docs/topography.md §Limits): the dimensions before anything is copied, the spacings, the heights'
//! range; NaN heights and the points a mask clears are invalid points, as a file reader marks them.
use std::path::PathBuf;

use glossmeter::report::topography::TopographyDoc;
use glossmeter::request::TopographyRequest;
use glossmeter::topography::analysis::analyse;
use glossmeter::topography::map::{check_dimensions, check_spacing, Format, HeightMap};
use glossmeter::topography::text::Calibration;
use glossmeter::topography::units;
use numpy::PyReadonlyArray2;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::args::{opt_real, opt_string, type_name};
use crate::{from_json, guarded, to_py_err};

/// How a map from an array names itself in messages and in the document's `map.file`.
const ARRAY: &str = "<array>";

/// The (rows, columns) of a 2-D NumPy array of real numbers (float, signed or unsigned integer), refused
/// naming `name` otherwise.
fn shape_2d(py: Python<'_>, name: &str, a: &Bound<'_, PyAny>, what: &str) -> PyResult<(usize, usize)> {
    let np = py.import("numpy")?;
    if !a.is_instance(&np.getattr("ndarray")?)? {
        return Err(PyTypeError::new_err(format!("{name}: expected a 2-D NumPy array {what}, got {}", type_name(a))));
    }
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    match shape.as_slice() {
        [ny, nx] => Ok((*ny, *nx)),
        _ => Err(PyValueError::new_err(format!(
            "{name}: expected a 2-D NumPy array {what} (rows along y, columns along x), got {} dimensions",
            shape.len()
        ))),
    }
}

/// The dtype's kind letter (`f`, `i`, `u`, `b`, ...) and its name.
fn dtype(a: &Bound<'_, PyAny>) -> PyResult<(String, String)> {
    let d = a.getattr("dtype")?;
    Ok((d.getattr("kind")?.extract()?, d.str()?.to_string()))
}

/// A lateral spacing keyword in µm, in metres (the library checks its range, naming the keyword).
fn spacing_um(name: &str, v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<f64>> {
    Ok(opt_real(name, v, "the pixel spacing in µm, e.g. 0.5")?.map(|um| um * 1e-6))
}

/// The height unit keyword (`"um"` when None), in metres.
fn height_unit(v: Option<&Bound<'_, PyAny>>) -> PyResult<f64> {
    let u = opt_string("unit", v, &units::allowed())?.unwrap_or_else(|| "um".into());
    units::metres_per(&u)
        .ok_or_else(|| PyValueError::new_err(format!("unit: unknown length unit {u:?}; allowed: {}", units::allowed())))
}

/// A height map from a 2-D array (`array[j, i]` the height at x = i·dx, y = j·dy, in `unit`), its spacings and
/// an optional boolean mask of the same shape (True: a valid point). NaN heights are invalid points; the
/// library's limits and checks apply, naming the keyword.
pub(crate) fn from_array(
    py: Python<'_>,
    array: &Bound<'_, PyAny>,
    dx: f64,
    dy: f64,
    z_unit: f64,
    mask: Option<&Bound<'_, PyAny>>,
) -> PyResult<HeightMap> {
    let (ny, nx) = shape_2d(py, "array", array, "of heights")?;
    let (kind, name) = dtype(array)?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        return Err(PyTypeError::new_err(format!(
            "array: the heights are of dtype {name}; allowed: real numbers (a float or integer dtype)"
        )));
    }
    // The limits before anything of the map's size is copied.
    check_dimensions(ARRAY, "array", nx as u64, ny as u64).map_err(to_py_err)?;
    let np = py.import("numpy")?;
    let contiguous = np.call_method1("ascontiguousarray", (array, "float64"))?;
    let heights: PyReadonlyArray2<'_, f64> = contiguous.extract()?;
    let mut z: Vec<f64> = heights.as_slice().map_err(|e| PyValueError::new_err(format!("array: {e}")))?.to_vec();
    for v in z.iter_mut() {
        *v *= z_unit;
    }
    if let Some(m) = mask.filter(|m| !m.is_none()) {
        let shape = shape_2d(py, "mask", m, "of booleans (True: a valid point)")?;
        if shape != (ny, nx) {
            return Err(PyValueError::new_err(format!(
                "mask: a mask of {} × {} for heights of {ny} × {nx}; give one of the heights' shape",
                shape.0, shape.1
            )));
        }
        let (kind, name) = dtype(m)?;
        if kind != "b" {
            return Err(PyTypeError::new_err(format!(
                "mask: dtype {name}; allowed: bool (True: a valid point, False: an invalid one)"
            )));
        }
        let valid: PyReadonlyArray2<'_, bool> = np.call_method1("ascontiguousarray", (m,))?.extract()?;
        let valid = valid.as_slice().map_err(|e| PyValueError::new_err(format!("mask: {e}")))?;
        for (v, ok) in z.iter_mut().zip(valid) {
            if !ok {
                *v = f64::NAN;
            }
        }
    }
    HeightMap::new(ARRAY, Format::Array, nx, ny, dx, dy, z, "array").map_err(to_py_err)
}

/// topography(source, dx_um=None, dy_um=None, unit=None, mask=None, levelling=None) -> dict
///
/// The document of `glossmeter topography --format json` (docs/topography.md) for a height map: `source` a
/// 2-D NumPy array of heights (rows along y) with `dx_um` (and `dy_um`, `dx_um` when None) its pixel spacing in
/// µm, `unit` its heights' unit ("um" when None) and `mask` an optional bool array (True: valid); or the path
/// of a topography file (.x3p, .sdf, .gsf, .sur; a plain text matrix with `dx_um` and `unit`).
#[pyfunction]
#[pyo3(signature = (source, dx_um=None, dy_um=None, unit=None, mask=None, levelling=None))]
pub(crate) fn topography<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    dx_um: Option<&Bound<'py, PyAny>>,
    dy_um: Option<&Bound<'py, PyAny>>,
    unit: Option<&Bound<'py, PyAny>>,
    mask: Option<&Bound<'py, PyAny>>,
    levelling: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    guarded(|| {
        let levelling = opt_string("levelling", levelling, "\"mean\", \"plane\", \"poly2\" … \"poly5\"")?;
        let how = TopographyRequest { levelling, ..TopographyRequest::default() }.levelling().map_err(to_py_err)?;
        let dx = spacing_um("dx_um", dx_um)?;
        let dy = spacing_um("dy_um", dy_um)?;
        for (name, d) in [("dx_um", dx), ("dy_um", dy)] {
            if let Some(d) = d {
                check_spacing(ARRAY, name, d).map_err(to_py_err)?;
            }
        }
        let map = if py.import("numpy")?.getattr("ndarray").and_then(|t| source.is_instance(&t))? {
            let dx = dx.ok_or_else(|| {
                PyValueError::new_err("dx_um: missing: an array carries no calibration; give its pixel spacing in µm")
            })?;
            from_array(py, source, dx, dy.unwrap_or(dx), height_unit(unit)?, mask)?
        } else {
            let path = file_path(py, source)?;
            if mask.is_some_and(|m| !m.is_none()) {
                return Err(PyValueError::new_err("mask: only for an array (a file marks its own invalid points)"));
            }
            let calibration = match dx {
                Some(dx) => Some(Calibration { dx, dy: dy.unwrap_or(dx), z_unit: height_unit(unit)? }),
                None => None,
            };
            py.detach(|| glossmeter::topography::load(&path, calibration)).map_err(to_py_err)?
        };
        let analysis = py.detach(|| analyse(&map, how)).map_err(to_py_err)?;
        from_json(py, &glossmeter::report::to_json(&TopographyDoc::new(&map, &analysis)))
    })
}

/// A path (str or os.PathLike), refused naming `source`.
fn file_path(py: Python<'_>, source: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    if let Ok(s) = source.cast::<PyString>() {
        return Ok(PathBuf::from(&*s.to_cow()?));
    }
    match py.import("os")?.call_method1("fspath", (source,)) {
        Ok(p) => p.extract(),
        Err(_) => Err(PyTypeError::new_err(format!(
            "source: expected a 2-D NumPy array of heights or the path of a topography file (str or os.PathLike), \
             got {}",
            type_name(source)
        ))),
    }
}
