//! The plan in plain words: [`Plan::explain`] prints the stored methods (nothing is worked out again), the
//! text of `glossmeter measure --explain`.
use std::collections::BTreeMap;

use crate::brdf::{Lobe, Tail, Term, TermKind};
use crate::colorimetry::weighting::Weighting;
use crate::instrument::aperture::{grazing_u_scale, lobe_widths_uv, Chart, DELTA_SHARE, GRAZING_REACH};
use crate::instrument::geometry::Integral;
use crate::instrument::method::{
    Method, Projection, Rule, Target, DELTA_FIT_RADIUS, DELTA_RADII, DELTA_RADIUS, DELTA_SAFETY, DELTA_TAIL_SAFETY,
    DELTA_T_ORDERS, LOBE_LEVELS, LOBE_REACH, POLAR_LEVELS, POLAR_REACH, TENSOR_MAX_LEVEL,
};
use crate::instrument::reading::ReadingSpec;
use crate::quadrature::{tensor, Refine};

use super::{Plan, SPECIMEN_SHARE, STANDARD_SHARE};

impl Plan {
    /// The plan in plain words: the stored methods, printed (nothing is worked out again here).
    pub fn explain(&self) -> String {
        let mut s = String::new();
        self.explain_material(&mut s);
        self.explain_geometries(&mut s);
        self.explain_integrals(&mut s);
        self.explain_readings(&mut s);
        s.push_str(&format!(
            "Tolerance: relative {:e} on every reading; {} of it to each specimen flux ({} of that to its analytic \
             part), {} to the gloss standard.\n",
            self.options.rtol, SPECIMEN_SHARE, DELTA_SHARE, STANDARD_SHARE
        ));
        s
    }

    /// The material, its spectral sampling and weighting, and how each of its terms is integrated.
    fn explain_material(&self, s: &mut String) {
        let m = &self.material;
        s.push_str(&format!("Material: {}\n", m.describe()));
        s.push_str(&format!("Spectral samples: {}\n", m.sampling().describe()));
        let projection =
            self.jobs.iter().find(|j| j.method.aperture.target == Target::Specimen).map(|j| j.method.projection);
        s.push_str(&format!(
            "Spectral weighting: {} ({} component(s) per flux, from {} sample(s)); {}\n",
            self.weighting.describe(),
            self.weighting.len(),
            m.sampling().len(),
            match projection {
                Some(Projection::Fold) | None =>
                    "applied in the integrand, so each aperture integral has one component per weighted quantity",
                Some(Projection::FoldInMaterial) => {
                    let row = Weighting::luminous(m.sampling()).ok().and_then(|w| w.rows.into_iter().next());
                    if row.is_some_and(|r| m.folds(&r)) {
                        "applied in the integrand, so each aperture integral has one component per weighted \
                         quantity; a luminous-only integral has the material sum its samples itself (folded tables)"
                    } else {
                        "applied in the integrand, so each aperture integral has one component per weighted quantity"
                    }
                }
                Some(Projection::Separate) => "folding off: each sample is integrated separately, then weighted",
            }
        ));
        s.push_str("Terms of the material, and how each is integrated:\n");
        for t in &self.terms {
            let how = match &t.kind {
                TermKind::Delta => {
                    "ideal mirror: analytic in the lobe variables, a 2-D integral over the stops' mirror overlap"
                        .to_string()
                }
                TermKind::Diffuse => "smooth in direction: no lobe splits needed".to_string(),
                TermKind::Lobe(l) => format!(
                    "glossy lobe, slope width {}{}{}: lobe variables split at 0 and ±(1, 3, 10, 30, …)× its width as \
                     each receptor sees it (see each geometry below), {}",
                    width(l.slope_width),
                    if l.medium_eta != 1.0 {
                        format!(" inside a medium of index {}", l.medium_eta)
                    } else {
                        String::new()
                    },
                    match l.tail {
                        Tail::Table { half_width, resolution } if half_width.is_finite() => format!(
                            ", a measured table's tail (its own half width at half maximum {half_width:.3e}; also \
                             split at 0 and ± its first ring, resolution {resolution:.3e}; the other kinks at its \
                             cells left to the adaptive partition)"
                        ),
                        Tail::Table { resolution, .. } => format!(
                            ", a measured table's tail (it does not fall to half within {}° of tilt; split at 0 and \
                             ± its first ring, resolution {resolution:.3e}; the other kinks at its cells left to the \
                             adaptive partition)",
                            crate::measured::table::HALF_WIDTH_MAX_TILT_DEG
                        ),
                        t if t.is_heavy() => ", heavy tail".to_string(),
                        _ => String::new(),
                    },
                    if l.tail.is_heavy() {
                        "out to the ends of the range"
                    } else {
                        "out to 10× its width (Gaussian tail)"
                    }
                ),
            };
            s.push_str(&format!("  - {}: {how}\n", t.label));
        }
        s.push_str("  Terms the material does not have are not built and cost nothing.\n");
    }

