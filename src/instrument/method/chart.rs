//! The chart map: a point of a regular part's chart (its [`Chart`], and the kinks the part cuts it at) to
//! the stops' coordinates (p_s, q_s, p_r, q_r) and the Jacobian of the change of variables
//! (`docs/instrument.md` §Quadrature). One value, built once per rule run and handed to the regular part's
//! integrand, which evaluates the BRDF at the two directions of the mapped point.
use crate::instrument::aperture::{half_angle_kink_point, kinked_position, plain_kink_point, AxisMap, Chart};
use crate::instrument::geometry::{Axes, Stop};

/// A chart with everything its map needs: the source's and the receptor's axes, the clipped stops, and the
/// cosines of the half-angle kinks that cut its position variable (`RegularPart::kinks`; empty: none).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChartMap<'a> {
    pub chart: Chart,
    kinks: &'a [f64],
    axes: Axes,
    rec_axes: Axes,
    src: Stop,
    ap: AxisMap,
    aq: AxisMap,
}

impl<'a> ChartMap<'a> {
    /// The map of `chart` for source axis θ, receptor axis `viewing` and the clipped stops; `kinks` cut the
    /// first position variable: t of p_s in the plain chart (`aperture::plain_kink_point`), t_p in the lobe
    /// chart (`aperture::half_angle_kink_point`); the mixed chart `PlainPLobeQ` has none.
    pub(crate) fn new(
        chart: Chart,
        kinks: &'a [f64],
        theta: f64,
        viewing: f64,
        (src, rec): (Stop, Stop),
    ) -> ChartMap<'a> {
        ChartMap {
            chart,
            kinks,
            axes: Axes::new(theta),
            rec_axes: Axes::new(viewing),
            src,
            ap: AxisMap { s: src.p, r: rec.p },
            aq: AxisMap { s: src.q, r: rec.q },
        }
    }

    /// The source's axes (θ).
    pub(crate) fn axes(&self) -> &Axes {
        &self.axes
    }

    /// The receptor's axes (the viewing angle).
    pub(crate) fn rec_axes(&self) -> &Axes {
        &self.rec_axes
    }

    /// The stops' coordinates (p_s, q_s, p_r, q_r) of the chart's point `x` and the Jacobian; a Jacobian
    /// ≤ 0 marks a point outside the overlap (the integrand skips it).
    #[inline]
    pub(crate) fn map(&self, x: &[f64; 4]) -> ([f64; 4], f64) {
        let (src, axes) = (self.src, &self.axes);
        let (ps, qs, pr, qr, jac) = match self.chart {
            // The plain chart cut at the kinks: x[0] is the kinked position t of p_s.
            Chart::Plain if !self.kinks.is_empty() => {
                let wo = self.rec_axes.receptor_dir(x[2], x[3]);
                let (ps, jp) = kinked_position(x[0], src.p[0], src.p[1], self.kinks.len(), |k| {
                    let c = self.kinks[k];
                    plain_kink_point(axes, 2.0 * c * c - 1.0, x[1], wo, src.p[0], src.p[1])
                });
                (ps, x[1], x[2], x[3], jp)
            }
            Chart::Plain => (x[0], x[1], x[2], x[3], 1.0),
            Chart::PlainPLobeQ => {
                let (qs, qr, jq) = self.aq.at(x[2], x[3]);
                (x[0], qs, x[1], qr, jq)
            }
            Chart::Lobe if self.kinks.is_empty() => {
                let (ps, pr, jp) = self.ap.at(x[0], x[1]);
                let (qs, qr, jq) = self.aq.at(x[2], x[3]);
                (ps, qs, pr, qr, jp * jq)
            }
            Chart::Lobe => {
                let (qs, qr, jq) = self.aq.at(x[2], x[3]);
                let u = x[0];
                let (lo, hi) = self.ap.overlap(u);
                let (ps, jp) = kinked_position(x[1], lo, hi, self.kinks.len(), |k| {
                    let c = self.kinks[k];
                    half_angle_kink_point(axes, 2.0 * c * c - 1.0, u, qs, qr, lo, hi)
                });
                (ps, qs, u - ps, qr, jp * jq)
            }
        };
        ([ps, qs, pr, qr], jac)
    }
}
