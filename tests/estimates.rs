//! The one promise a reading must never break (docs/accuracy.md §The estimate property): its error estimate is
//! not below its actual error. For recipes generated over every model family (Lambert; smooth and rough
//! dielectrics and conductors, including real indices below 1 with their critical-angle kinks; Phong; Ward;
//! multi-lobe Cook–Torrance; paints with smooth and rough coats, metallic flakes and pearlescent flakes whose
//! mica lies below the resin's index; measured tables), read on every shipped geometry (the colour geometries
//! too, unless the recipe is RGB), the default reading's |value − value at rtol 10⁻¹⁰| must be at most its
//! error estimate. The reference runs without a wall-clock budget; a reference that does not converge is no
//! reference, and the reading is counted as unchecked (the test requires almost all to be checked).
//!
//! `GLOSSMETER_ESTIMATE_CASES=N` sets the number of generated recipes (default 240, about 2–3 minutes of the suite on
//! a loaded 2-core machine; the 36 it once ran missed four readings below their actual error, docs/accuracy.md
//! §The estimate property); `GLOSSMETER_ESTIMATE_REPORT=1` prints the distribution of estimate/actual that
//! docs/accuracy.md records.
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards;

/// A small deterministic generator (SplitMix64): the same recipes on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.next()).exp()
    }
    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[((self.next() * xs.len() as f64) as usize).min(xs.len() - 1)]
    }
}

