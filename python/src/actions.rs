//! The actions besides `measure` (docs/python.md §Actions): `read_sheet`, `compare`, `sweep`, `fit`, `profile`
//! and `convergence`. Each converts its keyword arguments into the library's typed request
//! (`glossmeter::request`) in one place, the request built at the top of its function (with
//! [`sheet_request`] for the sheet's keywords), as the command line converts its flags (`cli::*::request`)
//! and the server its JSON bodies; the request checks them with the library's messages,
//! which name each argument as its keyword ([`crate::args::keyword`]). Each returns the library's own document
//! (`glossmeter::report`), the one `glossmeter ACTION --format json` prints, as Python dicts and lists.
//!
//! Every call runs inside the panic boundary ([`guarded`]). The computations run without the GIL on a worker
//! thread ([`interruptible`]); the calling thread checks for signals meanwhile, so Ctrl-C raises
//! `KeyboardInterrupt`, and for sweep, fit, compare and profile it first raises the library's stop signal
//! ([`Cancel`], as the server does when a client goes away), so that the work stops at its next integral.
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

use glossmeter::comparison;
use glossmeter::comparison::sheet::{self, Sheet};
use glossmeter::fit::FitOptions;
use glossmeter::instrument::plan::{Cancel, PlanOptions};
use glossmeter::instrument::standards::{self as stds, StandardGeometry};
use glossmeter::request::{
    CompareRequest, ConvergenceRequest, FitRequest, PlanRequest, ProfileRequest, SheetRequest, SweepRequest,
    CONVERGENCE_GEOMETRIES, DEFAULT_K, PROFILE_GEOMETRY,
};
use glossmeter::{report, Error};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyDict, PyList, PyString};

use crate::args::{self, opt_count, opt_real, opt_string, strings};
use crate::{find_builtin, from_json, guarded, json_text, load_geometries, load_geometry, load_recipe, to_py_err};

/// How often the calling thread looks for a signal (Ctrl-C) while the work runs.
const POLL: Duration = Duration::from_millis(50);

/// Run `work` on a worker thread without the GIL, inside the panic boundary, while this (the calling) thread
/// checks for signals: on one (Ctrl-C: `KeyboardInterrupt`), raise `cancel`, wait for the work to stop and
/// raise the signal's exception instead of the work's result.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &Cancel,
    work: impl FnOnce() -> PyResult<T> + Send,
) -> PyResult<T> {
    let (tx, rx) = mpsc::channel();
    std::thread::scope(|scope| {
        scope.spawn(move || {
            let _ = tx.send(guarded(work));
        });
        let mut rx = rx;
        loop {
            // The receiver travels into the closure and back (a `&Receiver` may not leave the thread).
            let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
            rx = back;
            match got {
                Ok(out) => return out,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(interrupt) = py.check_signals() {
                        cancel.raise();
                        let _ = py.detach(move || rx.recv());
                        return Err(interrupt);
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err(
                        "internal error in glossmeter: the work ended without a result",
                    ))
                }
            }
        }
    })
}

/// Where a sheet comes from: a path (str or os.PathLike), or its bytes (bytes or bytearray, named `<bytes>`).
enum SheetSource {
    Path(PathBuf),
    Bytes(Vec<u8>),
}

fn sheet_source(py: Python<'_>, v: &Bound<'_, PyAny>, name: &str) -> PyResult<SheetSource> {
    if let Ok(b) = v.cast::<PyBytes>() {
        return Ok(SheetSource::Bytes(b.as_bytes().to_vec()));
    }
    if let Ok(b) = v.cast::<PyByteArray>() {
        return Ok(SheetSource::Bytes(b.to_vec()));
    }
    let path: Option<PathBuf> = if let Ok(s) = v.cast::<PyString>() {
        Some(PathBuf::from(&*s.to_cow()?))
    } else {
        py.import("os")?.call_method1("fspath", (v,)).ok().map(|p| p.extract()).transpose()?
    };
    match path {
        // `-` is a file of that name, as for open(): standard input is the command line's.
        Some(p) if glossmeter::input::is_stdin(&p) => Ok(SheetSource::Path(PathBuf::from(".").join(p))),
        Some(p) => Ok(SheetSource::Path(p)),
        None => Err(PyTypeError::new_err(format!(
            "{name}: expected the path of a sheet (str or os.PathLike: a CSV or an .xlsx/.xls/.ods workbook) or its \
             bytes, got {}",
            args::type_name(v)
        ))),
    }
}

