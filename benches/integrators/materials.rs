//! Bench materials, written out here (independently of src/optics/microfacet.rs) so that the baselines and
//! the engine evaluate exactly the same object, and so that the Python baselines can re-implement the same
//! formulas.

use glossmeter::brdf::{Brdf, Hints, Lobe, Tail, Term, TermKind};
use glossmeter::optics::fresnel::fr_dielectric;
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;

#[derive(Debug)]
pub(crate) struct BenchLambert {
    pub(crate) albedo: f64,
    pub(crate) s: Sampling,
}

impl Brdf for BenchLambert {
    fn sampling(&self) -> &Sampling {
        &self.s
    }
    fn eval(&self, _: Vec3, _: Vec3, out: &mut [f64]) {
        out[0] = self.albedo / std::f64::consts::PI;
    }
    fn hints(&self) -> Hints {
        Hints::new(vec![Term { label: "lambert".into(), kind: TermKind::Diffuse }])
    }
    fn describe(&self) -> String {
        format!("Lambert albedo {}", self.albedo)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Dist {
    Beckmann,
    Ggx,
}

/// F(ωi·h)·D(h)·G/(4 cos θi cos θo) on a dielectric of index n; Smith height-correlated G (Heitz 2014);
/// tan²θ from components (numerics notes §4.4), Beckmann Λ through erfc (§4.5), GGX Λ without cancellation.
#[derive(Debug)]
pub(crate) struct BenchMicrofacet {
    pub(crate) dist: Dist,
    pub(crate) alpha: f64,
    pub(crate) n: f64,
    pub(crate) s: Sampling,
}

impl BenchMicrofacet {
    pub(crate) fn new(dist: Dist, alpha: f64, n: f64) -> Self {
        BenchMicrofacet { dist, alpha, n, s: Sampling::grey() }
    }
    fn lambda(&self, w: Vec3) -> f64 {
        let t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
        if t2 == 0.0 {
            return 0.0;
        }
        match self.dist {
            Dist::Beckmann => {
                let a = 1.0 / (self.alpha * t2.sqrt());
                0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - libm::erfc(a))
            }
            Dist::Ggx => {
                let x = self.alpha * self.alpha * t2;
                0.5 * x / ((1.0 + x).sqrt() + 1.0)
            }
        }
    }
}

impl Brdf for BenchMicrofacet {
    fn sampling(&self) -> &Sampling {
        &self.s
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            out[0] = 0.0;
            return;
        }
        let h = (wi + wo).normalize();
        let t2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        let a2 = self.alpha * self.alpha;
        let c4 = h.z.powi(4);
        let d = match self.dist {
            Dist::Beckmann => (-t2 / a2).exp() / (std::f64::consts::PI * a2 * c4),
            Dist::Ggx => {
                let k = a2 + t2;
                a2 / (std::f64::consts::PI * c4 * k * k)
            }
        };
        let g = 1.0 / (1.0 + self.lambda(wi) + self.lambda(wo));
        out[0] = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), self.n) * d * g / (4.0 * wi.z * wo.z);
    }
    fn hints(&self) -> Hints {
        let label = format!("{:?} {}", self.dist, self.alpha);
        Hints::new(vec![Term {
            label: label.clone(),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.alpha,
                medium_eta: 1.0,
                label,
                tail: if self.dist == Dist::Ggx { Tail::InverseQuartic } else { Tail::Gaussian },
            }),
        }])
    }
    fn describe(&self) -> String {
        format!("{:?} α = {}, n = {}", self.dist, self.alpha, self.n)
    }
}