    /// Each geometry: its angle and standard, and the lobes' widths in its lobe variables.
    fn explain_geometries(&self, s: &mut String) {
        let lobes: Vec<&Lobe> = self
            .terms
            .iter()
            .filter_map(|t| match &t.kind {
                TermKind::Lobe(l) => Some(l),
                _ => None,
            })
            .collect();
        for g in &self.geometries {
            let geo = &g.geometry;
            if geo.is_composite() {
                s.push_str(&format!(
                    "Geometry {} ({}): combines other geometries' gloss readings\n",
                    geo.id, geo.title
                ));
                continue;
            }
            if geo.is_colour() {
                s.push_str(&format!(
                    "Geometry {} ({}): colour, X, Y, Z under {} relative to the perfect reflecting diffuser \
                     (the spectral dimension is not folded into one luminous component: three components per \
                     flux), then L*, a*, b*, C*, h\n",
                    geo.id,
                    geo.title,
                    self.options.colour.describe()
                ));
                continue;
            }
            s.push_str(&format!(
                "Geometry {} ({}), θ = {:.4}°, standard: {}\n",
                geo.id,
                geo.title,
                geo.theta.to_degrees(),
                geo.scale.describe()
            ));
            if let Some(text) = crate::instrument::standards::gloss::pixel_array_text(g) {
                s.push_str(&text);
            }
            for l in &lobes {
                let w = lobe_widths_uv(l, geo.theta);
                // The u splits at grazing (`aperture::narrowed_in_u`, docs/instrument.md §Quadrature, *The u
                // width at grazing*, *Under a coat*): min(w_u, grazing_u_scale / y²), y ≤ GRAZING_REACH widths
                // out in v.
                let narrowest = grazing_u_scale(geo.theta, l.medium_eta) / (GRAZING_REACH * GRAZING_REACH);
                let grazing = if narrowest < w[0] {
                    format!(
                        "; its u splits use the narrower width the lobe has away from the plane of incidence, \
                         {} / y² at y lobe widths out in v (y ≤ {GRAZING_REACH}, so down to {})",
                        if l.medium_eta == 1.0 { "cot θ" } else { "η² cos² θ' / (sin θ cos θ)" },
                        width(narrowest)
                    )
                } else {
                    String::new()
                };
                let heavy = if matches!(l.tail, Tail::InverseQuartic | Tail::Table { .. }) {
                    "; a receptor off the specular direction sees its heavy tail wider, by √(1 + (gap/width)²) on \
                     the other axis"
                } else {
                    ""
                };
                s.push_str(&format!(
                    "  lobe '{}' is {} × {} wide in the lobe variables (u, v){grazing}{heavy}\n",
                    l.label,
                    width(w[0]),
                    width(w[1])
                ));
            }
        }
    }

    /// The aperture integrals of the plan, each with its method and the readings that use it.
    fn explain_integrals(&self, s: &mut String) {
        let n_spec = self.jobs.iter().filter(|j| j.method.aperture.target == Target::Specimen).count();
        let n_std = self.jobs.len() - n_spec;
        let uses: usize = self.readings.iter().map(|r| r.specimen_jobs.len() + r.standard_jobs.len()).sum();
        s.push_str(&format!(
            "Aperture integrals: {} on the specimen, {} on gloss standards ({} uses by {} readings{})\n",
            n_spec,
            n_std,
            uses,
            self.readings.len(),
            if self.engine.share_fluxes {
                "; each distinct integral computed once and shared"
            } else {
                "; sharing off"
            }
        ));
        for (i, j) in self.jobs.iter().enumerate() {
            let viewing = if j.method.aperture.viewing != j.method.aperture.theta {
                format!(
                    ", receptor axis {:.4}° (off specular: no mirror image)",
                    j.method.aperture.viewing.to_degrees()
                )
            } else {
                String::new()
            };
            s.push_str(&format!(
                "  #{i}: {:?} at {:.4}°{viewing}, {} component(s), {}; used by {}\n",
                j.method.aperture.target,
                j.method.aperture.theta.to_degrees(),
                j.method.weighting.len(),
                describe_method(&j.method, &self.terms),
                j.used_by.join(", ")
            ));
        }
    }