impl SheetSource {
    /// The one sheet reader of every front end (`comparison::sheet::from_bytes`, through `load` for a file).
    fn read(&self, request: &SheetRequest) -> glossmeter::Result<Sheet> {
        let options = request.options()?;
        match self {
            SheetSource::Path(p) => sheet::load(p, &options),
            SheetSource::Bytes(b) => sheet::from_bytes(b, "<bytes>", &options),
        }
    }
}

/// The keywords of how a sheet is read: the sheet's request (the one place they become the library's).
fn sheet_request(
    delimiter: Option<&Bound<'_, PyAny>>,
    sheet_name: Option<&Bound<'_, PyAny>>,
    header_row: Option<&Bound<'_, PyAny>>,
    ignore_columns: Option<&Bound<'_, PyAny>>,
) -> PyResult<SheetRequest> {
    let header_row = opt_count("header_row", header_row, "the header's 1-based line or workbook row")?;
    if header_row == Some(0) {
        return Err(PyValueError::new_err(
            "header_row: expected a whole number ≥ 1 (the header's 1-based line or workbook row), got 0",
        ));
    }
    Ok(SheetRequest {
        delimiter: opt_string("delimiter", delimiter, "\",\", \";\" or \"tab\"")?,
        ignore_columns: strings("ignore_columns", ignore_columns, "headers of columns to skip")?,
        sheet_name: opt_string("sheet_name", sheet_name, "the sheet of a workbook")?,
        header_row: header_row.map(|n| n as usize),
    })
}

/// read_sheet(sheet, delimiter=None, sheet_name=None, header_row=None, ignore_columns=None) -> dict
///
/// Read an instrument sheet (a CSV, or an .xlsx/.xls/.ods workbook; a path or its bytes) as `glossmeter
/// compare` and `fit --sheet` read it: what the reader found out about the file and every value with its
/// line, column, sample, geometry and reading (`schema("sheet")`).
#[pyfunction]
#[pyo3(signature = (sheet, delimiter=None, sheet_name=None, header_row=None, ignore_columns=None))]
pub fn read_sheet<'py>(
    py: Python<'py>,
    sheet: &Bound<'py, PyAny>,
    delimiter: Option<&Bound<'py, PyAny>>,
    sheet_name: Option<&Bound<'py, PyAny>>,
    header_row: Option<&Bound<'py, PyAny>>,
    ignore_columns: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    guarded(|| {
        let request = sheet_request(delimiter, sheet_name, header_row, ignore_columns)?;
        let source = sheet_source(py, sheet, "sheet")?;
        let read = py.detach(|| source.read(&request)).map_err(to_py_err)?;
        from_json(py, &report::to_json(&report::compare::SheetReadDoc::new(&read)))
    })
}

/// `tolerance=`: a number (every reading), a str in the command line's grammar (`gloss=2`,
/// `astm-e430-30/doi=3`), a dict of such keys to numbers, or a list of numbers and strs: the request's
/// `tolerances`, as `--tolerance` gives them.
fn tolerances(v: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    const ALLOWED: &str = "a number for every reading, \"KEY=NUMBER\", a dict {KEY: NUMBER} (KEY a reading, \
                           \"gloss\", or GEOMETRY/READING, \"astm-e430-30/doi\"), or a list of these";
    let Some(v) = v.filter(|v| !v.is_none()) else { return Ok(vec![]) };
    let one = |name: &str, x: &Bound<'_, PyAny>| -> PyResult<String> {
        match x.cast::<PyString>() {
            Ok(s) => Ok(s.to_cow()?.into_owned()),
            Err(_) => Ok(args::real(name, x, ALLOWED)?.to_string()),
        }
    };
    if let Ok(d) = v.cast::<PyDict>() {
        let mut out = Vec::new();
        for (k, x) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("tolerance: a key is not a str ({ALLOWED}), got {}", args::type_name(&k)))
            })?;
            out.push(format!("{key}={}", args::real(&format!("tolerance[{key:?}]"), &x, ALLOWED)?));
        }
        return Ok(out);
    }
    if v.is_instance_of::<PyString>() || v.extract::<f64>().is_ok() {
        return Ok(vec![one("tolerance", v)?]);
    }
    let items = v
        .try_iter()
        .map_err(|_| PyTypeError::new_err(format!("tolerance: expected {ALLOWED}, got {}", args::type_name(v))))?;
    items.enumerate().map(|(i, x)| one(&format!("tolerance[{i}]"), &x?)).collect()
}

