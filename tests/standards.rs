//! The standards as data: every builtin loads, ids and key numbers are as documented, stops match an
//! independent closed form, user geometry files load, and bad files are refused with file + field.
use glossmeter::instrument::geometry::Stop;
use glossmeter::instrument::reading::{ReadingSpec, Scale};
use glossmeter::instrument::standards::{self, BUILTIN};
use glossmeter::Error;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

const IDS: &[&str] = &[
    "astm-d523-20",
    "astm-d523-60",
    "astm-d523-85",
    "iso-2813-20",
    "iso-2813-60",
    "iso-2813-85",
    "astm-e430-30",
    "astm-e430-20",
    "iso-13803-20",
    "astm-d4039",
    "astm-d2457-45",
    "tappi-t480-75",
    "rspec-20",
    "rhopoint-iq-20",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn deg(x: f64) -> f64 {
    x.to_radians()
}

#[test]
fn all_builtins_load_with_exact_ids() {
    let all = standards::builtin().expect("builtin geometries must load");
    let ids: BTreeSet<&str> = all.iter().map(|g| g.geometry.id.as_str()).collect();
    let want: BTreeSet<&str> = IDS.iter().copied().collect();
    assert_eq!(ids, want);
    assert_eq!(all.len(), IDS.len());
    for g in &all {
        assert_eq!(g.origin, "builtin");
        assert_eq!(g.reading_names.len(), g.geometry.readings.len());
        assert!(!standards::describe(g).is_empty());
        assert!(standards::list_line(g).starts_with(&g.geometry.id));
    }
}

#[test]
fn embedded_set_equals_files_on_disk() {
    let mut on_disk = BTreeSet::new();
    for e in std::fs::read_dir(root().join("standards")).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() && p.extension().is_some_and(|x| x == "json") {
            on_disk.insert(p.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    let embedded: BTreeSet<String> = BUILTIN.iter().map(|(f, _)| f.to_string()).collect();
    assert_eq!(on_disk, embedded, "standards/*.json and standards::BUILTIN differ");
    // The embedded text is the file's text.
    for (f, text) in BUILTIN {
        assert_eq!(std::fs::read_to_string(root().join("standards").join(f)).unwrap(), *text, "{f}");
    }
}

#[test]
fn every_number_has_source_and_status() {
    fn walk(v: &serde_json::Value, path: &str, n: &mut usize) {
        match v {
            serde_json::Value::Object(m) if m.contains_key("value") => {
                assert!(m["source"].as_str().is_some_and(|s| !s.trim().is_empty()), "{path}: source");
                assert!(["verified", "secondary", "assumed"].contains(&m["status"].as_str().unwrap()), "{path}");
                *n += 1;
            }
            serde_json::Value::Object(m) => m.iter().for_each(|(k, x)| walk(x, &format!("{path}.{k}"), n)),
            serde_json::Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| walk(x, &format!("{path}[{i}]"), n)),
            serde_json::Value::Number(_) => panic!("{path}: bare number without provenance"),
            _ => {}
        }
    }
    for g in standards::builtin().unwrap() {
        let mut n = 0;
        walk(&g.spec, &g.geometry.id, &mut n);
        assert!(g.geometry.is_composite() || n >= 6, "{}: only {n} sourced numbers", g.geometry.id);
    }
}

#[test]
fn d523_numbers() {
    let g60 = standards::find("astm-d523-60").unwrap().geometry;
    assert!((g60.theta - deg(60.0)).abs() < 1e-15);
    assert_eq!(g60.scale.black_glass_index().unwrap(), 1.567);
    assert_eq!(g60.receptor("gloss"), Some(&Stop::from_angles(deg(4.4), deg(11.7), 0.0)));
    let r = g60.receptor("gloss").unwrap();
    assert!((r.p[1].atan().to_degrees() * 2.0 - 4.4).abs() < 1e-12);
    assert!((r.q[1].atan().to_degrees() * 2.0 - 11.7).abs() < 1e-12);
    assert_eq!(g60.readings, vec![ReadingSpec::Gloss { receptor: "gloss".into() }]);
    for (id, a, b) in [("astm-d523-20", 1.8, 3.6), ("astm-d523-85", 4.0, 6.0), ("iso-2813-60", 4.4, 11.7)] {
        let g = standards::find(id).unwrap().geometry;
        assert_eq!(g.receptor("gloss"), Some(&Stop::from_angles(deg(a), deg(b), 0.0)), "{id}");
    }
    // ISO 2813 and D523 are the same geometry.
    for a in [20, 60, 85] {
        let d = standards::find(&format!("astm-d523-{a}")).unwrap().geometry;
        let i = standards::find(&format!("iso-2813-{a}")).unwrap().geometry;
        assert_eq!((d.theta, d.scale, d.source, &d.receptors), (i.theta, i.scale, i.source, &i.receptors));
    }
    assert_eq!(standards::find("tappi-t480-75").unwrap().geometry.scale.black_glass_index(), Some(1.540));
}

#[test]
fn stop_solid_angle_matches_rectangular_pyramid() {
    // Independent closed form for a centred stop of full angles a × b: Ω = 4·asin(sin(a/2)·sin(b/2)).
    let pyramid = |a: f64, b: f64| 4.0 * ((0.5 * a).sin() * (0.5 * b).sin()).asin();
    for (id, a, b) in [("astm-d523-20", 1.8, 3.6), ("astm-d523-60", 4.4, 11.7), ("astm-d523-85", 4.0, 6.0)] {
        let g = standards::find(id).unwrap().geometry;
        let om = g.receptor("gloss").unwrap().solid_angle();
        assert!((om - pyramid(deg(a), deg(b))).abs() < 1e-12, "{id}: {om}");
        let s = g.source.solid_angle();
        assert!((s - pyramid(deg(0.75), deg(2.5))).abs() < 1e-12, "{id} source: {s}");
    }
    // Values from the project notes (computed there independently): 1.974e-3, 1.565e-2, 7.306e-3 sr.
    let om = |id: &str| standards::find(id).unwrap().geometry.receptor("gloss").unwrap().solid_angle();
    assert!((om("astm-d523-20") - 1.974e-3).abs() < 1e-6);
    assert!((om("astm-d523-60") - 1.565e-2).abs() < 1e-5);
    assert!((om("astm-d523-85") - 7.306e-3).abs() < 1e-6);
}

#[test]
fn e430_offsets_and_named_readings() {
    let g = standards::find("astm-e430-30").unwrap();
    assert_eq!(
        g.reading_names,
        vec!["gloss", "haze-narrow", "haze-wide", "doi", "haze-narrow-compensated", "haze-wide-compensated"]
    );
    let geo = &g.geometry;
    let centre = |n: &str| {
        let s = geo.receptor(n).unwrap();
        0.5 * (s.p[0].atan() + s.p[1].atan()).to_degrees()
    };
    for (n, off) in [
        ("specular", 0.0),
        ("doi-minus", -0.3),
        ("doi-plus", 0.3),
        ("haze-narrow-minus", -2.0),
        ("haze-narrow-plus", 2.0),
        ("haze-wide-minus", -5.0),
        ("haze-wide-plus", 5.0),
    ] {
        assert!((centre(n) - off).abs() < 1e-12, "{n}");
    }
    // A perfect mirror puts nothing into the ±0.3° DOI receptors: the source image (in-plane half-width)
    // and the receptor half-width together stay inside 0.3°.
    let src_half = geo.source.p[1].atan();
    let doi = geo.receptor("doi-plus").unwrap();
    assert!(doi.p[0].atan() > src_half);
    let g20 = standards::find("astm-e430-20").unwrap().geometry;
    let c = |n: &str| {
        let s = g20.receptor(n).unwrap();
        (g20.theta + 0.5 * (s.p[0].atan() + s.p[1].atan())).to_degrees()
    };
    assert!((c("haze-narrow-minus") - 18.1).abs() < 1e-9 && (c("haze-narrow-plus") - 21.9).abs() < 1e-9);
}

#[test]
fn iso_13803_and_d4039() {
    let g = standards::find("iso-13803-20").unwrap().geometry;
    assert!(g.readings.iter().any(|r| matches!(r, ReadingSpec::LogHaze { k, .. } if *k == 1285.1)));
    let k = 1285.1f64;
    assert!((k * (100.0f64 / 20.0 + 1.0).log10() - 1000.0).abs() < 0.05);
    let c = standards::find("astm-d4039").unwrap();
    assert!(c.geometry.is_composite());
    assert_eq!(
        c.geometry.readings,
        vec![ReadingSpec::HazeIndex { minuend: "astm-d523-60".into(), subtrahend: "astm-d523-20".into() }]
    );
    assert!(standards::describe(&c).contains("composite"));
}

#[test]
fn unknown_id_lists_known_ids() {
    match standards::find("astm-d523-45") {
        Err(Error::Usage(m)) => assert!(m.contains("astm-d523-45") && m.contains("astm-d523-60"), "{m}"),
        other => panic!("expected a usage error, got {other:?}"),
    }
}

#[test]
fn describe_shows_every_number_with_status_and_source() {
    let d = standards::describe(&standards::find("astm-d523-60").unwrap());
    for needle in ["ASTM D523-14", "60°", "1.567", "4.4°", "11.7°", "0.75°", "[assumed]", "[secondary]", "source:"]
    {
        assert!(d.contains(needle), "missing {needle} in\n{d}");
    }
}

fn fixture(name: &str) -> PathBuf {
    root().join("fixtures/geometry").join(name)
}

#[test]
fn user_geometry_at_89_degrees_loads() {
    let p = fixture("user-grazing-89.json");
    let g = standards::load_file(&p).unwrap();
    assert!((g.geometry.theta - deg(89.0)).abs() < 1e-15);
    assert_eq!(g.origin, p.display().to_string());
    let g = standards::load_file(&fixture("user-e430-like.json")).unwrap();
    assert_eq!(g.reading_names.len(), g.geometry.readings.len());
}

fn expect_input_error(path: &Path, field: &str, words: &str) {
    match standards::load_file(path) {
        Err(e @ Error::Input { .. }) => {
            let Error::Input { file, field: f, message } = &e else { unreachable!() };
            assert_eq!(file, &path.display().to_string());
            assert_eq!(f, field, "{e}");
            assert!(message.contains(words), "{e}");
            let shown = e.to_string();
            assert!(shown.contains(&path.display().to_string()) && shown.contains(field), "{shown}");
        }
        other => panic!("{}: expected an input error, got {other:?}", path.display()),
    }
}

#[test]
fn bad_geometry_files_name_file_and_field() {
    expect_input_error(&fixture("bad-malformed.json"), "", "malformed JSON");
    expect_input_error(&fixture("bad-missing-angle.json"), "/angle_deg", "missing");
    expect_input_error(&fixture("bad-negative-aperture.json"), "/receptors/0/in_plane_deg/value", "out of range");
    expect_input_error(
        &fixture("bad-unknown-receptor.json"),
        "/readings/1/receptors/1",
        "unknown receptor \"haze-far\"",
    );
    expect_input_error(&fixture("bad-unknown-status.json"), "/reference_index/status", "verified, secondary, assumed");
    expect_input_error(&fixture("bad-circle.json"), "/receptors/0/shape", "circular stops are not supported yet");
    expect_input_error(&fixture("bad-unknown-field.json"), "/source/in_plane", "unknown field");
    expect_input_error(&fixture("bad-below-horizon.json"), "/receptors/0/offset_deg", "below");
    expect_input_error(&fixture("bad-empty-source.json"), "/angle_deg/source", "must not be empty");
    // A composite naming an unknown id was once an error with neither file nor field, and a user file could
    // take a shipped id (`docs/instrument.md` §2.5: every error names the file and the field).
    expect_input_error(
        &fixture("bad-composite-unknown-part.json"),
        "/readings/0/minuend",
        "\"astm-d523-61\" is not a shipped non-composite geometry id",
    );
    expect_input_error(&fixture("bad-shipped-id.json"), "/id", "is the id of a shipped geometry");
}

#[test]
fn every_bad_fixture_is_refused_and_every_user_fixture_loads() {
    for e in std::fs::read_dir(root().join("fixtures/geometry")).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let r = standards::load_file(&p);
        if name.starts_with("bad-") {
            assert!(matches!(r, Err(Error::Input { .. })), "{name} should be refused");
        } else {
            assert!(r.is_ok(), "{name}: {:?}", r.err());
        }
    }
}

#[test]
fn range_checks() {
    let base = std::fs::read_to_string(fixture("user-grazing-89.json")).unwrap();
    let with = |from: &str, to: &str| {
        assert!(base.contains(from), "{from}");
        standards::parse(&base.replacen(from, to, 1), "t.json")
    };
    let field = |r: glossmeter::Result<_>| match r {
        Err(Error::Input { field, .. }) => field,
        Ok(_) => "accepted".to_string(),
        Err(e) => panic!("{e}"),
    };
    assert_eq!(field(with("\"value\": 89", "\"value\": 90")), "/angle_deg/value");
    assert_eq!(field(with("\"value\": 89", "\"value\": 0")), "/angle_deg/value");
    assert_eq!(field(with("\"value\": 1.567", "\"value\": 2.1")), "/reference_index/value");
    assert_eq!(field(with("\"value\": 1.567", "\"value\": 1.3")), "accepted");
    assert_eq!(field(with("\"value\": 0.5,", "\"value\": 20,")), "/source/in_plane_deg/value");
    assert_eq!(field(with("\"value\": 0.5,", "\"value\": 0,")), "/source/in_plane_deg/value");
    assert_eq!(field(with("\"status\": \"assumed\"", "\"status\": \"guess\"")), "/angle_deg/status");
    assert_eq!(field(with("\"quantity\": \"gloss\"", "\"quantity\": \"sheen\"")), "/readings/0/quantity");
    let missing_readings = standards::parse(&base.replacen("\"readings\"", "\"readingz\"", 1), "t.json");
    assert_eq!(field(missing_readings), "/readingz");
}

/// Scales as data (`docs/instrument.md` §1.5): every shipped non-composite geometry states its scale; a user file may
/// choose the mirror scale; unknown kinds and a doubly given scale are refused with the field named.
#[test]
fn scales_are_data_and_user_files_choose() {
    for g in standards::builtin().unwrap() {
        if g.geometry.is_composite() {
            continue;
        }
        assert!(g.spec.get("scale").is_some(), "{}: no scale", g.geometry.id);
        assert!(g.spec.get("reference_index").is_none(), "{}: old top-level reference_index", g.geometry.id);
        assert!(standards::describe(&g).contains("scale: "), "{}", g.geometry.id);
    }
    let base = std::fs::read_to_string(fixture("user-e430-like.json")).unwrap();
    assert!(base.contains("\"reference_index\""), "the user fixture keeps the older form");
    let legacy = standards::parse(&base, "t.json").unwrap();
    assert_eq!(legacy.geometry.scale, Scale::BlackGlass { index: 1.5, value: 100.0 });
    let v: serde_json::Value = serde_json::from_str(&base).unwrap();
    let with_scale = |scale: serde_json::Value, keep_old: bool| {
        let mut v = v.clone();
        if !keep_old {
            v.as_object_mut().unwrap().remove("reference_index");
        }
        v["scale"] = scale;
        standards::parse(&v.to_string(), "t.json")
    };
    let sourced = |x: f64| serde_json::json!({"value": x, "source": "test", "status": "assumed"});
    let mirror = with_scale(serde_json::json!({"kind": "mirror", "assigned_gu": sourced(1000.0)}), false).unwrap();
    assert_eq!(mirror.geometry.scale, Scale::Mirror { value: 1000.0 });
    assert!(standards::describe(&mirror).contains("mirror scale: reflectance × 1000"));
    let glass =
        serde_json::json!({"kind": "black-glass", "reference_index": sourced(1.54), "assigned_gu": sourced(100.0)});
    assert_eq!(
        with_scale(glass.clone(), false).unwrap().geometry.scale,
        Scale::BlackGlass { index: 1.54, value: 100.0 }
    );
    let field = |r: glossmeter::Result<standards::StandardGeometry>| match r {
        Err(Error::Input { field, message, .. }) => (field, message),
        Ok(_) => panic!("accepted"),
        Err(e) => panic!("{e}"),
    };
    let (f, m) = field(with_scale(serde_json::json!({"kind": "paper", "assigned_gu": sourced(1.0)}), false));
    assert_eq!(f, "/scale/kind");
    assert!(m.contains("unknown scale kind") && m.contains("black-glass, mirror"), "{m}");
    let (f, m) = field(with_scale(glass, true));
    assert_eq!(f, "/reference_index");
    assert!(m.contains("not both"), "{m}");
    let (f, _) = field(with_scale(serde_json::json!({"kind": "mirror"}), false));
    assert_eq!(f, "/scale/assigned_gu");
    let mut none = v.clone();
    none.as_object_mut().unwrap().remove("reference_index");
    let (f, m) = field(standards::parse(&none.to_string(), "t.json"));
    assert_eq!(f, "/scale");
    assert!(m.contains("missing"), "{m}");
}
