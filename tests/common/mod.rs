//! Test helpers shared by the integration tests.
#![allow(dead_code)]
use glossmeter::brdf::{Brdf, Lobe, Term, TermKind};
use glossmeter::optics::fresnel::fr_dielectric;
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;

/// Beckmann microfacet on a dielectric (F·D·G/(4 cos cos)), written out here from Walter et al. 2007 so
/// the test does not share code with the models under test; G = Smith height-correlated.
#[derive(Debug)]
pub struct TestBeckmann {
    pub m: f64,
    pub n: f64,
    pub s: Sampling,
}
impl TestBeckmann {
    fn lambda(&self, w: Vec3) -> f64 {
        let t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
        if t2 == 0.0 {
            return 0.0;
        }
        let a = 1.0 / (self.m * t2.sqrt());
        0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - libm::erfc(a))
    }
}
impl Brdf for TestBeckmann {
    fn sampling(&self) -> &Sampling {
        &self.s
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let h = (wi + wo).normalize();
        let t2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        let m2 = self.m * self.m;
        let d = (-t2 / m2).exp() / (std::f64::consts::PI * m2 * h.z.powi(4));
        let g = 1.0 / (1.0 + self.lambda(wi) + self.lambda(wo));
        let f = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), self.n) * d * g / (4.0 * wi.z * wo.z);
        out.iter_mut().for_each(|o| *o = f);
    }
    fn terms(&self) -> Vec<Term> {
        vec![Term {
            label: "beckmann".into(),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.m,
                medium_eta: 1.0,
                label: "beckmann".into(),
                heavy_tail: false,
            }),
        }]
    }
    fn describe(&self) -> String {
        format!("test beckmann m = {}", self.m)
    }
}
