//! The measured formats other than MERL (RGL `.bsdf`, in-plane CSV, ASTM E1392 text) on synthetic files
//! written by scripts under `tools/` from the formats' descriptions (`tools/make_rgl_fixture.py`,
//! `tools/make_inplane_fixture.py`): each holds a Lambertian or a Beckmann lobe, so its readings must equal the
//! engine's own `lambert` and `microfacet` models within the table's resolution error, stated per test. Broken
//! files are refused with the offset (or line) and the field.
mod common;
use common::tmp_dir;
use glossmeter::brdf::Brdf;
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards;
use glossmeter::recipe;
use glossmeter::Vec3;
use std::path::{Path, PathBuf};

const GEOMETRIES: [&str; 3] = ["astm-d523-20", "astm-d523-60", "astm-d523-85"];
const BECKMANN: &str = r#"{"model": "microfacet", "distribution": "beckmann", "roughness": 0.15, "ior": 1.5}"#;

fn fixture(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures").join(p)
}

/// Gloss readings at 20°, 60°, 85° (value, error estimate).
fn gloss(brdf: std::sync::Arc<dyn Brdf>) -> Vec<(f64, f64)> {
    let geos = GEOMETRIES.iter().map(|g| standards::find(g).unwrap()).collect();
    let plan = Plan::compile(brdf, geos, PlanOptions { rtol: 1e-5, ..Default::default() }).unwrap();
    plan.execute().into_iter().map(|r| (r.value.expect("a value"), r.error_estimate)).collect()
}

fn recipe_for(dir: &Path, name: &str, body: String) -> recipe::Material {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    recipe::load_file(&p).unwrap()
}

