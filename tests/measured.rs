//! Measured BRDF tables (MERL `.binary`): the half/difference conversion against closed forms, the index
//! mapping and reciprocity fold on synthetic tables written here, both lookups, the instrument on a
//! Lambertian table against the `lambert` model, and the refusals. No MERL data file is needed: every table
//! is generated in a temporary directory.
// Channels index several parallel arrays (values, scales, expected values) at once.
#![allow(clippy::needless_range_loop)]
mod common;
use common::tmp_dir;

use glossmeter::brdf::{Brdf, Hints, TermKind};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards;
use glossmeter::measured::merl::{fold_phi_d, half_diff, Interpolation, MerlBrdf, MERL_DIMS, MERL_SCALE};
use glossmeter::recipe;
use glossmeter::Vec3;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};

/// Write a MERL file whose stored (unscaled) value of cell (ih, id, ip) in channel c is `raw(ih, id, ip, c)`.
fn write_merl(path: &Path, dims: [usize; 3], raw: impl Fn(usize, usize, usize, usize) -> f64) {
    let [nh, nd, np] = dims;
    let n = nh * nd * np;
    let mut bytes = Vec::with_capacity(12 + 24 * n);
    for d in dims {
        bytes.extend_from_slice(&(d as i32).to_le_bytes());
    }
    for c in 0..3 {
        for ih in 0..nh {
            for id in 0..nd {
                for ip in 0..np {
                    bytes.extend_from_slice(&raw(ih, id, ip, c).to_le_bytes());
                }
            }
        }
    }
    std::fs::write(path, bytes).unwrap();
}

fn write_recipe(dir: &Path, name: &str, body: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p
}

fn eval(b: &dyn Brdf, wi: Vec3, wo: Vec3) -> [f64; 3] {
    let mut out = [f64::NAN; 3];
    b.eval(wi, wo, &mut out);
    out
}

fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Directions from half/difference angles, written out independently of the library: the difference vector
/// rotated by +θh about y and by +φh about z gives ωi; ωo is ωi mirrored about h.
fn from_half_diff(th: f64, ph: f64, td: f64, pd: f64) -> (Vec3, Vec3) {
    let d = Vec3::new(td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos());
    let y = Vec3::new(d.x * th.cos() + d.z * th.sin(), d.y, -d.x * th.sin() + d.z * th.cos());
    let wi = Vec3::new(y.x * ph.cos() - y.y * ph.sin(), y.x * ph.sin() + y.y * ph.cos(), y.z);
    let h = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
    let wo = 2.0 * wi.dot(h) * h - wi;
    (wi, wo)
}

/// A small deterministic generator (xorshift) so that the tests need no RNG crate.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

// ---------------------------------------------------------------------------------------------------------
// Half/difference angles
// ---------------------------------------------------------------------------------------------------------

/// In the plane of incidence, ωi at θi on the +x side and ωo at θo on the −x side: the half vector is at the
/// signed angle (θi − θo)/2, so θh = |θi − θo|/2, and ωi makes the angle θd = (θi + θo)/2 with it. φd is 0
/// when h leans towards ωi's side, π otherwise (which reciprocity folds to 0).
#[test]
fn half_diff_in_plane_closed_form() {
    for ti in [0.0, 1.0, 10.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.0] {
        for to in [0.5, 3.0, 20.0, 30.0, 60.0, 84.0, 88.0] {
            let (ri, ro) = (f64::to_radians(ti), f64::to_radians(to));
            let (wi, wo) = (Vec3::new(ri.sin(), 0.0, ri.cos()), Vec3::new(-ro.sin(), 0.0, ro.cos()));
            let hd = half_diff(wi, wo);
            let (th, td) = (((ti - to) / 2.0_f64).abs().to_radians(), ((ti + to) / 2.0_f64).to_radians());
            assert!((hd.theta_h - th).abs() < 1e-14, "θi {ti} θo {to}: θh {} vs {th}", hd.theta_h);
            assert!((hd.theta_d - td).abs() < 1e-14, "θi {ti} θo {to}: θd {} vs {td}", hd.theta_d);
            if ti == to {
                continue; // h = n: φh and φd are undefined (the specular pair, tested below)
            }
            let (ph, pd) = if ti > to { (0.0, 0.0) } else { (PI, PI) };
            assert!((hd.phi_h.abs() - ph).abs() < 1e-14, "θi {ti} θo {to}: φh {}", hd.phi_h);
            assert!((hd.phi_d.abs() - pd).abs() < 1e-14, "θi {ti} θo {to}: φd {}", hd.phi_d);
            assert_eq!(fold_phi_d(hd.phi_d), 0.0);
        }
    }
}