    /// Each reported reading and the integrals it is made of.
    fn explain_readings(&self, s: &mut String) {
        s.push_str("Readings, from the integrals above:\n");
        for r in self.readings.iter().filter(|r| r.reported) {
            let jobs = |m: &BTreeMap<String, usize>| m.iter().map(|(n, j)| format!("{n} #{j}")).collect::<Vec<_>>();
            let extra = match &r.spec {
                ReadingSpec::HazeCompensated { compensation, factor, .. }
                | ReadingSpec::LogHazeCompensated { compensation, factor, .. } => {
                    format!("; minus {factor:.6} × {compensation} (ratio of projected solid angles)")
                }
                _ => String::new(),
            };
            s.push_str(&format!(
                "  {}/{} ({}): specimen {}; standard {}{extra}\n",
                r.geometry,
                r.name,
                r.spec.quantity(),
                if r.specimen_jobs.is_empty() { "—".to_string() } else { jobs(&r.specimen_jobs).join(", ") },
                if r.standard_jobs.is_empty() { "—".to_string() } else { jobs(&r.standard_jobs).join(", ") },
            ));
        }
    }
}

/// One method in words, from its stored fields.
fn describe_method(m: &Method, terms: &[Term]) -> String {
    match m.aperture.integral {
        Integral::Hemisphere => {
            return "d/8 sphere: directional–hemispherical reflectance at the viewing angle per sample (brdf::albedo of \
                    the transposed BRDF, Gauss–Kronrod in half-vector coordinates), delta included, then weighted"
                .to_string()
        }
        Integral::Port { half_angle } => {
            return format!(
                "d/8 specular port: delta + ∫ f cos θ dω over a {:.1}° cone about the mirror of the viewing \
                 direction per sample (Genz–Malik, polar tangent coordinates), then weighted",
                half_angle.to_degrees()
            )
        }
        Integral::Aperture => {}
    }
    if m.clipped.is_none() {
        return "stops below the horizon: zero".to_string();
    }
    let material_has_delta = m.aperture.target == Target::Standard || terms.iter().any(|t| t.kind == TermKind::Delta);
    let frozen = |r: Refine| if r == Refine::Frozen { ", frozen" } else { "" };
    let delta = match (&m.delta, material_has_delta, m.mirror.is_some()) {
        (Some(p), _, _) => format!(
            "analytic delta{} ({} box{})",
            describe_kinks(&p.kinks, "p cut along cos θi = cos θc"),
            p.cells.len(),
            frozen(p.refine)
        ),
        (None, true, false) => "no mirror image in this stop (delta skipped)".to_string(),
        _ => String::new(),
    };
    let regular = m.regular.as_ref().map(|p| {
        let chart = match p.chart {
            Chart::Plain => format!(
                "plain variables (no lobe narrower than the stops){}",
                describe_kinks(&p.kinks, "p_s cut along ωi·h = cos θc")
            ),
            Chart::Lobe | Chart::PlainPLobeQ => format!(
                "lobe variables, {} × {} split points{}",
                p.splits[0].len(),
                p.splits[1].len(),
                describe_kinks(&p.kinks, "t_p cut along ωi·h = cos θc")
            ),
        };
        let rule = match p.rule {
            Rule::GenzMalik75 => format!("Genz–Malik 7/5 on {} initial box(es)", p.cells.len()),
            Rule::TailBound => format!(
                "the material's bound of its tail at the smallest angle the stops leave from the mirror image \
                 (half of it ± half, when within the tolerance; else Genz–Malik 7/5 on {} initial box(es))",
                p.cells.len()
            ),
            Rule::LobeGaussHermite { width, levels } => format!(
                "Gauss–Hermite in (u, v) scaled to the lobe ({:.3e} × {:.3e}) × Gauss–Legendre in (t_p, t_q), \
                 orders {} raised until two successive agree (the lobe is ≥ {} widths from every overlap kink; \
                 fallback: Genz–Malik 7/5 on {} initial box(es))",
                width[0],
                width[1],
                LOBE_LEVELS[levels.0..=levels.1]
                    .iter()
                    .map(|(h, l)| format!("{h}²×{l}²"))
                    .collect::<Vec<_>>()
                    .join(" → "),
                LOBE_REACH,
                p.cells.len()
            ),
            Rule::LobeDelta { width } => format!(
                "delta limit of the lobe ({:.3e} × {:.3e}): per Gauss–Legendre node of (t_p, t_q) ({}²), the mass \
                 π·F(0)/√det B from the lobe's curvature B on a ring of {} width, accepted when its bound meets the \
                 tolerance: {}× the largest |h_e(x) − h(0)|/xᵀBx of the even part of h = F·e^{{xᵀBx}} on rings of \
                 {} and {:?} widths, + the tail beyond {} widths, F(0)·(e^{{−R²}} + e^{{−λR²}}/λ) with λ the lobe's \
                 decay rate there ÷ {}, + the t rule's difference from {}² nodes (the lobe is ≥ {} widths from every \
                 overlap kink; else Gauss–Hermite orders {}, then Genz–Malik 7/5 on {} initial box(es))",
                width[0],
                width[1],
                DELTA_T_ORDERS.1,
                DELTA_FIT_RADIUS,
                DELTA_SAFETY,
                DELTA_FIT_RADIUS,
                DELTA_RADII,
                DELTA_RADIUS,
                DELTA_TAIL_SAFETY,
                DELTA_T_ORDERS.0,
                LOBE_REACH,
                LOBE_LEVELS.iter().map(|(h, l)| format!("{h}²×{l}²")).collect::<Vec<_>>().join(" → "),
                p.cells.len()
            ),
            Rule::LobePolar { width, u, v, levels } => describe_polar(width, u, v, levels, p.cells.len()),
            Rule::TensorGauss { chart, levels, path } => describe_tensor(chart, levels, path, p.cells.len()),
        };
        format!("{chart}, {rule}{}", frozen(p.refine))
    });
    match (delta.is_empty(), regular) {
        (true, None) => "nothing to integrate: zero".to_string(),
        (false, None) if m.delta.is_none() => format!("{delta} and no regular part: zero"),
        (false, None) => format!("{delta} only"),
        (true, Some(r)) => r,
        (false, Some(r)) => format!("{delta} + {r}"),
    }
}

