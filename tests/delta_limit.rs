//! The delta limit of a narrow Gaussian-tailed lobe (`Rule::LobeDelta`): its reported error
//! (the majorant of `docs/instrument.md` §Quadrature, "The delta limit of a narrow lobe") is never below its
//! actual error, bounded by the difference from the lobe's own Gauss–Hermite rule run to rtol 1e-12 … 1e-10
//! (the partition at rtol 1e-10 where it tops out) plus that reference's own estimate,
//! on Beckmann (dielectric and conductor), Phong and Ward lobes of 1e-4 … 1e-7 on every receptor of ASTM D523
//! 20/60/85°, E430 20/30° and ISO 13803 where the lobe rule applies; the delta reading converges to that reference as m → 0; the planner chooses it only where the lobe is far from
//! the kinks, never for GGX or a measured table, and never over a diffuse body.
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::method::{
    delta_fit, delta_stencil, DeltaFit, Method, Rule, DELTA_FIT_RADIUS, DELTA_RADII, DELTA_SAFETY, DELTA_TAIL_SAFETY,
    DELTA_T_ORDERS, LOBE_LEVELS,
};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards;
use glossmeter::quadrature::legendre_on;

const GEOMETRIES: [&str; 6] =
    ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-20", "astm-e430-30", "iso-13803-20"];

fn parse(text: &str) -> Arc<dyn Brdf> {
    glossmeter::recipe::parse_str(text, "<delta>").unwrap().brdf
}

