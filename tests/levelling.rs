//! The levelling model (src/optics/levelling.rs, docs/model.md §Levelling of the applied texture) against an
//! independent solution of the full, nonlinear thin-film equation on a periodic 1-D profile
//! (tools/levelling/thin_film.py, run by hand; its output and provenance in
//! fixtures/reference/levelling-thin-film.json).
use glossmeter::optics::levelling::{Application, ViscosityPoint};
use serde_json::Value;

fn fixture() -> Value {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/reference/levelling-thin-film.json"))
            .expect("the levelling fixture");
    serde_json::from_str(&text).expect("the levelling fixture is JSON")
}

fn application(v: &Value) -> Application {
    Application {
        wet_film_um: v["wet_film_um"].as_f64().unwrap(),
        volume_solids: v["volume_solids"].as_f64().unwrap(),
        surface_tension_mn_m: v["surface_tension_mn_m"].as_f64().unwrap(),
        flash_off_s: v["flash_off_s"].as_f64().unwrap(),
        viscosity: v["viscosity"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| ViscosityPoint { t_s: p[0].as_f64().unwrap(), eta_pa_s: p[1].as_f64().unwrap() })
            .collect(),
        surface_tension_gradient_mn_m_per_um: v["surface_tension_gradient_mn_m_per_um"].as_f64().unwrap_or(0.0),
    }
}

#[test]
fn the_levelling_integral_agrees_with_scipys_quad() {
    let f = fixture();
    let app = application(&f["application"]);
    app.validate().unwrap();
    let l = app.levelling_integral_um4();
    let reference = f["levelling_integral_um4"].as_f64().unwrap();
    assert!((l / reference - 1.0).abs() < 1e-11, "L = {l} µm⁴, SciPy {reference}");
}

#[test]
fn small_textures_level_as_the_linear_model_says_and_the_difference_grows_as_the_amplitude_squared() {
    let f = fixture();
    let app = application(&f["application"]);
    let runs = f["runs"].as_array().unwrap();
    assert!(runs.len() >= 9, "the fixture holds {} runs", runs.len());
    for r in runs {
        let (lambda, eps) = (r["wavelength_um"].as_f64().unwrap(), r["epsilon"].as_f64().unwrap());
        let nonlinear = r["nonlinear_ratio"].as_f64().unwrap();
        let linear = app.amplitude_transfer(1.0 / lambda);
        let rel = nonlinear / linear - 1.0;
        // The nonlinear mobility h³ makes the difference second order in ε = a₀/h: measured 0.2–0.65 ε² here.
        assert!(rel.abs() <= 0.7 * eps * eps + 1e-7, "Λ = {lambda} µm, ε = {eps}: nonlinear/linear − 1 = {rel:e}");
        if eps <= 0.01 {
            assert!(rel.abs() < 1e-4, "Λ = {lambda} µm, ε = {eps}: {rel:e}");
        }
    }
}

/// The surface-tension gradient's Marangoni term (docs/model.md §Levelling of the applied texture) against the full
/// equation with the Marangoni flux: at ε = 10⁻³ the linear transfer exp(−(16π⁴/3)f⁴L + 4π²f²M) agrees to the
/// same second-order difference as without it, for γ' of both signs, and M agrees with SciPy's quad.
#[test]
fn a_surface_tension_gradient_moves_the_transfer_as_the_full_equation_does() {
    let f = fixture();
    let base = &f["application"];
    let runs = f["gradient"].as_array().expect("the gradient block");
    assert!(runs.len() >= 6, "the fixture holds {} gradient runs", runs.len());
    let mut signs = (0, 0);
    for r in runs {
        let g = r["surface_tension_gradient_mn_m_per_um"].as_f64().unwrap();
        let mut v = base.clone();
        v["surface_tension_gradient_mn_m_per_um"] = g.into();
        let app = application(&v);
        app.validate().unwrap();
        let m = app.gradient_integral_um2();
        let reference = r["gradient_integral_um2"].as_f64().unwrap();
        assert!((m / reference - 1.0).abs() < 1e-11, "γ' {g}: M = {m} µm², SciPy {reference}");
        let lambda = r["wavelength_um"].as_f64().unwrap();
        let linear = app.amplitude_transfer(1.0 / lambda);
        let nonlinear = r["nonlinear_ratio"].as_f64().unwrap();
        let rel = nonlinear / linear - 1.0;
        assert!(rel.abs() < 1e-5, "γ' {g}, Λ = {lambda} µm: nonlinear/linear − 1 = {rel:e}");
        // The gradient's sign moves the transfer the way the flux says, against the same film without it.
        let mut plain = app.clone();
        plain.surface_tension_gradient_mn_m_per_um = 0.0;
        let without = plain.amplitude_transfer(1.0 / lambda);
        if g > 0.0 {
            assert!(nonlinear > without, "γ' {g} > 0 levels less: {nonlinear} vs {without}");
            signs.0 += 1;
        } else {
            assert!(nonlinear < without, "γ' {g} < 0 levels more: {nonlinear} vs {without}");
            signs.1 += 1;
        }
    }
    assert!(signs.0 > 0 && signs.1 > 0, "both signs of γ' are in the fixture");
}

#[test]
fn a_thicker_film_a_thinner_paint_and_a_longer_open_time_each_level_more() {
    let base = Application {
        wet_film_um: 60.0,
        volume_solids: 0.5,
        surface_tension_mn_m: 30.0,
        flash_off_s: 60.0,
        viscosity: vec![
            ViscosityPoint { t_s: 0.0, eta_pa_s: 0.3 },
            ViscosityPoint { t_s: 60.0, eta_pa_s: 3.0 },
            ViscosityPoint { t_s: 600.0, eta_pa_s: 300.0 },
        ],
        surface_tension_gradient_mn_m_per_um: 0.0,
    };
    let l0 = base.levelling_integral_um4();
    let mut thick = base.clone();
    thick.wet_film_um = 80.0;
    let mut thin_paint = base.clone();
    thin_paint.viscosity.iter_mut().for_each(|p| p.eta_pa_s *= 0.5);
    let mut longer = base.clone();
    longer.flash_off_s = 120.0;
    // L ∝ h³ at fixed times: (80/60)³ exactly; ∝ 1/η: 2 exactly; a slower flash keeps the film thick longer.
    assert!((thick.levelling_integral_um4() / l0 - (80.0f64 / 60.0).powi(3)).abs() < 1e-12);
    assert!((thin_paint.levelling_integral_um4() / l0 - 2.0).abs() < 1e-12);
    assert!(longer.levelling_integral_um4() > l0);
}
