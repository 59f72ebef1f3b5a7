//! The server's API (docs/serve.md §The API): one function per endpoint, synchronous (the server runs it on its
//! blocking pool), JSON in and the command line's documents out, written by the same code (`crate::report`,
//! the pictures of `report::pictures`, the JUnit of `report::junit`). A request is one JSON
//! object: the recipe (the JSON of a recipe file, under `recipe`) and the options, named as the command
//! line's flags are (`rtol`, `geometries`, `vary`, `free`, `target`, `k`, `tolerance`, …). The recipe's text
//! is read as sent, as `measure` reads a file, so that a reading is the same bits as `measure`'s.
use std::borrow::Cow;
use std::path::Path;

use serde_json::{json, Value};

use super::security::{table_path, Limits};
use crate::colorimetry::{Conditions, Illuminant, Observer};
use crate::comparison;
use crate::comparison::sheet::{self, Sheet};
use crate::fit::{self, FitOptions};
use crate::input::json::{kind, parse_json, Obj};
use crate::instrument::plan::{Cancel, Plan, PlanOptions, DEFAULT_RTOL, MIN_RTOL};
use crate::instrument::standards::{self, StandardGeometry};
use crate::recipe::{self, Material};
use crate::registry::{self, Type};
use crate::request::{
    CompareRequest, FitRequest, PlanRequest, ProfileRequest, SheetRequest, Spacing, SweepRequest, VsParameterRequest,
    DEFAULT_K, PLOT_GEOMETRIES,
};
use crate::sweep::Sweep;
use crate::{report, Error, Result};

/// How a request body is named in messages.
pub(crate) const REQUEST: &str = "request";
/// How the request's recipe is named in messages (and in the documents' `material.file`).
pub(crate) const RECIPE: &str = "recipe";

/// What every endpoint knows of the server.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Context<'a> {
    pub limits: &'a Limits,
    /// Where recipes may name table files (None: nowhere).
    pub data_dir: Option<&'a Path>,
    /// The request's stop signal (its client gone, its time limit passed), handed to every plan it runs.
    pub cancel: &'a Cancel,
}

/// An answer: its media type and its body.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Reply {
    pub content_type: &'static str,
    pub body: String,
}

impl Reply {
    fn json(doc: &Value) -> Reply {
        Reply { content_type: "application/json", body: report::pretty(doc) }
    }
}

/// A request: its JSON object, and the text of its `recipe` member as sent.
pub(crate) struct Request {
    pub value: Value,
    pub recipe: Option<String>,
}

impl Request {
    /// Parse a body (UTF-8 JSON, an object; a key given twice is refused, as in recipe files).
    pub fn parse(bytes: &[u8]) -> Result<Request> {
        let text = std::str::from_utf8(bytes).map_err(|e| Error::input(REQUEST, "", format!("not UTF-8 text: {e}")))?;
        let value = parse_json(text, REQUEST)?;
        Obj::new(REQUEST, "", &value)?;
        #[derive(serde::Deserialize)]
        struct Raw<'a> {
            #[serde(borrow)]
            recipe: Option<&'a serde_json::value::RawValue>,
        }
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let raw: Raw =
            serde_json::from_str(text).map_err(|e| Error::input(REQUEST, "/recipe", format!("cannot be read: {e}")))?;
        Ok(Request { value, recipe: raw.recipe.map(|r| r.get().to_string()) })
    }

    fn obj(&self) -> Obj<'_> {
        Obj::new(REQUEST, "", &self.value).expect("checked by parse")
    }
}

/// The recipe's text with every table path (a registry entry `…/file` of the recipe's model) replaced by
/// the file it names in the data directory ([`table_path`]); the text as sent when it names none.
fn with_tables<'t>(text: &'t str, ctx: Context) -> Result<Cow<'t, str>> {
    let mut v = parse_json(text, RECIPE)?;
    let Some(model) = v.get("model").and_then(Value::as_str).map(str::to_string) else {
        return Ok(Cow::Borrowed(text));
    };
    let mut changed = false;
    for p in registry::PARAMS.iter().filter(|p| p.applies_to(&model) && p.ty == Type::Text && p.key() == "file") {
        let Some(Value::String(given)) = v.pointer(p.pointer) else { continue };
        let found = table_path(ctx.data_dir, given, RECIPE, p.pointer)?;
        let found = found
            .to_str()
            .ok_or_else(|| Error::input(RECIPE, p.pointer, "the table's path in the data directory is not UTF-8"))?
            .to_string();
        *v.pointer_mut(p.pointer).expect("found above") = Value::String(found);
        changed = true;
    }
    Ok(if changed { Cow::Owned(v.to_string()) } else { Cow::Borrowed(text) })
}