fn beckmann(m: f64, ior: &str) -> Arc<dyn Brdf> {
    parse(&format!(r#"{{"model":"microfacet","distribution":"beckmann","roughness":{m:e},"ior":{ior}}}"#))
}

/// The regular part's (value, error, evaluations, rule) of one receptor's method with its rule replaced by
/// `rule` (None: the planner's), at relative tolerance `rtol`.
fn run(brdf: &dyn Brdf, geometry: &str, receptor: usize, rtol: f64, rule: Option<Rule>) -> (f64, f64, usize, Rule) {
    let g = standards::find(geometry).unwrap().geometry;
    let rec = g.receptors[receptor].1;
    let mut m = Method::for_material(brdf, g.theta, g.source, rec, (rtol, 0.0), 50_000_000).unwrap();
    if let (Some(rule), Some(part)) = (rule, m.regular.as_mut()) {
        part.rule = rule;
    }
    let (flux, frozen) = m.execute_and_freeze(brdf);
    let rule = frozen.regular.as_ref().map(|p| p.rule).unwrap_or(Rule::GenzMalik75);
    (flux.regular[0], flux.error[0], flux.evaluations, rule)
}

/// The lobe's widths when the lobe rule applies to this receptor (far from every kink), else None.
fn widths(brdf: &dyn Brdf, geometry: &str, receptor: usize) -> Option<[f64; 2]> {
    let g = standards::find(geometry).unwrap().geometry;
    let rec = g.receptors[receptor].1;
    let m = Method::for_material(brdf, g.theta, g.source, rec, (1.0, 0.0), 50_000_000).unwrap();
    match m.regular.as_ref()?.rule {
        Rule::LobeDelta { width } | Rule::LobeGaussHermite { width, .. } => Some(width),
        _ => None,
    }
}

/// The delta reading (accepted whatever its bound: rtol 1) and the rtol-1e-12 Gauss–Hermite reference.
fn delta_and_reference(brdf: &dyn Brdf, geometry: &str, receptor: usize) -> Option<((f64, f64), (f64, f64))> {
    let width = widths(brdf, geometry, receptor)?;
    let (v, e, _, rule) = run(brdf, geometry, receptor, 1.0, Some(Rule::LobeDelta { width }));
    if !matches!(rule, Rule::LobeDelta { .. }) {
        // The rule refused itself (a value not positive on the curvature ring, or a curvature not positive
        // definite: the lobe is not Gaussian in these variables there) and the Gauss–Hermite rule read.
        eprintln!("{geometry} {receptor}: the delta limit refused itself, {rule:?}");
        return None;
    }
    // The lobe's Gauss–Hermite rule at the tightest tolerance its levels reach (at 85° they stop near 1e-11).
    for rtol in [1e-12, 1e-11, 1e-10] {
        let gh = Rule::LobeGaussHermite { width, levels: (0, LOBE_LEVELS.len() - 1) };
        let (r, re, _, rule) = run(brdf, geometry, receptor, rtol, Some(gh));
        if matches!(rule, Rule::LobeGaussHermite { .. }) {
            return Some(((v, e), (r, re)));
        }
    }
    // Else the partition at rtol 1e-10 (the narrowest lobes at 85°, where the Gauss–Hermite t rule tops out).
    let (r, re, _, _) = run(brdf, geometry, receptor, 1e-10, Some(Rule::GenzMalik75));
    Some(((v, e), (r, re)))
}

fn materials() -> Vec<(String, Arc<dyn Brdf>)> {
    let mut out = Vec::new();
    for m in [1e-4, 1e-5, 1e-6, 1e-7] {
        out.push((format!("beckmann {m:e} n=1.5"), beckmann(m, "1.5")));
    }
    for m in [1e-4, 1e-6] {
        out.push((format!("beckmann {m:e} gold"), beckmann(m, "[0.47, 2.4]")));
    }
    out.push(("phong 1e9".to_string(), parse(r#"{"model":"phong","exponent":1e9,"ks":0.05}"#)));
    for a in [1e-4, 1e-5] {
        let text = format!(r#"{{"model":"ward","alpha":{a:e},"rho_s":0.05}}"#);
        out.push((format!("ward {a:e}"), parse(&text)));
    }
    out
}

/// The majorant is never below the actual error, on every case where the lobe rule applies.
#[test]
fn the_delta_bound_is_never_below_the_actual_error() {
    let mut cases = 0;
    for (name, brdf) in materials() {
        for geometry in GEOMETRIES {
            let receptors = standards::find(geometry).unwrap().geometry.receptors.len();
            for receptor in 0..receptors {
                let Some(((v, bound), (r, re))) = delta_and_reference(brdf.as_ref(), geometry, receptor) else {
                    continue;
                };
                let actual = (v - r).abs();
                eprintln!(
                    "{name:24} {geometry:14} {receptor}: rel actual {:.2e}, rel bound {:.2e} (×{:.0}), ref est {:.1e}",
                    actual / r,
                    bound / r,
                    bound / actual,
                    re / r
                );
                // The true error is at most the difference from the reference plus the reference's own error.
                assert!(
                    actual + re <= bound,
                    "{name} {geometry} {receptor}: actual {actual:e} + {re:e} above {bound:e}"
                );
                cases += 1;
            }
        }
    }
    assert!(cases >= 30, "{cases} cases");
}

/// The delta reading converges to the reference as m → 0: its relative error falls as m² (by ≥ 50× per
/// decade from 1e-4 to 1e-5) and stays below 2e-9 for m ≤ 1e-6 (the floor of its (t_p, t_q) rule and of the
/// references).
#[test]
fn the_delta_reading_converges_as_the_lobe_narrows() {
    for geometry in ["astm-d523-20", "astm-d523-60", "astm-d523-85"] {
        let mut last: Option<f64> = None;
        for m in [1e-4, 1e-5, 1e-6, 1e-7] {
            let brdf = beckmann(m, "1.5");
            let ((v, bound), (r, _)) = delta_and_reference(brdf.as_ref(), geometry, 0).expect("far from the kinks");
            let rel = ((v - r) / r).abs();
            eprintln!("{geometry} {m:e}: relative error {rel:.3e}, bound {:.3e}", bound / r);
            if let (Some(prev), true) = (last, m >= 1e-5) {
                assert!(rel <= prev / 50.0 || rel < 1e-9, "{geometry} {m:e}: {rel:e} after {prev:e}");
            }
            // Below 1e-5 the floor: the (t_p, t_q) rule's, and the reference's own (at 85° the partition's).
            assert!(m >= 1e-5 || rel < 2e-9, "{geometry} {m:e}: {rel:e}");
            last = Some(rel);
        }
    }
}

/// The planner tries the delta limit for a narrow Beckmann lobe far from the kinks and reads with it when its
/// bound meets the tolerance; it refuses near the kinks (Beckmann 1e-3 at 20°), for GGX (a heavy tail), for a
/// measured-like lobe of unknown tail and over a diffuse body; `--explain` names it.
#[test]
fn the_planner_chooses_the_delta_limit_only_where_it_applies() {
    let narrow = beckmann(1e-6, "1.5");
    let (_, e, evals, rule) = run(narrow.as_ref(), "astm-d523-20", 0, 1e-6, None);
    assert!(matches!(rule, Rule::LobeDelta { .. }), "{rule:?}");
    assert!(evals <= 200, "{evals}");
    assert!(e > 0.0);
    let options = PlanOptions { rtol: 1e-6, max_seconds: None, ..PlanOptions::default() };
    let plan = Plan::compile(narrow.clone(), vec![standards::find("astm-d523-20").unwrap()], options.clone()).unwrap();
    let text = plan.explain();
    assert!(text.contains("delta limit of the lobe") && text.contains("bound"), "{text}");
    // Near the kinks: not even the Gauss–Hermite rule.
    let wide = beckmann(1e-3, "1.5");
    let (_, _, _, rule) = run(wide.as_ref(), "astm-d523-20", 0, 1e-6, None);
    assert!(matches!(rule, Rule::GenzMalik75), "{rule:?}");
    // GGX, however narrow: the polar rule.
    let ggx = parse(r#"{"model":"microfacet","distribution":"ggx","roughness":1e-6,"ior":1.5}"#);
    let (_, _, _, rule) = run(ggx.as_ref(), "astm-d523-20", 0, 1e-6, None);
    assert!(matches!(rule, Rule::LobePolar { .. }), "{rule:?}");
    // Over a diffuse body.
    let phong = parse(r#"{"model":"phong","exponent":1e9,"ks":0.05,"kd":0.2}"#);
    let (_, _, _, rule) = run(phong.as_ref(), "astm-d523-20", 0, 1e-6, None);
    assert!(!matches!(rule, Rule::LobeDelta { .. }), "{rule:?}");
    // Too wide for a tight tolerance: not tried (the design-time gate), the Gauss–Hermite rule reads.
    let b4 = beckmann(1e-4, "1.5");
    let (_, _, _, rule) = run(b4.as_ref(), "astm-d523-20", 0, 1e-9, None);
    assert!(matches!(rule, Rule::LobeGaussHermite { .. }), "{rule:?}");
    // Tried, but its bound above the tolerance: the Gauss–Hermite rule reads instead, with its evaluations.
    let width = widths(b4.as_ref(), "astm-d523-20", 0).unwrap();
    let (v, _, evals, rule) = run(b4.as_ref(), "astm-d523-20", 0, 1e-12, Some(Rule::LobeDelta { width }));
    assert!(matches!(rule, Rule::LobeGaussHermite { .. }), "{rule:?}");
    let (r, _, gh_evals, _) = run(b4.as_ref(), "astm-d523-20", 0, 1e-12, None);
    assert_eq!(v, r);
    assert!(evals > gh_evals, "{evals} {gh_evals}");
}

/// A frozen delta method replays the same points: the same bits on the same material, the same evaluations on
/// a nearby one.
#[test]
fn a_frozen_delta_method_repeats_its_bits() {
    let g = standards::find("astm-d523-60").unwrap().geometry;
    let rec = g.receptors[0].1;
    let brdf = beckmann(1e-6, "1.5");
    let method = Method::for_material(brdf.as_ref(), g.theta, g.source, rec, (1e-6, 0.0), 50_000_000).unwrap();
    let (flux, frozen) = method.execute_and_freeze(brdf.as_ref());
    assert!(matches!(frozen.regular.as_ref().unwrap().rule, Rule::LobeDelta { .. }));
    let again = frozen.execute(brdf.as_ref());
    assert_eq!(again.value, flux.value);
    assert_eq!(again.error, flux.error);
    let near = frozen.execute(beckmann(1.01e-6, "1.5").as_ref());
    assert_eq!(near.evaluations, again.evaluations);
}

/// The cost of the gloss receptor's specimen flux, before (the planner without the delta limit: the lobe's
/// Gauss–Hermite rule where the delta limit is chosen now) and after, for Beckmann and GGX of 1e-3 … 1e-8 at
/// ASTM D523 20/60/85° (n = 1.5, rtol 1e-6; printed for `docs/performance.md`): never more, and less than half
/// wherever the delta limit reads.
#[test]
fn the_delta_limit_costs_less_where_it_reads() {
    for geometry in ["astm-d523-20", "astm-d523-60", "astm-d523-85"] {
        for d in ["beckmann", "ggx"] {
            for m in [1e-3, 1e-4, 1e-6, 1e-8] {
                let text = format!(r#"{{"model":"microfacet","distribution":"{d}","roughness":{m:e},"ior":1.5}}"#);
                let brdf = parse(&text);
                let (v, e, after, rule) = run(brdf.as_ref(), geometry, 0, 1e-6, None);
                let before_rule = match rule {
                    Rule::LobeDelta { width } => {
                        Some(Rule::LobeGaussHermite { width, levels: (0, LOBE_LEVELS.len() - 1) })
                    }
                    _ => None,
                };
                let (b, be, before, _) = match before_rule {
                    Some(r) => run(brdf.as_ref(), geometry, 0, 1e-6, Some(r)),
                    None => (v, e, after, rule),
                };
                let name = match rule {
                    Rule::LobeDelta { .. } => "delta limit",
                    Rule::LobeGaussHermite { .. } => "Gauss–Hermite",
                    Rule::LobePolar { .. } => "polar",
                    Rule::TensorGauss { .. } => "tensor",
                    Rule::GenzMalik75 => "Genz–Malik (or no regular part)",
                    Rule::TailBound => "tail bound",
                };
                eprintln!(
                    "COST {geometry} {d} {m:e}: before {before}, after {after} ({name}); rel estimate {:.1e} → {:.1e}, \
                     values differ by {:.1e} relative",
                    be / b.max(1e-300),
                    e / v.max(1e-300),
                    ((v - b) / b.max(1e-300)).abs()
                );
                assert!(after <= before, "{geometry} {d} {m:e}: {before} → {after}");
                if before_rule.is_some() {
                    assert!(2 * after < before, "{geometry} {d} {m:e}: {before} → {after}");
                    assert!((v - b).abs() <= e + be, "{geometry} {d} {m:e}: {v} vs {b}");
                }
            }
        }
    }
}

/// What the rule's stencil sees at one (t_p, t_q) node, and what a denser stencil sees there.
struct NodeCheck {
    /// The rule's own fit and sampled constants (`delta_fit` on its stencil, before the safety factors).
    fit: DeltaFit,
    /// The same constants over the dense stencil: Q over the ellipse xᵀBx ≤ R², λ outside it (to 12 widths).
    q_dense: f64,
    lambda_dense: f64,
}

impl NodeCheck {
    /// `delta_node`'s majorant (relative to π w_u w_v): the rule's constants with the safety factors.
    fn rule_bound(&self) -> f64 {
        self.fit.majorant(DELTA_SAFETY * self.fit.q, self.fit.lambda / DELTA_TAIL_SAFETY)
    }
    /// The same majorant with the dense stencil's constants and no safety factors.
    fn dense_bound(&self) -> f64 {
        self.fit.majorant(self.q_dense, self.lambda_dense)
    }
}

/// The rule's stencil (`delta_stencil`, read by `delta_fit`) and a dense one at node (t_p, t_q), from the
/// method's own integrand (`Method::sample_regular`); None where the rule would refuse itself (values not
/// positive on the curvature ring, the curvature not positive definite, or no decay by the outer ring). The
/// dense stencil: 24 directions (every 7.5°, each with its opposite) at radii 0.25, 0.5, …, 6 and 7, 8, …,
/// 12 widths.
fn node_check(method: &Method, brdf: &dyn Brdf, width: [f64; 2], tp: f64, tq: f64) -> Option<NodeCheck> {
    let at = |x: [f64; 2]| [x[0] * width[0], tp, x[1] * width[1], tq];
    let radii = [DELTA_FIT_RADIUS, DELTA_RADII[0], DELTA_RADII[1]];
    let mut rule_pts = Vec::new();
    delta_stencil(width, tp, tq, &radii, &mut rule_pts);
    let ncomp = method.sample_regular(brdf, &rule_pts[..1]).len();
    let vals: Vec<f64> = method.sample_regular(brdf, &rule_pts).chunks(ncomp).map(|c| c[0]).collect();
    let fit = delta_fit(&vals, &radii)?;
    if !(fit.lambda > 0.0) {
        return None;
    }
    let ([bxx, byy, bxy], f0) = (fit.b, fit.f0);
    let quad = |x: [f64; 2]| bxx * x[0] * x[0] + 2.0 * bxy * x[0] * x[1] + byy * x[1] * x[1];
    let mut dense = Vec::new();
    let rs: Vec<f64> = (1..=24).map(|i| 0.25 * i as f64).chain((7..=12).map(f64::from)).collect();
    for r in &rs {
        for k in 0..24 {
            let phi = k as f64 * std::f64::consts::PI / 24.0;
            let x = [r * phi.cos(), r * phi.sin()];
            dense.push(x);
            dense.push([-x[0], -x[1]]);
        }
    }
    // The integrand's own rounding, as the even part's spread at 10⁻³ widths from the peak (where the smooth
    // part of h_e − h(0) is ~10⁻⁶ of its value at one width): Phong's cos^n rounds its exponent by ~n·ε.
    let near = dense.len();
    for k in 0..24 {
        let phi = k as f64 * std::f64::consts::PI / 24.0;
        let x = [1e-3 * phi.cos(), 1e-3 * phi.sin()];
        dense.push(x);
        dense.push([-x[0], -x[1]]);
    }
    let pts: Vec<[f64; 4]> = dense.iter().map(|x| at(*x)).collect();
    let dv: Vec<f64> = method.sample_regular(brdf, &pts).chunks(ncomp).map(|c| c[0]).collect();
    let (mut q_dense, mut lambda_dense) = (0.0f64, f64::INFINITY);
    let noise = dv[near..].chunks(2).map(|p| (0.5 * (p[0] + p[1]) - f0).abs()).fold(0.0, f64::max);
    for (pair, x) in dv[..near].chunks(2).zip(dense.chunks(2)) {
        let qx = quad(x[0]);
        let e = qx.exp();
        let (a, c) = (pair[0] * e, pair[1] * e);
        if qx <= fit.r2 {
            // Less the rounding of F: four times the measured spread, a few ulps of the exponent and of
            // e^{xᵀBx}, and the cancellation in the half vector, ω_i + ω_o of O(1) terms cancelling to
            // O(w·|x|), which rounds the lobe's exponent xᵀBx by ~4ε·|x|/w (allowed 4× that, 16ε·|x|/w,
            // with |x| ≤ √(xᵀBx)·(1 + O(w)) as B ≈ I). Below it a denser stencil sees
            // only rounding (at 20°: F(±x) at a quarter width differ from their Gaussian by 2e-11 relative for
            // Beckmann 1e-6; by 2e-8 for Phong 1e8 at 85°, where 1e8·ε = 1.1e-8).
            let w = width[0].min(width[1]);
            let scale = a.abs().max(c.abs()).max(f0);
            let rounding = 4.0 * noise + (64.0 * (1.0 + qx) + 16.0 * qx.sqrt() / w) * f64::EPSILON * scale;
            q_dense = q_dense.max(((0.5 * (a + c) - f0).abs() - rounding).max(0.0) / qx);
        } else {
            for v in pair.iter().filter(|v| **v != 0.0) {
                lambda_dense = lambda_dense.min((f0 / v.abs()).ln() / qx);
            }
        }
    }
    Some(NodeCheck { fit, q_dense, lambda_dense })
}

/// Beckmann (three dielectrics, two conductors), Ward and Phong lobes over the widths where the rule can be
/// tried (at a loose tolerance up to m ≈ 3e-4, at the default 1e-6 below ≈ 1.5e-5).
fn dense_materials() -> Vec<(String, Arc<dyn Brdf>)> {
    let mut out = Vec::new();
    for ior in ["1.2", "1.5", "2.4", "[0.47, 2.4]", "[1.2, 7.0]"] {
        for m in [3e-4, 1e-4, 1e-5, 1e-6, 1e-7] {
            out.push((format!("beckmann {m:e} n={ior}"), beckmann(m, ior)));
        }
    }
    for a in [3e-4, 1e-5, 1e-6] {
        out.push((format!("ward {a:e}"), parse(&format!(r#"{{"model":"ward","alpha":{a:e},"rho_s":0.05}}"#))));
    }
    for n in ["1e7", "1e8", "1e9"] {
        out.push((format!("phong {n}"), parse(&format!(r#"{{"model":"phong","exponent":{n},"ks":0.05}}"#))));
    }
    out
}

/// The assumption behind the delta bound's constants (`docs/instrument.md` §Quadrature, "The delta limit of a
/// narrow lobe", *What is verified*): at every (t_p, t_q) node, the largest |h_e − h(0)|/xᵀBx over the
/// ellipse and |h| beyond it, sampled on a stencil of 24 directions × 30 radii (to 12 widths), are at most
/// `DELTA_SAFETY` times what the rule's 12 rays at three radii see; and the majorant integrated over t by the
/// rule's 2 × 2 Gauss–Legendre nodes is at least the dense stencil's majorant (without the safety factor)
/// integrated on 6 × 6 nodes. On every material of `dense_materials` and every receptor of the six
/// geometries where the lobe rule applies. Also checks that `Method::sample_regular` is the integrand the rule
/// reads: the delta value recomputed from it equals the rule's.
#[test]
fn the_delta_bounds_sampled_constants_hold_on_a_dense_stencil() {
    let (mut cases, mut nodes) = (0, 0);
    let (mut worst_q, mut worst_lambda, mut worst_bound) = (0.0f64, 0.0f64, 0.0f64);
    let (lo, hi) = DELTA_T_ORDERS;
    let (t_lo, w_lo) = legendre_on(lo, 0.0, 1.0);
    let (t_hi, w_hi) = legendre_on(hi, 0.0, 1.0);
    let (t_dense, w_dense) = legendre_on(6, 0.0, 1.0);
    for (name, brdf) in dense_materials() {
        let brdf = brdf.as_ref();
        for geometry in GEOMETRIES {
            let g = standards::find(geometry).unwrap().geometry;
            for receptor in 0..g.receptors.len() {
                let Some(width) = widths(brdf, geometry, receptor) else { continue };
                let rec = g.receptors[receptor].1;
                let method = Method::for_material(brdf, g.theta, g.source, rec, (1.0, 0.0), 50_000_000).unwrap();
                let check = |tp: f64, tq: f64| node_check(&method, brdf, width, tp, tq);
                // The rule's own nodes: its constants, and its value recomputed from `sample_regular`.
                let (mut rule_bound, mut value) = (0.0, 0.0);
                let mut refused = false;
                for (ts, ws, is_bound) in [(&t_lo, &w_lo, true), (&t_hi, &w_hi, false)] {
                    for (tp, wp) in ts.iter().zip(ws) {
                        for (tq, wq) in ts.iter().zip(ws) {
                            let Some(c) = check(*tp, *tq) else {
                                refused = true;
                                continue;
                            };
                            if is_bound {
                                rule_bound += wp * wq * c.rule_bound();
                                nodes += 1;
                                worst_q = worst_q.max(c.q_dense / c.fit.q);
                                if c.lambda_dense.is_finite() {
                                    worst_lambda = worst_lambda.max(c.fit.lambda / c.lambda_dense);
                                }
                                assert!(
                                    c.q_dense <= DELTA_SAFETY * c.fit.q
                                        && c.lambda_dense >= c.fit.lambda / DELTA_TAIL_SAFETY,
                                    "{name} {geometry} {receptor} t = ({tp}, {tq}): dense Q {:e}, λ {:e} against \
                                     the rule's {:e}, {:e}",
                                    c.q_dense,
                                    c.lambda_dense,
                                    c.fit.q,
                                    c.fit.lambda
                                );
                            } else {
                                value += wp * wq * c.fit.mass();
                            }
                        }
                    }
                }
                if refused {
                    continue;
                }
                let mut dense_bound = 0.0;
                for (tp, wp) in t_dense.iter().zip(&w_dense) {
                    for (tq, wq) in t_dense.iter().zip(&w_dense) {
                        let c = check(*tp, *tq).expect("positive definite between the rule's nodes");
                        dense_bound += wp * wq * c.dense_bound();
                    }
                }
                worst_bound = worst_bound.max(dense_bound / rule_bound);
                assert!(dense_bound <= rule_bound, "{name} {geometry} {receptor}: {dense_bound:e} > {rule_bound:e}");
                let scale = std::f64::consts::PI * width[0] * width[1];
                let (v, _, _, rule) = run(brdf, geometry, receptor, 1.0, Some(Rule::LobeDelta { width }));
                // At rtol 1 the rule reads unless its majorant exceeds the value itself (Phong 1e7 at 85°).
                if matches!(rule, Rule::LobeDelta { .. }) {
                    let rel = ((scale * value - v) / v).abs();
                    assert!(rel < 1e-13, "{name} {geometry} {receptor}: {} vs {v}", scale * value);
                }
                cases += 1;
            }
        }
    }
    eprintln!(
        "DENSE {cases} cases, {nodes} bound nodes: largest dense/rule Q {worst_q:.3} (safety {DELTA_SAFETY}), \
         rule/dense λ {worst_lambda:.4} (safety {DELTA_TAIL_SAFETY}), majorant {worst_bound:.3}"
    );
    assert!(cases >= 150, "{cases} cases");
}
