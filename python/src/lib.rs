//! Python bindings of glossmeter: a thin layer over the library, like the CLI.
//!
//! Why it exists: rendering and appearance engineers work in Python (Mitsuba, NumPy, notebooks) and want to
//! read *their* BRDF, a Python function, through the instrument apertures; paint designers want to spread
//! sweeps over a Dask cluster. Everything that computes lives in the library; this crate converts arguments,
//! turns library errors into Python exceptions (the CLI's messages, `ValueError` for bad input), catches
//! panics at the boundary, and adapts a Python callable to the `Brdf` trait ([`pybrdf`]). See `docs/python.md`.
#![forbid(unsafe_code)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use glossmeter::comparison::propagation::propagate;
use glossmeter::instrument::plan::{PlanOptions, Reading};
use glossmeter::instrument::standards::{self as stds, StandardGeometry};
use glossmeter::recipe::{self, Material};
use glossmeter::{report, Error};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyFloat, PyList, PyString, PyTuple};

mod actions;
mod args;
mod probe;
mod pybrdf;
mod topography;

/// A library error as the Python exception a caller expects, with the message the CLI prints after
/// "error: " (an argument it names as its keyword, `` `vary` ``, where the CLI writes `--vary`: [`args::keyword`]). Bad
/// input and bad requests are `ValueError`; files that cannot be read are `OSError` (`FileNotFoundError` when
/// missing); a computation without a finite result is `RuntimeError`.
pub(crate) fn to_py_err(e: Error) -> PyErr {
    // An argument the message gives a value to, as the keyword to pass: `give illuminant="A"`.
    let msg = e.naming_settings(&args::keyword, &|a, v| format!("{a}={v:?}"));
    match &e {
        Error::Input { .. } | Error::Usage(_) | Error::Argument(_) => PyValueError::new_err(msg),
        Error::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(msg),
        Error::Io { .. } => PyOSError::new_err(msg),
        Error::Numeric(_) | Error::Check(_) => PyRuntimeError::new_err(msg),
    }
}

/// Run `f` and turn a panic into a `RuntimeError` instead of unwinding into Python.
pub(crate) fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            Err(PyRuntimeError::new_err(format!(
                "internal error in glossmeter (a bug; please report it with the input): {what}"
            )))
        }
    }
}

/// A Python object as JSON text: a `str` as is, anything else through `json.dumps`. A float that is not
/// finite (NaN, ±inf) anywhere inside is refused with its place as a JSON Pointer: JSON has no such number,
/// and `json.dumps` would write `NaN`, which the reader then calls malformed JSON at a column.
pub(crate) fn json_text(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(s.to_cow()?.into_owned());
    }
    if let Some((at, x)) = non_finite_at(obj, String::new(), 0) {
        return Err(PyValueError::new_err(format!(
            "<dict>: field `{at}`: `{x}` is not a finite number (JSON has no NaN or infinity); give a finite number"
        )));
    }
    let json = py.import("json")?;
    let kwargs = PyDict::new(py);
    kwargs.set_item("default", wrap_pyfunction!(topography::json_default, py)?)?;
    json.call_method("dumps", (obj,), Some(&kwargs))?.extract()
}

/// The JSON Pointer of the first float that is not finite inside `obj` (through dicts, lists and tuples, to a
/// depth of 128, as deep as the recipe reader reads), and its value.
fn non_finite_at(obj: &Bound<'_, PyAny>, at: String, depth: usize) -> Option<(String, f64)> {
    if depth > 128 {
        return None;
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        let x = f.value();
        return (!x.is_finite()).then_some((at, x));
    }
    let inside = |key: String, v: Bound<'_, PyAny>| {
        let key = key.replace('~', "~0").replace('/', "~1");
        non_finite_at(&v, format!("{at}/{key}"), depth + 1)
    };
    if let Ok(d) = obj.cast::<PyDict>() {
        return d.iter().find_map(|(k, v)| inside(k.str().map(|s| s.to_string()).unwrap_or_default(), v));
    }
    if let Ok(l) = obj.cast::<PyList>() {
        return l.iter().enumerate().find_map(|(i, v)| inside(i.to_string(), v));
    }
    if let Ok(t) = obj.cast::<PyTuple>() {
        return t.iter().enumerate().find_map(|(i, v)| inside(i.to_string(), v));
    }
    None
}