fn recipe_text<'r>(req: &'r Request, ctx: Context) -> Result<Cow<'r, str>> {
    let text = req.recipe.as_deref().ok_or_else(|| {
        Error::input(REQUEST, "/recipe", "missing required field: the recipe, a JSON object (see `glossmeter schema`)")
    })?;
    with_tables(text, ctx)
}

/// The request's recipe, validated.
fn material(req: &Request, ctx: Context) -> Result<Material> {
    recipe::parse_str(&recipe_text(req, ctx)?, RECIPE)
}

fn strings(o: &Obj, key: &str) -> Result<Vec<String>> {
    match o.get(key) {
        None => Ok(vec![]),
        Some(_) => o
            .array(key)?
            .iter()
            .enumerate()
            .map(|(i, v)| {
                v.as_str().map(str::to_string).ok_or_else(|| {
                    Error::input(REQUEST, o.element(key, i), format!("expected a string, got {}", kind(v)))
                })
            })
            .collect(),
    }
}

fn whole(o: &Obj, key: &str, lo: usize, hi: usize, what: &str) -> Result<Option<usize>> {
    o.opt_num(key, lo as f64, hi as f64, what)?
        .map(|x| {
            if x.fract() == 0.0 {
                Ok(x as usize)
            } else {
                Err(o.err(key, format!("{x} is not a whole number ({what})")))
            }
        })
        .transpose()
}

/// `geometries`: shipped ids (at most `limits.geometries`; files are not read), else `default`.
fn geometries(o: &Obj, ctx: Context, default: &[&str]) -> Result<Vec<StandardGeometry>> {
    let ids = strings(o, "geometries")?;
    if ids.len() > ctx.limits.geometries {
        return Err(o.err(
            "geometries",
            format!("{} geometries; this server takes at most {}", ids.len(), ctx.limits.geometries),
        ));
    }
    crate::resolve_geometries_or(&ids, &[] as &[&str], default)
        .map_err(|e| o.err("geometries", e.naming(&|a| format!("`{a}`"))))
}

/// An error of a request that names an argument first (`` `rtol` must be … ``) as the field of the body it
/// came from (`request: field `/rtol`: must be …`); any other error as it is.
fn at_field(o: &Obj, e: Error) -> Error {
    match e {
        Error::Argument(words) => match words.leading_argument() {
            Some((name, rest)) => {
                o.err(name, rest.naming(&|a| format!("`{a}`")).trim_start_matches(':').trim_start().to_string())
            }
            None => Error::Argument(words),
        },
        e => e,
    }
}

/// The body's `rtol`, `max_evals` (at most the server's, which is also the default), `illuminant` and
/// `observer`: the plan's request (the one place where the server's JSON becomes the library's), each field
/// checked here and refused under its own name, so that a request built from it is already valid.
fn plan_request(o: &Obj, ctx: Context) -> Result<PlanRequest> {
    let rtol = match o.get("rtol") {
        None => None,
        Some(v) => {
            let x = v.as_f64().ok_or_else(|| o.err("rtol", format!("expected a number, got {}", kind(v))))?;
            // The server's own floor, below the library's (docs/serve.md §Limits).
            if x.is_finite() && x > 0.0 && x < MIN_RTOL {
                return Err(o.err(
                    "rtol",
                    format!(
                        "{} is below {MIN_RTOL:e}, the tightest relative tolerance this server computes to",
                        crate::error::given(x)
                    ),
                ));
            }
            Some(x)
        }
    };
    let max_evals = whole(o, "max_evals", 1, ctx.limits.max_evals, "evaluations per aperture integral")?
        .unwrap_or(ctx.limits.max_evals);
    let request = PlanRequest {
        rtol,
        max_evals: Some(max_evals),
        illuminant: o.opt_str("illuminant")?.map(str::to_owned),
        observer: o.opt_str("observer")?.map(str::to_owned),
    };
    if let Some(i) = &request.illuminant {
        Illuminant::parse(i).map_err(|e| o.err("illuminant", e.to_string()))?;
    }
    if let Some(x) = &request.observer {
        Observer::parse(x).map_err(|e| o.err("observer", e.to_string()))?;
    }
    // The tolerance's own range (the library's), whatever default a command gives it.
    request.options_or(DEFAULT_RTOL).map_err(|e| at_field(o, e))?;
    Ok(request)
}