/// The specular pair (ωo the mirror of ωi) has h = n: θh = 0 and the difference vector is ωi itself.
#[test]
fn half_diff_specular_pair() {
    for t in [0.0, 10.0, 45.0, 80.0] {
        for p in [10.0, 90.0, 135.0, 170.0] {
            let wi = dir(t, p);
            let hd = half_diff(wi, glossmeter::brdf::mirror(wi));
            assert_eq!(hd.theta_h, 0.0);
            assert!((hd.theta_d - f64::to_radians(t)).abs() < 1e-14);
            if t > 0.0 {
                assert!((hd.phi_d - f64::to_radians(p)).abs() < 1e-13, "{t} {p}: φd {}", hd.phi_d);
            }
        }
    }
}

/// Out of the plane: the conversion inverts the independent construction from (θh, φh, θd, φd), and
/// swapping ωi and ωo turns φd into φd ± π and leaves the other angles alone.
#[test]
fn half_diff_round_trip_and_swap() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    let mut n = 0;
    while n < 2000 {
        let (th, td) = (rng.next() * 1.5, rng.next() * 1.5);
        let (ph, pd) = ((rng.next() * 2.0 - 1.0) * PI * 0.999, (rng.next() * 2.0 - 1.0) * PI * 0.999);
        let (wi, wo) = from_half_diff(th, ph, td, pd);
        if wi.z <= 1e-3 || wo.z <= 1e-3 || th < 1e-3 || td < 1e-3 {
            continue;
        }
        n += 1;
        let hd = half_diff(wi, wo);
        assert!((hd.theta_h - th).abs() < 1e-12 && (hd.theta_d - td).abs() < 1e-12, "{hd:?} vs {th} {td}");
        assert!((hd.phi_h - ph).abs() < 1e-11 && (hd.phi_d - pd).abs() < 1e-11, "{hd:?} vs {ph} {pd}");
        let sw = half_diff(wo, wi);
        assert!((sw.theta_h - th).abs() < 1e-12 && (sw.theta_d - td).abs() < 1e-12);
        let dp = (sw.phi_d - pd).rem_euclid(2.0 * PI);
        assert!((dp - PI).abs() < 1e-11, "swap: φd {} vs {pd}", sw.phi_d);
        assert!((fold_phi_d(sw.phi_d) - fold_phi_d(pd)).abs() < 1e-11);
    }
}

// ---------------------------------------------------------------------------------------------------------
// Tables
// ---------------------------------------------------------------------------------------------------------

const RHO: [f64; 3] = [0.2, 0.5, 0.8];

fn lambert_table(path: &Path, dims: [usize; 3]) {
    write_merl(path, dims, |_, _, _, c| RHO[c] / PI / MERL_SCALE[c]);
}

fn grid() -> Vec<Vec3> {
    let mut v = Vec::new();
    for t in [0.0, 0.3, 5.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.9] {
        for p in [0.0, 37.0, 90.0, 180.0, 251.0] {
            v.push(dir(t, p));
        }
    }
    v
}