/// compare(recipe, sheet, tolerance=None, k=2.0, max_de00=None, rtol=None, illuminant=None, observer=None,
/// delimiter=None, sheet_name=None, header_row=None, ignore_columns=None, max_evals=None) -> dict
///
/// The recipe's predictions beside an instrument sheet (every sample of it), with the verdicts: the document
/// of `glossmeter compare RECIPE SHEET --format json`. Verdicts outside the allowance are in the document
/// (`summary`), not raised.
#[pyfunction]
#[pyo3(signature = (recipe, sheet, tolerance=None, k=None, max_de00=None, rtol=None, illuminant=None,
    observer=None, delimiter=None, sheet_name=None, header_row=None, ignore_columns=None, max_evals=None))]
#[allow(clippy::too_many_arguments)]
pub fn compare<'py>(
    py: Python<'py>,
    recipe: &Bound<'py, PyAny>,
    sheet: &Bound<'py, PyAny>,
    tolerance: Option<&Bound<'py, PyAny>>,
    k: Option<&Bound<'py, PyAny>>,
    max_de00: Option<&Bound<'py, PyAny>>,
    rtol: Option<&Bound<'py, PyAny>>,
    illuminant: Option<&Bound<'py, PyAny>>,
    observer: Option<&Bound<'py, PyAny>>,
    delimiter: Option<&Bound<'py, PyAny>>,
    sheet_name: Option<&Bound<'py, PyAny>>,
    header_row: Option<&Bound<'py, PyAny>>,
    ignore_columns: Option<&Bound<'py, PyAny>>,
    max_evals: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let request = guarded(|| {
        Ok(CompareRequest {
            k: opt_real("k", k, "standard errors of the mean allowed, ≥ 0")?.unwrap_or(DEFAULT_K),
            tolerance: None,
            tolerances: tolerances(tolerance)?,
            max_de00: opt_real("max_de00", max_de00, "the largest CIEDE2000 ΔE00, ≥ 0")?,
            plan: args::plan_request(rtol, max_evals, illuminant, observer)?,
            sheet: sheet_request(delimiter, sheet_name, header_row, ignore_columns)?,
        })
    })?;
    let cancel = Cancel::new(None);
    let (rule, max_de00, options) = guarded(|| {
        let rule = request.rule().map_err(to_py_err)?;
        let max_de00 = request.max_de00().map_err(to_py_err)?;
        let options = request.plan.options().map_err(to_py_err)?;
        Ok((rule, max_de00, PlanOptions { cancel: cancel.clone(), ..options }))
    })?;
    let source = guarded(|| sheet_source(py, sheet, "sheet"))?;
    let material = guarded(|| load_recipe(py, recipe))?;
    let out = interruptible(py, &cancel, || {
        let sheet = source.read(&request.sheet).map_err(to_py_err)?;
        let mut cmp = comparison::compare_sheet_with(&sheet, &material, &rule, &options).map_err(to_py_err)?;
        let des = comparison::colour_differences(&mut cmp, max_de00);
        Ok(report::to_json(&report::compare::json_doc(&sheet, &cmp, &rule, &[], None, &des)))
    })?;
    guarded(|| from_json(py, &out))
}

/// The template of a sweep: its text and the name messages give it (a path: the file; a dict: `<dict>`; a
/// JSON string: `<string>`), read as the command line reads the file.
fn template_text(py: Python<'_>, template: &Bound<'_, PyAny>) -> PyResult<(String, String)> {
    if let Ok(s) = template.cast::<PyString>() {
        let s = s.to_cow()?;
        if s.trim_start().starts_with('{') {
            return Ok((s.into_owned(), "<string>".into()));
        }
    } else if template.is_instance_of::<PyDict>() {
        return Ok((json_text(py, template)?, "<dict>".into()));
    }
    let path: PathBuf = match template.cast::<PyString>() {
        Ok(s) => PathBuf::from(&*s.to_cow()?),
        Err(_) => match py.import("os")?.call_method1("fspath", (template,)) {
            Ok(p) => p.extract()?,
            Err(_) => {
                return Err(PyTypeError::new_err(format!(
                    "template: expected a dict, a JSON string or a path (str or os.PathLike), got {}",
                    args::type_name(template)
                )))
            }
        },
    };
    let path = if glossmeter::input::is_stdin(&path) { PathBuf::from(".").join(path) } else { path };
    let text = glossmeter::input::read_text(&path, "recipe").map_err(to_py_err)?;
    Ok((text, path.display().to_string()))
}