/// The plan's options of the body ([`plan_request`]), `default_rtol` without a tolerance.
fn plan_options(o: &Obj, ctx: Context, default_rtol: f64) -> Result<PlanOptions> {
    let options = plan_request(o, ctx)?.options_or(default_rtol).map_err(|e| at_field(o, e))?;
    Ok(PlanOptions { cancel: ctx.cancel.clone(), ..options })
}

fn timing(o: &Obj) -> Result<bool> {
    flag(o, "timing")
}

/// A true/false field, false when absent.
fn flag(o: &Obj, key: &str) -> Result<bool> {
    match o.get(key) {
        None => Ok(false),
        Some(Value::Bool(b)) => Ok(*b),
        Some(v) => Err(o.err(key, format!("expected true or false, got {}", kind(v)))),
    }
}

const MEASURE_FIELDS: &[&str] =
    &["recipe", "geometries", "rtol", "max_evals", "illuminant", "observer", "timing", "omit_refused_colour"];

/// With `omit_refused_colour`: the colour geometries among `geos` that the library refuses for this material
/// (its samples define no X, Y, Z: an RGB recipe, docs/colour.md) are taken out, and the refusal is kept,
/// `{"geometries": [ids], "message": the library's message}`, for the document's `refused`.
fn omit_refused_colour(
    material: &Material,
    geos: Vec<StandardGeometry>,
    options: &PlanOptions,
) -> (Vec<StandardGeometry>, Option<Value>) {
    let Err(e) = crate::colorimetry::weights(material.brdf.sampling(), options.colour) else { return (geos, None) };
    let (colour, rest): (Vec<_>, Vec<_>) = geos.into_iter().partition(|g| g.geometry.is_colour());
    if colour.is_empty() {
        return (rest, None);
    }
    let ids: Vec<&str> = colour.iter().map(|g| g.geometry.id.as_str()).collect();
    let message = format!("{}: {}", ids.join(", "), e.naming(&|a| format!("`{a}`")));
    (rest, Some(json!({"geometries": ids, "message": message})))
}

/// A profile request on this server: the command line's budget, each part held to the server's per-integral
/// limit and the whole profile to ten times it (docs/serve.md §Safety).
fn profile_request(o: &Obj, ctx: Context) -> Result<ProfileRequest> {
    let d = ProfileRequest::default();
    Ok(ProfileRequest {
        plan: plan_request(o, ctx)?,
        max_evals: d.max_evals.min(ctx.limits.max_evals),
        max_total_evals: d.max_total_evals.min(ctx.limits.max_evals.saturating_mul(10)),
    })
}

/// `POST /api/measure`: the document of `glossmeter measure --format json` (with `--no-timing` unless
/// `timing` is true) for the recipe through `geometries` (default: the default panel).
pub(crate) fn measure(req: &Request, ctx: Context) -> Result<Reply> {
    let o = req.obj();
    o.deny_unknown(MEASURE_FIELDS)?;
    let options = plan_options(&o, ctx, DEFAULT_RTOL)?;
    let geos = geometries(&o, ctx, crate::api::DEFAULT_PANEL)?;
    let timing = timing(&o)?;
    let omit = flag(&o, "omit_refused_colour")?;
    let material = material(req, ctx)?;
    let (geos, refused) = if omit { omit_refused_colour(&material, geos, &options) } else { (geos, None) };
    let mut doc = if geos.is_empty() {
        // Every geometry asked for was a refused colour one: no reading, the refusal says why.
        report::to_json(&report::measure::json_doc(&material, &[], timing, 0))
    } else {
        let plan = Plan::compile(material.brdf.clone(), geos, options)?;
        let run = plan.run();
        let evaluations = run.evaluations();
        // The recipe's stated uncertainties propagated to each reading (nothing is run without them).
        let uncertainties =
            crate::comparison::propagation::propagate(&material, &plan.geometries, &plan.options, &run.readings)?;
        let doc =
            report::measure::json_doc(&material, &run.readings, timing, evaluations).with_uncertainties(&uncertainties);
        report::to_json(&doc)
    };
    if let Some(r) = refused {
        doc["refused"] = r;
    }
    Ok(Reply::json(&doc))
}

/// `POST /api/explain`: the measurement plan of `measure --explain`, as text in `{"plan": …}`.
pub(crate) fn explain(req: &Request, ctx: Context) -> Result<Reply> {
    let o = req.obj();
    o.deny_unknown(MEASURE_FIELDS)?;
    let options = plan_options(&o, ctx, DEFAULT_RTOL)?;
    let geos = geometries(&o, ctx, crate::api::DEFAULT_PANEL)?;
    let material = material(req, ctx)?;
    let plan = Plan::compile(material.brdf.clone(), geos, options)?;
    Ok(Reply::json(&json!({
        "material": {"name": material.name, "model": material.brdf.describe()},
        "plan": plan.explain(),
    })))
}