#[test]
fn lambertian_table_reads_rho_over_pi_with_both_lookups() {
    let d = tmp_dir("lambert");
    lambert_table(&d.join("lambert.binary"), MERL_DIMS);
    for interp in ["nearest", "trilinear"] {
        let r = write_recipe(
            &d,
            &format!("l-{interp}.json"),
            &format!(r#"{{"model": "merl", "file": "lambert.binary", "interpolation": "{interp}"}}"#),
        );
        let m = recipe::load_file(&r).unwrap();
        assert_eq!(m.brdf.sampling().len(), 3);
        for &wi in &grid() {
            for &wo in &grid() {
                let f = eval(m.brdf.as_ref(), wi, wo);
                for c in 0..3 {
                    assert!(close(f[c], RHO[c] / PI, 1e-15), "{interp}: {f:?} at {wi} {wo}");
                }
            }
        }
        // Below the horizon: 0.
        assert_eq!(eval(m.brdf.as_ref(), dir(30.0, 0.0), Vec3::new(0.0, 0.0, -1.0)), [0.0; 3]);
        let desc = m.brdf.describe();
        assert!(desc.contains("lambert.binary") && desc.contains("90 × 90 × 180") && desc.contains(interp), "{desc}");
        assert!(desc.contains("0 invalid"), "{desc}");
        // Every cell the same per channel: a constant BRDF, stated as a diffuse term (`docs/instrument.md` §Quadrature,
        // "Measured tables": the plain chart, 57 evaluations at D523 20°/60°/85°, instead of splits at the resolution).
        let terms = m.brdf.hints().terms;
        assert_eq!(terms.len(), 1);
        assert_eq!(terms[0].kind, TermKind::Diffuse, "{terms:?}");
        assert!(terms[0].label.contains("every cell the same value per channel"), "{}", terms[0].label);
        let table = MerlBrdf::load(&d.join("lambert.binary"), Interpolation::Nearest).unwrap();
        assert!(table.is_flat() && table.half_width().is_infinite());
        assert!(close(table.resolution_slope(), (FRAC_PI_2 / 8100.0).tan(), 1e-15));
        assert!((table.resolution_slope() - 1.939e-4).abs() < 1e-7);
    }
    // One cell different: no longer flat, a lobe whose tail is the table's, with the resolution as its width.
    let bumped = d.join("bumped.binary");
    write_merl(&bumped, MERL_DIMS, |ih, id, ip, c| {
        let v = RHO[c] / PI / MERL_SCALE[c];
        if (ih, id, ip) == (40, 10, 3) {
            1.01 * v
        } else {
            v
        }
    });
    let m = MerlBrdf::load(&bumped, Interpolation::Trilinear).unwrap();
    assert!(!m.is_flat());
    match &m.hints().terms[0].kind {
        TermKind::Lobe(l) => {
            assert_eq!((l.medium_eta, l.label.as_str()), (1.0, "measured (MERL)"));
            // The bump is far from the specular scan: the lobe never falls to half, its half width is infinite
            // (and so the slope width the partition splits at: the plain chart); the resolution is the table's.
            let glossmeter::brdf::Tail::Table { half_width, resolution } = l.tail else { panic!("{l:?}") };
            assert_eq!((half_width, l.slope_width), (f64::INFINITY, f64::INFINITY));
            assert!(close(resolution, (FRAC_PI_2 / 8100.0).tan(), 1e-15), "{resolution}");
        }
        k => panic!("expected a lobe, got {k:?}"),
    }
    std::fs::remove_dir_all(&d).ok();
}

/// A smooth function of the bin-centre angles, stored per cell: the nearest-bin lookup at a bin centre must
/// return exactly the function there, which checks the θh (square-root), θd and φd index mapping and the
/// channel order and scales; at any point inside a bin it returns the same cell.
fn smooth(th: f64, td: f64, pd: f64, c: usize) -> f64 {
    (0.05 + 0.3 * th + 0.2 * td * td + 0.1 * (1.0 + pd.cos()) + 0.01 * pd) * (1.0 + c as f64)
}

fn centre(ih: usize, id: usize, ip: usize) -> (f64, f64, f64) {
    let (nh, nd, np) = (MERL_DIMS[0] as f64, MERL_DIMS[1] as f64, MERL_DIMS[2] as f64);
    let u = (ih as f64 + 0.5) / nh;
    (FRAC_PI_2 * u * u, (id as f64 + 0.5) / nd * FRAC_PI_2, (ip as f64 + 0.5) / np * PI)
}

#[test]
fn nearest_lookup_index_mapping_and_reciprocity() {
    let d = tmp_dir("smooth");
    let file = d.join("smooth.binary");
    write_merl(&file, MERL_DIMS, |ih, id, ip, c| {
        let (th, td, pd) = centre(ih, id, ip);
        smooth(th, td, pd, c) / MERL_SCALE[c]
    });
    let b = MerlBrdf::load(&file, Interpolation::Nearest).unwrap();
    assert_eq!((b.dims(), b.invalid_entries()), (MERL_DIMS, 0));
    let mut rng = Rng(12345);
    let mut checked = 0;
    for ih in (0..90).step_by(7).chain([1, 2, 88, 89]) {
        for id in (0..90).step_by(11).chain([89]) {
            for ip in (0..180).step_by(13).chain([0, 179]) {
                let (th, td, pd) = centre(ih, id, ip);
                let ph = (rng.next() * 2.0 - 1.0) * PI;
                let (wi, wo) = from_half_diff(th, ph, td, pd);
                if wi.z <= 1e-6 || wo.z <= 1e-6 {
                    continue;
                }
                checked += 1;
                let f = eval(&b, wi, wo);
                let g = eval(&b, wo, wi); // φd + π: the same cell by reciprocity
                                          // φd − π (negative): MERL adds π, the same cell again.
                let (wi2, wo2) = from_half_diff(th, ph, td, pd - PI);
                let f2 = eval(&b, wi2, wo2);
                for c in 0..3 {
                    let want = smooth(th, td, pd, c);
                    assert!(close(f[c], want, 1e-14), "cell ({ih}, {id}, {ip}) c {c}: {} vs {want}", f[c]);
                    assert_eq!(f[c], g[c], "reciprocity at cell ({ih}, {id}, {ip})");
                    assert_eq!(f[c], f2[c], "φd − π at cell ({ih}, {id}, {ip})");
                }
                assert_eq!(b.cell(ih, id, ip).unwrap(), f);
                // Any point inside the bin reads the same cell.
                let nh = 90.0;
                let u = (ih as f64 + 0.05 + 0.9 * rng.next()) / nh;
                let th_in = FRAC_PI_2 * u * u;
                let td_in = (id as f64 + 0.05 + 0.9 * rng.next()) / 90.0 * FRAC_PI_2;
                let pd_in = (ip as f64 + 0.05 + 0.9 * rng.next()) / 180.0 * PI;
                let (wi, wo) = from_half_diff(th_in, ph, td_in, pd_in);
                if wi.z > 1e-6 && wo.z > 1e-6 {
                    assert_eq!(eval(&b, wi, wo), f, "inside cell ({ih}, {id}, {ip})");
                }
            }
        }
    }
    assert!(checked > 500, "{checked}");
    // Past the last θh and θd bins the lookup clamps (never reads outside the table).
    assert_eq!(b.bin(FRAC_PI_2 * 1.5, PI, 3.0 * PI), (89, 89, 0));
    assert_eq!(b.bin(-1.0, -1.0, -0.26 * PI), (0, 0, 133));
    assert_eq!(b.bin(f64::NAN, f64::NAN, f64::NAN), (0, 0, 0));
    std::fs::remove_dir_all(&d).ok();
}

/// Trilinear: with a table linear in (i, j, k) the interpolant is that linear function of the index
/// coordinates (u = n_θh·√(θh/(π/2)), v = n_θd·θd/(π/2), w = n_φd·φd/π) anywhere inside, wraps in φd between
/// the last sample and the first (period π), and is reciprocal. The table has non-MERL dimensions, which the
/// header allows.
#[test]
fn trilinear_interpolates_in_index_space() {
    let dims = [30, 20, 40];
    let d = tmp_dir("trilinear");
    let file = d.join("linear.binary");
    let lin = |u: f64, v: f64, w: f64, c: usize| 1.0 + 0.5 * u + 0.25 * v + 0.125 * w + c as f64;
    write_merl(&file, dims, |i, j, k, c| lin(i as f64, j as f64, k as f64, c) / MERL_SCALE[c]);
    let b = MerlBrdf::load(&file, Interpolation::Trilinear).unwrap();
    assert_eq!(b.dims(), dims);
    assert!(close(b.resolution_slope(), (FRAC_PI_2 / 900.0).tan(), 1e-15));
    let mut rng = Rng(777);
    let mut n = 0;
    while n < 3000 {
        let (u, v, w) = (rng.next() * 29.0, rng.next() * 19.0, rng.next() * 40.0);
        let (th, td, pd) = (FRAC_PI_2 * (u / 30.0).powi(2), v / 20.0 * FRAC_PI_2, w / 40.0 * PI);
        let (wi, wo) = from_half_diff(th, (rng.next() * 2.0 - 1.0) * PI, td, pd);
        // Near θh = 0 the azimuths φh and φd are ill-conditioned (at θh = 0 only φi − φh is defined).
        if wi.z <= 1e-6 || wo.z <= 1e-6 || th < 1e-6 {
            continue;
        }
        n += 1;
        let f = eval(&b, wi, wo);
        for c in 0..3 {
            let want = if w < 39.0 {
                lin(u, v, w, c)
            } else {
                // Between sample 39 and sample 0 (= 40 by periodicity).
                let t = w - 39.0;
                (1.0 - t) * lin(u, v, 39.0, c) + t * lin(u, v, 0.0, c)
            };
            assert!(close(f[c], want, 1e-9), "u {u} v {v} w {w} c {c}: {} vs {want}", f[c]);
        }
        let g = eval(&b, wo, wi);
        for c in 0..3 {
            assert!(close(f[c], g[c], 1e-9), "reciprocity: {f:?} vs {g:?}");
        }
    }
    std::fs::remove_dir_all(&d).ok();
}

/// Negative (unmeasured) and non-finite values are counted and read as 0, channel by channel.
#[test]
fn invalid_entries_are_counted_and_read_as_zero() {
    let d = tmp_dir("invalid");
    let file = d.join("holes.binary");
    let dims = [4, 3, 2];
    write_merl(&file, dims, |i, j, _, c| match (i, j, c) {
        (3, _, 0) => -1.0,
        (0, 2, 2) => f64::NAN,
        _ => 1500.0,
    });
    let b = MerlBrdf::load(&file, Interpolation::Nearest).unwrap();
    assert_eq!(b.invalid_entries(), 3 * 2 + 2);
    assert_eq!(b.cell(3, 0, 0).unwrap(), [0.0, 1.15, 1.66]);
    assert_eq!(b.cell(0, 2, 1).unwrap(), [1.0, 1.15, 0.0]);
    assert_eq!(b.cell(1, 1, 1).unwrap(), [1.0, 1.15, 1.66]);
    assert_eq!(b.cell(4, 0, 0), None);
    assert!(b.describe().contains("8 invalid"), "{}", b.describe());
    std::fs::remove_dir_all(&d).ok();
}

// ---------------------------------------------------------------------------------------------------------
// Through the instrument
// ---------------------------------------------------------------------------------------------------------

/// A Lambertian MERL table reads the same 60° gloss as the `lambert` model of the same RGB albedo. The
/// table's lobe term makes the integrator split around the specular direction at 1.9e-4, where the lambert
/// model has no splits: the partitions differ, the value must not.
#[test]
fn lambertian_table_gloss_equals_lambert_model() {
    let d = tmp_dir("gloss");
    lambert_table(&d.join("lambert.binary"), MERL_DIMS);
    let rtol = 1e-10;
    let read = |m: recipe::Material| {
        let plan = Plan::compile(
            m.brdf.clone(),
            vec![standards::find("astm-d523-60").unwrap()],
            PlanOptions { rtol, ..Default::default() },
        )
        .unwrap();
        let r = plan.execute();
        let g = r.iter().find(|r| r.quantity.contains("gloss") || r.unit == "GU").unwrap_or(&r[0]).clone();
        (g.value.unwrap(), g.error_estimate, g.converged)
    };
    let lambert = read(recipe::parse_str(r#"{"model": "lambert", "albedo": [0.2, 0.5, 0.8]}"#, "lambert").unwrap());
    for interp in ["nearest", "trilinear"] {
        let r = write_recipe(
            &d,
            &format!("m-{interp}.json"),
            &format!(r#"{{"model": "merl", "file": "lambert.binary", "interpolation": "{interp}"}}"#),
        );
        let merl = read(recipe::load_file(&r).unwrap());
        assert!(lambert.2 && merl.2, "not converged: {lambert:?} {merl:?}");
        assert!(lambert.0 > 0.0);
        assert!(close(merl.0, lambert.0, 1e-9), "{interp}: MERL {merl:?} vs lambert {lambert:?}");
    }
    std::fs::remove_dir_all(&d).ok();
}

// ---------------------------------------------------------------------------------------------------------
// Recipes and refusals
// ---------------------------------------------------------------------------------------------------------

#[test]
fn relative_paths_resolve_against_the_recipe_directory() {
    use glossmeter::recipe::measured::resolve;
    assert_eq!(resolve("/a/b/r.json", "t.binary"), PathBuf::from("/a/b/t.binary"));
    assert_eq!(resolve("/a/b/r.json", "/c/t.binary"), PathBuf::from("/c/t.binary"));
    assert_eq!(resolve("r.json", "sub/t.binary"), PathBuf::from("sub/t.binary"));
    assert_eq!(resolve("<stdin>", "sub/t.binary"), PathBuf::from("sub/t.binary"));
}

fn refusal(dir: &Path, recipe_name: &str, body: &str) -> String {
    let r = write_recipe(dir, recipe_name, body);
    let e = recipe::load_file(&r).unwrap_err().to_string();
    assert!(e.contains(recipe_name), "error does not name the recipe: {e}");
    e
}

#[test]
fn bad_tables_and_recipes_are_refused_with_the_file_named() {
    let d = tmp_dir("refuse");
    let good = d.join("good.binary");
    lambert_table(&good, [2, 2, 2]);
    let bytes = std::fs::read(&good).unwrap();

    // Truncated.
    std::fs::write(d.join("short.binary"), &bytes[..bytes.len() - 8]).unwrap();
    let e = refusal(&d, "r1.json", r#"{"model": "merl", "file": "short.binary"}"#);
    assert!(e.contains("field `/file`") && e.contains("short.binary") && e.contains("truncated"), "{e}");
    // Trailing bytes.
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 4]);
    std::fs::write(d.join("long.binary"), &long).unwrap();
    let e = refusal(&d, "r2.json", r#"{"model": "merl", "file": "long.binary"}"#);
    assert!(e.contains("long.binary") && e.contains("trailing"), "{e}");
    // Wrong header: a zero dimension; a header whose dims disagree with the size.
    let mut zero = bytes.clone();
    zero[8..12].copy_from_slice(&0i32.to_le_bytes());
    std::fs::write(d.join("zero.binary"), &zero).unwrap();
    let e = refusal(&d, "r3.json", r#"{"model": "merl", "file": "zero.binary"}"#);
    assert!(e.contains("zero.binary") && e.contains("header dimensions 2 × 2 × 0"), "{e}");
    let mut other = bytes.clone();
    other[0..4].copy_from_slice(&90i32.to_le_bytes());
    std::fs::write(d.join("other.binary"), &other).unwrap();
    let e = refusal(&d, "r4.json", r#"{"model": "merl", "file": "other.binary"}"#);
    assert!(e.contains("other.binary") && e.contains("90 × 2 × 2") && e.contains("truncated"), "{e}");
    // Huge dimensions (a text file read as a header) do not allocate, they are refused.
    std::fs::write(d.join("text.binary"), b"this is not a MERL file at all").unwrap();
    let e = refusal(&d, "r5.json", r#"{"model": "merl", "file": "text.binary"}"#);
    assert!(e.contains("text.binary") && e.contains("header dimensions"), "{e}");
    // Shorter than a header.
    std::fs::write(d.join("tiny.binary"), [1u8, 2, 3]).unwrap();
    let e = refusal(&d, "r6.json", r#"{"model": "merl", "file": "tiny.binary"}"#);
    assert!(e.contains("tiny.binary") && e.contains("too short"), "{e}");
    // Missing file: the recipe, the field and the OS error.
    let e = refusal(&d, "r7.json", r#"{"model": "merl", "file": "nowhere.binary"}"#);
    assert!(e.contains("field `/file`") && e.contains("nowhere.binary") && e.contains("os error"), "{e}");
    // A directory is not a table.
    let e = refusal(&d, "r8.json", &format!(r#"{{"model": "merl", "file": "{}"}}"#, d.display()));
    assert!(e.contains("field `/file`"), "{e}");
    // Recipe-level refusals.
    let e = refusal(&d, "r9.json", r#"{"model": "merl", "file": "good.binary", "interp": "nearest"}"#);
    assert!(e.contains("field `/interp`") && e.contains("unknown field"), "{e}");
    let e = refusal(&d, "r10.json", r#"{"model": "merl", "file": "good.binary", "interpolation": "cubic"}"#);
    assert!(e.contains("field `/interpolation`") && e.contains("trilinear"), "{e}");
    let e = refusal(&d, "r11.json", r#"{"model": "merl"}"#);
    assert!(e.contains("field `/file`") && e.contains("missing"), "{e}");
    let e = refusal(&d, "r12.json", r#"{"model": "merl", "file": 3}"#);
    assert!(e.contains("field `/file`") && e.contains("string"), "{e}");
    // Direct loading names the table file.
    let e = MerlBrdf::load(&d.join("short.binary"), Interpolation::Nearest).unwrap_err().to_string();
    assert!(e.starts_with(&d.join("short.binary").display().to_string()), "{e}");
    let e = MerlBrdf::from_bytes(&bytes[..20], "mem.binary", Interpolation::Nearest).unwrap_err().to_string();
    assert!(e.contains("mem.binary") && e.contains("truncated"), "{e}");
    // And the good one loads, with its metadata fields.
    let r = write_recipe(&d, "ok.json", r#"{"model": "merl", "name": "grey", "notes": ["x"], "file": "good.binary"}"#);
    assert_eq!(recipe::load_file(&r).unwrap().name, "grey");
    std::fs::remove_dir_all(&d).ok();
}

/// Not an assertion: what the integrator does with a tabulated lobe (run with `--ignored --nocapture`; the
/// numbers are quoted in docs/model.md §Measured tables). A Beckmann lobe (m = 0.1) over a Lambertian base,
/// analytic and tabulated at the table's sample points, read at 20° and 60°.
#[derive(Debug)]
struct LobeFn(glossmeter::spectrum::Sampling);
impl LobeFn {
    fn f(th: f64, td: f64) -> f64 {
        let m: f64 = 0.1;
        let t2 = th.tan().powi(2);
        let d = (-t2 / (m * m)).exp() / (PI * m * m * th.cos().powi(4));
        0.1 / PI + 0.05 * d / (4.0 * td.cos().powi(2))
    }
}
impl Brdf for LobeFn {
    fn sampling(&self) -> &glossmeter::spectrum::Sampling {
        &self.0
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let hd = half_diff(wi, wo);
        out.fill(Self::f(hd.theta_h, hd.theta_d));
    }
    fn hints(&self) -> Hints {
        let l = glossmeter::brdf::Lobe {
            slope_width: 0.1,
            medium_eta: 1.0,
            label: "lobe".into(),
            tail: glossmeter::brdf::Tail::Unknown,
        };
        Hints::new(vec![glossmeter::brdf::Term { label: "lobe".into(), kind: TermKind::Lobe(l) }])
    }
    fn describe(&self) -> String {
        "analytic lobe".into()
    }
}

#[test]
#[ignore]
fn report_tabulated_lobe_convergence() {
    let d = tmp_dir("report");
    let file = d.join("lobe.binary");
    write_merl(&file, MERL_DIMS, |ih, id, _, c| {
        let th = FRAC_PI_2 * (ih as f64 / 90.0).powi(2);
        let td = id as f64 / 90.0 * FRAC_PI_2;
        LobeFn::f(th, td) / MERL_SCALE[c]
    });
    let analytic: std::sync::Arc<dyn Brdf> = std::sync::Arc::new(LobeFn(glossmeter::spectrum::Sampling::rgb()));
    let nearest: std::sync::Arc<dyn Brdf> = std::sync::Arc::new(MerlBrdf::load(&file, Interpolation::Nearest).unwrap());
    let tri: std::sync::Arc<dyn Brdf> = std::sync::Arc::new(MerlBrdf::load(&file, Interpolation::Trilinear).unwrap());
    for id in ["astm-d523-20", "astm-d523-60"] {
        for rtol in [1e-4, 1e-6] {
            for (name, b) in [("analytic", &analytic), ("nearest", &nearest), ("trilinear", &tri)] {
                let plan = Plan::compile(
                    b.clone(),
                    vec![standards::find(id).unwrap()],
                    PlanOptions { rtol, max_evals: 5_000_000, ..Default::default() },
                )
                .unwrap();
                let t = std::time::Instant::now();
                let r = plan.execute().into_iter().find(|r| r.quantity == "gloss").unwrap();
                eprintln!(
                    "{id} rtol {rtol:e} {name:9}: gloss {:?} ± {:.2e}, {} evaluations, converged {}, {:.2} s",
                    r.value,
                    r.error_estimate,
                    r.evaluations,
                    r.converged,
                    t.elapsed().as_secs_f64()
                );
            }
        }
    }
    std::fs::remove_dir_all(&d).ok();
}