/// `shard=`: None (the whole sweep), "K/M" or (K, M): the K-th of M contiguous slices.
fn shard(v: Option<&Bound<'_, PyAny>>) -> PyResult<(u64, u64)> {
    let Some(v) = v.filter(|v| !v.is_none()) else { return Ok((1, 1)) };
    let text = match v.cast::<PyString>() {
        Ok(s) => s.to_cow()?.into_owned(),
        Err(_) => match v.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>() {
            Ok((k, m)) => {
                let allowed = "the K-th of M slices, 1 ≤ K ≤ M";
                let k = opt_count("shard[0]", Some(&k), allowed)?.unwrap_or(0);
                let m = opt_count("shard[1]", Some(&m), allowed)?.unwrap_or(0);
                format!("{k}/{m}")
            }
            Err(_) => {
                return Err(PyTypeError::new_err(format!(
                    "shard: expected None, \"K/M\" or a tuple (K, M) (the K-th of M contiguous slices), got {}",
                    args::type_name(v)
                )))
            }
        },
    };
    glossmeter::sweep::parse_shard(&text).map_err(to_py_err)
}

/// sweep(template, vary, log=None, lhs=None, seed=0, geometries=None, shard=None, rtol=None, max_evals=None,
/// timing=True, illuminant=None, observer=None) -> list[dict]
///
/// A template recipe measured over a grid (`vary` "PATH=LO..HI:N", repeatable) or a Latin hypercube (`lhs`
/// N points, `vary` "PATH=LO..HI"): one dict per point, the lines of `glossmeter sweep --format jsonl`.
#[pyfunction]
#[pyo3(signature = (template, vary, log=None, lhs=None, seed=None, geometries=None, shard=None, rtol=None,
    max_evals=None, timing=None, illuminant=None, observer=None))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    template: &Bound<'py, PyAny>,
    vary: &Bound<'py, PyAny>,
    log: Option<&Bound<'py, PyAny>>,
    lhs: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    geometries: Option<&Bound<'py, PyAny>>,
    shard: Option<&Bound<'py, PyAny>>,
    rtol: Option<&Bound<'py, PyAny>>,
    max_evals: Option<&Bound<'py, PyAny>>,
    timing: Option<&Bound<'py, PyAny>>,
    illuminant: Option<&Bound<'py, PyAny>>,
    observer: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let grammar = "\"PATH=LO..HI:N\" (a grid) or \"PATH=LO..HI\" (with lhs), PATH a JSON Pointer";
    let request = guarded(|| {
        Ok(SweepRequest {
            vary: strings("vary", Some(vary), grammar)?,
            log: strings("log", log, "the vary paths whose values are spaced logarithmically")?,
            lhs: opt_count("lhs", lhs, "the points of a Latin hypercube")?,
            seed: opt_count("seed", seed, "the hypercube's seed")?.unwrap_or(0),
            plan: args::plan_request(rtol, max_evals, illuminant, observer)?,
        })
    })?;
    let timing = args::flag("timing", timing, true)?;
    // Every check that needs no file comes before any work, as on the command line.
    guarded(|| {
        request.plan.options().map_err(to_py_err)?;
        request.axes().map_err(to_py_err)
    })?;
    let (k, m) = guarded(|| self::shard(shard))?;
    let (text, file) = guarded(|| template_text(py, template))?;
    let geos = guarded(|| load_geometries(py, geometries))?;
    let cancel = Cancel::new(None);
    let mut s = guarded(|| request.sweep(&text, &file, geos).map_err(to_py_err))?;
    s.options.cancel = cancel.clone();
    let lines = interruptible(py, &cancel, || {
        let mut lines = Vec::new();
        s.run(s.shard(k, m), |r| {
            // A raised signal ends the run at the end of the chunk (its remaining integrals skipped).
            if cancel.is_stopped() {
                return Err(Error::Usage("interrupted".into()));
            }
            lines.push(report::to_json(&s.line_doc(&r, timing)));
            Ok(())
        })
        .map_err(to_py_err)?;
        Ok(lines)
    })?;
    guarded(|| {
        let out = PyList::empty(py);
        for l in &lines {
            out.append(from_json(py, l)?)?;
        }
        Ok(out)
    })
}