/// `POST /api/plot`: an SVG picture drawn by the library's pictures (`report::pictures`, the same drawing as
/// the command line's): `kind` `section` (the in-plane BRDF
/// section with the apertures, `plot --kind section`), `profile` (the goniophotometric profile of
/// `geometry`, default rspec-20, `profile --plot`) or `gloss-vs-parameter` (`vary` PATH=LO..HI over `points`
/// values, `plot --kind gloss-vs-parameter`).
pub(crate) fn plot(req: &Request, ctx: Context) -> Result<Reply> {
    let o = req.obj();
    o.deny_unknown(&[
        "recipe",
        "kind",
        "geometries",
        "geometry",
        "vary",
        "points",
        "spacing",
        "rtol",
        "max_evals",
        "illuminant",
        "observer",
    ])?;
    let kind = o.str("kind")?;
    let svg = match kind {
        "section" => {
            let geos = geometries(&o, ctx, PLOT_GEOMETRIES)?;
            crate::report::pictures::charts::section_svg(&material(req, ctx)?, &geos)?
        }
        "profile" => {
            let (options, budget) = profile_request(&o, ctx)?.options().map_err(|e| at_field(&o, e))?;
            let options = PlanOptions { cancel: ctx.cancel.clone(), ..options };
            let id = o.opt_str("geometry")?.unwrap_or(crate::request::PROFILE_GEOMETRY);
            let g = standards::find(id).map_err(|e| o.err("geometry", e.to_string()))?;
            standards::profile::of(&g).map_err(|e| o.err("geometry", e.to_string()))?;
            let m = material(req, ctx)?;
            let prof = crate::instrument::profile::measure(m.brdf.clone(), &g, options, budget)?;
            crate::report::pictures::profile::svg(&prof, &format!("{}: {} profile", m.name, prof.geometry))?
        }
        "gloss-vs-parameter" => {
            let request = VsParameterRequest {
                vary: Some(o.str("vary")?.to_owned()),
                points: whole(&o, "points", 2, ctx.limits.plot_points, "values of the varied number")?,
                spacing: match o.opt_str("spacing")? {
                    None | Some("auto") => Spacing::Auto,
                    Some("linear") => Spacing::Linear,
                    Some("log") => Spacing::Log,
                    Some(other) => {
                        return Err(o.err(
                            "spacing",
                            format!("unknown spacing {other:?}; allowed: \"auto\", \"linear\", \"log\""),
                        ))
                    }
                },
                plan: plan_request(&o, ctx)?,
            };
            let geos = geometries(&o, ctx, PLOT_GEOMETRIES)?;
            let text = recipe_text(req, ctx)?;
            let v = request.read_until(&text, RECIPE, geos, ctx.cancel.clone()).map_err(|e| at_field(&o, e))?;
            crate::report::pictures::charts::vs_parameter_svg(&v.name, &v.label, v.log, &v.series)?
        }
        other => {
            return Err(o.err(
                "kind",
                format!("unknown kind {other:?}; allowed: \"section\", \"profile\", \"gloss-vs-parameter\""),
            ))
        }
    };
    Ok(Reply { content_type: "image/svg+xml", body: svg })
}

/// `POST /api/sweep`, checked before any work: the sweep of `glossmeter sweep --format jsonl --no-timing`
/// (`vary` PATH=LO..HI:N strings, `log` paths, `lhs` N and `seed`), at most `limits.sweep_points` points.
pub(crate) fn sweep(req: &Request, ctx: Context) -> Result<Sweep> {
    let o = req.obj();
    o.deny_unknown(&[
        "recipe",
        "vary",
        "log",
        "lhs",
        "seed",
        "geometries",
        "rtol",
        "max_evals",
        "illuminant",
        "observer",
    ])?;
    let geos = geometries(&o, ctx, crate::api::DEFAULT_PANEL)?;
    let request = SweepRequest {
        vary: strings(&o, "vary")?,
        log: strings(&o, "log")?,
        lhs: whole(&o, "lhs", 1, ctx.limits.sweep_points as usize, "points of the Latin hypercube")?.map(|n| n as u64),
        seed: whole(&o, "seed", 0, usize::MAX, "seed")?.unwrap_or(0) as u64,
        plan: plan_request(&o, ctx)?,
    };
    request.axes().map_err(|e| at_field(&o, e))?;
    let s = request.sweep_until(&recipe_text(req, ctx)?, RECIPE, geos, ctx.cancel.clone())?;
    if s.len() > ctx.limits.sweep_points {
        return Err(o.err(
            "vary",
            format!("{} points; this server sweeps at most {} in one request", s.len(), ctx.limits.sweep_points),
        ));
    }
    Ok(s)
}

