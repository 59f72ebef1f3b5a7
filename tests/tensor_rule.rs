//! The smooth-integrand rule `Rule::TensorGauss` (anisotropic tensor Gauss–Legendre with per-axis
//! p-refinement, `quadrature::tensor`; `docs/instrument.md` §Quadrature, "A tensor rule for smooth anisotropic
//! integrands"): closed forms, the estimate against the actual error, the planner's choice and `--explain`, frozen
//! replays and determinism.
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::method::{Chart, Method, Rule};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::reference::lambertian_flux_reference;
use glossmeter::instrument::standards;
use glossmeter::quadrature::tensor;

fn fixture(name: &str) -> Arc<dyn Brdf> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/recipes").join(name);
    glossmeter::recipe::load_file(&path).expect("fixture loads").brdf
}

fn tensor_rule(chart: Chart) -> Rule {
    Rule::TensorGauss { chart, levels: [1; 4], path: tensor::Path::default() }
}

/// The rule forced on a Lambertian body in each of its charts against Lambert's polygon formula (the
/// independent closed form of `instrument::reference`), on gloss geometries from 20° to 85°: the value within
/// the tolerance, the actual error at or below the estimate; a frozen re-run repeats the bits.
#[test]
fn the_tensor_rule_meets_the_lambert_polygon_closed_form_within_its_estimate() {
    let lambert = fixture("bench-b1-lambert.json");
    let f_lum = 0.5 / std::f64::consts::PI;
    for id in ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30"] {
        let g = standards::find(id).unwrap().geometry;
        let (theta, src) = (g.theta, g.source);
        for name in ["gloss", "haze-narrow"] {
            let Some(rec) = g.receptor(name) else { continue };
            let exact = lambertian_flux_reference(theta, src, *rec, f_lum);
            for chart in [Chart::Plain, Chart::Lobe, Chart::PlainPLobeQ] {
                for rtol in [1e-6, 1e-9] {
                    let mut m =
                        Method::for_material(lambert.as_ref(), theta, src, *rec, (rtol, 0.0), 10_000_000).unwrap();
                    m.regular.as_mut().unwrap().rule = tensor_rule(chart);
                    let (flux, frozen) = m.execute_and_freeze(lambert.as_ref());
                    let actual = (flux.value[0] - exact).abs();
                    assert!(flux.converged, "{id} {name} {chart:?} {rtol}: {flux:?}");
                    assert!(
                        actual <= flux.error[0] + 1e-14 * exact,
                        "{id} {name} {chart:?} rtol {rtol}: actual {actual:e} > estimate {:e}",
                        flux.error[0]
                    );
                    assert!(flux.error[0] <= rtol * exact, "{id} {name} {chart:?}: {:e}", flux.error[0]);
                    let rule = frozen.regular.as_ref().unwrap().rule;
                    assert!(matches!(rule, Rule::TensorGauss { .. }), "the tensor converged, no fallback: {rule:?}");
                    let again = frozen.execute(lambert.as_ref());
                    assert_eq!(again.value[0].to_bits(), flux.value[0].to_bits());
                    assert_eq!(again.error[0].to_bits(), flux.error[0].to_bits());
                    assert!(again.evaluations <= flux.evaluations);
                }
            }
        }
    }
}

/// B4 (GGX α = 0.3 on n = 1.5 at 85°): the planner chooses the tensor rule, `--explain` names it with its
/// fallback; the reading agrees with an independent run of the forced Genz–Malik engine at rtol 1e-11 within
/// its estimate, costs fewer evaluations than the Genz–Malik partition it replaces, and repeats its bits frozen
/// and on 1 and 2 threads. Lambert (B1), B2 and B4 at 75° keep Genz–Malik (where it was cheaper).
#[test]
fn the_planner_chooses_the_tensor_rule_for_b4_and_names_it() {
    let b4 = fixture("bench-b4-ggx-0.3.json");
    let g85 = standards::find("astm-d523-85").unwrap();
    let plan = Plan::compile(b4.clone(), vec![g85.clone()], PlanOptions::default()).unwrap();
    let text = plan.explain();
    assert!(text.contains("smooth integrand: tensor Gauss–Legendre in (p_s, p_r, v, t_q)"), "{text}");
    assert!(text.contains("fallback: Genz–Malik 7/5"), "{text}");
    let r = &plan.execute()[0];
    assert!(r.converged, "{r:?}");
    // An independent value: the Genz–Malik engine forced on the same integral, far tighter.
    let geo = &g85.geometry;
    let rec = *geo.receptor("gloss").unwrap();
    let mut gm = Method::for_material(b4.as_ref(), geo.theta, geo.source, rec, (1e-11, 0.0), 200_000_000).unwrap();
    assert!(matches!(gm.regular.as_ref().unwrap().rule, Rule::TensorGauss { .. }));
    gm.regular.as_mut().unwrap().rule = Rule::GenzMalik75;
    let tight = gm.execute(b4.as_ref());
    let ours = Method::for_material(b4.as_ref(), geo.theta, geo.source, rec, (1e-6, 0.0), 10_000_000)
        .unwrap()
        .execute(b4.as_ref());
    let actual = (ours.value[0] - tight.value[0]).abs();
    assert!(actual <= ours.error[0] + tight.error[0], "actual {actual:e}, estimate {:e}", ours.error[0]);
    assert!(ours.error[0] <= 1e-6 * ours.value[0]);
    // Cheaper than the Genz–Malik partition it replaces, at the same tolerance.
    let mut plain = Method::for_material(b4.as_ref(), geo.theta, geo.source, rec, (1e-6, 0.0), 10_000_000).unwrap();
    plain.regular.as_mut().unwrap().rule = Rule::GenzMalik75;
    let plain = plain.execute(b4.as_ref());
    assert!(
        ours.evaluations < plain.evaluations,
        "tensor {} against Genz–Malik {}",
        ours.evaluations,
        plain.evaluations
    );
    // Frozen, and thread counts.
    let (first, frozen) = plan.freeze();
    let again = frozen.execute();
    assert_eq!(first[0].value.map(f64::to_bits), r.value.map(f64::to_bits));
    assert_eq!(again[0].value.map(f64::to_bits), r.value.map(f64::to_bits));
    assert_eq!(again[0].error_estimate.to_bits(), r.error_estimate.to_bits());
    assert!(frozen.explain().contains("the highest final orders over the boxes"), "{}", frozen.explain());
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let x = pool.install(|| plan.execute());
        assert_eq!(x[0].value.map(f64::to_bits), r.value.map(f64::to_bits), "{threads} thread(s)");
    }
    for (name, id) in [
        ("bench-b1-lambert.json", "astm-d523-60"),
        ("bench-b2-beckmann-0.1.json", "astm-d523-20"),
        ("bench-b4-ggx-0.3.json", "tappi-t480-75"),
    ] {
        let p = Plan::compile(fixture(name), vec![standards::find(id).unwrap()], PlanOptions::default()).unwrap();
        assert!(!p.explain().contains("tensor Gauss–Legendre"), "{name} {id}");
    }
}
