//! A rough interface with a scatter halo: the two-scale surface of a lacquer whose large-scale slopes
//! (orange peel, a microfacet slope distribution in geometric optics) carry a small-scale micro-roughness
//! that scatters by Rayleigh–Rice (`brdf::halo`, `optics::scatter`). It exists because a real panel's
//! 20° profile shows both at once: the specular peak spread over tenths of a degree (Rspec far below 20°
//! gloss) and a halo reaching the haze windows near 2° (docs/optics.md §9, the two-scale
//! form; docs/instrument.md §1.10):
//!
//!   f = (1 − g(θ̄))·f_facets(ωi, ωo) + f_RR(ωi, ωo),     cos θ̄ = (cos θi + cos θo)/2,
//!
//! with g the band-limited Debye–Waller exponent of the halo (`Halo::loss`), the share of the interface's
//! reflection the micro-roughness scatters. The facets' lobe loses what the halo gains, as the smooth
//! interface's mirror does in `WithHalo`; g is taken at the mean cosine so that the product stays reciprocal
//! (at the specular direction of a facet it is g(θi), the smooth-interface loss; Beckmann & Spizzichino's
//! two-scale treatment multiplies the large-scale facets' reflection by the small scale's coherent factor in
//! the same way). The halo is added about the mean specular direction, not convolved with the facets'
//! slopes: for slope widths far below the halo's angular width (orange peel ~0.1°, the halo ~1° and more)
//! the convolution changes it to second order in their ratio.
use super::halo::Halo;
use super::{above_horizon, Brdf, Hints};
use crate::optics::tabulated::ChebTable;
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use std::sync::Arc;

/// A rough interface (a regular lobe, no mirror) with the scatter halo of its micro-roughness.
#[derive(Clone, Debug)]
pub(crate) struct RoughWithHalo {
    pub inner: Arc<dyn Brdf>,
    pub halo: Halo,
    /// g(cos θ̄) per sample as a verified piecewise Chebyshev table on [0, 1] (`optics::tabulated`; within
    /// 1e-13 of `Halo::loss`), or None where no table met that (then g is computed at each evaluation). The
    /// band-limited integral behind g costs a few µs, the table a few ns.
    loss: Vec<Option<ChebTable>>,
}

/// The largest deviation of a loss table from `Halo::loss` (g ≤ 0.25 by the smooth-surface bound).
const LOSS_TOL: f64 = 1e-13;

impl RoughWithHalo {
    /// `inner` is the rough interface (the recipe parser passes a microfacet surface whose roughness is above
    /// the smooth limit); `halo` the scatter of the same interface.
    pub(crate) fn new(inner: Arc<dyn Brdf>, halo: Halo) -> Result<RoughWithHalo> {
        if halo.eps.len() != inner.sampling().len() {
            return Err(Error::Usage("scatter halo: sampling differs from the model's".into()));
        }
        let loss = (0..halo.eps.len()).map(|k| ChebTable::fit(|c| halo.loss(k, c), 0.0, 1.0, LOSS_TOL)).collect();
        Ok(RoughWithHalo { inner, halo, loss })
    }

    /// The factor 1 − g(θ̄) of sample `k` for the pair (wi, wo).
    fn keep(&self, k: usize, wi: Vec3, wo: Vec3) -> f64 {
        let c = (0.5 * (wi.z + wo.z)).clamp(0.0, 1.0);
        let g = match &self.loss[k] {
            Some(t) => t.eval(c),
            None => self.halo.loss(k, c),
        };
        (1.0 - g).max(0.0)
    }
}

impl Brdf for RoughWithHalo {
    fn sampling(&self) -> &Sampling {
        self.inner.sampling()
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.inner.eval(wi, wo, out);
        if above_horizon(wi, wo) {
            for (k, o) in out.iter_mut().enumerate() {
                *o *= self.keep(k, wi, wo);
            }
            self.halo.add(wi, wo, out);
        }
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        // A smooth inner model is given a WithHalo by the parser; should one arrive here, its mirror loses
        // what the halo takes, as there.
        if !self.inner.delta_reflectance(wi, out) {
            return false;
        }
        self.halo.take_from_mirror(wi, out);
        true
    }

    /// The facets' hints with the halo's term (`Halo::over`): the factor 1 − g depends on ωi and ωo
    /// symmetrically, so the whole is reciprocal if the facets are, and g is analytic in cos θ̄ (the PSD
    /// integrated over a disc whose radius moves smoothly; its table within 1e-13, far below any tolerance),
    /// so the whole is smooth if the facets are.
    fn hints(&self) -> Hints {
        self.halo.over(self.inner.hints())
    }

    fn describe(&self) -> String {
        format!("{}; its micro-roughness scatters a halo ({})", self.inner.describe(), self.halo.describe())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::scatter::Psd;
    use crate::recipe::parse_str;
    use num_complex::Complex64;

    const RECIPE: &str = r#"{"model": "microfacet", "distribution": "beckmann", "roughness": 0.003, "ior": 1.5,
        "scatter": {"psd": "k-correlation", "rms_roughness_nm": 10, "correlation_length_um": 4, "c": 2}}"#;

    fn unit(x: f64, y: f64) -> Vec3 {
        Vec3::new(x, y, (1.0 - x * x - y * y).sqrt())
    }

    #[test]
    fn reciprocal_and_the_facets_lose_what_the_halo_scatters() {
        let f = parse_str(RECIPE, "<test>").unwrap().brdf;
        assert!(f.describe().contains("halo"), "{}", f.describe());
        let (a, b) = (unit(-0.3, 0.1), unit(0.35, -0.05));
        let (mut x, mut y) = ([0.0], [0.0]);
        f.eval(a, b, &mut x);
        f.eval(b, a, &mut y);
        assert!(x[0] > 0.0 && (x[0] - y[0]).abs() <= 1e-12 * x[0], "{x:?} {y:?}");
        // Near the specular direction: (1 − g(θ̄))·facets + halo, with the halo of the same PSD.
        let bare =
            parse_str(r#"{"model": "microfacet", "distribution": "beckmann", "roughness": 0.003, "ior": 1.5}"#, "<t>")
                .unwrap()
                .brdf;
        let halo = Halo::new(Psd::k_correlation(10.0, 4.0, 2.0), &[Complex64::new(1.5, 0.0)], bare.sampling()).unwrap();
        let t = 20f64.to_radians();
        let (wi, wo) = (unit(-t.sin(), 0.0), unit(t.sin() + 0.002, 0.001));
        let (mut with, mut without, mut h) = ([0.0], [0.0], [0.0]);
        f.eval(wi, wo, &mut with);
        bare.eval(wi, wo, &mut without);
        halo.add(wi, wo, &mut h);
        let g = halo.loss(0, 0.5 * (wi.z + wo.z));
        assert!(g > 0.0 && g < 0.2, "{g}");
        let want = (1.0 - g) * without[0] + h[0];
        assert!((with[0] - want).abs() <= 1e-12 * want, "{with:?} vs {want}");
    }
}