/// Run a checked sweep, handing each JSON line (a row of `sweep --format jsonl --no-timing`) to `line` in
/// index order, a few points at a time (so that the page can show progress).
pub(crate) fn run_sweep(s: &Sweep, mut line: impl FnMut(String) -> Result<()>) -> Result<()> {
    let step = rayon::current_num_threads().max(1) as u64;
    let mut start = 0;
    while start < s.len() {
        let end = (start + step).min(s.len());
        s.run(start..end, |r| line(s.jsonl_row(&r, false)))?;
        start = end;
    }
    Ok(())
}

/// The body's `delimiter`, `ignore_columns`, `sheet_name` and `header_row`: how the sheet is read, as
/// `compare --delimiter --ignore-column --sheet-name --header-row` say it (docs/serve.md §The API).
fn sheet_request(o: &Obj) -> Result<SheetRequest> {
    Ok(SheetRequest {
        delimiter: o.opt_str("delimiter")?.map(str::to_owned),
        ignore_columns: strings(o, "ignore_columns")?,
        sheet_name: o.opt_str("sheet_name")?.map(str::to_owned),
        header_row: whole(o, "header_row", 1, 1_000_000, "the header's 1-based row")?,
    })
}

/// The fields of a body that say how its sheet is read ([`sheet_request`]).
const SHEET_FIELDS: &[&str] = &["sheet", "delimiter", "ignore_columns", "sheet_name", "header_row"];

/// The sheet of a request: `{"name": …, "base64": …}` (any file `compare` reads) or `{"name": …, "text": …}`,
/// read by the same code as `compare`'s files (`comparison::sheet::from_bytes`: text or workbook) with the
/// request's options; `name` names it in messages and nothing is written to disk.
fn sheet(o: &Obj, request: &SheetRequest) -> Result<Sheet> {
    let s = o.obj("sheet")?;
    s.deny_unknown(&["name", "base64", "text"])?;
    let name: String = s.opt_str("name")?.unwrap_or("sheet.csv").chars().take(200).collect();
    let bytes = match (s.opt_str("base64")?, s.opt_str("text")?) {
        (Some(b), None) => {
            use base64::Engine;
            base64::engine::general_purpose::STANDARD
                .decode(b.trim())
                .map_err(|e| s.err("base64", format!("not base64: {e}")))?
        }
        (None, Some(t)) => t.as_bytes().to_vec(),
        _ => return Err(s.err("text", "give the sheet as `base64` (its bytes) or as `text`, one of the two")),
    };
    let options = request.options().map_err(|e| at_field(o, e))?;
    sheet::from_bytes(&bytes, &name, &options)
}

/// The body's `tolerance` as `compare --tolerance` takes it (docs/serve.md §The API): a number for every
/// reading; an array of `[KEY=]NUMBER` strings, one per `--tolerance`; or an object `{KEY: NUMBER}`. Each
/// entry is checked by the command line's parser ([`comparison::parse_tolerance`]) and a refusal names its
/// element (`/tolerance/1`, `/tolerance/gloss`). The plain number and the entries, for [`CompareRequest`].
fn tolerances(o: &Obj) -> Result<(Option<f64>, Vec<String>)> {
    let entry = |pointer: String, text: String| -> Result<String> {
        comparison::parse_tolerance(&text).map_err(|e| match e {
            Error::Argument(words) => {
                let why = match words.leading_argument() {
                    Some((_, rest)) => rest.naming(&|a| format!("`{a}`")),
                    None => words.naming(&|a| format!("`{a}`")),
                };
                Error::input(REQUEST, pointer, why.trim_start().to_string())
            }
            e => e,
        })?;
        Ok(text)
    };
    match o.get("tolerance") {
        None => Ok((None, vec![])),
        Some(Value::Number(_)) => Ok((o.opt_num("tolerance", 0.0, f64::INFINITY, "tolerance")?, vec![])),
        Some(Value::Array(a)) => {
            let texts = a
                .iter()
                .enumerate()
                .map(|(i, v)| match v.as_str() {
                    Some(t) => entry(o.element("tolerance", i), t.to_string()),
                    None => Err(Error::input(
                        REQUEST,
                        o.element("tolerance", i),
                        format!("expected a string `[KEY=]NUMBER` (`gloss=2`), got {}", kind(v)),
                    )),
                })
                .collect::<Result<Vec<_>>>()?;
            Ok((None, texts))
        }
        Some(Value::Object(m)) => {
            let at = |key: &str| registry::child(&o.field("tolerance"), key);
            let texts = m
                .iter()
                .map(|(key, v)| match v {
                    Value::Number(n) => entry(at(key), format!("{key}={n}")),
                    v => Err(Error::input(REQUEST, at(key), format!("expected a number, got {}", kind(v)))),
                })
                .collect::<Result<Vec<_>>>()?;
            Ok((None, texts))
        }
        Some(v) => Err(o.err(
            "tolerance",
            format!(
                "expected a number, an array of `[KEY=]NUMBER` strings or an object {{KEY: NUMBER}}, got {}",
                kind(v)
            ),
        )),
    }
}