/// `free=`: "PATH=LO..HI" or "PATH=log:LO..HI" strs, or a dict {PATH: (LO, HI)} (or {PATH: "log:LO..HI"}).
fn free_parameters(v: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    const ALLOWED: &str = "\"PATH=LO..HI\" or \"PATH=log:LO..HI\", PATH a JSON Pointer; or a dict {PATH: (LO, HI)}";
    let Ok(d) = v.cast::<PyDict>() else { return strings("free", Some(v), ALLOWED) };
    let mut out = Vec::new();
    for (k, x) in d.iter() {
        let path: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!("free: a key is not a str ({ALLOWED}), got {}", args::type_name(&k)))
        })?;
        let name = format!("free[{path:?}]");
        let bounds = match x.cast::<PyString>() {
            Ok(s) => s.to_cow()?.into_owned(),
            Err(_) => {
                let b = args::reals(&name, &x, "(LO, HI)")?;
                match b.as_slice() {
                    [lo, hi] => format!("{lo}..{hi}"),
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "{name}: expected two numbers (LO, HI), got {}",
                            b.len()
                        )))
                    }
                }
            }
        };
        out.push(format!("{path}={bounds}"));
    }
    Ok(out)
}

/// `targets=`: "GEOMETRY/READING=VALUE[±U]" strs, or a dict {"GEOMETRY/READING": VALUE or (VALUE, U)}.
fn target_readings(v: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    const ALLOWED: &str = "\"GEOMETRY/READING=VALUE[±U]\", or a dict {\"GEOMETRY/READING\": VALUE or (VALUE, U)}";
    let Some(v) = v.filter(|v| !v.is_none()) else { return Ok(vec![]) };
    let Ok(d) = v.cast::<PyDict>() else { return strings("targets", Some(v), ALLOWED) };
    let mut out = Vec::new();
    for (k, x) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!("targets: a key is not a str ({ALLOWED}), got {}", args::type_name(&k)))
        })?;
        let name = format!("targets[{key:?}]");
        if let Ok(value) = args::real(&name, &x, ALLOWED) {
            out.push(format!("{key}={value}"));
            continue;
        }
        match args::reals(&name, &x, ALLOWED)?.as_slice() {
            [value, u] => out.push(format!("{key}={value}±{u}")),
            b => {
                return Err(PyValueError::new_err(format!(
                    "{name}: expected VALUE or (VALUE, U), got {} numbers",
                    b.len()
                )))
            }
        }
    }
    Ok(out)
}