/// A JSON value as the Python objects `json.loads` makes of its text, built directly: null → None, a boolean →
/// bool, an integer → int, any other number → float (the same double: serde_json writes the shortest decimal
/// that reads back to it), a string → str, an array → list, an object → dict with the keys in the value's
/// order (the order of its text).
pub(crate) fn from_json<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.into_pyobject(py)?.into_any(),
            (None, Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, None, Some(f)) => f.into_pyobject(py)?.into_any(),
            (None, None, None) => return Err(PyRuntimeError::new_err(format!("a JSON number out of range: {n}"))),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for x in items {
                list.append(from_json(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(fields) => {
            let dict = PyDict::new(py);
            for (k, x) in fields {
                dict.set_item(k, from_json(py, x)?)?;
            }
            dict.into_any()
        }
    })
}

/// A recipe given as a dict, a JSON string or a path (str or os.PathLike).
pub(crate) fn load_recipe(py: Python<'_>, recipe: &Bound<'_, PyAny>) -> PyResult<Material> {
    if let Ok(s) = recipe.cast::<PyString>() {
        let s = s.to_cow()?;
        let t = s.trim_start();
        if t.starts_with('{') {
            return recipe::parse_str(&s, "<string>").map_err(to_py_err);
        }
        return recipe::load_file(std::path::Path::new(&*s)).map_err(to_py_err);
    }
    if recipe.is_instance_of::<PyDict>() {
        let text = json_text(py, recipe)?;
        return recipe::parse_str(&text, "<dict>").map_err(to_py_err);
    }
    let os = py.import("os")?;
    match os.call_method1("fspath", (recipe,)) {
        Ok(p) => {
            let p: PathBuf = p.extract()?;
            recipe::load_file(&p).map_err(to_py_err)
        }
        Err(_) => Err(PyTypeError::new_err(format!(
            "recipe: expected a dict, a JSON string or a path (str or os.PathLike), got {}",
            args::type_name(recipe)
        ))),
    }
}

/// The builtin geometries, parsed and validated once per process (the library parses them on every lookup,
/// which costs more than measuring a simple recipe).
fn builtin() -> PyResult<&'static [StandardGeometry]> {
    static BUILTIN: OnceLock<Vec<StandardGeometry>> = OnceLock::new();
    if let Some(b) = BUILTIN.get() {
        return Ok(b);
    }
    let all = stds::builtin().map_err(to_py_err)?;
    Ok(BUILTIN.get_or_init(|| all))
}

/// A builtin geometry by id, with the library's message for an unknown one.
pub(crate) fn find_builtin(id: &str) -> PyResult<StandardGeometry> {
    match builtin()?.iter().find(|g| g.geometry.id == id) {
        Some(g) => Ok(g.clone()),
        None => stds::find(id).map_err(to_py_err),
    }
}

/// One geometry: a builtin id, a path to a geometry file (str ending in ".json" or os.PathLike), or a dict in
/// the standards format. `name` is how a refusal names the argument (`id`, `geometries`, `geometries[2]`).
pub(crate) fn load_geometry(py: Python<'_>, g: &Bound<'_, PyAny>, name: &str) -> PyResult<StandardGeometry> {
    if let Ok(s) = g.cast::<PyString>() {
        let s = s.to_cow()?;
        if s.ends_with(".json") || s.contains(std::path::MAIN_SEPARATOR) {
            return stds::load_file(std::path::Path::new(&*s)).map_err(to_py_err);
        }
        return find_builtin(&s);
    }
    if g.is_instance_of::<PyDict>() {
        let text = json_text(py, g)?;
        return stds::parse(&text, "<dict>").map_err(to_py_err);
    }
    let os = py.import("os")?;
    match os.call_method1("fspath", (g,)) {
        Ok(p) => {
            let p: PathBuf = p.extract()?;
            stds::load_file(&p).map_err(to_py_err)
        }
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name}: expected a geometry id (str, e.g. \"astm-d523-60\"), the path of a geometry file (str ending \
             in .json, or os.PathLike) or a geometry dict, got {}",
            args::type_name(g)
        ))),
    }
}