/// `POST /api/compare`: the sheet beside the recipe's predictions (the one recipe for every sample), as
/// `compare --format json|csv|junit` writes them (`format`, default json); verdicts are in the document, the
/// HTTP status is 200 whatever they are.
pub(crate) fn compare(req: &Request, ctx: Context) -> Result<Reply> {
    let o = req.obj();
    let fields = ["recipe", "k", "tolerance", "max_de00", "rtol", "max_evals", "illuminant", "observer", "format"];
    o.deny_unknown(&[&fields[..], SHEET_FIELDS].concat())?;
    let (tolerance, tolerances) = tolerances(&o)?;
    let request = CompareRequest {
        k: o.opt_num("k", 0.0, f64::INFINITY, "k")?.unwrap_or(DEFAULT_K),
        tolerance,
        tolerances,
        max_de00: o.opt_num("max_de00", 0.0, f64::INFINITY, "largest ΔE00")?,
        plan: plan_request(&o, ctx)?,
        sheet: sheet_request(&o)?,
    };
    let rule = request.rule().map_err(|e| at_field(&o, e))?;
    let max_de00 = request.max_de00().map_err(|e| at_field(&o, e))?;
    let options = request.plan.options_or(DEFAULT_RTOL).map_err(|e| at_field(&o, e))?;
    let options = PlanOptions { cancel: ctx.cancel.clone(), ..options };
    let format = o.opt_str("format")?.unwrap_or("json");
    if !["json", "csv", "junit"].contains(&format) {
        return Err(o.err("format", format!("unknown format {format:?}; allowed: \"json\", \"csv\", \"junit\"")));
    }
    let sheet = sheet(&o, &request.sheet)?;
    let ids = sheet.geometry_ids();
    if ids.len() > ctx.limits.geometries {
        return Err(
            o.err("sheet", format!("{} geometries; this server takes at most {}", ids.len(), ctx.limits.geometries))
        );
    }
    let material = material(req, ctx)?;
    let mut cmp = comparison::compare_sheet_with(&sheet, &material, &rule, &options)?;
    let des = comparison::colour_differences(&mut cmp, max_de00);
    Ok(match format {
        "csv" => Reply { content_type: "text/csv; charset=utf-8", body: report::compare::csv(&cmp)? },
        "junit" => Reply { content_type: "application/xml", body: crate::report::junit::compare(&sheet, &cmp, &[])? },
        _ => Reply::json(&report::to_json(&report::compare::json_doc(&sheet, &cmp, &rule, &[], None, &des))),
    })
}

