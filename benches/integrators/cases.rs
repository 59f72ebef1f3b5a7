//! The cases B1–B4 and the one way every section runs the engine on a case: its designed method
//! (`problem`), with a rule forced (`forced`, `rule_rows`), and what actually ran (`rule_label`).
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::geometry::Stop;
use glossmeter::instrument::method::{Chart, Flux, Method, Rule};
use glossmeter::instrument::standards::{self, StandardGeometry};

use crate::report::{timed, Row};

/// The default measurement panel of `measure`.
pub(crate) const PANEL: &[&str] = glossmeter::DEFAULT_PANEL;

pub(crate) struct Case {
    pub(crate) id: &'static str,
    pub(crate) title: String,
    pub(crate) brdf: Arc<dyn Brdf>,
    pub(crate) geometry: StandardGeometry,
    pub(crate) theta: f64,
    pub(crate) source: Stop,
    pub(crate) receptor: Stop,
}

/// The recipe of each case (written by the `convergence` work; the same B1–B4).
pub(crate) fn recipe_of(id: &str) -> Option<&'static str> {
    match id {
        "B1" => Some("bench-b1-lambert.json"),
        "B2" => Some("bench-b2-beckmann-0.1.json"),
        "B3" => Some("bench-b3-beckmann-1e-4.json"),
        "B4" => Some("bench-b4-ggx-0.3.json"),
        _ => None,
    }
}

pub(crate) fn case(id: &'static str, title: &str, brdf: Arc<dyn Brdf>, geometry: &str) -> Case {
    let g = standards::find(geometry).expect("builtin geometry");
    let (theta, source, receptor) =
        (g.geometry.theta, g.geometry.source, *g.geometry.receptor("gloss").expect("gloss receptor"));
    Case { id, title: title.into(), brdf, geometry: g, theta, source, receptor }
}

/// The specimen flux of a case, as a method designed for its BRDF (executed with `solve`).
pub(crate) struct Problem<'a> {
    pub(crate) brdf: &'a dyn Brdf,
    pub(crate) method: Method,
}

impl Problem<'_> {
    pub(crate) fn solve(&self) -> Flux {
        self.method.execute(self.brdf)
    }
}

pub(crate) fn problem(c: &Case, rtol: f64) -> Problem<'_> {
    let b: &dyn Brdf = c.brdf.as_ref();
    let method =
        Method::for_material(b, c.theta, c.source, c.receptor, (rtol, 0.0), 200_000_000).expect("luminous weighting");
    Problem { brdf: b, method }
}

/// The specimen flux of a case with the regular part's rule replaced by `rule` (None: the planner's own).
pub(crate) fn forced(c: &Case, rtol: f64, rule: Option<Rule>) -> Problem<'_> {
    let mut p = problem(c, rtol);
    if let (Some(part), Some(rule)) = (p.method.regular.as_mut(), rule) {
        part.rule = rule;
    }
    p
}

/// What a run of `m` actually integrated, from its frozen method (an untimed run): the final rule and its
/// variables, so a forced shaped rule that fell back says so, and the tensor rule's mixed chart is not called
/// the lobe chart.
pub(crate) fn rule_label(m: &Method, brdf: &dyn Brdf) -> String {
    let (_, frozen) = m.execute_and_freeze(brdf);
    let Some(part) = frozen.regular.as_ref() else { return "no regular part".into() };
    let chart = match part.chart {
        glossmeter::instrument::aperture::Chart::Plain => "plain (p_s, q_s, p_r, q_r)",
        glossmeter::instrument::aperture::Chart::Lobe => "lobe (u, t_p, v, t_q)",
        glossmeter::instrument::aperture::Chart::PlainPLobeQ => "mixed (p_s, p_r, v, t_q)",
    };
    match part.rule {
        Rule::GenzMalik75 => {
            // Where the refinement went: the bisections per axis, summed over the final regions (each
            // region's log₂ of its initial box's half-width over its own).
            let initial = &m.regular.as_ref().expect("the same parts").cells;
            let mut cuts = [0.0f64; 4];
            for c in &part.cells {
                let inside = |b: &&glossmeter::quadrature::Cell<4>| {
                    (0..4).all(|k| (c.center[k] - b.center[k]).abs() <= b.half[k] * (1.0 + 1e-12))
                };
                if let Some(b) = initial.iter().find(inside) {
                    for (k, cut) in cuts.iter_mut().enumerate() {
                        *cut += (b.half[k] / c.half[k]).log2().round();
                    }
                }
            }
            format!(
                "Genz–Malik 7/5, {chart} chart, {} initial → {} final regions, bisections per axis {:?}",
                initial.len(),
                part.cells.len(),
                cuts.map(|x| x as usize)
            )
        }
        Rule::LobeGaussHermite { .. } => "Gauss–Hermite × Gauss–Legendre, lobe chart".into(),
        Rule::LobeDelta { .. } => "delta limit of the lobe, lobe chart".into(),
        Rule::LobePolar { .. } => "polar + tail boxes, lobe chart".into(),
        Rule::TailBound => "the material's tail bound (no evaluation)".into(),
        Rule::TensorGauss { chart, .. } => format!(
            "tensor Gauss–Legendre, {} chart",
            match chart {
                Chart::Plain => "plain (p_s, q_s, p_r, q_r)",
                Chart::Lobe => "lobe (u, t_p, v, t_q) kink-partition",
                Chart::PlainPLobeQ => "mixed (p_s, p_r, v, t_q)",
            }
        ),
    }
}

/// The rows of one case with each rule of `rules` forced on its regular part (None: the planner's choice),
/// side by side in one run (review D2: one helper for every case and section).
pub(crate) fn rule_rows(c: &Case, rtol: f64, rules: &[(&str, Option<Rule>)], reference: f64) -> Vec<Row> {
    let mut rows = Vec::new();
    for (label, rule) in rules {
        let p = forced(c, rtol, *rule);
        if rule.is_some() && p.method.regular.is_none() {
            continue;
        }
        let (f, secs, runs): (Flux, f64, usize) = timed(|| p.solve());
        rows.push(Row::of_flux(
            c.id,
            format!("{label}, rtol {rtol:.0e}"),
            &f,
            reference,
            secs,
            runs,
            format!("{}{}", rule_label(&p.method, p.brdf), if f.converged { "" } else { ", NOT converged" }),
        ));
    }
    rows
}

/// Whether `BENCH_CASES` (a comma-separated list; unset: everything) asks for the section `id`.
pub(crate) fn wants(id: &str) -> bool {
    std::env::var("BENCH_CASES").map_or(true, |l| l.split(',').any(|x| x.trim() == id))
}
