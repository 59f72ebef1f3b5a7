//! The `microfacet` recipe's mixture of slope populations (`populations`, docs/optics.md §4.1): with one
//! population it is today's model to the bit; it is reciprocal and reflects at most what it receives (white
//! furnace with F → 1); its D523 glosses agree with an independent Monte Carlo (`tools/iq/check_mixture.py`, on
//! check_85.py's optics) within that Monte Carlo's standard error; bad input exits 2 naming the file and field.
mod common;
use glossmeter::brdf::albedo::directional_albedo_to;
use glossmeter::brdf::dielectric::Ior;
use glossmeter::brdf::mixture::MixtureSurface;
use glossmeter::brdf::Brdf;
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards;
use glossmeter::optics::microfacet::{Distribution, Microfacet, Shadowing};
use glossmeter::optics::slope_mixture::SlopeMixture;
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;
use num_complex::Complex64;

fn load(json: &str) -> glossmeter::recipe::Material {
    glossmeter::recipe::parse_str(json, "mixture.json").unwrap_or_else(|e| panic!("{e}\n{json}"))
}

fn dirs() -> Vec<Vec3> {
    (0..12)
        .flat_map(|i| (0..6).map(move |j| (i, j)))
        .map(|(i, j)| {
            let th = (i as f64 * 7.3 + 0.4).to_radians();
            let ph = j as f64 * 1.05;
            Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
        })
        .collect()
}