/// `POST /api/fit`: `glossmeter fit --format json --no-timing`: `free` parameters (PATH=LO..HI or
/// PATH=log:LO..HI) fitted to `target` readings (GEOMETRY/READING=VALUE[±U]) or to a `sheet`'s `sample`.
pub(crate) fn fit(req: &Request, ctx: Context) -> Result<Reply> {
    let o = req.obj();
    let fields = [
        "recipe",
        "free",
        "target",
        "sample",
        "uncertainty",
        "restarts",
        "rtol",
        "max_evals",
        "illuminant",
        "observer",
    ];
    o.deny_unknown(&[&fields[..], SHEET_FIELDS].concat())?;
    let l = ctx.limits;
    let request = FitRequest {
        free: strings(&o, "free")?,
        targets: strings(&o, "target")?,
        uncertainty: o
            .opt_num("uncertainty", f64::MIN_POSITIVE, f64::INFINITY, "uncertainty")?
            .unwrap_or(fit::DEFAULT_UNCERTAINTY),
        restarts: whole(&o, "restarts", 0, l.fit_restarts, "restarts")?
            .unwrap_or(fit::DEFAULT_RESTARTS.min(l.fit_restarts)),
        plan: plan_request(&o, ctx)?,
        sheet: sheet_request(&o)?,
        sample: o.opt_str("sample")?.map(str::to_owned),
    };
    let options = request.options().map_err(|e| at_field(&o, e))?;
    let free = request.free()?;
    if free.len() > l.fit_free {
        return Err(o.err("free", format!("{} free parameters; this server fits at most {}", free.len(), l.fit_free)));
    }
    if o.get("sheet").is_none() {
        // As `fit --sheet-name` without `--sheet` is refused: options of no sheet.
        if let Some(k) = SHEET_FIELDS[1..].iter().find(|k| o.get(k).is_some()) {
            return Err(o.err(k, "says how a sheet is read, but the request has no `sheet`"));
        }
    }
    let sheet = match o.get("sheet") {
        Some(_) if o.get("target").is_some() => {
            return Err(o.err("target", "give `target` readings or a `sheet`, not both"))
        }
        Some(_) => Some(sheet(&o, &request.sheet)?),
        None => None,
    };
    let targets = request.targets(sheet.as_ref())?.0;
    if targets.len() > l.fit_targets {
        return Err(o.err("target", format!("{} targets; this server fits at most {}", targets.len(), l.fit_targets)));
    }
    let options = FitOptions { max_iterations: l.fit_iterations, cancel: ctx.cancel.clone(), ..options };
    let material = material(req, ctx)?;
    let report = fit::fit(&material.json, &material.file, &free, &targets, &options)?;
    Ok(Reply::json(&report::fit::json(&report, false)))
}

/// `GET /api/registry`: every recipe parameter (JSON Pointer, models, type, unit, range, default, meaning)
/// and the models, from which the page builds its editor.
pub(crate) fn registry_doc() -> Reply {
    let params: Vec<Value> = registry::PARAMS
        .iter()
        .map(|p| {
            json!({
                "pointer": p.pointer,
                "models": p.models,
                "type": p.ty.describe(),
                "numeric": p.ty.is_numeric(),
                "number": p.ty == Type::Number,
                "choices": match p.ty { Type::Choice(c) => json!(c), _ => Value::Null },
                "unit": p.unit,
                "range": p.range.map(|r| json!({
                    "lo": finite(r.lo), "hi": finite(r.hi), "lo_closed": r.lo_closed, "hi_closed": r.hi_closed,
                    "text": r.describe_short(),
                })),
                "default": match p.presence { registry::Presence::Required => Value::Null, registry::Presence::Default(d) => json!(d) },
                "required": p.presence == registry::Presence::Required,
                "description": p.description,
            })
        })
        .collect();
    Reply::json(&json!({"models": registry::MODELS, "parameters": params, "colour_conditions": colour_conditions()}))
}

/// The illuminants and observers a colour reading can be computed under, by the names the requests take
/// (`illuminant`, `observer`), and the default pair: the page's choice is built from these.
fn colour_conditions() -> Value {
    let default = Conditions::default();
    json!({
        "illuminants": Illuminant::ALL.map(|i| json!({"id": i.id(), "title": i.describe()})),
        "observers": Observer::ALL.map(|x| json!({"id": x.id(), "title": x.describe()})),
        "default": {"illuminant": default.illuminant.id(), "observer": default.observer.id()},
    })
}

