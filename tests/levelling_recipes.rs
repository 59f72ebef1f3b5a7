//! Levelling in recipes (docs/model.md §From the cured spectrum to the coat): a paint coat given by its
//! application. The cured spectrum's moments against closed forms, the smooth limit bit for bit, the readings'
//! direction and size against film build and viscosity, bad input naming its JSON Pointer, and the shipped
//! example recipes read through the default panel.
mod common;
use glossmeter::instrument::plan::{PlanOptions, Reading};
use glossmeter::instrument::standards;
use glossmeter::optics::levelling::{Application, CuredPsd, Flow, ViscosityPoint};
use glossmeter::optics::scatter::Psd;
use glossmeter::{api, recipe};
use serde_json::{json, Value};
use std::f64::consts::PI;

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn black() -> Value {
    let text = std::fs::read_to_string(root().join("fixtures/recipes/solid-black.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A Gaussian texture (σ nm, ℓ µm) on a film of wet thickness `wet` µm, η constant, flowing 60 s.
fn application(sigma: f64, ell: f64, wet: f64, eta: f64) -> Value {
    json!({
        "texture": {"psd": "gaussian", "rms_roughness_nm": sigma, "correlation_length_um": ell},
        "wet_film_um": wet, "volume_solids": 0.5, "surface_tension_mn_m": 30, "flash_off_s": 20,
        "viscosity": [{"t_s": 0, "eta_pa_s": eta}, {"t_s": 60, "eta_pa_s": eta}]
    })
}

fn with_application(app: Value) -> Value {
    let mut v = black();
    v["clear_coat"]["application"] = app;
    v
}

const IDS: [&str; 3] = ["astm-d523-20", "astm-e430-30", "iso-13803-20"];

fn read(v: &Value) -> Vec<Reading> {
    let m = recipe::parse_str(&v.to_string(), "test.json").unwrap();
    let gs: Vec<_> = IDS.iter().map(|id| standards::find(id).unwrap()).collect();
    api::measure(&m, &gs, &PlanOptions::default()).unwrap()
}

fn value(rs: &[Reading], geometry: &str, name: &str) -> f64 {
    let r = rs.iter().find(|r| r.geometry == geometry && r.name == name).unwrap_or_else(|| {
        panic!("{geometry} {name} among {:?}", rs.iter().map(|r| (&r.geometry, &r.name)).collect::<Vec<_>>())
    });
    r.value.unwrap()
}

/// The Gaussian texture's cured moments in closed form. With u = f², a = π²ℓ², c = (32π⁴/3)L:
/// Sq² = v²π²ℓ²σ²·I, Sdq² = 4π²·v²π²ℓ²σ²·J, I = ∫₀^∞ e^{−au−cu²} du = ½√(π/c)·e^{a²/4c}·erfc(a/(2√c)),
/// J = ∫₀^∞ u e^{−au−cu²} du = (1 − a·I)/(2c); without levelling Sq = vσ and Sdq = 2vσ/ℓ.
fn gaussian_closed_form(sigma: f64, ell: f64, v: f64, l: f64) -> (f64, f64) {
    let k = v * v * PI * PI * ell * ell * sigma * sigma;
    if l == 0.0 {
        return ((v * sigma).powi(2), (2.0 * v * sigma / ell).powi(2));
    }
    let (a, c) = (PI * PI * ell * ell, 32.0 * PI.powi(4) / 3.0 * l);
    let i = 0.5 * (PI / c).sqrt() * (a * a / (4.0 * c)).exp() * libm::erfc(a / (2.0 * c.sqrt()));
    let j = (1.0 - a * i) / (2.0 * c);
    (k * i, 4.0 * PI * PI * k * j)
}

#[test]
fn gaussian_cured_moments_match_their_closed_forms() {
    for (sigma, ell, v, l) in
        [(500.0, 100.0, 0.5, 0.0), (500.0, 100.0, 0.5, 1.0e6), (2000.0, 40.0, 0.3, 2.0e5), (800.0, 300.0, 0.8, 3.0e8)]
    {
        let cured = CuredPsd::new(Psd::Gaussian { sigma, ell }, v, Flow { l_um4: l, m_um2: 0.0 });
        let (sq2, sdq2) = gaussian_closed_form(sigma, ell, v, l);
        let got_sq2 = cured.band_ms(0.0, f64::INFINITY);
        let got_sdq2 = cured.slope_ms();
        assert!((got_sq2 / sq2 - 1.0).abs() < 1e-9, "σ {sigma} ℓ {ell} L {l}: Sq² {got_sq2} vs {sq2}");
        assert!((got_sdq2 / sdq2 - 1.0).abs() < 1e-9, "σ {sigma} ℓ {ell} L {l}: Sdq² {got_sdq2} vs {sdq2}");
        if l > 0.0 {
            // Levelling takes more of the slopes (short waves) than of the heights.
            let (sq0, sdq0) = gaussian_closed_form(sigma, ell, v, 0.0);
            assert!(sdq2 / sdq0 < sq2 / sq0 && sq2 < sq0, "{sq2} {sdq2}");
        }
    }
}

/// A texture levelled to nothing (Sdq below the smooth limit 10⁻⁷) gives the smooth coat: every reading of the
/// recipe without an application, bit for bit.
#[test]
fn levelling_to_nothing_reads_as_the_smooth_coat_bit_for_bit() {
    let smooth = read(&black());
    let levelled = read(&with_application(application(1e-4, 100.0, 60.0, 1.0)));
    assert_eq!(smooth.len(), levelled.len());
    for (a, b) in smooth.iter().zip(&levelled) {
        assert_eq!((&a.geometry, &a.name), (&b.geometry, &b.name));
        assert_eq!(a.value.map(f64::to_bits), b.value.map(f64::to_bits), "{} {}", a.geometry, a.name);
        assert_eq!(a.error_estimate.to_bits(), b.error_estimate.to_bits(), "{} {}", a.geometry, a.name);
    }
}

/// The coat's roughness from the application is the cured texture's Sdq: the Gaussian texture's closed form.
/// Film build h and viscosity η enter through L = γ·∫h³/η dt only: a thicker film or a thinner paint levels
/// more (L ∝ h³/η), so Sdq falls, and with it the facets' spread: 20° gloss and DOI rise, haze falls.
#[test]
fn film_build_and_viscosity_move_gloss_haze_and_doi_as_the_levelling_gives() {
    let (sigma, ell) = (3000.0, 60.0);
    let alpha = |wet: f64, eta: f64| {
        let a = Application {
            wet_film_um: wet,
            volume_solids: 0.5,
            surface_tension_mn_m: 30.0,
            flash_off_s: 20.0,
            viscosity: vec![ViscosityPoint { t_s: 0.0, eta_pa_s: eta }, ViscosityPoint { t_s: 60.0, eta_pa_s: eta }],
            surface_tension_gradient_mn_m_per_um: 0.0,
        };
        gaussian_closed_form(sigma, ell, 0.5, a.levelling_integral_um4()).1.sqrt() * 1e-3
    };
    let readings = |wet: f64, eta: f64| {
        let rs = read(&with_application(application(sigma, ell, wet, eta)));
        (value(&rs, "astm-d523-20", "gloss"), value(&rs, "iso-13803-20", "haze"), value(&rs, "astm-e430-30", "doi"))
    };
    // The computed example: the film's own L, the closed-form α, and the reading of the same coat given that
    // α as an explicit roughness.
    let mut explicit = black();
    explicit["clear_coat"]["roughness"] = json!(alpha(20.0, 100.0));
    let rs = read(&explicit);
    let (g, h, d) = readings(20.0, 100.0);
    for (x, y) in [
        (g, value(&rs, "astm-d523-20", "gloss")),
        (h, value(&rs, "iso-13803-20", "haze")),
        (d, value(&rs, "astm-e430-30", "doi")),
    ] {
        assert!((x - y).abs() <= 1e-6 * y.abs().max(1.0), "application {x} vs explicit roughness {y}");
    }
    let builds = [15.0, 20.0, 25.0, 30.0];
    let by_build: Vec<_> = builds.iter().map(|&w| (alpha(w, 100.0), readings(w, 100.0))).collect();
    let etas = [400.0, 200.0, 100.0, 50.0];
    let by_eta: Vec<_> = etas.iter().map(|&e| (alpha(20.0, e), readings(20.0, e))).collect();
    for series in [&by_build, &by_eta] {
        for w in series.windows(2) {
            let ((a0, (g0, h0, d0)), (a1, (g1, h1, d1))) = (w[0], w[1]);
            assert!(a1 < a0, "α falls with more levelling: {series:?}");
            assert!(g1 > g0 && h1 < h0 && d1 > d0, "gloss ↑ haze ↓ DOI ↑ with more levelling: {series:?}");
        }
    }
    eprintln!("film build {builds:?} µm: {by_build:?}\nviscosity {etas:?} Pa·s: {by_eta:?}");
}

#[test]
fn bad_applications_name_their_pointer() {
    let cases: Vec<(Value, &str)> = vec![
        (json!({"wet_film_um": -5}), "/clear_coat/application/wet_film_um"),
        (json!({"wet_film_um": 0}), "/clear_coat/application/wet_film_um"),
        (json!({"surface_tension_mn_m": 0}), "/clear_coat/application/surface_tension_mn_m"),
        (json!({"volume_solids": 1.5}), "/clear_coat/application/volume_solids"),
        (
            json!({"viscosity": [{"t_s": 0, "eta_pa_s": 1}, {"t_s": 60, "eta_pa_s": 0}]}),
            "/clear_coat/application/viscosity/1/eta_pa_s",
        ),
        (
            json!({"viscosity": [{"t_s": 0, "eta_pa_s": 10}, {"t_s": 60, "eta_pa_s": 1}]}),
            "/clear_coat/application/viscosity/1/eta_pa_s",
        ),
        (
            json!({"viscosity": [{"t_s": 0, "eta_pa_s": 1}, {"t_s": 0, "eta_pa_s": 2}]}),
            "/clear_coat/application/viscosity/1/t_s",
        ),
        (json!({"viscosity": [{"t_s": 5, "eta_pa_s": 1}]}), "/clear_coat/application/viscosity/0/t_s"),
        (json!({"viscosity": []}), "/clear_coat/application/viscosity"),
        // A levelling integral beyond double precision: a film the model cannot integrate.
        (
            json!({"wet_film_um": 10000, "surface_tension_mn_m": 1000, "flash_off_s": 0,
                   "viscosity": [{"t_s": 0, "eta_pa_s": 1e-300}, {"t_s": 1e7, "eta_pa_s": 1e-300}]}),
            "/clear_coat/application/viscosity",
        ),
        (
            json!({"texture": {"psd": "gaussian", "rms_roughness_nm": 0, "correlation_length_um": 50}}),
            "/clear_coat/application/texture/rms_roughness_nm",
        ),
        (
            json!({"texture": {"psd": "gaussian", "rms_roughness_nm": 10, "correlation_length_um": 50, "c": 2}}),
            "/clear_coat/application/texture/c",
        ),
        (
            json!({"texture": {"psd": "lorentz", "rms_roughness_nm": 10, "correlation_length_um": 50}}),
            "/clear_coat/application/texture/psd",
        ),
        // A surface-tension gradient outside its range, or one that grows the texture beyond the linear model.
        (
            json!({"surface_tension_gradient_mn_m_per_um": 5000}),
            "/clear_coat/application/surface_tension_gradient_mn_m_per_um",
        ),
        (
            json!({"surface_tension_gradient_mn_m_per_um": "high"}),
            "/clear_coat/application/surface_tension_gradient_mn_m_per_um",
        ),
        (
            json!({"surface_tension_gradient_mn_m_per_um": 900}),
            "/clear_coat/application/surface_tension_gradient_mn_m_per_um",
        ),
    ];
    for (patch, pointer) in cases {
        let mut app = application(3000.0, 60.0, 20.0, 100.0);
        for (k, v) in patch.as_object().unwrap() {
            app[k] = v.clone();
        }
        match recipe::parse_str(&with_application(app).to_string(), "coat.json") {
            Err(glossmeter::Error::Input { file, field, message }) => {
                assert_eq!((file.as_str(), field.as_str()), ("coat.json", pointer), "{patch}: {message}");
                assert!(!message.to_string().is_empty());
            }
            other => panic!("{patch}: expected an input error at {pointer}, got {other:?}"),
        }
    }
    // An application beside an explicit roughness or scatter is refused at the application.
    for (key, v) in [
        ("roughness", json!(0.01)),
        ("scatter", json!({"psd": "gaussian", "rms_roughness_nm": 2, "correlation_length_um": 5})),
    ] {
        let mut r = with_application(application(3000.0, 60.0, 20.0, 100.0));
        r["clear_coat"][key] = v;
        match recipe::parse_str(&r.to_string(), "coat.json") {
            Err(glossmeter::Error::Input { field, message, .. }) => {
                assert_eq!(field, "/clear_coat/application", "{message}");
                assert!(message.to_string().contains(key), "{message}");
            }
            other => panic!("{key}: expected an input error, got {other:?}"),
        }
    }
}

/// A surface-tension gradient (docs/model.md §Levelling of the applied texture, Overdiep's term) moves the readings
/// the way its sign says: γ' > 0 works against levelling (rougher cured coat: lower 20° gloss and DOI, more haze),
/// γ' < 0 helps it. The gradient is chosen so that the largest growth is 4× (within the linear model's 10×).
#[test]
fn a_surface_tension_gradient_moves_the_readings_by_its_sign() {
    let (sigma, ell, wet, eta) = (3000.0, 60.0, 40.0, 1000.0);
    let film = |g: f64| Application {
        wet_film_um: wet,
        volume_solids: 0.5,
        surface_tension_mn_m: 30.0,
        flash_off_s: 20.0,
        viscosity: vec![ViscosityPoint { t_s: 0.0, eta_pa_s: eta }, ViscosityPoint { t_s: 60.0, eta_pa_s: eta }],
        surface_tension_gradient_mn_m_per_um: g,
    };
    // The growth's exponent is quadratic in γ': ln growth(γ') = (γ'/γ₀)²·ln growth(γ₀).
    let g0 = 1e-3;
    let ln0 = film(g0).largest_growth().ln();
    assert!(ln0.is_finite() && ln0 > 0.0, "{ln0}");
    let g = g0 * (4f64.ln() / ln0).sqrt();
    assert!((film(g).largest_growth() / 4.0 - 1.0).abs() < 1e-9);
    let readings = |g: f64| {
        let mut app = application(sigma, ell, wet, eta);
        app["surface_tension_gradient_mn_m_per_um"] = g.into();
        let rs = read(&with_application(app));
        (value(&rs, "astm-d523-20", "gloss"), value(&rs, "iso-13803-20", "haze"), value(&rs, "astm-e430-30", "doi"))
    };
    let (against, plain, with) = (readings(g), readings(0.0), readings(-g));
    assert!(against.0 < plain.0 && plain.0 < with.0, "20° gloss: {against:?} {plain:?} {with:?}");
    assert!(against.1 > plain.1 && plain.1 > with.1, "haze: {against:?} {plain:?} {with:?}");
    assert!(against.2 < plain.2 && plain.2 < with.2, "DOI: {against:?} {plain:?} {with:?}");
}

/// A Gwyddion Simple Field of `z` (µm), `n` × `n` points `dx_um` apart, for a recipe's measured texture.
fn write_gsf(path: &std::path::Path, n: usize, dx_um: f64, z: impl Fn(usize, usize) -> f64) {
    let side = n as f64 * dx_um;
    let mut bytes = format!(
        "Gwyddion Simple Field 1.0\nXRes = {n}\nYRes = {n}\nXReal = {side}\nYReal = {side}\nXYUnits = um\nZUnits = um\n"
    )
    .into_bytes();
    bytes.extend(std::iter::repeat_n(0u8, 4 - bytes.len() % 4));
    for j in 0..n {
        for i in 0..n {
            bytes.extend((z(i, j) as f32).to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// A measured texture (docs/model.md §From the cured spectrum to the coat) is levelled mode by mode: a map that is
/// one sinusoid of amplitude a and wavelength Λ cures to the rms slope v·T(1/Λ)·(2π/Λ)·a/√2 (T the amplitude
/// transfer), so the coat reads as the same paint given that α as its roughness. A map and a PSD together, a map
/// that levels flat and a missing file are refused at their pointers.
#[test]
fn a_measured_texture_levels_mode_by_mode() {
    let dir = common::tmp_dir("measured-texture");
    std::fs::create_dir_all(&dir).unwrap();
    let (n, dx, periods, a) = (64, 10.0, 4.0, 1.0);
    let lambda = n as f64 * dx / periods;
    let wave = dir.join("wave.gsf");
    write_gsf(&wave, n, dx, |i, _| a * (2.0 * PI * periods * i as f64 / n as f64).cos());
    // η chosen so that the wave keeps half its amplitude: L ∝ 1/η at constant η.
    let film = |eta: f64| Application {
        wet_film_um: 20.0,
        volume_solids: 0.5,
        surface_tension_mn_m: 30.0,
        flash_off_s: 20.0,
        viscosity: vec![ViscosityPoint { t_s: 0.0, eta_pa_s: eta }, ViscosityPoint { t_s: 60.0, eta_pa_s: eta }],
        surface_tension_gradient_mn_m_per_um: 0.0,
    };
    let l_target = 2f64.ln() / (16.0 * PI.powi(4) / 3.0 * lambda.powi(-4));
    let eta = film(1.0).levelling_integral_um4() / l_target;
    let t = film(eta).amplitude_transfer(1.0 / lambda);
    assert!((t - 0.5).abs() < 1e-9, "{t}");
    let alpha = 0.5 * t * 2.0 * PI / lambda * a / 2f64.sqrt();
    let mut app = application(1.0, 1.0, 20.0, eta);
    app["texture"] = json!({"file": wave.to_str().unwrap(), "levelling": "mean"});
    let measured = read(&with_application(app.clone()));
    let mut explicit = black();
    explicit["clear_coat"]["roughness"] = json!(alpha);
    let given = read(&explicit);
    for (m, g) in measured.iter().zip(&given) {
        let (m, g) = (m.value.unwrap(), g.value.unwrap());
        assert!((m - g).abs() <= 1e-5 * g.abs().max(1.0), "{m} vs {g} (α = {alpha})");
    }
    // Refused: both a PSD and a file; a flat map; a file that is not there.
    let mut both = app.clone();
    both["texture"]["psd"] = json!("gaussian");
    let flat = dir.join("flat.gsf");
    write_gsf(&flat, 8, 1.0, |_, _| 0.25);
    let mut level = app.clone();
    level["texture"]["file"] = json!(flat.to_str().unwrap());
    let mut missing = app.clone();
    missing["texture"]["file"] = json!(dir.join("none.x3p").to_str().unwrap());
    for (case, pointer) in [(both, "file"), (level, "file"), (missing, "file")] {
        match recipe::parse_str(&with_application(case).to_string(), "coat.json") {
            Err(glossmeter::Error::Input { field, message, .. }) => {
                assert_eq!(field, format!("/clear_coat/application/texture/{pointer}"), "{message}")
            }
            other => panic!("expected an input error at texture/{pointer}, got {other:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The command line: a bad application exits 2 naming the file and the pointer; the shipped examples read
/// through the default panel from their application data alone (no roughness, no scatter).
#[test]
fn the_command_line_reads_levelled_recipes_and_refuses_bad_ones() {
    let exe = env!("CARGO_BIN_EXE_glossmeter");
    let dir = common::tmp_dir("levelling");
    std::fs::create_dir_all(&dir).unwrap();
    let mut app = application(3000.0, 60.0, 20.0, 100.0);
    app["viscosity"][1]["eta_pa_s"] = json!(-3);
    let bad = dir.join("bad-coat.json");
    std::fs::write(&bad, with_application(app).to_string()).unwrap();
    let out = std::process::Command::new(exe).arg("measure").arg(&bad).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad-coat.json") && err.contains("/clear_coat/application/viscosity/1/eta_pa_s"), "{err}");
    for name in ["clear-coat-2k-levelled.json", "waterborne-basecoat-levelled.json"] {
        let path = root().join("fixtures/recipes").join(name);
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let coat = &v["clear_coat"];
        assert!(coat.get("roughness").is_none() && coat.get("scatter").is_none() && coat.get("application").is_some());
        let out =
            std::process::Command::new(exe).arg("measure").arg(&path).arg("--format").arg("json").output().unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
        let text = doc.to_string();
        for id in api::DEFAULT_PANEL {
            assert!(text.contains(id), "{name}: {id} missing from {text}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `sweep` varies the application's numbers like any other parameter (one vary grammar): the DOI of the
/// poorly levelling film rises with film build and flash-off time and falls as the later viscosity rises.
#[test]
fn sweep_varies_film_build_flash_off_and_viscosity() {
    let exe = env!("CARGO_BIN_EXE_glossmeter");
    let dir = common::tmp_dir("levelling-sweep");
    std::fs::create_dir_all(&dir).unwrap();
    let template = dir.join("template.json");
    std::fs::write(&template, with_application(application(3000.0, 60.0, 20.0, 100.0)).to_string()).unwrap();
    let doi_along = |vary: &str| -> Vec<f64> {
        let out = std::process::Command::new(exe)
            .args(["sweep", template.to_str().unwrap(), "--vary", vary, "-g", "astm-e430-30"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{vary}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = header.iter().position(|h| *h == "astm-e430-30 doi (DOI)").unwrap_or_else(|| panic!("{header:?}"));
        lines.map(|l| l.split(',').nth(col).unwrap().parse().unwrap()).collect()
    };
    let rising = |v: &[f64]| v.windows(2).all(|w| w[1] > w[0]);
    let by_build = doi_along("/clear_coat/application/wet_film_um=15..30:4");
    let by_flash = doi_along("/clear_coat/application/flash_off_s=0..60:4");
    let by_eta = doi_along("/clear_coat/application/viscosity/1/eta_pa_s=100..1000:4");
    assert!(by_build.len() == 4 && rising(&by_build), "{by_build:?}");
    assert!(by_flash.len() == 4 && rising(&by_flash), "{by_flash:?}");
    assert!(by_eta.len() == 4 && by_eta.windows(2).all(|w| w[1] < w[0]), "{by_eta:?}");
    std::fs::remove_dir_all(&dir).ok();
}