/// fit(recipe, targets=None, free=..., sheet=None, sample=None, uncertainty=0.2, restarts=2, rtol=None,
/// geometries=None, timing=True, delimiter=None, sheet_name=None, header_row=None, ignore_columns=None,
/// max_evals=None, illuminant=None, observer=None) -> dict
///
/// Recipe parameters from readings: the `free` parameters fitted to `targets` or to a `sheet`'s `sample`;
/// the document of `glossmeter fit --format json`. `rtol` None is the library's default relative tolerance
/// (`DEFAULT_RTOL`, the one `glossmeter fit --rtol` defaults to); `max_evals`, `illuminant` and `observer` are
/// `measure`'s (the budget of each aperture integral of every forward run, the conditions of colour targets). A fit not to be trusted is said in the document
/// (`reproduces`, `identifiable`, `verdict`), not raised; a fit that cannot run raises RuntimeError.
#[pyfunction]
#[pyo3(signature = (recipe, targets=None, *, free, sheet=None, sample=None, uncertainty=None, restarts=None,
    rtol=None, geometries=None, timing=None, delimiter=None, sheet_name=None, header_row=None,
    ignore_columns=None, max_evals=None, illuminant=None, observer=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    recipe: &Bound<'py, PyAny>,
    targets: Option<&Bound<'py, PyAny>>,
    free: &Bound<'py, PyAny>,
    sheet: Option<&Bound<'py, PyAny>>,
    sample: Option<&Bound<'py, PyAny>>,
    uncertainty: Option<&Bound<'py, PyAny>>,
    restarts: Option<&Bound<'py, PyAny>>,
    rtol: Option<&Bound<'py, PyAny>>,
    geometries: Option<&Bound<'py, PyAny>>,
    timing: Option<&Bound<'py, PyAny>>,
    delimiter: Option<&Bound<'py, PyAny>>,
    sheet_name: Option<&Bound<'py, PyAny>>,
    header_row: Option<&Bound<'py, PyAny>>,
    ignore_columns: Option<&Bound<'py, PyAny>>,
    max_evals: Option<&Bound<'py, PyAny>>,
    illuminant: Option<&Bound<'py, PyAny>>,
    observer: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = FitRequest::default();
    let request = guarded(|| {
        Ok(FitRequest {
            free: free_parameters(free)?,
            targets: target_readings(targets)?,
            uncertainty: opt_real("uncertainty", uncertainty, "the uncertainty of a target given without one, > 0")?
                .unwrap_or(d.uncertainty),
            restarts: opt_count("restarts", restarts, "solver restarts of an exactly determined fit")?
                .map_or(d.restarts, |n| n as usize),
            plan: args::plan_request(rtol, max_evals, illuminant, observer)?,
            sheet: sheet_request(delimiter, sheet_name, header_row, ignore_columns)?,
            sample: opt_string("sample", sample, "the sample of the sheet to fit")?,
        })
    })?;
    let timing = args::flag("timing", timing, true)?;
    let sheet = sheet.filter(|s| !s.is_none());
    if sheet.is_some() && !request.targets.is_empty() {
        return Err(PyValueError::new_err("targets and sheet: give the target readings or a sheet, not both"));
    }
    let cancel = Cancel::new(None);
    let options = guarded(|| request.options().map_err(to_py_err))?;
    let free = guarded(|| request.free().map_err(to_py_err))?;
    let source = guarded(|| sheet.map(|s| sheet_source(py, s, "sheet")).transpose())?;
    let user: Vec<StandardGeometry> = match geometries.filter(|g| !g.is_none()) {
        None => vec![],
        Some(g) => guarded(|| load_geometries(py, Some(g)))?,
    };
    let material = guarded(|| load_recipe(py, recipe))?;
    let options = FitOptions { geometries: user, cancel: cancel.clone(), ..options };
    let out = interruptible(py, &cancel, || {
        let sheet = source.as_ref().map(|s| s.read(&request.sheet)).transpose().map_err(to_py_err)?;
        let (targets, _notes) = request.targets(sheet.as_ref()).map_err(to_py_err)?;
        let report =
            glossmeter::fit::fit(&material.json, &material.file, &free, &targets, &options).map_err(to_py_err)?;
        Ok(report::fit::json(&report, timing))
    })?;
    guarded(|| from_json(py, &out))
}

/// profile(recipe, geometry=None, rtol=None, max_evals=None, max_total_evals=None) -> dict
///
/// The goniophotometric profile of a recipe on a geometry with a profile array (None: rspec-20, the
/// 512-pixel array of a Rhopoint IQ-class meter): the document of `glossmeter profile --format json`.
#[pyfunction]
#[pyo3(signature = (recipe, geometry=None, rtol=None, max_evals=None, max_total_evals=None))]
pub fn profile<'py>(
    py: Python<'py>,
    recipe: &Bound<'py, PyAny>,
    geometry: Option<&Bound<'py, PyAny>>,
    rtol: Option<&Bound<'py, PyAny>>,
    max_evals: Option<&Bound<'py, PyAny>>,
    max_total_evals: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = ProfileRequest::default();
    let request = guarded(|| {
        Ok(ProfileRequest {
            plan: PlanRequest {
                rtol: opt_real("rtol", rtol, "the relative tolerance of the integrals, in (0, 1), e.g. 1e-6")?,
                ..PlanRequest::default()
            },
            max_evals: opt_count("max_evals", max_evals, "the evaluation budget of each part of a pixel's integral")?
                .map_or(d.max_evals, |n| n as usize),
            max_total_evals: opt_count("max_total_evals", max_total_evals, "the evaluation budget of the profile")?
                .map_or(d.max_total_evals, |n| n as usize),
        })
    })?;
    let cancel = Cancel::new(None);
    let (options, budget) = guarded(|| request.options().map_err(to_py_err))?;
    let options = PlanOptions { cancel: cancel.clone(), ..options };
    let g = guarded(|| match geometry.filter(|g| !g.is_none()) {
        None => find_builtin(PROFILE_GEOMETRY),
        Some(g) => load_geometry(py, g, "geometry"),
    })?;
    // Checked before any work: the geometry must have a profile array.
    guarded(|| stds::profile::of(&g).map(|_| ()).map_err(to_py_err))?;
    let material = guarded(|| load_recipe(py, recipe))?;
    let out = interruptible(py, &cancel, || {
        let prof =
            glossmeter::instrument::profile::measure(material.brdf.clone(), &g, options, budget).map_err(to_py_err)?;
        Ok(report::to_json(&report::profile::ProfileDoc::new(&material, &prof)))
    })?;
    guarded(|| from_json(py, &out))
}