fn finite(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// `GET /api/geometries`: the shipped geometries (id, the instrument's title and standards as the geometry
/// file names them, the line of `glossmeter standards`, whether it is in the default panel, whether it has a
/// profile array, and every number of the file whose status is `assumed`, with its JSON Pointer and reason).
pub(crate) fn geometries_doc() -> Result<Reply> {
    let all = standards::builtin_all()?;
    let list: Vec<Value> = all
        .iter()
        .map(|g| {
            let mut assumed = Vec::new();
            assumed_numbers(&g.spec, &mut String::new(), &mut assumed);
            json!({
                "id": g.geometry.id,
                "title": g.spec.get("title").and_then(Value::as_str).unwrap_or(&g.geometry.id),
                "standards": g.spec.get("standards").cloned().unwrap_or_else(|| json!([])),
                "line": standards::list_line_any(g),
                "default": crate::api::DEFAULT_PANEL.contains(&g.geometry.id.as_str()),
                "profile": standards::profile::of(g).is_ok(),
                "colour": g.geometry.is_colour(),
                "assumed": assumed,
            })
        })
        .collect();
    Ok(Reply::json(&json!({"geometries": list})))
}

/// The models whose recipe names a table file (`/file`), with the file name endings each reads.
pub(crate) const TABLE_MODELS: &[(&str, &[&str])] = &[
    ("merl", &[".binary"]),
    ("rgl", &[".bsdf"]),
    ("inplane-csv", &[".csv"]),
    ("e1392", &[".txt"]),
    ("topography", &[".x3p", ".sdf", ".gsf", ".sur"]),
];

/// `GET /api/tables`: the table files a recipe may name on this server, per model (docs/serve.md §The page:
/// switching to a table model fills `/file` with the first): every file of the data directory (four folders
/// deep at most, 200 files at most, in path order) whose name ends as the model's tables do, named by its path
/// relative to the directory, each resolved as a recipe's path is ([`table_path`]: a link out of the
/// directory is not listed). Without `--data-dir`, `"data_dir": false` and no files.
pub(crate) fn tables_doc(data_dir: Option<&Path>) -> Reply {
    let mut found: Vec<String> = Vec::new();
    if let Some(root) = data_dir {
        walk_tables(root, root, 0, &mut found);
    }
    found.sort();
    found.truncate(200);
    let models: Vec<Value> = TABLE_MODELS
        .iter()
        .map(|(model, ends)| {
            let files: Vec<&String> = found.iter().filter(|f| ends.iter().any(|e| f.ends_with(e))).collect();
            json!({"model": model, "extensions": ends, "files": files})
        })
        .collect();
    Reply::json(&json!({"data_dir": data_dir.is_some(), "models": models}))
}

fn walk_tables(root: &Path, dir: &Path, depth: usize, out: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries.into_iter().take(1000) {
        let Ok(rel) = p.strip_prefix(root) else { continue };
        let Some(rel) = rel.to_str().map(str::to_string) else { continue };
        if p.is_dir() {
            if depth < 3 {
                walk_tables(root, &p, depth + 1, out);
            }
        } else if TABLE_MODELS.iter().any(|(_, ends)| ends.iter().any(|e| rel.ends_with(e)))
            && table_path(Some(root), &rel, RECIPE, "/file").is_ok()
        {
            out.push(rel);
        }
        if out.len() >= 1000 {
            return;
        }
    }
}

/// The sourced numbers of a geometry file (`{"value", "source", "status"}`) whose
/// status is `assumed` (docs/instrument.md §2.1 Sourced numbers): `{pointer, value, source}` in document order.
fn assumed_numbers(v: &Value, at: &mut String, out: &mut Vec<Value>) {
    let len = at.len();
    match v {
        Value::Object(o) => {
            if o.get("status").and_then(Value::as_str) == Some("assumed") {
                if let Some(x) = o.get("value").filter(|x| x.is_number()) {
                    out.push(json!({"pointer": at.clone(), "value": x, "source": o.get("source")}));
                }
            }
            for (k, x) in o {
                at.push('/');
                at.push_str(&k.replace('~', "~0").replace('/', "~1"));
                assumed_numbers(x, at, out);
                at.truncate(len);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                at.push('/');
                at.push_str(&i.to_string());
                assumed_numbers(x, at, out);
                at.truncate(len);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recipe_text_is_kept_as_sent() {
        let r = Request::parse(br#"{"recipe": {"model": "lambert", "albedo": 0.1000000000000000055511151231257827}}"#)
            .unwrap();
        assert_eq!(
            r.recipe.as_deref(),
            Some(r#"{"model": "lambert", "albedo": 0.1000000000000000055511151231257827}"#)
        );
        assert!(Request::parse(b"[1]").is_err());
        assert!(Request::parse(br#"{"a": 1, "a": 2}"#).is_err());
    }

    #[test]
    fn a_table_needs_the_data_directory() {
        let l = Limits::default();
        let ctx = Context { limits: &l, data_dir: None, cancel: &Cancel::default() };
        // A measured topography's file is a table path like any other (registry `…/file` entries).
        for body in [
            &br#"{"recipe": {"model": "merl", "file": "x.binary"}}"#[..],
            br#"{"recipe": {"model": "topography", "file": "panel.x3p", "ior": 1.5}}"#,
        ] {
            let r = Request::parse(body).unwrap();
            let e = measure(&r, ctx).unwrap_err().to_string();
            assert!(e.contains("--data-dir"), "{e}");
        }
    }
}