fn rgl(dir: &Path, file: &str) -> recipe::Material {
    let path = fixture(&format!("materials/rgl/{file}"));
    recipe_for(dir, &format!("{file}.json"), format!(r#"{{"model": "rgl", "file": "{}"}}"#, path.display()))
}

/// The message of a refused recipe (the material's Debug form is too large for a panic message).
fn refused(r: glossmeter::Result<recipe::Material>) -> String {
    match r {
        Ok(m) => panic!("{} was accepted", m.file),
        Err(e) => e.to_string(),
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn eval(b: &dyn Brdf, wi: Vec3, wo: Vec3) -> Vec<f64> {
    let mut out = vec![f64::NAN; b.sampling().len()];
    b.eval(wi, wo, &mut out);
    out
}

fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

#[test]
fn rgl_lambertian_reads_rho_over_pi_and_the_lambert_gloss() {
    let d = tmp_dir("rgl-lambert");
    let m = rgl(&d, "lambert-rgb.bsdf");
    // Point values: f = ρ/π wherever the warp's grid reaches (12 × 12 grid; σ and the spectra are smooth).
    for (wi, wo) in
        [(dir(20.0, 180.0), dir(20.0, 0.0)), (dir(60.0, 180.0), dir(35.0, 40.0)), (dir(5.0, 0.0), dir(70.0, 100.0))]
    {
        let f = eval(m.brdf.as_ref(), wi, wo);
        for (c, rho) in [0.2, 0.5, 0.8].iter().enumerate() {
            // Pointwise within 10 % (the warped grid's interpolation between slices; measured ≤ 8 % on the
            // 12 × 12 grid, 1e-3 at the nodes' incident angles).
            assert!(rel(f[c], rho / std::f64::consts::PI) < 0.1, "{wi:?} {wo:?}: {f:?}");
        }
    }
    let lambert = gloss(recipe::parse_str(r#"{"model": "lambert", "albedo": [0.2, 0.5, 0.8]}"#, "l").unwrap().brdf);
    let table = gloss(m.brdf);
    for (g, (t, l)) in GEOMETRIES.iter().zip(table.iter().zip(&lambert)) {
        eprintln!("{g}: RGL {t:?} vs lambert {l:?}: {:.3e}", rel(t.0, l.0));
        // Resolution error of the 24 × 24 table (measured 2.7e-4, 5.0e-3, 4.4e-2 at 20°, 60°, 85°: the
        // 5° steps of theta_i at the spectra's fixed warped coordinates, and the coarse u_θ grid near grazing).
        let bound = [1e-3, 1e-2, 6e-2][GEOMETRIES.iter().position(|x| x == g).unwrap()];
        assert!(rel(t.0, l.0) < bound, "{g}");
    }
}

#[test]
fn rgl_beckmann_reads_the_microfacet_gloss_within_its_resolution() {
    let d = tmp_dir("rgl-beckmann");
    let exact = gloss(recipe::parse_str(BECKMANN, "b").unwrap().brdf);
    let coarse = gloss(rgl(&d, "beckmann-iso-16.bsdf").brdf);
    let fine = gloss(rgl(&d, "beckmann-iso-32.bsdf").brdf);
    let aniso = gloss(rgl(&d, "beckmann-aniso-24.bsdf").brdf);
    for (k, g) in GEOMETRIES.iter().enumerate() {
        let (e16, e32, ea) = (rel(coarse[k].0, exact[k].0), rel(fine[k].0, exact[k].0), rel(aniso[k].0, exact[k].0));
        eprintln!(
            "{g}: exact {:?} 16: {:?} ({e16:.2e}) 32: {:?} ({e32:.2e}) aniso 24: {:?} ({ea:.2e})",
            exact[k], coarse[k], fine[k], aniso[k]
        );
        // Resolution errors (measured with these files, bounds with margin): at 20° the u-grid dominates
        // (16: 2.5e-4, 32: 7e-6); at 60° a 0.26 % offset that the finer u-grid does not reduce (the 5° steps of
        // theta_i); at 85° the coarse u_θ = √(2θ/π) grid near the horizon (16: 3.6 %, 32: 2.1 %).
        let bound = [(1e-3, 5e-5, 5e-4), (5e-3, 5e-3, 5e-3), (5e-2, 3e-2, 4e-2)][k];
        assert!(e16 < bound.0 && e32 < bound.1 && ea < bound.2, "{g}: {e16:.2e} {e32:.2e} {ea:.2e}");
        if k != 1 {
            assert!(e32 < e16, "{g}: refinement did not reduce the error");
        }
    }
}

fn inplane(dir: &Path, model: &str, file: &str) -> recipe::Material {
    let path = fixture(&format!("materials/inplane/{file}"));
    recipe_for(dir, &format!("{file}.json"), format!(r#"{{"model": "{model}", "file": "{}"}}"#, path.display()))
}

#[test]
fn inplane_tables_read_the_closed_forms() {
    let d = tmp_dir("inplane");
    let lambert = gloss(recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "l").unwrap().brdf);
    let exact = gloss(recipe::parse_str(BECKMANN, "b").unwrap().brdf);
    let lam = gloss(inplane(&d, "inplane-csv", "lambert-cos.csv").brdf);
    let csv = gloss(inplane(&d, "inplane-csv", "beckmann.csv").brdf);
    let txt = gloss(inplane(&d, "e1392", "beckmann-e1392.txt").brdf);
    for (k, g) in GEOMETRIES.iter().enumerate() {
        let (el, ec, et) = (rel(lam[k].0, lambert[k].0), rel(csv[k].0, exact[k].0), rel(txt[k].0, exact[k].0));
        eprintln!("{g}: lambert {el:.3e}  csv {:?} vs {:?} ({ec:.3e})  e1392 ({et:.3e})", csv[k], exact[k]);
        // A constant BRDF is reproduced exactly by the table and its isotropic extension.
        assert!(el < 1e-6, "{g}: lambert {el:e}");
        // Both files hold the same points (the E1392 one as f·cos θo, rounded to 13 digits): the same reading
        // within the two integrations' error estimates.
        assert!((csv[k].0 - txt[k].0).abs() <= csv[k].1 + txt[k].1, "{g}: csv {:?} e1392 {:?}", csv[k], txt[k]);
        // The Beckmann lobe (tables with θi every degree over 15–25° and 50–89°, θo every 0.1° near the
        // specular direction): 20° within 5e-4 (measured 1.1e-4); 60° within 2 % (measured 1.1 %) and 85°
        // within 8 % (measured 6.0 %, an overestimate): the isotropy assumption across the perpendicular
        // receptor, where f·cos θi·cos θo, not f, is the bivariate function of a microfacet lobe (and, at 85°,
        // pairs beyond the in-plane domain read at its edge).
        let bound = [5e-4, 2e-2, 8e-2][k];
        assert!(ec < bound && csv[k].0 > 0.0, "{g}: in-plane Beckmann {ec:e}");
    }
}

#[test]
fn broken_files_are_refused_with_offset_and_field() {
    let d = tmp_dir("broken");
    let good = std::fs::read(fixture("materials/rgl/lambert-rgb.bsdf")).unwrap();
    let try_rgl = |name: &str, bytes: &[u8]| -> String {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        let r = d.join(format!("{name}.json"));
        std::fs::write(&r, format!(r#"{{"model": "rgl", "file": "{name}"}}"#)).unwrap();
        match recipe::load_file(&r) {
            Ok(_) => panic!("{name} was accepted"),
            Err(e) => e.to_string(),
        }
    };
    let mut magic = good.clone();
    magic[0] = b'X';
    let e = try_rgl("magic.bsdf", &magic);
    assert!(e.contains("wrong magic at byte offset 0") && e.contains("field `/file`"), "{e}");
    let e = try_rgl("short.bsdf", &good[..good.len() - 100]);
    assert!(e.contains("truncated or mis-sized") && e.contains("byte offset"), "{e}");
    let e = try_rgl("header.bsdf", &good[..40]);
    assert!(e.contains("truncated at byte offset"), "{e}");
    let e = try_rgl("empty.bsdf", b"");
    assert!(e.contains("truncated at byte offset 0"), "{e}");
    // A field name is the file's text: a newline and a backquote in it come back escaped, on one line. The
    // first field's name length is the u16 at byte 18 (after the 12-byte magic, the version and the field
    // count), its name follows, then its rank, here made too large so that the error names the field.
    let mut odd = good.clone();
    let len = u16::from_le_bytes([odd[18], odd[19]]) as usize;
    assert!(len >= 2, "the fixture's first field name has {len} bytes");
    odd[20] = b'\n';
    odd[21] = b'`';
    odd[20 + len..22 + len].copy_from_slice(&u16::MAX.to_le_bytes());
    let e = try_rgl("odd-name.bsdf", &odd);
    assert!(e.contains("rank 65535") && e.contains("field `\\n`"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    // A mis-sized field: the luminance grid does not match the spectra's.
    let tf = glossmeter::measured::rgl::TensorFile::parse(&good, "g").unwrap();
    let lum = tf.field("luminance").unwrap();
    let mut bad = good.clone();
    // The shape of `luminance` is written right after its header entry; find it by its offset field.
    let pos = good.windows(8).position(|w| w == (lum.offset as u64).to_le_bytes()).unwrap() + 8;
    bad[pos..pos + 8].copy_from_slice(&2u64.to_le_bytes());
    let e = try_rgl("missized.bsdf", &bad);
    assert!(e.contains("luminance") && e.contains("byte offset"), "{e}");
    // In-plane files: the line and the column.
    let p = d.join("bad.csv");
    std::fs::write(&p, "theta_i,theta_o,brdf\n20,10,1\n20,20,NaN\n").unwrap();
    let r = d.join("bad-csv.json");
    std::fs::write(&r, r#"{"model": "inplane-csv", "file": "bad.csv"}"#).unwrap();
    let e = refused(recipe::load_file(&r));
    assert!(e.contains("line 3, column brdf"), "{e}");
    let p2 = d.join("bad.txt");
    std::fs::write(&p2, "theta_i phi_i theta_s phi_s BRDF\n20 0 10 180 1\n20 0 20 180\n").unwrap();
    let r = d.join("bad-txt.json");
    std::fs::write(&r, r#"{"model": "e1392", "file": "bad.txt"}"#).unwrap();
    let e = refused(recipe::load_file(&r));
    assert!(e.contains("line 3"), "{e}");
    let _ = p;
}

/// The table's resolution the lobe states (`Tail::Table`'s `resolution`) is its own: for an RGL file
/// tan((π/2)/(n − 1)²), n the finer of the NDF and VNDF grids (the first u_θ node off the pole); for an
/// in-plane table tan(Δ/2), Δ its smallest θo step (0.1° in the fixtures). The lobe's slope width, where the
/// partition splits, is its half width (`docs/instrument.md` §Quadrature, *Measured tables*).
#[test]
fn the_table_resolution_is_stated_with_the_lobe() {
    use glossmeter::brdf::{Tail, TermKind};
    let width = |m: &recipe::Material| -> f64 {
        let terms = m.brdf.hints().terms;
        assert_eq!(terms.len(), 1);
        match &terms[0].kind {
            TermKind::Lobe(l) => {
                let Tail::Table { half_width, resolution } = l.tail else { panic!("{l:?}") };
                assert_eq!(l.slope_width.to_bits(), half_width.to_bits(), "{l:?}");
                resolution
            }
            other => panic!("{other:?}"),
        }
    };
    let d = tmp_dir("widths");
    for file in ["beckmann-iso-16.bsdf", "beckmann-iso-32.bsdf", "lambert-rgb.bsdf"] {
        let bytes = std::fs::read(fixture(&format!("materials/rgl/{file}"))).unwrap();
        let tf = glossmeter::measured::rgl::TensorFile::parse(&bytes, file).unwrap();
        let n = tf.field("ndf").unwrap().shape[1].max(tf.field("vndf").unwrap().shape[3]) as f64;
        let expect = (std::f64::consts::FRAC_PI_2 / ((n - 1.0) * (n - 1.0))).tan();
        let got = width(&rgl(&d, file));
        assert!((got - expect).abs() <= 1e-15 * expect, "{file}: {got} vs {expect}");
    }
    let expect = (0.05f64).to_radians().tan();
    for (model, file) in [("inplane-csv", "beckmann.csv"), ("e1392", "beckmann-e1392.txt")] {
        let got = width(&inplane(&d, model, file));
        assert!((got - expect).abs() < 1e-9 * expect, "{file}: {got} vs {expect}");
    }
}

/// Broken tables through the command line: exit status 2, the message on stderr names the file.
#[cfg(feature = "cli")]
#[test]
fn broken_tables_exit_with_status_2() {
    use glossmeter::cli::run;
    let d = tmp_dir("broken-cli");
    let good = std::fs::read(fixture("materials/rgl/lambert-rgb.bsdf")).unwrap();
    std::fs::write(d.join("cut.bsdf"), &good[..good.len() / 2]).unwrap();
    let mut magic = good.clone();
    magic[3] = b'?';
    std::fs::write(d.join("magic.bsdf"), &magic).unwrap();
    std::fs::write(d.join("bad.csv"), "theta_i,theta_o,brdf\n20,10,1\n20,20,-1\n").unwrap();
    std::fs::write(d.join("bad.txt"), "theta_i phi_i theta_s phi_s BRDF\n20 0 10\n").unwrap();
    for (model, file) in [("rgl", "cut.bsdf"), ("rgl", "magic.bsdf"), ("inplane-csv", "bad.csv"), ("e1392", "bad.txt")]
    {
        let r = d.join(format!("{file}.json"));
        std::fs::write(&r, format!(r#"{{"model": "{model}", "file": "{file}"}}"#)).unwrap();
        let out = d.join(format!("{file}.out"));
        let status = run(["glossmeter", "measure", r.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_eq!(status, 2, "{model} {file}");
        assert!(!out.exists(), "{file}: no output file on bad input");
    }
}

fn inplane_with(dir: &Path, model: &str, file: &str, off_plane: &str) -> recipe::Material {
    let path = fixture(&format!("materials/inplane/{file}"));
    recipe_for(
        dir,
        &format!("{file}-{off_plane}.json"),
        format!(r#"{{"model": "{model}", "file": "{}", "off_plane": "{off_plane}"}}"#, path.display()),
    )
}

/// The other isotropy assumption, f_r·cos θi·cos θo = g(θh, θd): the microfacet form, so the Beckmann lobe
/// reads its closed form at 20° and 60° within the table's resolution and a Lambertian is off by the cosine
/// factor instead; at 85° both read low (stated bounds, measured values in the comments).
#[test]
fn inplane_cosine_weighted_extension_reads_the_lobe() {
    let d = tmp_dir("inplane-coscos");
    let lambert = gloss(recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "l").unwrap().brdf);
    let exact = gloss(recipe::parse_str(BECKMANN, "b").unwrap().brdf);
    let csv = gloss(inplane_with(&d, "inplane-csv", "beckmann.csv", "f-cos-cos").brdf);
    let txt = gloss(inplane_with(&d, "e1392", "beckmann-e1392.txt", "f-cos-cos").brdf);
    let lam = gloss(inplane_with(&d, "inplane-csv", "lambert-cos.csv", "f-cos-cos").brdf);
    for (k, g) in GEOMETRIES.iter().enumerate() {
        let (ec, et, el) = (rel(csv[k].0, exact[k].0), rel(txt[k].0, exact[k].0), rel(lam[k].0, lambert[k].0));
        eprintln!("{g}: f-cos-cos beckmann csv {ec:.3e} e1392 {et:.3e}; lambert {el:.3e}");
        assert!((csv[k].0 - txt[k].0).abs() <= csv[k].1 + txt[k].1, "{g}: csv {:?} e1392 {:?}", csv[k], txt[k]);
        // 20° and 60°: the lobe within 1e-4 and 1e-3 (measured 1.4e-5, 4.6e-4), the Lambertian off by the
        // cosine factor (measured 6.2e-5, 1.1 %). 85°: both read low, by 41 % (lobe) and 66 % (Lambertian),
        // measured: the masking term the assumption leaves out (beyond the measured θo the lobe is continued
        // by separability from θo = 89°, where G2 is small; `microfacet` carries G2 and reads it, next test);
        // the bound says the reading is below the closed form and by less than 50 % (lobe) or 70 % (flat).
        let (lobe, flat) = [(1e-4, 1e-4), (1e-3, 2e-2), (0.5, 0.7)][k];
        assert!(ec < lobe && el < flat, "{g}: f-cos-cos lobe {ec:e}, Lambertian {el:e}");
        if k == 2 {
            assert!(csv[k].0 < exact[k].0 && lam[k].0 < lambert[k].0, "{g}: the 85° reading is an underestimate");
        }
    }
}

/// The `microfacet` assumption: f_r·cos θi·cos θo/G2 = F(θd)·D(θh)/4 with the Smith G2 of the table's own
/// distribution (docs/recipe-format.md §inplane-csv): the Beckmann lobe reads its closed form at 20°, 60° and
/// 85° within the table's resolution error (bounds with margin over the measured values in the comments).
#[test]
fn inplane_microfacet_extension_reads_the_closed_forms() {
    let d = tmp_dir("inplane-microfacet");
    let exact = gloss(recipe::parse_str(BECKMANN, "b").unwrap().brdf);
    let csv = gloss(inplane_with(&d, "inplane-csv", "beckmann.csv", "microfacet").brdf);
    let txt = gloss(inplane_with(&d, "e1392", "beckmann-e1392.txt", "microfacet").brdf);
    for (k, g) in GEOMETRIES.iter().enumerate() {
        let (ec, et) = (rel(csv[k].0, exact[k].0), rel(txt[k].0, exact[k].0));
        eprintln!("{g}: microfacet beckmann csv {:?} vs {:?}: {ec:.3e} e1392 {et:.3e}", csv[k], exact[k]);
        assert!((csv[k].0 - txt[k].0).abs() <= csv[k].1 + txt[k].1, "{g}: csv {:?} e1392 {:?}", csv[k], txt[k]);
        // Measured: 1.4e-5, 4.6e-4, 2.6e-3 (the shipped tables: θi every 1° over 15–25° and 50–89°, so D's
        // cut at θd = 15° crosses the 26–49° gap by interpolation; θo every 0.1° within 10° of specular and
        // every 1° elsewhere, up to 89°). Finer tables read closer (next test).
        let bound = [5e-5, 1e-3, 5e-3][k];
        assert!(ec < bound, "{g}: microfacet {ec:e}");
    }
}

/// Write an in-plane CSV of the engine's own `microfacet` model (the closed form) on a chosen grid: θi every
/// `di` degrees over 0..=89, θo every `dto` degrees over (−90, 90) (the grid's last node below 90°).
fn write_inplane_table(path: &Path, di: f64, dto: f64) {
    let m = recipe::parse_str(BECKMANN, "b").unwrap();
    let grid = |h: f64, hi: f64| -> Vec<f64> {
        let n = (hi / h).floor() as i64;
        (-n..=n).map(|k| (k as f64 * h * 1e6).round() / 1e6).collect()
    };
    let mut s = String::from("theta_i,theta_o,brdf\n");
    for ti in grid(di, 89.0).into_iter().filter(|t| *t >= 0.0) {
        for to in grid(dto, 89.99) {
            let f = eval(m.brdf.as_ref(), dir(ti, 180.0), dir(to.abs(), if to >= 0.0 { 0.0 } else { 180.0 }));
            s.push_str(&format!("{ti},{to},{:e}\n", f[0]));
        }
    }
    std::fs::write(path, s).unwrap();
}

/// The `microfacet` reading's error is the table's resolution: halving both steps divides it by about four at
/// every geometry (linear interpolation), so nothing else (the Λ of the table's own distribution, the
/// continuation beyond the measured θo) is left at this level. Tables written from the closed form here.
#[test]
fn inplane_microfacet_error_is_the_tables_resolution() {
    let d = tmp_dir("inplane-resolution");
    let exact = gloss(recipe::parse_str(BECKMANN, "b").unwrap().brdf);
    let mut errors = Vec::new();
    for (di, dto) in [(1.0, 0.1), (0.5, 0.05)] {
        let p = d.join(format!("table-{di}.csv"));
        write_inplane_table(&p, di, dto);
        let r = recipe_for(
            &d,
            &format!("table-{di}.json"),
            format!(r#"{{"model": "inplane-csv", "file": "{}", "off_plane": "microfacet"}}"#, p.display()),
        );
        let g = gloss(r.brdf);
        let e: Vec<f64> = (0..3).map(|k| rel(g[k].0, exact[k].0)).collect();
        eprintln!("θi every {di}°, θo every {dto}°: relative errors at 20/60/85°: {e:?}");
        errors.push(e);
    }
    for (k, g) in GEOMETRIES.iter().enumerate() {
        // Measured: 1.4e-5 → 3.6e-6, 4.3e-4 → 1.1e-4, 5.2e-4 → 1.4e-4.
        assert!(
            errors[0][k] < 1e-3 && errors[1][k] < errors[0][k] / 3.0,
            "{g}: {:?} → {:?}",
            errors[0][k],
            errors[1][k]
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Measured tables (`docs/instrument.md` §Quadrature, "Measured tables"): every table states its lobe's own half width
/// at half maximum, measured from the table at load (`Tail::Table`); the shipped Beckmann α = 0.15 tables all
/// read ≈ 0.122 (the closed form's in-plane f at 20° halves at a half-vector tilt of ≈ 6.9°), the Lambertian RGL table
/// never halves (∞). A constant table is a diffuse term: the plain chart, 57 evaluations per flux at D523 20°/60°/85°
/// (6 840 / 7 980 / 9 120 on the resolution splits before), the reading unchanged within its estimate.
#[test]
fn tables_state_their_half_width_and_a_flat_table_is_diffuse() {
    use glossmeter::brdf::{Tail, TermKind};
    let d = tmp_dir("half-width");
    let tail = |m: &recipe::Material| match &m.brdf.hints().terms[0].kind {
        TermKind::Lobe(l) => Some(l.tail),
        _ => None,
    };
    for m in [
        rgl(&d, "beckmann-iso-16.bsdf"),
        rgl(&d, "beckmann-iso-32.bsdf"),
        rgl(&d, "beckmann-aniso-24.bsdf"),
        inplane(&d, "inplane-csv", "beckmann.csv"),
        inplane(&d, "e1392", "beckmann-e1392.txt"),
        inplane_with(&d, "inplane-csv", "beckmann.csv", "microfacet"),
    ] {
        let Some(Tail::Table { half_width, .. }) = tail(&m) else { panic!("{}: {:?}", m.file, m.brdf.hints().terms) };
        // Measured 0.1217 (RGL 16) and 0.1219 (the others).
        assert!((0.118..0.126).contains(&half_width), "{}: {half_width}", m.file);
    }
    assert!(
        matches!(tail(&rgl(&d, "lambert-rgb.bsdf")), Some(Tail::Table { half_width, .. }) if half_width == f64::INFINITY)
    );
    let flat = inplane(&d, "inplane-csv", "lambert-cos.csv");
    assert_eq!(flat.brdf.hints().terms[0].kind, TermKind::Diffuse);
    // With the f-cos-cos extension the same file is not a constant BRDF: a lobe again.
    assert!(tail(&inplane_with(&d, "inplane-csv", "lambert-cos.csv", "f-cos-cos")).is_some());
    let geos: Vec<_> = GEOMETRIES.iter().map(|g| standards::find(g).unwrap()).collect();
    let plan = Plan::compile(flat.brdf.clone(), geos, PlanOptions { max_seconds: None, ..Default::default() }).unwrap();
    let text = plan.explain();
    assert!(text.contains("every value the same") && text.contains("plain variables"), "{text}");
    let lambert = gloss(recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "l").unwrap().brdf);
    for (r, l) in plan.execute().iter().zip(&lambert) {
        // 17 on the gloss standard and 57 on each of the table and its two coarse twins at each of the three
        // pilot tolerances (docs/accuracy.md §Data uncertainty of measured tables): the file's values differ
        // from a constant in the last digits, so the twins differ from the table by rounding and no pilot
        // resolves the difference; the last pilot is the flux.
        assert_eq!(r.evaluations, 17 + 3 * 3 * 57, "{}", r.geometry);
        assert!(r.data_uncertainty.is_some_and(|u| u <= 1e-3 * r.value.unwrap()), "{r:?}");
        let v = r.value.unwrap();
        assert!((v - l.0).abs() <= r.error_estimate + l.1 + 1e-12 * v, "{}: {v} vs {l:?}", r.geometry);
    }
}

/// The planner's choice for a table lobe is the Genz–Malik partition on the resolution splits (the polar rule
/// was measured on the tables and lost, `docs/instrument.md` §Quadrature, *Measured tables*), `--explain` says
/// so with the half width, and a frozen method on a table repeats its bits.
#[test]
fn a_table_lobe_keeps_the_partition_and_its_frozen_method_repeats_its_bits() {
    use glossmeter::instrument::method::{Method, Rule};
    let d = tmp_dir("table-plan");
    let m = inplane_with(&d, "inplane-csv", "beckmann.csv", "microfacet");
    let plan = Plan::compile(
        m.brdf.clone(),
        vec![standards::find("astm-d523-20").unwrap()],
        PlanOptions { max_seconds: None, ..Default::default() },
    )
    .unwrap();
    let text = plan.explain();
    assert!(text.contains("a measured table's tail (its own half width at half maximum 1.2"), "{text}");
    assert!(text.contains("Genz–Malik 7/5") && !text.contains("polar variables"), "{text}");
    let g = standards::find("astm-d523-20").unwrap().geometry;
    let rec = g.receptor("gloss").copied().unwrap();
    let method = Method::for_material(m.brdf.as_ref(), g.theta, g.source, rec, (1e-6, 0.0), 50_000_000).unwrap();
    assert_eq!(method.regular.as_ref().unwrap().rule, Rule::GenzMalik75);
    let (flux, frozen) = method.execute_and_freeze(m.brdf.as_ref());
    assert!(flux.converged && frozen.is_frozen());
    let again = frozen.execute(m.brdf.as_ref());
    assert_eq!((again.value, again.error), (flux.value.clone(), flux.error.clone()));
    // The same bits on one and on two threads (each integral runs on one thread).
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| plan.execute());
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| plan.execute());
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(a.value.map(f64::to_bits), b.value.map(f64::to_bits));
        assert_eq!(a.error_estimate.to_bits(), b.error_estimate.to_bits());
    }
}