/// [`Rule::LobePolar`] in words: the pieces, their rules, the levels (the designed ones, or a frozen method's).
fn describe_polar(width: [f64; 2], u: [f64; 4], v: [f64; 4], levels: [u8; 9], boxes: usize) -> String {
    let holds = |b: &[f64; 4], i: usize| b[i] < 0.0 && b[i + 1] > 0.0;
    let mut tails = 0;
    let mut central = 1;
    let mut tail_levels = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            if !(u[i + 1] > u[i] && v[j + 1] > v[j]) {
                continue;
            }
            if holds(&u, i) && holds(&v, j) {
                central = levels[3 * i + j];
            } else {
                tails += 1;
                tail_levels.push(levels[3 * i + j].to_string());
            }
        }
    }
    format!(
        "polar variables about the specular point in the kink square (x = u/{:.3e} = ρ cos φ, y = v/{:.3e} = \
         ρ sin φ, ρ = tan β for GGX's tail; Gauss–Legendre in φ per sector and in ρ, level {central} of {}) + Gauss–Legendre on \
         {tails} tail box(es) (in σ = 1/x along its tail coordinate × y = c·tan γ across it; levels {}) × Gauss–Legendre in (t_p, t_q); each piece raised until \
         the summed differences of successive levels meet the tolerance (the lobe is ≥ {} widths from every \
         overlap kink; fallback: Genz–Malik 7/5 on {boxes} initial box(es))",
        width[0],
        width[1],
        POLAR_LEVELS.len() - 1,
        if tail_levels.is_empty() { "none".to_string() } else { tail_levels.join(", ") },
        POLAR_REACH,
    )
}

/// [`Rule::TensorGauss`] in words: its boxes, its orders (the starting ones, or the final ones of a frozen
/// method's path) and its fallback.
fn describe_tensor(chart: Chart, levels: [usize; 4], path: tensor::Path, fallback_boxes: usize) -> String {
    let orders = path.replayed(levels, tensor::MAX_BOXES).map(|l| tensor::ORDERS[l]);
    let (vars, boxes) = match chart {
        Chart::Plain => ("(p_s, q_s, p_r, q_r)", "on the one box of the stops' product"),
        Chart::Lobe => ("(u, t_p, v, t_q)", "on the boxes between the overlap kinks of u and v"),
        Chart::PlainPLobeQ => ("(p_s, p_r, v, t_q)", "on the boxes between the overlap kinks of v"),
    };
    format!(
        "smooth integrand: tensor Gauss–Legendre in {vars} {boxes}, orders {} {}, per-axis orders raised \
         (up to {}) until the sum of the per-axis differences of successive orders (calibrated) meets the \
         tolerance (fallback: Genz–Malik 7/5 on {fallback_boxes} initial box(es) of the lobe variables)",
        orders.map(|o| o.to_string()).join("×"),
        if path.len > 0 { "(the highest final orders over the boxes)" } else { "to start on every box" },
        tensor::ORDERS[TENSOR_MAX_LEVEL],
    )
}

/// The kinks of a part in words: ", <how> at θc = 19.72°, …" (empty without kinks).
fn describe_kinks(kinks: &[f64], how: &str) -> String {
    if kinks.is_empty() {
        return String::new();
    }
    let angles: Vec<String> = kinks.iter().map(|c| format!("{:.4}°", c.acos().to_degrees())).collect();
    format!(", {how} (Fresnel critical angle{} θc = {})", if kinks.len() > 1 { "s" } else { "" }, angles.join(", "))
}

/// A width as `--explain` prints it: a finite one in three digits, and one with no finite value (a measured
/// table's lobe that does not fall to half within 40° of tilt) in words, never as `inf`.
fn width(w: f64) -> String {
    if w.is_finite() {
        format!("{w:.3e}")
    } else {
        "unbounded".to_string()
    }
}
