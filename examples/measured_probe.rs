//! Probe (measured tables): the cost of a measured table's gloss integrals with the lobe the table
//! states and with other lobe descriptions, and the shape of the table's lobe in the plane of incidence.
//! It exists to reproduce the counts of `docs/instrument.md` §Quadrature, *Measured tables*:
//! `cargo run --release --example measured_probe -- RECIPE... [--width W] [--quartic | --gaussian]
//! [--diffuse] [--max-evals N] [-g id,id]`; a RECIPE `merl-ggx:ALPHA` is a MERL-format table (90 × 90 × 180,
//! trilinear) of the engine's own GGX on n = 1.5, written in memory. The overrides replace the lobe the
//! table states (its width, its tail) or state a diffuse term instead, to measure what the planner would do
//! with that description; the values are the table's own.
use glossmeter::brdf::{Brdf, Hints, Lobe, Tail, Term, TermKind};
use glossmeter::instrument::method::Method;
use glossmeter::instrument::standards;
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;
use std::sync::Arc;

#[derive(Debug)]
struct Override {
    inner: Arc<dyn Brdf>,
    terms: Vec<Term>,
}

impl Brdf for Override {
    fn sampling(&self) -> &Sampling {
        self.inner.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.inner.eval(wi, wo, out)
    }
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.inner.eval_batch(wi, wo, out)
    }
    fn hints(&self) -> Hints {
        Hints::new(self.terms.clone())
    }
    fn describe(&self) -> String {
        self.inner.describe()
    }
}

fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// A MERL-format table (90 × 90 × 180, trilinear) of the engine's GGX microfacet model (n = 1.5), sampled at
/// the bins' lower edges.
fn merl_ggx(alpha: f64) -> glossmeter::measured::merl::MerlBrdf {
    use glossmeter::measured::merl::{Interpolation, MerlBrdf, MERL_DIMS};
    let m = glossmeter::recipe::parse_str(
        &format!(r#"{{"model":"microfacet","distribution":"ggx","roughness":{alpha},"ior":1.5}}"#),
        "ggx",
    )
    .unwrap()
    .brdf;
    MerlBrdf::tabulate(m.as_ref(), MERL_DIMS, Interpolation::Trilinear).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut width = None;
    let mut diffuse = false;
    let mut tail = Tail::Unknown;
    let mut recipes = Vec::new();
    let mut geos = vec!["astm-d523-20".to_string(), "astm-d523-60".to_string(), "astm-d523-85".to_string()];
    let mut max_evals = 3_000_000;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--width" => {
                width = Some(args[i + 1].parse::<f64>().unwrap());
                i += 1;
            }
            "--diffuse" => diffuse = true,
            "--quartic" => tail = Tail::InverseQuartic,
            "--gaussian" => tail = Tail::Gaussian,
            "--max-evals" => {
                max_evals = args[i + 1].parse().unwrap();
                i += 1;
            }
            "-g" => {
                geos = args[i + 1].split(',').map(String::from).collect();
                i += 1;
            }
            a => recipes.push(a.to_string()),
        }
        i += 1;
    }
    for r in &recipes {
        let brdf: Arc<dyn Brdf> = if let Some(a) = r.strip_prefix("merl-ggx:") {
            Arc::new(merl_ggx(a.parse().unwrap()))
        } else {
            glossmeter::recipe::load_file(std::path::Path::new(r)).unwrap().brdf
        };
        // The in-plane lobe at θi = 20°: f(θo = θi + δ) / f(specular), δ in degrees.
        let n = brdf.sampling().len();
        let mut f = vec![0.0; n];
        let ti = 20f64.to_radians();
        let at = |d: f64, f: &mut [f64]| {
            brdf.eval(dir(ti, std::f64::consts::PI), dir(ti + d.to_radians(), 0.0), f);
            f[0]
        };
        let f0 = at(0.0, &mut f);
        let shape: Vec<String> = [0.05, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 40.0]
            .iter()
            .map(|d| format!("{d}°:{:.3e}", at(*d, &mut f) / f0))
            .collect();
        println!("{r}: f(spec) = {f0:.4e}; in-plane f(θi + δ)/f(spec): {}", shape.join(" "));
        let terms = brdf.hints().terms;
        let brdf: Arc<dyn Brdf> = if width.is_some() || diffuse || tail != Tail::Unknown {
            let kind = if diffuse {
                TermKind::Diffuse
            } else {
                let TermKind::Lobe(l) = &terms[0].kind else { panic!("{terms:?}") };
                TermKind::Lobe(Lobe {
                    slope_width: width.unwrap_or(l.slope_width),
                    medium_eta: 1.0,
                    label: l.label.clone(),
                    tail,
                })
            };
            Arc::new(Override { inner: brdf, terms: vec![Term { label: "probe".into(), kind }] })
        } else {
            brdf
        };
        for g in &geos {
            let sg = standards::find(g).unwrap().geometry;
            let rec = sg.receptor("gloss").copied().unwrap();
            let method = Method::for_material(brdf.as_ref(), sg.theta, sg.source, rec, (1e-6, 0.0), max_evals).unwrap();
            let rule = format!("{:?}", method.regular.as_ref().map(|p| (p.chart, p.rule, p.cells.len())));
            let t = std::time::Instant::now();
            let flux = method.execute(brdf.as_ref());
            println!(
                "  {g}: flux {:.12e} err {:.2e} evals {} converged {} ({:.2} s) {}",
                flux.value[0],
                flux.error[0],
                flux.evaluations,
                flux.converged,
                t.elapsed().as_secs_f64(),
                &rule[..rule.len().min(160)]
            );
        }
    }
}