/// convergence(recipe, geometries=None, tolerances=None, min_time_ms=20.0, max_repetitions=50,
/// reference_run=False, illuminant=None, observer=None) -> dict
///
/// Value, estimated error, actual error, evaluations and time of every reading over a sweep of tolerances
/// (None: 1e-2 … 1e-10), on `geometries` (None: astm-d523-20, -60, -85): the document of `glossmeter
/// convergence --format json`. Ctrl-C is seen, but the sweep runs to its end first (it has no stop signal).
#[pyfunction]
#[pyo3(signature = (recipe, geometries=None, tolerances=None, min_time_ms=None, max_repetitions=None,
    reference_run=None, illuminant=None, observer=None))]
#[allow(clippy::too_many_arguments)]
pub fn convergence<'py>(
    py: Python<'py>,
    recipe: &Bound<'py, PyAny>,
    geometries: Option<&Bound<'py, PyAny>>,
    tolerances: Option<&Bound<'py, PyAny>>,
    min_time_ms: Option<&Bound<'py, PyAny>>,
    max_repetitions: Option<&Bound<'py, PyAny>>,
    reference_run: Option<&Bound<'py, PyAny>>,
    illuminant: Option<&Bound<'py, PyAny>>,
    observer: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = ConvergenceRequest::default();
    let request = guarded(|| {
        // The colour conditions through the one conversion of a plan's keywords.
        let colour = args::plan_request(None, None, illuminant, observer)?;
        Ok(ConvergenceRequest {
            tolerances: match tolerances.filter(|t| !t.is_none()) {
                None => vec![],
                Some(t) => args::reals("tolerances", t, "relative tolerances, each in (0, 1)")?,
            },
            min_time_ms: opt_real("min_time_ms", min_time_ms, "milliseconds, ≥ 0")?.unwrap_or(d.min_time_ms),
            max_repetitions: opt_count("max_repetitions", max_repetitions, "timed executions per tolerance, ≥ 1")?
                .map_or(d.max_repetitions, |n| n as usize),
            reference_run: args::flag("reference_run", reference_run, false)?,
            illuminant: colour.illuminant,
            observer: colour.observer,
        })
    })?;
    let (tolerances, options) = guarded(|| request.options().map_err(to_py_err))?;
    let geos = guarded(|| match geometries.filter(|g| !g.is_none()) {
        None => CONVERGENCE_GEOMETRIES.iter().map(|id| find_builtin(id)).collect(),
        Some(g) => load_geometries(py, Some(g)),
    })?;
    let material = guarded(|| load_recipe(py, recipe))?;
    let out = interruptible(py, &Cancel::default(), || {
        let sweep = glossmeter::instrument::convergence::sweep(material.brdf.clone(), geos, &tolerances, &options)
            .map_err(to_py_err)?;
        Ok(report::to_json(&report::convergence::ConvergenceDoc::new(&material, &sweep)))
    })?;
    guarded(|| from_json(py, &out))
}

/// Register the actions in the module.
pub fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_sheet, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(profile, m)?)?;
    m.add_function(wrap_pyfunction!(convergence, m)?)?;
    Ok(())
}