/// `None` → the CLI's default panel; a str → one geometry; a list → each in order.
pub(crate) fn load_geometries(
    py: Python<'_>,
    geometries: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<StandardGeometry>> {
    match geometries {
        None => glossmeter::api::DEFAULT_PANEL.iter().map(|id| find_builtin(id)).collect(),
        Some(g) if g.is_none() => load_geometries(py, None),
        Some(g) if g.is_instance_of::<PyString>() || g.is_instance_of::<PyDict>() => {
            Ok(vec![load_geometry(py, g, "geometries")?])
        }
        Some(g) => {
            let items = match g.try_iter() {
                Ok(items) => items,
                // os.PathLike: one geometry file.
                Err(_) if g.hasattr("__fspath__")? => return Ok(vec![load_geometry(py, g, "geometries")?]),
                Err(_) => {
                    return Err(PyTypeError::new_err(format!(
                        "geometries: expected None (the default panel), a geometry id, a path, a geometry dict, or a \
                         list of these, got {}",
                        args::type_name(g)
                    )))
                }
            };
            let mut out = Vec::new();
            for (i, item) in items.enumerate() {
                out.push(load_geometry(py, &item?, &format!("geometries[{i}]"))?);
            }
            if out.is_empty() {
                return Err(PyValueError::new_err("geometries: an empty list; give None for the default panel"));
            }
            Ok(out)
        }
    }
}

/// The readings as the list of dicts of `measure --format json` (each built from the library's reading object,
/// `report::reading_json`, which that output writes, so the fields cannot drift apart).
pub(crate) fn readings_to_py<'py>(py: Python<'py>, readings: &[Reading], timing: bool) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for r in readings {
        list.append(from_json(py, &report::reading_json(r, timing))?)?;
    }
    Ok(list)
}

/// Compile and run the plan without holding the GIL (the BRDF of `measure_brdf` takes it back per batch).
/// `one_thread`: run the integrals on one thread, for a BRDF that calls Python: every evaluation takes the
/// GIL, so several threads only hand it back and forth (measured ≈ 30× slower per call on 2 cores). The
/// readings are the same bits whatever the thread count.
pub(crate) fn run_plan(
    py: Python<'_>,
    brdf: Arc<dyn glossmeter::brdf::Brdf>,
    geos: Vec<StandardGeometry>,
    options: PlanOptions,
    one_thread: bool,
) -> PyResult<Vec<Reading>> {
    let run = move || {
        guarded(|| {
            let material = Material {
                name: String::new(),
                file: String::new(),
                brdf,
                json: serde_json::Value::Null,
                uncertainty: vec![],
            };
            glossmeter::api::measure(&material, &geos, &options).map_err(to_py_err)
        })
    };
    py.detach(|| {
        if one_thread {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .map_err(|e| PyRuntimeError::new_err(format!("cannot start the integration thread: {e}")))?;
            pool.install(run)
        } else {
            run()
        }
    })
}

/// measure(recipe, geometries=None, rtol=None, timing=True, *, max_evals=None, max_seconds=None,
/// illuminant=None, observer=None) -> list[dict]
///
/// Read a recipe (a dict, a JSON string or a path) through instrument geometries (None: the default panel of
/// `glossmeter measure`; or a list of builtin ids, geometry files or geometry dicts). Returns one dict per
/// reading with the fields of `glossmeter measure --format json`. Bad input raises ValueError with the
/// message the CLI prints; a reading without a finite value has value None and a "problem".
#[pyfunction]
#[pyo3(signature = (recipe, geometries=None, rtol=None, timing=None, *, max_evals=None, max_seconds=None,
    illuminant=None, observer=None))]
#[pyo3(text_signature = "(recipe, geometries=None, rtol=None, timing=True, *, max_evals=None, max_seconds=None, \
    illuminant=None, observer=None)")]
#[allow(clippy::too_many_arguments)]
fn measure<'py>(
    py: Python<'py>,
    recipe: &Bound<'py, PyAny>,
    geometries: Option<&Bound<'py, PyAny>>,
    rtol: Option<&Bound<'py, PyAny>>,
    timing: Option<&Bound<'py, PyAny>>,
    max_evals: Option<&Bound<'py, PyAny>>,
    max_seconds: Option<&Bound<'py, PyAny>>,
    illuminant: Option<&Bound<'py, PyAny>>,
    observer: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let request = args::measure_request(rtol, max_evals, max_seconds, illuminant, observer)?;
    let options = guarded(|| request.options().map_err(to_py_err))?;
    let timing = args::flag("timing", timing, true)?;
    let material = guarded(|| load_recipe(py, recipe))?;
    let geos = guarded(|| load_geometries(py, geometries))?;
    let readings = run_plan(py, material.brdf.clone(), geos.clone(), options.clone(), false)?;
    // The recipe's stated uncertainties propagated to each reading, as `measure --format json` gives them
    // (docs/instrument.md §The prediction's uncertainty; nothing is run without an `uncertainty` block).
    let uncertainties =
        py.detach(|| guarded(|| propagate(&material, &geos, &options, &readings).map_err(to_py_err)))?;
    guarded(|| {
        let list = PyList::empty(py);
        for (i, r) in readings.iter().enumerate() {
            let doc =
                report::ReadingDoc::new(r, timing).with_uncertainty(uncertainties.get(i).and_then(Option::as_ref));
            list.append(from_json(py, &report::to_json(&doc))?)?;
        }
        Ok(list)
    })
}