/// One population (weight 1 given, or omitted) is the one-roughness recipe: the same BRDF values and the same
/// readings, bit for bit, at every shipped geometry it compiles for, for each distribution, shadowing and a
/// conductor.
#[test]
fn a_one_population_mixture_is_the_microfacet_model() {
    let all = standards::builtin_all().unwrap();
    let gloss = standards::builtin().unwrap();
    let cases = [
        (r#""distribution": "beckmann""#, "0.0074", "1.5229", ""),
        (r#""distribution": "ggx""#, "0.05", "1.5", r#", "shadowing": "smith-separable""#),
        (r#""distribution": "ggx""#, "0.2", "[0.2, 3.5]", r#", "shadowing": "v-cavity""#),
    ];
    for (dist, m, ior, shadow) in cases {
        let one = load(&format!(r#"{{"model": "microfacet", {dist}, "roughness": {m}, "ior": {ior}{shadow}}}"#));
        for pops in [format!(r#"[{{"weight": 1, "roughness": {m}}}]"#), format!(r#"[{{"roughness": {m}}}]"#)] {
            let mix =
                load(&format!(r#"{{"model": "microfacet", {dist}, "populations": {pops}, "ior": {ior}{shadow}}}"#));
            let n = one.brdf.sampling().len();
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            for &wi in &dirs() {
                for &wo in &dirs() {
                    one.brdf.eval(wi, wo, &mut a);
                    mix.brdf.eval(wi, wo, &mut b);
                    assert_eq!(
                        a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        b.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        "{m} {ior}"
                    );
                }
            }
            let geos = if Plan::compile(one.brdf.clone(), all.clone(), PlanOptions::default()).is_ok() {
                all.clone()
            } else {
                gloss.clone()
            };
            let ra = Plan::compile(one.brdf.clone(), geos.clone(), PlanOptions::default()).unwrap().execute();
            let rb = Plan::compile(mix.brdf.clone(), geos.clone(), PlanOptions::default()).unwrap().execute();
            assert_eq!(ra.len(), rb.len());
            for (x, y) in ra.iter().zip(&rb) {
                assert_eq!((&x.geometry, &x.name), (&y.geometry, &y.name));
                assert_eq!(x.value.map(f64::to_bits), y.value.map(f64::to_bits), "{} {} ({m})", x.geometry, x.name);
                assert_eq!(x.error_estimate.to_bits(), y.error_estimate.to_bits(), "{} {}", x.geometry, x.name);
            }
        }
    }
}

fn mixtures() -> Vec<(SlopeMixture, Shadowing)> {
    let b = |m| Microfacet::new(Distribution::Beckmann, m);
    let g = |m| Microfacet::new(Distribution::Ggx, m);
    vec![
        (SlopeMixture::new(vec![(0.9325, b(0.0074)), (0.0675, b(0.0741))]), Shadowing::SmithHeightCorrelated),
        (
            SlopeMixture::new(vec![(0.3, g(0.00064)), (0.57, b(0.008)), (0.13, b(0.028))]),
            Shadowing::SmithHeightCorrelated,
        ),
        (SlopeMixture::new(vec![(0.5, g(0.1)), (0.3, b(0.4)), (0.2, g(0.8))]), Shadowing::SmithHeightCorrelated),
        (SlopeMixture::new(vec![(0.6, b(0.2)), (0.4, g(0.6))]), Shadowing::SmithSeparable),
    ]
}

/// Helmholtz reciprocity: f(ωi, ωo) = f(ωo, ωi) to rounding (F(ωi·h) and F(ωo·h) differ only by the rounding
/// of the two dot products).
#[test]
fn the_mixture_is_reciprocal() {
    for (mix, sh) in mixtures() {
        let s = MixtureSurface::new(mix, sh, vec![Ior::Dielectric(1.52)], Sampling::grey()).unwrap();
        assert!(s.hints().reciprocal);
        let (mut a, mut b) = ([0.0], [0.0]);
        for &wi in &dirs() {
            for &wo in &dirs() {
                s.eval(wi, wo, &mut a);
                s.eval(wo, wi, &mut b);
                assert!((a[0] - b[0]).abs() <= 1e-12 * a[0].abs().max(1e-300), "{wi:?} {wo:?}: {} {}", a[0], b[0]);
            }
        }
    }
}

/// White furnace: with F ≈ 1 (a conductor of k = 10⁶) the directional albedo of every mixture is at most 1 at
/// every incidence (single scattering with Smith masking loses energy, never gains it), and close to 1 near
/// normal incidence for the narrow mixtures.
#[test]
fn the_mixture_reflects_at_most_what_it_receives() {
    let mirror = vec![Ior::Conductor(Complex64::new(1.0, 1e6))];
    for (k, (mix, sh)) in mixtures().into_iter().enumerate() {
        let s = MixtureSurface::new(mix, sh, mirror.clone(), Sampling::grey()).unwrap();
        for deg in [0.0f64, 20.0, 45.0, 60.0, 75.0, 85.0, 89.0] {
            let t = deg.to_radians();
            let (a, err) = directional_albedo_to(&s, Vec3::new(t.sin(), 0.0, t.cos()), 1e-9);
            assert!(a[0] <= 1.0 + err + 1e-9, "mixture {k} at {deg}°: albedo {} (± {err})", a[0]);
            if k < 2 && deg <= 60.0 {
                assert!(a[0] > 0.999, "mixture {k} at {deg}°: albedo {}", a[0]);
            }
        }
    }
}

/// check_85.py §3's best two-scale surface (0.9325 × 0.30° + 0.0675 × 3.0° rms slope per axis, Beckmann,
/// n from its bisection) read at D523 20°, 60°, 85°, against the independent Monte Carlo's mixture-G column
/// (`tools/iq/check_mixture.out.txt`, values and standard errors read from the file): each within two standard
/// errors of the Monte Carlo.
#[test]
fn the_d523_glosses_agree_with_the_independent_monte_carlo() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tools/iq/check_mixture.out.txt")).unwrap();
    let field = |line: &str, key: &str| -> f64 {
        let at = line.find(key).unwrap_or_else(|| panic!("{key} in {line}")) + key.len();
        line[at..].split([',', ' ', ';']).find(|s| !s.is_empty()).unwrap().parse().unwrap()
    };
    let surface = text.lines().find(|l| l.starts_with("surface:")).expect("the surface line");
    let (m1, m2, n) = (field(surface, "m1 = "), field(surface, "m2 = "), field(surface, "n = "));
    let json = format!(
        r#"{{"model": "microfacet", "distribution": "beckmann", "ior": {n},
            "populations": [{{"roughness": {m1}}}, {{"weight": 0.0675, "roughness": {m2}}}]}}"#
    );
    let mix = load(&json);
    let mut seen = 0;
    for line in text.lines() {
        let cols: Vec<&str> = line.split_whitespace().collect();
        let Some(angle) = cols.first().and_then(|a| a.parse::<u32>().ok()) else { continue };
        let (mc, se): (f64, f64) = (cols[3].parse().unwrap(), cols[4].parse().unwrap());
        let g = standards::find(&format!("astm-d523-{angle}")).unwrap();
        let r = &Plan::compile(mix.brdf.clone(), vec![g], PlanOptions::default()).unwrap().execute()[0];
        let v = r.value.unwrap();
        assert!((v - mc).abs() <= 2.0 * se + r.error_estimate, "{angle}°: glossmeter {v}, Monte Carlo {mc} ± {se}");
        seen += 1;
    }
    assert_eq!(seen, 3, "three geometries in check_mixture.out.txt");
}

fn measure(json: &str, name: &str) -> (i32, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, json).unwrap();
    let out =
        common::glossmeter().args(["measure", path.to_str().unwrap(), "--geometry", "astm-d523-60"]).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Bad populations exit 2 with the file, the JSON Pointer and what is allowed.
#[test]
fn bad_populations_are_refused_with_file_field_and_range() {
    let base =
        |pops: &str| format!(r#"{{"model": "microfacet", "distribution": "ggx", "ior": 1.5, "populations": {pops}}}"#);
    let cases: Vec<(String, &str, &str)> = vec![
        (base(r#"[{"weight": 0, "roughness": 0.01}, {"roughness": 0.1}]"#), "/populations/0/weight", "(0, 1]"),
        (base(r#"[{"weight": 1.5, "roughness": 0.01}]"#), "/populations/0/weight", "(0, 1]"),
        (base(r#"[{"weight": 0.5, "roughness": 0.01}, {"weight": 0.4, "roughness": 0.1}]"#), "/populations", "1 (within 1e-9)"),
        (base(r#"[{"weight": 0.7, "roughness": 0.01}, {"weight": 0.3, "roughness": 0.1}, {"roughness": 0.2}]"#), "/populations", "below 1"),
        (base(r#"[{"roughness": 0.01}, {"roughness": 0.1}]"#), "/populations/1/weight", "at most one population omits"),
        (base("[]"), "/populations", "1 to 8"),
        (base(r#"[{"weight": 1, "roughness": 0}]"#), "/populations/0/roughness", "[0.0000001, 10]"),
        (base(r#"[{"weight": 1, "roughness": 11}]"#), "/populations/0/roughness", "[0.0000001, 10]"),
        (base(r#"[{"weight": 1, "roughness": 0.1, "distribution": "phong"}]"#), "/populations/0/distribution", "\"ggx\""),
        (base(r#"[{"weight": 1, "roughness": 0.1, "m": 2}]"#), "/populations/0", "m"),
        (base(r#"{"weight": 1}"#), "/populations", "array"),
        (
            r#"{"model": "microfacet", "distribution": "ggx", "ior": 1.5, "roughness": 0.1, "populations": [{"roughness": 0.1}]}"#.into(),
            "/populations",
            "not both",
        ),
        (r#"{"model": "microfacet", "distribution": "ggx", "ior": 1.5}"#.into(), "/roughness", "exactly one"),
    ];
    for (json, pointer, allowed) in cases {
        let (code, err) = measure(&json, "bad-mixture.json");
        assert_eq!(code, 2, "{json}: {err}");
        assert!(err.contains("bad-mixture.json"), "{json}: {err}");
        assert!(err.contains(pointer), "{json}: want {pointer}: {err}");
        assert!(err.contains(allowed), "{json}: want {allowed:?}: {err}");
    }
}
