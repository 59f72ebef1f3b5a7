//! Height maps from Python (docs/python.md §Topography): a 2-D NumPy array of heights with its pixel spacing,
//! or a topography file, as the library's [`HeightMap`], converted in this one place with the library's own
//! checks (docs/topography.md §Limits): the dimensions before anything is copied, the spacings, the heights'
//! range; NaN heights and the points a mask clears are invalid points, as a file reader marks them. A map held
//! for recipes ([`PyHeightMap`]) is registered in the library's `topography::memory`, whose label a recipe's
//! `file` entry carries through `json.dumps` ([`json_default`]).
use std::path::PathBuf;

use glossmeter::report::topography::TopographyDoc;
use glossmeter::request::TopographyRequest;
use glossmeter::topography::analysis::analyse;
use glossmeter::topography::map::{check_dimensions, check_spacing, Format, HeightMap};
use glossmeter::topography::memory::InMemory;
use glossmeter::topography::text::Calibration;
use glossmeter::topography::units;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::args::{given, opt_real, opt_string, type_name};
use crate::{from_json, guarded, to_py_err};
use pyo3::types::PyTuple;

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
        let map = if let Ok(held) = source.cast::<PyHeightMap>() {
            if dx.is_some() || dy.is_some() || given(unit).is_some() || given(mask).is_some() {
                return Err(PyValueError::new_err(
                    "dx_um, dy_um, unit, mask: not for a HeightMap, which carries its calibration and invalid points",
                ));
            }
            held.get().held.map().clone()
        } else if py.import("numpy")?.getattr("ndarray").and_then(|t| source.is_instance(&t))? {
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

/// A height map held in memory for recipes (docs/python.md §Topography): a recipe's `file` entry (the
/// `topography` model's, a paint's applied texture) may be one, and every reading, sweep and fit of that
/// recipe reads it. Pickled (to a Dask worker), it is registered again where it is unpickled, bit for bit.
#[pyclass(frozen, name = "HeightMap", module = "glossmeter")]
pub(crate) struct PyHeightMap {
    held: InMemory,
}

#[pymethods]
impl PyHeightMap {
    /// The label a recipe carries in its place (`<height map N>`), and the map's name in messages.
    #[getter]
    fn label(&self) -> &str {
        self.held.label()
    }

    /// (rows, columns): points along y and along x.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        let m = self.held.map();
        (m.ny, m.nx)
    }

    /// The pixel spacing along x, µm.
    #[getter]
    fn dx_um(&self) -> f64 {
        self.held.map().dx * 1e6
    }

    /// The pixel spacing along y, µm.
    #[getter]
    fn dy_um(&self) -> f64 {
        self.held.map().dy * 1e6
    }

    fn __repr__(&self) -> String {
        let m = self.held.map();
        format!("HeightMap({}, {} × {} points, dx {} µm, dy {} µm)", m.file, m.ny, m.nx, m.dx * 1e6, m.dy * 1e6)
    }

    /// Pickled as its heights in metres (NaN at invalid points) and its spacings in metres, so that the map
    /// registered again on unpickling is the same to the bit.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let m = self.held.map();
        let z = PyArray1::from_slice(py, &m.z).reshape([m.ny, m.nx])?;
        let rebuild = py.import("glossmeter._glossmeter")?.getattr("_height_map_m")?;
        Ok((
            rebuild,
            PyTuple::new(py, [z.into_any(), m.dx.into_pyobject(py)?.into_any(), m.dy.into_pyobject(py)?.into_any()])?,
        ))
    }
}

/// height_map(array, dx_um, dy_um=None, unit=None, mask=None) -> HeightMap
///
/// A 2-D NumPy array of heights (rows along y; `unit` "um" when None) with its pixel spacing in µm (`dy_um`
/// `dx_um` when None) and an optional bool mask (True: valid), checked as `topography` checks it and held in
/// memory for recipes: `{"model": "topography", "file": glossmeter.height_map(z, dx_um=2.0), "ior": 1.5}`.
#[pyfunction]
#[pyo3(signature = (array, dx_um, dy_um=None, unit=None, mask=None))]
pub(crate) fn height_map<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    dx_um: &Bound<'py, PyAny>,
    dy_um: Option<&Bound<'py, PyAny>>,
    unit: Option<&Bound<'py, PyAny>>,
    mask: Option<&Bound<'py, PyAny>>,
) -> PyResult<PyHeightMap> {
    guarded(|| {
        let dx = spacing_um("dx_um", Some(dx_um))?
            .ok_or_else(|| PyValueError::new_err("dx_um: missing: give the array's pixel spacing in µm"))?;
        let dy = spacing_um("dy_um", dy_um)?.unwrap_or(dx);
        for (name, d) in [("dx_um", dx), ("dy_um", dy)] {
            check_spacing(ARRAY, name, d).map_err(to_py_err)?;
        }
        let map = from_array(py, array, dx, dy, height_unit(unit)?, mask)?;
        Ok(PyHeightMap { held: InMemory::register(map) })
    })
}

/// The inverse of `HeightMap.__reduce__`: heights and spacings in metres.
#[pyfunction]
pub(crate) fn _height_map_m<'py>(py: Python<'py>, z: &Bound<'py, PyAny>, dx: f64, dy: f64) -> PyResult<PyHeightMap> {
    guarded(|| {
        let map = from_array(py, z, dx, dy, 1.0, None)?;
        Ok(PyHeightMap { held: InMemory::register(map) })
    })
}

/// `json.dumps`'s `default` for a recipe: a [`PyHeightMap`] is written as its label (which the library finds
/// in `topography::memory`); a bare array is refused with the way to give its calibration; anything else as
/// `json.dumps` refuses it.
#[pyfunction]
pub(crate) fn json_default<'py>(py: Python<'py>, o: &Bound<'py, PyAny>) -> PyResult<String> {
    if let Ok(held) = o.cast::<PyHeightMap>() {
        return Ok(held.get().held.label().to_string());
    }
    if py.import("numpy")?.getattr("ndarray").and_then(|t| o.is_instance(&t))? {
        return Err(PyTypeError::new_err(
            "a NumPy array in a recipe carries no pixel spacing: give glossmeter.height_map(array, dx_um=…) \
             (a topography's `file`), or a list",
        ));
    }
    Err(PyTypeError::new_err(format!("Object of type {} is not JSON serializable", type_name(o))))
}