/// standards() -> list[dict]: every shipped geometry, as in `standards/*.json` (with the provenance of
/// every number).
#[pyfunction]
fn standards(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    guarded(|| {
        let out = PyList::empty(py);
        for g in builtin()? {
            out.append(from_json(py, &g.spec)?)?;
        }
        Ok(out)
    })
}

/// geometry(id) -> dict: one geometry (a builtin id, a geometry file's path, or a dict to validate), in the
/// standards format.
#[pyfunction]
fn geometry<'py>(py: Python<'py>, id: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    guarded(|| {
        let g = load_geometry(py, id, "id")?;
        from_json(py, &g.spec)
    })
}

/// describe_geometry(id) -> str: the text of `glossmeter standards ID`.
#[pyfunction]
fn describe_geometry(py: Python<'_>, id: &Bound<'_, PyAny>) -> PyResult<String> {
    guarded(|| Ok(stds::describe(&load_geometry(py, id, "id")?)))
}

/// schema(output_format=None) -> dict: the JSON Schema of the recipe format (`glossmeter schema`), or of an
/// output, "measure", "compare", "sweep", "fit", "profile" or "convergence" (`glossmeter schema
/// --output-format …`), or of a sheet as `read_sheet` reads it, "sheet".
#[pyfunction]
#[pyo3(signature = (output_format=None))]
fn schema<'py>(py: Python<'py>, output_format: Option<&str>) -> PyResult<Bound<'py, PyAny>> {
    guarded(|| {
        let schema = match output_format {
            None => recipe::schema::schema(),
            Some("measure") => report::schema::measure(),
            Some("compare") => report::schema::compare(),
            Some("sweep") => report::schema::sweep(),
            Some("fit") => report::schema::fit(),
            Some("profile") => report::schema::profile(),
            Some("convergence") => report::schema::convergence(),
            Some("sheet") => report::schema::sheet(),
            Some(other) => {
                return Err(PyValueError::new_err(format!(
                    "output_format: unknown output {other:?}; allowed: \"measure\", \"compare\", \"sweep\", \"fit\", \
                     \"profile\", \"convergence\", \"sheet\""
                )))
            }
        };
        from_json(py, &schema)
    })
}

/// _cli(argv) -> int: the command line on `argv` (`argv[0]` the program's name), with the server as
/// `glossmeter serve` (`glossmeter::cli::run_with` and `glossmeter::serve::run_command`, what the binary's
/// `main` runs); returns its exit status. The wheel's console command `glossmeter` calls it
/// (`glossmeter/_cli.py`), so a pip user runs every command, `serve` included, without Rust.
#[pyfunction]
fn _cli(py: Python<'_>, argv: Vec<String>) -> i32 {
    py.detach(|| glossmeter::cli::run_with(argv, &glossmeter::serve::run_command))
}

/// describe(recipe) -> str: the one-line description of the model a recipe builds.
#[pyfunction]
fn describe<'py>(py: Python<'py>, recipe: &Bound<'py, PyAny>) -> PyResult<String> {
    guarded(|| Ok(load_recipe(py, recipe)?.brdf.describe()))
}

/// _panic(): raise a Rust panic inside the boundary (for the test that panics become RuntimeError).
#[pyfunction]
fn _panic() -> PyResult<()> {
    guarded(|| -> PyResult<()> { panic!("deliberate panic for the bindings' test") })
}

#[pymodule]
fn _glossmeter(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    m.add_function(wrap_pyfunction!(standards, m)?)?;
    m.add_function(wrap_pyfunction!(geometry, m)?)?;
    m.add_function(wrap_pyfunction!(describe_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(schema, m)?)?;
    m.add_function(wrap_pyfunction!(describe, m)?)?;
    m.add_function(wrap_pyfunction!(_cli, m)?)?;
    m.add_function(wrap_pyfunction!(_panic, m)?)?;
    m.add_function(wrap_pyfunction!(pybrdf::measure_brdf, m)?)?;
    m.add_function(wrap_pyfunction!(topography::topography, m)?)?;
    m.add_function(wrap_pyfunction!(topography::height_map, m)?)?;
    m.add_function(wrap_pyfunction!(topography::_height_map_m, m)?)?;
    m.add_class::<topography::PyHeightMap>()?;
    actions::add(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_GEOMETRIES", glossmeter::api::DEFAULT_PANEL.to_vec())?;
    Ok(())
}