/// Recipe `i` of the generated set: (a label, the recipe JSON, the file name it is read as, for relative
/// table paths).
fn recipe(i: usize, rng: &mut Rng) -> (String, String, String) {
    let f = |x: f64| format!("{x:.6}");
    let here = "fixtures/recipes/generated.json".to_string();
    let family = i % 12;
    let (label, json) = match family {
        0 => {
            let a = rng.uniform(0.02, 0.98);
            ("lambert".into(), format!(r#"{{"model":"lambert","albedo":{}}}"#, f(a)))
        }
        1 => {
            let n = rng.uniform(1.3, 2.4);
            ("smooth dielectric".into(), format!(r#"{{"model":"smooth-dielectric","ior":{}}}"#, f(n)))
        }
        2 | 3 => {
            let d = rng.pick(&["beckmann", "ggx"]);
            let m = rng.log_uniform(0.003, 0.5);
            let n = rng.uniform(1.3, 2.0);
            let shadow = if family == 3 { r#","shadowing":"v-cavity""# } else { "" };
            (
                format!("rough dielectric {d} m={m:.4}{}", if family == 3 { " v-cavity" } else { "" }),
                format!(r#"{{"model":"microfacet","distribution":"{d}","roughness":{},"ior":{}{shadow}}}"#, f(m), f(n)),
            )
        }
        4 => {
            // A conductor; every other one a real index below 1 (k = 0): a Fresnel critical angle.
            let d = rng.pick(&["beckmann", "ggx"]);
            let m = rng.log_uniform(0.003, 0.4);
            let (n, k) = if i % 24 < 12 {
                (rng.uniform(0.3, 0.95), 0.0)
            } else {
                (rng.uniform(0.1, 3.0), rng.uniform(0.5, 8.0))
            };
            (
                format!("rough conductor {d} m={m:.4} n={n:.3}+{k:.3}i"),
                format!(
                    r#"{{"model":"microfacet","distribution":"{d}","roughness":{},"ior":[{},{}]}}"#,
                    f(m),
                    f(n),
                    f(k)
                ),
            )
        }
        5 => {
            let (n, k) = if i % 24 < 12 {
                (rng.uniform(0.3, 0.95), 0.0)
            } else {
                (rng.uniform(0.1, 3.0), rng.uniform(0.5, 8.0))
            };
            (
                format!("smooth conductor n={n:.3}+{k:.3}i"),
                format!(r#"{{"model":"conductor","ior":[{},{}]}}"#, f(n), f(k)),
            )
        }
        6 => {
            let e = rng.log_uniform(5.0, 1e4);
            let ks = rng.uniform(0.01, 0.3);
            let kd = rng.uniform(0.0, 0.6);
            ("phong".into(), format!(r#"{{"model":"phong","exponent":{},"ks":{},"kd":{}}}"#, f(e), f(ks), f(kd)))
        }
        7 => {
            let a = rng.log_uniform(0.01, 0.3);
            let rs = rng.uniform(0.01, 0.2);
            let rd = rng.uniform(0.0, 0.6);
            ("ward".into(), format!(r#"{{"model":"ward","alpha":{},"rho_s":{},"rho_d":{}}}"#, f(a), f(rs), f(rd)))
        }
        8 => {
            let kd = rng.uniform(0.0, 0.4);
            let (k1, k2) = (rng.uniform(0.02, 0.3), rng.uniform(0.01, 0.2));
            let (m1, m2) = (rng.log_uniform(0.05, 0.4), rng.log_uniform(0.005, 0.05));
            let (r1, r2) = (rng.uniform(0.02, 0.9), rng.uniform(0.02, 0.9));
            (
                "cook-torrance lobes".into(),
                format!(
                    r#"{{"model":"cook-torrance-lobes","kd":{},"lobes":[{{"ks":{},"r":{},"m":{}}},{{"ks":{},"r":{},"m":{}}}]}}"#,
                    f(kd),
                    f(k1),
                    f(r1),
                    f(m1),
                    f(k2),
                    f(r2),
                    f(m2)
                ),
            )
        }
        9 | 10 => {
            // Paints: smooth or rough coat, metallic or pearlescent flakes; pearl mica often below the resin.
            let coat_n = rng.uniform(1.4, 1.8);
            let rough = if family == 10 {
                format!(
                    r#","roughness":{},"distribution":"{}""#,
                    f(rng.log_uniform(0.005, 0.2)),
                    rng.pick(&["beckmann", "ggx"])
                )
            } else {
                String::new()
            };
            let (k, s) = (rng.log_uniform(0.05, 3.0), rng.log_uniform(0.05, 3.0));
            let flakes = if i % 4 < 2 {
                metallic_flakes(
                    rng.uniform(0.5, 2.5),
                    rng.uniform(2.0, 7.0),
                    rng.uniform(0.1, 0.4),
                    rng.uniform(0.05, 0.4),
                )
            } else {
                pearlescent_flakes(
                    rng.uniform(0.1, 0.4),
                    rng.uniform(0.05, 0.3),
                    rng.uniform(40.0, 160.0),
                    rng.uniform(1.5, 1.62),
                )
            };
            (
                format!("paint coat n={coat_n:.3}{}", if family == 10 { " rough" } else { "" }),
                paint(coat_n, &rough, [k, 0.5 * k, 0.2 * k], [s; 3], &flakes),
            )
        }
        _ => {
            // Measured tables, as shipped (their readings are the tables' own, interpolated).
            let which = (i / 12) % 3;
            let (label, json, file) = match which {
                0 => ("merl table", r#"{"model":"merl","file":"../materials/merl/lambert-tiny.binary"}"#, here.clone()),
                1 => (
                    "in-plane table",
                    r#"{"model":"inplane-csv","file":"../materials/inplane/lambert-cos.csv"}"#,
                    here.clone(),
                ),
                _ => ("rgl table", r#"{"model":"rgl","file":"../materials/rgl/lambert-rgb.bsdf"}"#, here.clone()),
            };
            return (label.into(), json.into(), file);
        }
    };
    (label, json, here)
}

#[test]
fn every_default_reading_s_estimate_covers_its_actual_error() {
    let cases = cases_from("GLOSSMETER_ESTIMATE_CASES", 240);
    campaign(cases, None, 1e-10);
}

/// The same promise at other tolerances on the first 12 recipes (one of each family): rtol 10⁻⁴ and 10⁻⁸
/// (the estimate's calibration and its limits were measured there too, docs/accuracy.md §5.1–5.2; a chance
/// agreement of I₇ and I₅ at 10⁻⁷–10⁻⁸ was found by a sweep, not by this test at the default rtol). Against the
/// same rtol-10⁻¹⁰ reference, whose own estimate is added to the bound (at 10⁻⁸ it is no longer negligible).
#[test]
fn the_estimate_covers_its_actual_error_at_rtol_1e_4_and_1e_8() {
    // `GLOSSMETER_ESTIMATE_TIGHT_CASES=N`: more of the generated recipes, by hand.
    let cases = cases_from("GLOSSMETER_ESTIMATE_TIGHT_CASES", 12);
    campaign(cases, Some(&[1e-4, 1e-8]), 1e-10);
}

/// The same promise at rtol 10⁻¹⁰, the tightest tolerance it is measured at, against an rtol-10⁻¹¹ reference
/// (at `MIN_RTOL`, 10⁻¹², the rough-coat paints' references reach the evaluation budget unconverged, as in the
/// pearl test below), whose own estimate is added to the bound: by hand,
/// `GLOSSMETER_ESTIMATE_TIGHT_CASES=240 cargo test --test estimates at_rtol_1e_10 -- --ignored` (about 5 min
/// on two cores; its result is in docs/accuracy.md §The estimate property).
#[test]
#[ignore = "a measurement of about 5 min: see the doc comment"]
fn the_estimate_covers_its_actual_error_at_rtol_1e_10() {
    let cases = cases_from("GLOSSMETER_ESTIMATE_TIGHT_CASES", 12);
    campaign(cases, Some(&[1e-10]), 1e-11);
}

/// Read the first `cases` generated recipes at the default settings (`rtols` None) or at each of `rtols`, and
/// compare each reading with the reference read at `reference_rtol` (plus the reference's own estimate when `rtols` is
/// given).
fn campaign(cases: usize, rtols: Option<&[f64]>, reference_rtol: f64) {
    let report = std::env::var_os("GLOSSMETER_ESTIMATE_REPORT").is_some();
    let gloss = standards::builtin().unwrap();
    let all = standards::builtin_all().unwrap();
    let default = PlanOptions::default();
    let runs: Vec<(PlanOptions, bool)> = match rtols {
        None => vec![(default.clone(), false)],
        Some(rtols) => rtols
            .iter()
            .map(|&rtol| (PlanOptions { rtol, max_seconds: None, rtol_from_data: false, ..default.clone() }, true))
            .collect(),
    };
    // Without a wall-clock budget: what is checked must not depend on the machine's load.
    let tight =
        PlanOptions { rtol: reference_rtol, max_seconds: None, rtol_from_data: false, ..PlanOptions::default() };
    let mut rng = Rng(0x0005_EED0_FE57);
    let (mut checked, mut unchecked, mut exact) = (0usize, 0usize, 0usize);
    let mut ratios: Vec<f64> = Vec::new();
    // The same ratios split by whether the reading's estimate came within 1/100 of its allowance rtol·|v|
    // (`near`: the refinement ran until this reading's tolerance was met) or stayed far below it (`far`).
    let (mut near, mut far): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut failures = Vec::new();
    for i in 0..cases {
        let (label, json, file) = recipe(i, &mut rng);
        let m =
            glossmeter::recipe::parse_str(&json, &file).unwrap_or_else(|e| panic!("case {i} ({label}): {e}\n{json}"));
        let geos = match Plan::compile(m.brdf.clone(), all.clone(), default.clone()) {
            Ok(_) => all.clone(),
            Err(_) => gloss.clone(),
        };
        let r = Plan::compile(m.brdf.clone(), geos.clone(), tight.clone()).unwrap().execute();
        for (options, add_reference) in &runs {
            let d = Plan::compile(m.brdf.clone(), geos.clone(), options.clone()).unwrap().execute();
            for (a, b) in d.iter().zip(&r) {
                assert_eq!((&a.geometry, &a.name), (&b.geometry, &b.name));
                let (Some(v), Some(vr)) = (a.value, b.value) else { continue };
                if !b.converged {
                    unchecked += 1;
                    continue;
                }
                checked += 1;
                let actual = (v - vr).abs();
                let bound = a.error_estimate + if *add_reference { b.error_estimate } else { 0.0 };
                if actual == 0.0 {
                    exact += 1;
                } else {
                    ratios.push(bound / actual);
                    // The head room: the estimate against what the tolerance allowed the reading (rtol·|v|).
                    let room = a.error_estimate / (options.rtol * v.abs());
                    if room >= 0.01 { &mut near } else { &mut far }.push(bound / actual);
                }
                if actual > bound {
                    failures.push(format!(
                        "case {i} ({label}) {} {} at rtol {:e}: value {v:e}, reference {vr:e} ± {:e}: actual {actual:e} \
                         > estimate {:e}\n  {json}",
                        a.geometry, a.name, options.rtol, b.error_estimate, a.error_estimate
                    ));
                }
            }
        }
    }
    ratios.sort_by(f64::total_cmp);
    let q = |p: f64| ratios.get(((ratios.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(f64::NAN);
    if report {
        eprintln!(
            "{cases} recipes (rtol {rtols:?}, None: the default), {checked} readings checked ({exact} exact), {unchecked} unchecked; estimate/actual: \
             min {:.3e}, 1 % {:.3e}, 10 % {:.3e}, median {:.3e}, 90 % {:.3e}, max {:.3e}",
            q(0.0),
            q(0.01),
            q(0.1),
            q(0.5),
            q(0.9),
            q(1.0)
        );
        for (label, mut v) in [("within 1/100 of rtol·|v|", near), ("below 1/100 of rtol·|v|", far)] {
            v.sort_by(f64::total_cmp);
            let q = |p: f64| v.get(((v.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(f64::NAN);
            eprintln!(
                "  estimate {label}: {} readings; min {:.3e}, 10 % {:.3e}, median {:.3e}, 90 % {:.3e}",
                v.len(),
                q(0.0),
                q(0.1),
                q(0.5),
                q(0.9)
            );
        }
    }
    assert!(
        checked >= 20 * cases * runs.len(),
        "only {checked} readings checked over {cases} recipes ({unchecked} unchecked)"
    );
    // Almost all checked: at most 1 in 25 references may reach the evaluation budget unconverged (mostly
    // tables at 85° and plain-chart integrals at 10⁻¹⁰, whose boxes keep N₁: 71 of 3 412 in the first 36
    // recipes, 262 of 22 777 in 240; docs/accuracy.md §The estimate property).
    assert!(unchecked * 25 <= checked, "{unchecked} references did not converge (of {})", checked + unchecked);
    assert!(failures.is_empty(), "{} estimate(s) below the actual error:\n{}", failures.len(), failures.join("\n"));
}

/// The case the 240-recipe campaign left (docs/accuracy.md §The estimate property): a Beckmann lobe about as
/// wide as the stops (m = 0.029) at D523 / ISO 2813 85°, read 1.19× (V-cavity G, recipe 123 of the generated
/// set) and 1.25× (its Smith-G twin) below its actual error, because one unsplit box's I₇ and I₅ agreed by
/// chance (`quadrature::unsplit_estimate`, §5.2). Both must now cover their error against the rtol-10⁻¹⁰
/// reference.
#[test]
fn a_lobe_about_as_wide_as_the_stops_at_85_degrees_is_covered() {
    for shadowing in [r#","shadowing":"v-cavity""#, ""] {
        let json = format!(
            r#"{{"model":"microfacet","distribution":"beckmann","roughness":0.029052,"ior":1.548226{shadowing}}}"#
        );
        let failures = below_their_actual_error(&json, "astm-d523-85", 1e-6);
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}

/// The two readings of the Rhopoint IQ-class pixel-array geometry whose estimates fell below their actual error
/// (docs/accuracy.md §5.2, "A lobe between half and the whole range wide"): a Phong lobe (n = 5091.6) whose
/// width in u, 1.98·10⁻², lies between half and the whole u-range of the 0.1° source against the 1.8° gloss
/// window (3.34·10⁻²), read 2.07× below its error at the default rtol; and the Rayleigh–Rice halo of
/// `clear-coat-haze` (1.73·10⁻² wide in u), 1.33× below at rtol 10⁻⁸. The lobe chart had no split at the lobe's
/// centre on u, so one box held the peak. Each reading of the geometry must now cover its error against the
/// rtol-10⁻¹⁰ reading (the gloss reading was the one found; the others are checked with it).
#[test]
fn a_lobe_between_half_and_the_whole_range_wide_is_covered_on_the_pixel_array() {
    let haze = std::fs::read_to_string("fixtures/recipes/clear-coat-haze.json").unwrap();
    let cases = [(r#"{"model":"phong","exponent":5091.6,"ks":0.28455,"kd":0.140315}"#, 1e-6), (haze.as_str(), 1e-8)];
    for (json, rtol) in cases {
        let failures = below_their_actual_error(json, "rhopoint-iq-20", rtol);
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}

/// The slope mixtures (`microfacet` with `populations`, docs/optics.md §4.1): one lobe per population for the
/// planner, widths from 6·10⁻⁴ to 0.6 side by side. Every default reading's estimate at every shipped geometry
/// the mixture compiles for must cover its actual error against the rtol-10⁻¹⁰ reading (as the generated
/// recipes above).
#[test]
fn slope_mixtures_estimates_cover_their_actual_error() {
    let gloss = standards::builtin().unwrap();
    let all = standards::builtin_all().unwrap();
    let tight = PlanOptions { rtol: 1e-10, max_seconds: None, rtol_from_data: false, ..PlanOptions::default() };
    let recipes = [
        // check_85.py §3's two-scale surface (tools/iq/check_mixture.py).
        r#"{"model":"microfacet","distribution":"beckmann","ior":1.52285,"populations":[{"roughness":0.0074049},{"weight":0.0675,"roughness":0.074116}]}"#,
        // The orange-peel panel's three populations (fixtures/real/models/panel-three-populations.json).
        r#"{"model":"microfacet","distribution":"ggx","ior":1.5202,"populations":[{"roughness":0.00064412},{"weight":0.56828,"roughness":0.0080461,"distribution":"beckmann"},{"weight":0.13205,"roughness":0.028039,"distribution":"beckmann"}]}"#,
        // GGX and Beckmann, rough, a conductor.
        r#"{"model":"microfacet","distribution":"ggx","ior":[0.2,3.5],"populations":[{"weight":0.5,"roughness":0.1},{"weight":0.3,"roughness":0.4,"distribution":"beckmann"},{"weight":0.2,"roughness":0.6}]}"#,
        // A narrow lobe beside a broad one with a halo (the two-scale surface over a mixture).
        r#"{"model":"microfacet","distribution":"ggx","ior":1.5,"populations":[{"roughness":0.002},{"weight":0.1,"roughness":0.05,"distribution":"beckmann"}],"scatter":{"psd":"k-correlation","rms_roughness_nm":10,"correlation_length_um":1.5,"c":4}}"#,
    ];
    let (mut checked, mut failures) = (0, Vec::new());
    for json in recipes {
        let m = glossmeter::recipe::parse_str(json, "fixtures/recipes/generated.json").unwrap();
        let geos = match Plan::compile(m.brdf.clone(), all.clone(), PlanOptions::default()) {
            Ok(_) => all.clone(),
            Err(_) => gloss.clone(),
        };
        let d = Plan::compile(m.brdf.clone(), geos.clone(), PlanOptions::default()).unwrap().execute();
        let r = Plan::compile(m.brdf.clone(), geos.clone(), tight.clone()).unwrap().execute();
        for (a, b) in d.iter().zip(&r) {
            let (Some(v), Some(vr)) = (a.value, b.value) else { continue };
            if !b.converged {
                continue;
            }
            checked += 1;
            let actual = (v - vr).abs();
            if actual > a.error_estimate {
                failures.push(format!(
                    "{} {}: actual {actual:e} > estimate {:e}: {json}",
                    a.geometry, a.name, a.error_estimate
                ));
            }
        }
    }
    assert!(checked >= 4 * 20, "only {checked} readings checked");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Pearlescent paints on every haze receptor, from rtol 10⁻⁴ to 10⁻¹⁰ (docs/accuracy.md §The estimate property,
/// *Pearl paints on the haze receptors*). The generated campaign above gives pearl flakes only to rough-coat paints
/// (family 10; family 9 is always metallic) and checks the default rtol alone. Here pearl paints with a smooth and
/// a rough coat, with mica above the resin's index (a smooth flake reflectance, read from its verified table) and
/// below it (ρ kinks at the critical cosine of total internal reflection and is evaluated directly), are read on
/// every geometry with a haze reading (E430 20° and 30°, ISO 13803, Rhopoint IQ, D4039) at rtol 10⁻⁴, 10⁻⁶,
/// 10⁻⁸ and 10⁻¹⁰, against the engine's rtol-10⁻¹¹ reading, with that reference's own estimate added to the
/// bound. `GLOSSMETER_PEARL_CASES=N` reads N recipes (default 4: one of each kind).
#[test]
fn pearl_paints_estimates_cover_their_actual_error_on_every_haze_receptor() {
    // The rtol-10⁻¹¹ reading (docs/accuracy.md): at `MIN_RTOL` (10⁻¹²) the rough-coat paints' ISO 13803
    // compensation and D4039 integrals reach the evaluation budget unconverged.
    const REFERENCE_RTOL: f64 = 1e-11;
    let cases = cases_from("GLOSSMETER_PEARL_CASES", 4);
    let report = std::env::var_os("GLOSSMETER_ESTIMATE_REPORT").is_some();
    let geos: Vec<_> = ["astm-e430-20", "astm-e430-30", "iso-13803-20", "rhopoint-iq-20", "astm-d4039"]
        .iter()
        .map(|id| standards::find(id).unwrap())
        .collect();
    let at = |rtol: f64| PlanOptions { rtol, max_seconds: None, rtol_from_data: false, ..PlanOptions::default() };
    let f = |x: f64| format!("{x:.6}");
    let mut rng = Rng(0x0000_9EA2_1F1A_4E55);
    let (mut checked, mut unchecked) = (0usize, 0usize);
    let (mut ratios, mut failures) = (vec![Vec::new(); 4], Vec::new());
    for i in 0..cases {
        // i % 4: 0 smooth coat, mica above the resin; 1 smooth, below; 2 rough, above; 3 rough, below.
        let mica = rng.uniform(1.50, 1.62);
        let coat = if i % 2 == 0 { rng.uniform(1.40, mica - 0.02) } else { rng.uniform(mica + 0.02, 1.80) };
        let rough = if i % 4 >= 2 {
            format!(
                r#","roughness":{},"distribution":"{}""#,
                f(rng.log_uniform(0.005, 0.2)),
                rng.pick(&["beckmann", "ggx"])
            )
        } else {
            String::new()
        };
        let (k, s) = (rng.log_uniform(0.05, 3.0), rng.log_uniform(0.05, 3.0));
        let flakes = pearlescent_flakes(rng.uniform(0.1, 0.4), rng.uniform(0.05, 0.3), rng.uniform(40.0, 160.0), mica);
        let json = paint(coat, &rough, [k, 0.5 * k, 0.2 * k], [s; 3], &flakes);
        let m = glossmeter::recipe::parse_str(&json, "fixtures/recipes/generated.json").unwrap();
        let r = Plan::compile(m.brdf.clone(), geos.clone(), at(REFERENCE_RTOL)).unwrap().execute();
        for (j, rtol) in [1e-4, 1e-6, 1e-8, 1e-10].into_iter().enumerate() {
            let d = Plan::compile(m.brdf.clone(), geos.clone(), at(rtol)).unwrap().execute();
            for (a, b) in d.iter().zip(&r) {
                assert_eq!((&a.geometry, &a.name), (&b.geometry, &b.name));
                let (Some(v), Some(vr)) = (a.value, b.value) else { continue };
                if !b.converged || !a.converged {
                    if report {
                        eprintln!(
                            "unchecked: pearl {i} {} {} at rtol {rtol:e} ({}, {})",
                            a.geometry, a.name, a.converged, b.converged
                        );
                    }
                    unchecked += 1;
                    continue;
                }
                checked += 1;
                let actual = (v - vr).abs();
                let bound = a.error_estimate + b.error_estimate;
                if actual > 0.0 {
                    ratios[j].push(bound / actual);
                }
                if actual > bound {
                    failures.push(format!(
                        "pearl {i} {} {} at rtol {rtol:e}: value {v:e}, reference {vr:e} ± {:e}: actual {actual:e} > \
                         estimate {:e}\n  {json}",
                        a.geometry, a.name, b.error_estimate, a.error_estimate
                    ));
                }
            }
        }
    }
    if report {
        for (ratios, rtol) in ratios.iter_mut().zip(["1e-4", "1e-6", "1e-8", "1e-10"]) {
            ratios.sort_by(f64::total_cmp);
            let q = |p: f64| ratios.get(((ratios.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(f64::NAN);
            eprintln!(
                "{cases} pearl paints at rtol {rtol}: {} inexact readings; (estimate + reference's)/actual: min \
                 {:.3e}, 10 % {:.3e}, median {:.3e}, 90 % {:.3e}",
                ratios.len(),
                q(0.0),
                q(0.1),
                q(0.5),
                q(0.9)
            );
        }
        eprintln!("{checked} readings checked, {unchecked} unchecked");
    }
    assert!(checked >= 60 * cases, "only {checked} readings checked ({unchecked} unchecked)");
    assert!(unchecked * 25 <= checked, "{unchecked} references did not converge (of {})", checked + unchecked);
    assert!(failures.is_empty(), "{} estimate(s) below the actual error:\n{}", failures.len(), failures.join("\n"));
}

/// Whether every reading of `json` on geometry `id` at `rtol` is within its estimate (plus the reference's) of
/// the rtol-10⁻¹⁰ reading; the failures as lines. A reading or reference without a value, or not converged, is
/// a failure too (a check that compared nothing must not pass).
/// The JSON of a generated paint: a clear coat of index `coat` (`rough`: the coat's roughness members, or
/// nothing), one pigment of K = `k` and S = `s` per mm, 0.05 mm thick over a 0.6 primer, and the flake member
/// `flakes` ([`metallic_flakes`], [`pearlescent_flakes`]). Numbers are written to six decimals.
fn paint(coat: f64, rough: &str, k: [f64; 3], s: [f64; 3], flakes: &str) -> String {
    let f = |x: f64| format!("{x:.6}");
    format!(
        r#"{{"model":"paint","clear_coat":{{"index":{}{rough}}},"pigmented_layer":{{"thickness_mm":0.05,"primer_reflectance":[0.6,0.6,0.6],"pigments":[{{"name":"p","concentration":1.0,"k_per_mm":[{},{},{}],"s_per_mm":[{},{},{}]}}]}},{flakes}}}"#,
        f(coat),
        f(k[0]),
        f(k[1]),
        f(k[2]),
        f(s[0]),
        f(s[1]),
        f(s[2])
    )
}

/// The `metallic_flakes` member of [`paint`]: index n + ik, slope spread, area ratio, 0.03 mm deep.
fn metallic_flakes(n: f64, k: f64, spread: f64, area: f64) -> String {
    let f = |x: f64| format!("{x:.6}");
    format!(
        r#""metallic_flakes":{{"n":{},"k":{},"spread_slope":{},"area_ratio":{},"depth_mm":0.03}}"#,
        f(n),
        f(k),
        f(spread),
        f(area)
    )
}

/// The `pearlescent_flakes` member of [`paint`]: slope spread, area ratio, TiO₂ thickness on 400 nm of mica of
/// index `mica`, 0.02 mm deep.
fn pearlescent_flakes(spread: f64, area: f64, tio2_nm: f64, mica: f64) -> String {
    let f = |x: f64| format!("{x:.6}");
    format!(
        r#""pearlescent_flakes":{{"spread_slope":{},"area_ratio":{},"depth_mm":0.02,"tio2_thickness_nm":{},"tio2_index":2.5,"mica_thickness_nm":400,"mica_index":{}}}"#,
        f(spread),
        f(area),
        f(tio2_nm),
        f(mica)
    )
}

fn below_their_actual_error(json: &str, id: &str, rtol: f64) -> Vec<String> {
    below_at(json, &[id], &[rtol], &mut Vec::new())
}

/// [`below_their_actual_error`] on the geometries `ids` at each of `rtols` against one rtol-10⁻¹⁰ reference,
/// with each (estimate + reference's)/actual pushed to `ratios`.
fn below_at(json: &str, ids: &[&str], rtols: &[f64], ratios: &mut Vec<f64>) -> Vec<String> {
    let tight = PlanOptions { rtol: 1e-10, max_seconds: None, rtol_from_data: false, ..PlanOptions::default() };
    let brdf = glossmeter::recipe::parse_str(json, "open.json").unwrap().brdf;
    let geos: Vec<_> = ids.iter().map(|id| standards::find(id).unwrap()).collect();
    let r = Plan::compile(brdf.clone(), geos.clone(), tight.clone()).unwrap().execute();
    let mut failures = Vec::new();
    for &rtol in rtols {
        let options = PlanOptions { rtol, ..tight.clone() };
        let d = Plan::compile(brdf.clone(), geos.clone(), options).unwrap().execute();
        if d.is_empty() || d.len() != r.len() {
            failures.push(format!("{json} {ids:?}: {} readings against {} references", d.len(), r.len()));
        }
        for (a, b) in d.iter().zip(&r) {
            let id = &a.geometry;
            let (Some(v), Some(vr), true, true) = (a.value, b.value, a.converged, b.converged) else {
                failures.push(format!("{json} {id} {} at rtol {rtol:e}: no converged value to compare", a.name));
                continue;
            };
            let actual = (v - vr).abs();
            if actual > 0.0 {
                let ratio = (a.error_estimate + b.error_estimate) / actual;
                if ratio < 2.0 && std::env::var_os("GLOSSMETER_ESTIMATE_REPORT").is_some() {
                    eprintln!("within 2× of its actual error: {json} {id} {} at rtol {rtol:e}: {ratio:.3}", a.name);
                }
                ratios.push(ratio);
            }
            if actual > a.error_estimate + b.error_estimate {
                failures.push(format!(
                    "{json} {id} {} at rtol {rtol:e}: actual {actual:e} > {:e}",
                    a.name, a.error_estimate
                ));
            }
        }
    }
    failures
}

/// GGX lobes wider than the u range at grazing (docs/instrument.md §Quadrature, *The u width at grazing*): the
/// Ward reading that set the narrowed u width had a Gaussian tail; a GGX tail is heavy, and the campaign's
/// generated GGX lobes are mostly narrower than D523 85°'s u range. Dielectrics and conductors, α 0.05–0.4,
/// every reading at D523 85° and TAPPI T480 75°, at rtol 10⁻⁴, 10⁻⁶ and 10⁻⁸, against the rtol-10⁻¹⁰ reading
/// (more cases by hand: `GLOSSMETER_GRAZING_CASES=N GLOSSMETER_ESTIMATE_REPORT=1`).
#[test]
fn wide_ggx_lobes_at_grazing_are_covered() {
    let cases = cases_from("GLOSSMETER_GRAZING_CASES", 2);
    let f = |x: f64| format!("{x:.6}");
    let mut rng = Rng(0x0000_0006_6A2E_85D5);
    let (mut failures, mut ratios) = (Vec::new(), Vec::new());
    for i in 0..cases {
        let alpha = rng.log_uniform(0.05, 0.4);
        let ior = if i % 2 == 0 {
            f(rng.uniform(1.4, 1.8))
        } else {
            format!("[{},{}]", f(rng.uniform(0.2, 2.5)), f(rng.uniform(0.0, 4.0)))
        };
        let json = format!(r#"{{"model":"microfacet","distribution":"ggx","roughness":{},"ior":{ior}}}"#, f(alpha));
        failures.extend(below_at(&json, &["astm-d523-85", "tappi-t480-75"], &[1e-4, 1e-6, 1e-8], &mut ratios));
    }
    assert_covered(&format!("{cases} wide GGX lobes at grazing"), ratios, &failures);
}

/// Narrow flakes under a smooth coat near grazing (docs/instrument.md §Quadrature, *The u width at grazing*,
/// *Under a coat*): the u splits of a lobe formed in the coat use η² cos² θ' / (y² sin θ cos θ), far wider than
/// the air's cot θ / y². The generated campaign's flakes (spread slopes 0.1–0.4) are wider than the stops and
/// never reach the lobe chart; these (0.002–0.03, as the literal reading of the paper's 0.25°, slope 0.0044)
/// do. Every reading at D523 85°, TAPPI T480 75° and D523 60°, at rtol 10⁻⁴, 10⁻⁶ and 10⁻⁸, against the
/// rtol-10⁻¹⁰ reading (more cases by hand: `GLOSSMETER_FLAKE_CASES=N GLOSSMETER_ESTIMATE_REPORT=1`).
#[test]
fn narrow_flakes_under_a_coat_are_covered_near_grazing() {
    let cases = cases_from("GLOSSMETER_FLAKE_CASES", 2);
    let mut rng = Rng(0x0000_F1A4_E5C0_A7ED);
    let (mut failures, mut ratios) = (Vec::new(), Vec::new());
    for i in 0..cases {
        let spread = rng.log_uniform(0.002, 0.03);
        let flakes = if i % 2 == 0 {
            metallic_flakes(rng.uniform(0.5, 2.5), rng.uniform(2.0, 7.0), spread, rng.uniform(0.05, 0.4))
        } else {
            pearlescent_flakes(spread, rng.uniform(0.05, 0.3), rng.uniform(40.0, 160.0), rng.uniform(1.5, 1.62))
        };
        let json = paint(rng.uniform(1.4, 1.8), "", [0.5, 0.3, 0.2], [0.4; 3], &flakes);
        failures.extend(below_at(
            &json,
            &["astm-d523-85", "tappi-t480-75", "astm-d523-60"],
            &[1e-4, 1e-6, 1e-8],
            &mut ratios,
        ));
    }
    assert_covered(&format!("{cases} narrow-flake paints"), ratios, &failures);
}

/// The verdict of a check made with [`below_at`]: something compared and nothing below its actual error; with
/// `GLOSSMETER_ESTIMATE_REPORT`, the ratios' minimum and median under `label`.
fn assert_covered(label: &str, mut ratios: Vec<f64>, failures: &[String]) {
    ratios.sort_by(f64::total_cmp);
    if std::env::var_os("GLOSSMETER_ESTIMATE_REPORT").is_some() {
        let q = |p: f64| ratios.get(((ratios.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(f64::NAN);
        eprintln!(
            "{label}: {} inexact readings; (estimate + reference's)/actual: min {:.3e}, median {:.3e}",
            ratios.len(),
            q(0.0),
            q(0.5)
        );
    }
    assert!(!ratios.is_empty(), "nothing compared");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The number of cases from the environment variable `name`, or `default`.
fn cases_from(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// The polar rule on an elongated kink square: GGX α = 0.0058 at D523 60° at 10⁻⁴, whose square's short sides
/// subtend 158°, read 1.20× below its actual error while that sector took one φ rule (its first two levels
/// agreed while both were pre-asymptotic); with sectors of at most 100° it is covered (docs/instrument.md
/// §Quadrature, "Polar variables for a narrow GGX lobe", *Why the cut*).
#[test]
fn the_polar_rule_on_an_elongated_kink_square_is_covered_at_1e_4() {
    let json = r#"{"model":"microfacet","distribution":"ggx","roughness":0.005809,"ior":1.816350}"#;
    let failures = below_their_actual_error(json, "astm-d523-60", 1e-4);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A lobe wider than the u range at grazing: Ward α = 0.161 at D523 85° at 10⁻⁸ read 2.9× below its actual
/// error while two boxes spanned the whole u range two widths out in v, where the lobe narrows in u to
/// cot θ / y² (docs/accuracy.md §The estimate property, "The Ward reading"; docs/instrument.md §Quadrature,
/// *The u width at grazing*).
#[test]
fn a_wide_lobe_at_grazing_is_covered_at_1e_8() {
    let json = r#"{"model":"ward","alpha":0.161047,"rho_s":0.194125,"rho_d":0.422030}"#;
    let failures = below_their_actual_error(json, "astm-d523-85", 1e-8);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
