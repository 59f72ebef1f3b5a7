//! The facet term of a measured surface (`"model": "topography"`): a dielectric interface whose distribution
//! of normals is the topography's own slope distribution (`optics::slope_table`), with Smith masking from the
//! same slopes' second moments, and no fitted parameter:
//! f = F(ωi·h)·D(h)·G(ωi, ωo)/(4 cos θi cos θo) (Walter et al. 2007 Eq. 20), F the dielectric Fresnel
//! reflectance of the index beneath (docs/topography.md §The facet term of a measured surface).
//!
//! The map's x axis is the plane of measurement's (a surface's anisotropy is kept: D is the 2-D slope
//! density, not its radial average). For the planner it is one lobe as wide as the largest Gaussian-equivalent
//! α of the slopes, of unknown tail (a measured density is no Gaussian nor GGX, so no shaped rule applies:
//! the adaptive partition integrates it).
use super::dielectric::Ior;
use super::{below_horizon, fresnel_kinks, Brdf, Hints, Lobe, Tail, Term, TermKind};
use crate::optics::microfacet::{g_with_lambda, Shadowing};
use crate::optics::slope_table::SlopeTable;
use crate::spectrum::Sampling;
use crate::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TopographySurface {
    pub slopes: SlopeTable,
    /// The index beneath the surface (real: a dielectric).
    pub ior: f64,
    /// What the slopes came from, for `describe` (the file, the levelling).
    pub source: String,
    sampling: Sampling,
}

impl TopographySurface {
    /// A finite index > 0 (the recipe's range is narrower; this is the library's check).
    pub fn new(slopes: SlopeTable, ior: f64, source: String) -> crate::Result<Self> {
        if !(ior.is_finite() && ior > 0.0) {
            return Err(crate::Error::Usage(format!("topography surface: index {ior}; allowed: a finite n > 0")));
        }
        Ok(TopographySurface { slopes, ior, source, sampling: Sampling::grey() })
    }
}

impl Brdf for TopographySurface {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        let h = (wi + wo).normalize();
        let cos_d = wi.dot(h).clamp(0.0, 1.0);
        let d = self.slopes.d(h);
        if d == 0.0 {
            out.fill(0.0);
            return;
        }
        let g = g_with_lambda(wi, wo, h, Shadowing::SmithHeightCorrelated, |w| self.slopes.lambda(w));
        let f = Ior::Dielectric(self.ior).reflectance(cos_d) * d * g / (4.0 * wi.z * wo.z);
        out.fill(f);
    }

    fn hints(&self) -> Hints {
        let label = format!("measured facets ({} slopes, rms {:.4})", self.slopes.samples, self.slopes.rms_slope());
        let lobe =
            Lobe { slope_width: self.slopes.width(), medium_eta: 1.0, label: label.clone(), tail: Tail::Unknown };
        Hints::new(vec![Term { label, kind: TermKind::Lobe(lobe) }])
            .with_kinks(fresnel_kinks([Ior::Dielectric(self.ior).critical_cosine()], false))
    }

    fn describe(&self) -> String {
        format!(
            "topography facets ({}; {} slopes, rms slope {:.4}, kernel h = {:.2e}; n = {}, Smith height-correlated with \
             the Gaussian-equivalent Λ)",
            self.source,
            self.slopes.samples,
            self.slopes.rms_slope(),
            self.slopes.bandwidth,
            self.ior
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::albedo::directional_albedo;
    use crate::optics::fresnel::fr_dielectric;

    /// Anisotropic Gaussian slopes (rms sx along x, sy along y) from a 2-D Halton sequence, as the slope
    /// table's tests make them.
    fn slopes(sx: f64, sy: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let halton = |mut i: usize, b: usize| {
            let (mut f, mut r) = (1.0, 0.0);
            while i > 0 {
                f /= b as f64;
                r += f * (i % b) as f64;
                i /= b;
            }
            r
        };
        (1..=n)
            .map(|i| {
                let (u, v) = (halton(i, 2), halton(i, 3));
                let rad = (-2.0 * u.ln()).sqrt();
                let t = 2.0 * std::f64::consts::PI * v;
                (rad * t.cos() * sx, rad * t.sin() * sy)
            })
            .unzip()
    }

    #[test]
    fn reciprocal_energy_conserving_and_anisotropic() {
        let (x, y) = slopes(0.12, 0.04, 8000);
        let t = SlopeTable::from_slopes(&x, &y).unwrap();
        // The slopes' anisotropy is kept: the widest azimuth is x's, √2·σx widened by the kernel.
        assert!((t.width() - t.alpha_along(Vec3::new(1.0, 0.0, 1.0))).abs() < 1e-3 * t.width());
        assert!(t.alpha_along(Vec3::new(0.0, 1.0, 1.0)) < 0.5 * t.width());
        let s = TopographySurface::new(t, 1.5, "test".into()).unwrap();
        let dir = |th: f64, ph: f64| {
            let (th, ph) = (th.to_radians(), ph.to_radians());
            Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
        };
        let (mut a, mut b) = ([0.0], [0.0]);
        for (i, o) in [((20.0, 180.0), (22.0, 3.0)), ((60.0, 180.0), (55.0, -2.0)), ((85.0, 180.0), (82.0, 0.5))] {
            let (wi, wo) = (dir(i.0, i.1), dir(o.0, o.1));
            s.eval(wi, wo, &mut a);
            s.eval(wo, wi, &mut b);
            assert!(a[0] > 0.0 && (a[0] - b[0]).abs() <= 1e-14 * a[0], "{a:?} {b:?}");
        }
        // A lobe wider along x than along y: for facets tilted by the same slope 0.1 along x and along y, the
        // reflection off the x-tilted ones is the stronger.
        let wi = dir(30.0, 180.0);
        let reflect = |h: Vec3| {
            let h = h.normalize();
            2.0 * wi.dot(h) * h - wi
        };
        let (mut along, mut across) = ([0.0], [0.0]);
        s.eval(wi, reflect(Vec3::new(0.1, 0.0, 1.0)), &mut along);
        s.eval(wi, reflect(Vec3::new(0.0, 0.1, 1.0)), &mut across);
        assert!(along[0] > 2.0 * across[0], "{along:?} {across:?}");
        // The directional albedo is below 1 and near the Fresnel reflectance F(θi) of a smooth interface (the
        // facets see angles about θi; masking only removes light).
        for th in [20.0f64, 60.0] {
            let (r, _) = directional_albedo(&s, dir(th, 180.0));
            assert!(r[0] > 0.0 && r[0] < 1.0, "{th}: {r:?}");
            assert!((r[0] - fr_dielectric(th.to_radians().cos(), 1.5)).abs() < 0.2 * r[0], "{th}: {r:?}");
        }
    }
}
