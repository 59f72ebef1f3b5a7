//! The BRDF contract between reflectance models and the virtual instrument.
//!
//! A model evaluates f_r(ωi, ωo) for all of its spectral samples at once, and tells the integrator what it
//! needs in order to find the mass of the function: the ideal-mirror (delta) component with its weight, and
//! the glossy lobes with their widths. The integrator never searches for a lobe blindly (adaptive cubature
//! silently returns 0 on a lobe narrower than its first sample spacing; `docs/instrument.md` §Quadrature).
//!
//! Conventions (all models): local frame with the specimen normal along +z and the plane of measurement x–z;
//! `wi` points from the surface towards the source, `wo` towards the receptor; both are unit vectors with
//! z > 0. `eval` returns the *regular* part of f_r in sr⁻¹ (no cosine factor), zero for a pair not
//! [`above_horizon`] (every model guards with [`below_horizon`], the one copy of the guard); a delta component
//! is reported separately by [`Brdf::delta_reflectance`].
//!
//! The contract has two halves. Evaluation: `sampling`, `eval`, `eval_batch` and its batched contract, `folds`
//! and `eval_batch_folded`, `delta_reflectance`. The planner's hints, one value: `hints` returns [`Hints`] (the
//! terms, kinks, seams, reciprocity and smoothness), so a wrapper forwards or edits one thing. Beside them
//! `coarser` (a measured table's coarse twins, models built on demand, not a fact) and `describe`.
//!
//! The folder:
//! * `mod.rs` (this): the contract, [`Brdf`] and [`Hints`], what a model tells the integrator ([`Term`],
//!   [`TermKind`], [`Lobe`], [`Tail`], [`Kink`]), the horizon guard ([`above_horizon`], [`below_horizon`]) and
//!   [`mirror`];
//! * the models, one per file, each over the optics it cites: `lambert.rs` ([`lambert::Lambert`]),
//!   `dielectric.rs` (the smooth dielectric [`dielectric::SmoothDielectric`] and the rough interface of a
//!   dielectric or a conductor [`dielectric::MicrofacetSurface`], with its [`dielectric::Ior`]), `conductor.rs`
//!   ([`conductor::SmoothConductor`]), `mixture.rs` (a rough interface of several slope populations,
//!   [`mixture::MixtureSurface`]), `phong.rs` ([`phong::Phong`]), `ward.rs` ([`ward::Ward`]),
//!   `multilobe.rs` ([`multilobe::CookTorranceLobes`]), `halo.rs` (a Rayleigh–Rice scatter halo on a model's
//!   mirror, [`halo::WithHalo`] over [`halo::Halo`]), `two_scale.rs` (a rough interface with that halo,
//!   [`two_scale::RoughWithHalo`]), `topography.rs` (the facets of a measured surface's own slopes,
//!   [`topography::TopographySurface`]) and `paint`, the paint model of Ďurikovič & Ágošton
//!   (2007) ([`paint::Paint`] built from a [`paint::PaintSpec`]);
//! * `annotated.rs`: a model with a note on where its parameters came from ([`annotated::Annotated`], the
//!   inner model's bits, its description and the note);
//! * `albedo.rs`: the directional albedo that resolves narrow lobes
//!   ([`albedo::directional_albedo`], [`albedo::directional_albedo_to`]): a d/8 sphere's hemisphere
//!   reading (`instrument::sphere`) and the tests' white furnace.
//!
//! Measured materials are `crate::measured`'s: its readers implement this trait over their tables.
use crate::optics::microfacet::{Distribution, Microfacet};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};

pub mod albedo;
pub(crate) mod annotated;
pub(crate) mod conductor;
pub mod dielectric;
pub mod halo;
pub(crate) mod kirchhoff;
pub mod lambert;
pub(crate) mod map_two_scale;
pub mod mixture;
pub mod multilobe;
pub mod paint;
pub mod phong;
pub(crate) mod topography;
pub(crate) mod two_scale;
pub mod ward;

/// A glossy lobe centred on the specular direction (half vector along the normal, or, for a lobe formed
/// under a smooth coat, along the normal inside the coat). Every model in this crate produces only such
/// lobes; the integrator splits its lobe variable at multiples of the width around the specular direction.
#[derive(Clone, Debug, PartialEq)]
pub struct Lobe {
    /// Width of the facet (or flake) normal distribution as a slope: the Beckmann rms slope m, the GGX α,
    /// or the equivalent for Phong / Ward lobes. Dimensionless (tan of an angle).
    pub slope_width: f64,
    /// Refractive index of the medium in which the lobe is formed: 1 for a lobe on the surface, the coat
    /// index for flakes under a smooth clear coat (refraction widens the lobe when it leaves).
    pub medium_eta: f64,
    /// Short label for `--explain`, e.g. "metallic flakes".
    pub label: String,
    /// How the lobe falls off far from its centre ([`Tail`]).
    pub tail: Tail,
}

/// The tail of a lobe: how its value falls off with the distance u from the specular direction, in widths.
/// The integrator places its split points and chooses its rule by it (`instrument::method`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tail {
    /// Gaussian (Beckmann, Phong, Ward, flakes): below e⁻¹⁰⁰ of its peak beyond 10 widths, so the integrator
    /// stops splitting there.
    Gaussian,
    /// The GGX (Trowbridge–Reitz) tail, D ∝ α²/(α² + tan²θh)² (Walter et al. 2007, Eq. 33): ∝ u⁻⁴, and exactly
    /// 1/(1 + ρ²)² in the scaled polar radius ρ, which the polar rule (`Rule::LobePolar`) maps to a polynomial.
    InverseQuartic,
    /// Heavier than a Gaussian in a way the model does not state (a user's function probed from Python), or
    /// a shape no shaped rule fits (a Rayleigh–Rice halo, `halo.rs`: a power law in spatial frequency, not a
    /// Gaussian or a GGX tail in the lobe variables): split geometrically out to the ends of the range,
    /// integrated by the adaptive partition.
    Unknown,
    /// A measured table's lobe: it falls off however the table's values do, and the table's interpolation
    /// kinks at every cell boundary (rings of θh around the specular direction, steps of θd, θi and φd), so
    /// no shaped rule for an analytic tail applies; split like `Unknown`, integrated by the partition
    /// (`docs/instrument.md` §Quadrature, *Measured tables*). `half_width` is the lobe's own half width at half
    /// maximum as a slope (tan of the half-vector tilt), measured from the table when it is loaded
    /// ([`crate::measured::table::specular_half_width`]); infinite when the table does not fall to half its
    /// specular value within `table::HALF_WIDTH_MAX_TILT_DEG` (40°) of tilt. `resolution` is the table's
    /// angular resolution at the specular direction (tan of its finest step there), kept for `--explain` and for
    /// the rule that splits at it. The lobe's `slope_width`, where the partition splits, is `half_width`
    /// (∞ when the table does not halve: the plain chart): at the tolerance a table's data allow, the kinks at
    /// its cells are below the tolerance and the adaptive partition finds the few that are not
    /// (`docs/instrument.md` §Quadrature, *Measured tables*, "The partition at the lobe's width").
    Table { half_width: f64, resolution: f64 },
}

impl Tail {
    /// Whether the tail falls off slower than a Gaussian (split out to the ends of the range).
    pub(crate) fn is_heavy(self) -> bool {
        self != Tail::Gaussian
    }
}

impl Lobe {
    /// The lobe of a microfacet distribution formed in a medium of index `medium_eta`: its width is the
    /// roughness, its tail the distribution's own (GGX: `Tail::InverseQuartic`, Beckmann: `Tail::Gaussian`). (It lives here rather than on
    /// `Microfacet` because `optics` sits below `brdf` and knows nothing of lobes.)
    pub(crate) fn of_facets(facets: &Microfacet, medium_eta: f64, label: String) -> Lobe {
        let tail = match facets.distribution {
            Distribution::Ggx => Tail::InverseQuartic,
            Distribution::Beckmann => Tail::Gaussian,
        };
        Lobe { slope_width: facets.alpha, medium_eta, label, tail }
    }
}

/// A kink of a model: a surface in (ωi, ωo) across which its value is continuous but its derivative is not
/// (a Fresnel critical angle: `optics::fresnel::critical_cosine`). Adaptive cubature converges only slowly
/// on a kink that crosses its boxes (a √-shaped knee costs refinement down to rounding on every box it
/// crosses), so the plan puts every reported kink on partition boundaries (`instrument::aperture::kink_point`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kink {
    /// The delta term's weight R(cos θi) kinks at cos θi = `cos`.
    Incidence { cos: f64 },
    /// The regular part kinks where ωi·h = `cos`, h = normalize(ωi + ωo) (the Fresnel factor of a
    /// microfacet lobe). As ωi·ωo = 2(ωi·h)² − 1, that is the surface ωi·ωo = 2·cos² − 1: a condition on the
    /// angle between the two directions alone.
    HalfAngle { cos: f64 },
}

impl Kink {}

/// The kinks of a set of Fresnel indices, one per distinct critical angle, in increasing order of cos θc;
/// `delta` selects the term (the delta limit kinks in cos θi, a lobe in ωi·h).
pub(crate) fn fresnel_kinks(critical: impl IntoIterator<Item = Option<f64>>, delta: bool) -> Vec<Kink> {
    let mut c: Vec<f64> = critical.into_iter().flatten().collect();
    c.sort_by(f64::total_cmp);
    c.dedup();
    c.into_iter().map(|cos| if delta { Kink::Incidence { cos } } else { Kink::HalfAngle { cos } }).collect()
}

/// A term of a model, for the measurement plan's explanation: what is evaluated and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    pub label: String,
    /// How the integrator must treat it.
    pub kind: TermKind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TermKind {
    /// Ideal specular reflection: integrated analytically over the aperture overlap.
    Delta,
    /// Smooth in direction (Lambertian-like): no lobe splitting needed.
    Diffuse,
    /// A glossy lobe, see [`Lobe`].
    Lobe(Lobe),
}

/// What a model tells the planner about itself, apart from its values ([`Brdf::hints`]): one value, so that a
/// wrapper forwards (or edits) one thing. [`Hints::new`] takes the terms, which every model has, and gives the
/// defaults of the rest (no kinks, no seams, reciprocal, not smooth); a model states only what differs, with
/// the `with_*` builders.
#[derive(Clone, Debug, PartialEq)]
pub struct Hints {
    /// The terms of the model (delta, diffuse, lobes) in evaluation order. The integrator uses the lobes to
    /// place its splits and the delta flag to add the analytic part; `--explain` prints them.
    pub terms: Vec<Term>,
    /// The kinks of the model's terms (see [`Kink`]), in increasing order of their cosine within each kind:
    /// none by default. A model whose value has a discontinuous derivative inside the upper hemisphere must
    /// report it, or the integrator refines around it to its budget.
    pub kinks: Vec<Kink>,
    /// The cosines at which the regular part, as a function of cos θi or of cos θo, has a seam: a point where
    /// a tabulated factor of one direction changes piece or is held constant (the rough coat's E(μ),
    /// `optics::coat_albedo`), so that its value or derivative jumps by more than rounding. Sorted, in (0, 1);
    /// none by default. The directional albedo (`brdf::albedo`) puts them on its panel boundaries: a
    /// Gauss–Kronrod panel across a seam underestimates its own error (docs/accuracy.md §The estimate property,
    /// over generated recipes).
    pub seams: Vec<f64>,
    /// Whether f_r(ωi, ωo) = f_r(ωo, ωi) holds for this model (Helmholtz reciprocity); true by default.
    pub reciprocal: bool,
    /// Whether the model's value is smooth (analytic formulas, no min/max, clamp, table or interpolation
    /// seam — short of a table of a smooth function verified far below any tolerance, as a paint's flake
    /// reflectances within 10⁻¹²) everywhere in the upper hemispheres except on the kinks it reports
    /// ([`Hints::kinks`]). False by default. A smooth model lets the integrator trust its region estimates further
    /// (`quadrature::Options::checked`, `docs/accuracy.md` §5): on a model with a kink it does not report
    /// (the V-cavity G's min, a table's seams) the null rules and the parent–children check both miss the
    /// kink, and the deeper estimates fell below the actual error at rtol 10⁻⁷ and 10⁻⁸.
    pub smooth: bool,
}

impl Hints {
    /// The hints of a model with these terms and the defaults of everything else: no kinks, no seams,
    /// reciprocal, not smooth.
    pub fn new(terms: Vec<Term>) -> Hints {
        Hints { terms, kinks: Vec::new(), seams: Vec::new(), reciprocal: true, smooth: false }
    }

    /// With these kinks ([`Hints::kinks`]).
    pub(crate) fn with_kinks(self, kinks: Vec<Kink>) -> Hints {
        Hints { kinks, ..self }
    }

    /// With these seams ([`Hints::seams`]).
    pub(crate) fn with_seams(self, seams: Vec<f64>) -> Hints {
        Hints { seams, ..self }
    }

    /// Reciprocal or not ([`Hints::reciprocal`]).
    pub fn with_reciprocal(self, reciprocal: bool) -> Hints {
        Hints { reciprocal, ..self }
    }

    /// Smooth or not ([`Hints::smooth`]).
    pub(crate) fn with_smooth(self, smooth: bool) -> Hints {
        Hints { smooth, ..self }
    }

    /// The lobes among the terms.
    pub(crate) fn lobes(&self) -> Vec<Lobe> {
        self.terms
            .iter()
            .filter_map(|t| match &t.kind {
                TermKind::Lobe(l) => Some(l.clone()),
                _ => None,
            })
            .collect()
    }

    /// Whether the model has a delta term.
    pub(crate) fn has_delta(&self) -> bool {
        self.terms.iter().any(|t| t.kind == TermKind::Delta)
    }

    /// Whether `eval` can be non-zero (the model has a diffuse or lobe term).
    pub(crate) fn has_regular(&self) -> bool {
        self.terms.iter().any(|t| t.kind != TermKind::Delta)
    }

    /// Whether the model has a diffuse term.
    pub(crate) fn has_diffuse(&self) -> bool {
        self.terms.iter().any(|t| t.kind == TermKind::Diffuse)
    }
}

/// Whether both directions are above the horizon (z > 0; a NaN is not): the regular part of every model is
/// zero elsewhere (the conventions above). The horizon guard, written once for every model and wrapper.
#[inline]
pub(crate) fn above_horizon(wi: Vec3, wo: Vec3) -> bool {
    wi.z > 0.0 && wo.z > 0.0
}

/// The horizon guard of an `eval`: true, with `out` zeroed, when the pair is not [`above_horizon`].
#[inline]
pub(crate) fn below_horizon(wi: Vec3, wo: Vec3, out: &mut [f64]) -> bool {
    let below = !above_horizon(wi, wo);
    if below {
        out.fill(0.0);
    }
    below
}

/// A material whose aperture fluxes come from a far field (docs/optics.md §11): `aperture_flux(θ, viewing,
/// source stop, receptor stop)` with the stops as tangent-coordinate boxes `[[p0, p1], [q0, q1]]`
/// (docs/instrument.md §1.2) gives the grey flux ∫_S R·P(R | ωi) cos θi dωi (the units of docs/instrument.md §1.4)
/// with its numerical error and its data (speckle) uncertainty, or why this receptor cannot be read (a reading
/// marked with it).
pub trait FarField: Send + Sync {
    fn aperture_flux(
        &self,
        theta: f64,
        viewing: f64,
        source: [[f64; 2]; 2],
        receptor: [[f64; 2]; 2],
    ) -> std::result::Result<FarFieldFlux, String>;
}

/// One grey aperture flux of a [`FarField`]: its value, the estimate of its numerical error, and its data
/// uncertainty (docs/optics.md §11.3–§11.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarFieldFlux {
    pub value: f64,
    pub error: f64,
    pub data_uncertainty: f64,
}

/// A reflectance model. Implementations must be pure: the same arguments give the same bits.
pub trait Brdf: Send + Sync + std::fmt::Debug {
    /// The spectral samples this model evaluates.
    fn sampling(&self) -> &Sampling;

    /// Regular part of f_r(ωi, ωo) in sr⁻¹, one value per spectral sample, written to `out`
    /// (`out.len() == self.sampling().len()`); zeros for a pair not [`above_horizon`] ([`below_horizon`]).
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]);

    /// The regular part at many direction pairs in one call (the integrator hands over a whole quadrature
    /// region's points, or a refinement step's). The contract:
    ///
    /// * `wi.len() == wo.len() == m` and `out.len() == m · n` with n = `self.sampling().len()`, point-major:
    ///   the n sample values of pair i go to `out[i*n..(i+1)*n]`;
    /// * every one of the m · n outputs must be written, zeros included (the buffer is reused between calls
    ///   and its contents on entry are unspecified); a pair not [`above_horizon`] gets zeros, as from
    ///   [`Brdf::eval`] (the instrument passes only pairs above the horizon, but a model must not rely on it);
    /// * the values must be the same bits as m calls of [`Brdf::eval`]: the integrator's sums, and so every
    ///   reading, must not depend on how the points were batched.
    ///
    /// The default loops over [`Brdf::eval`]; a model overrides it when it can do better per batch (a
    /// Python callable crossing the interpreter boundary once per batch, SIMD, a GPU).
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        let n = self.sampling().len();
        for ((a, b), o) in wi.iter().zip(wo).zip(out.chunks_exact_mut(n)) {
            self.eval(*a, *b, o);
        }
    }

    /// Whether [`Brdf::eval_batch_folded`] evaluates the weighted sum with the row `w` (n weights) itself.
    /// False by default. The plan asks once per integral whose weighting is that one row (a luminous-only
    /// flux) and then calls `eval_batch_folded` for its batches; otherwise it weights the n samples.
    fn folds(&self, _w: &[f64]) -> bool {
        false
    }

    /// The weighted sum of the samples, Σ_j w_j f_j(ωi, ωo), at many pairs, when the model has prepared that
    /// row ([`Brdf::folds`]): `out` has m values, every one written (zeros below the horizon). It must equal
    /// Σ_j w_j·(the samples of [`Brdf::eval_batch`]) to rounding (a model sums in its own order, e.g. one
    /// folded reflectance table instead of n, so the last bits may differ) and not depend on the batching.
    /// Returns false, leaving `out` alone, for a row the model has not prepared (the default).
    fn eval_batch_folded(&self, _w: &[f64], _wi: &[Vec3], _wo: &[Vec3], _out: &mut [f64]) -> bool {
        false
    }

    /// The ideal-mirror component: f_δ = R(ωi)·δ(ωo − mirror(ωi)) / cos θo. Writes R per sample and returns
    /// true if the model has one; returns false (and leaves `out` alone) otherwise.
    fn delta_reflectance(&self, _wi: Vec3, _out: &mut [f64]) -> bool {
        false
    }

    /// An upper bound of f_j(ωi, ωo)·cos θi·cos θo over every spectral sample j and every pair above the
    /// horizon whose ωo is at least `psi` radians from the mirror image of ωi (docs/instrument.md
    /// §Quadrature, "A receptor the lobe cannot reach"), or None when the model has none (the default). The
    /// executor settles a receptor the lobe cannot reach with it ([`Rule::TailBound`]), so it must be a true
    /// bound, never an estimate.
    ///
    /// [`Rule::TailBound`]: crate::instrument::method::Rule::TailBound
    fn tail_majorant(&self, _psi: f64) -> Option<f64> {
        None
    }

    /// What the model tells the planner about itself, in one value ([`Hints`]: its terms, kinks, seams,
    /// reciprocity and smoothness). A model states only what differs from [`Hints::new`]'s defaults; a
    /// wrapper forwards or edits this one value. The planner reads it once per plan
    /// (`instrument::method::MaterialFacts`), the executor once per integral (for [`Hints::smooth`]), so it
    /// must not change over the model's life.
    fn hints(&self) -> Hints;

    /// The same measured table read on about every second sample along each of its axes (its two *coarse
    /// twins*, on the even samples and on the odd ones), from which the planner estimates a reading's data
    /// (resolution) uncertainty: the larger difference of the readings through a twin and through the table
    /// (`docs/accuracy.md` §Data uncertainty of measured tables). Empty for a model that is not a table (the
    /// default) and for a twin itself. Not one of the [`Hints`]: the twins are models built on demand, each a
    /// copy of the table, which a plan asks for once.
    fn coarser(&self) -> Vec<std::sync::Arc<dyn Brdf>> {
        Vec::new()
    }

    /// The material's own aperture fluxes, when it is read by a far field rather than by integrating its BRDF
    /// (a topography read by the Kirchhoff method, docs/optics.md §11): the planner then takes each specimen
    /// aperture flux from it and the quadrature runs on nothing. None (the default) for every BRDF.
    fn far_field(&self) -> Option<&dyn FarField> {
        None
    }

    /// A one-line human description, e.g. "microfacet (GGX α = 0.1, n = 1.5, Smith height-correlated)".
    fn describe(&self) -> String;
}

impl dyn Brdf + '_ {
    /// The lobes among the model's terms ([`Hints::lobes`]).
    pub fn lobes(&self) -> Vec<Lobe> {
        self.hints().lobes()
    }

    /// Whether the model has a delta term ([`Hints::has_delta`]).
    pub fn has_delta(&self) -> bool {
        self.hints().has_delta()
    }

    /// True if `eval` can be non-zero (the model has a diffuse or lobe term; [`Hints::has_regular`]).
    pub fn has_regular(&self) -> bool {
        self.hints().has_regular()
    }
}

/// Mirror direction of `w` about the normal z.
#[inline]
pub fn mirror(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// The check every model's constructor makes on caller data: one finite value per spectral sample.
pub(crate) fn per_sample(what: &str, values: &[f64], sampling: &Sampling) -> Result<()> {
    if values.len() != sampling.len() {
        return Err(Error::Usage(format!(
            "{what}: {} value(s) for {} spectral sample(s); give one per sample",
            values.len(),
            sampling.len()
        )));
    }
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Error::Usage(format!("{what}: {v} is not a finite number")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn delta() -> Term {
        Term { label: "mirror".into(), kind: TermKind::Delta }
    }

    #[test]
    fn hints_default_to_no_kinks_no_seams_reciprocal_not_smooth_and_each_builder_sets_its_field_alone() {
        let h = Hints::new(vec![delta()]);
        assert_eq!((h.kinks.len(), h.seams.len(), h.reciprocal, h.smooth), (0, 0, true, false));
        let k = vec![Kink::Incidence { cos: 0.5 }];
        assert_eq!(h.clone().with_kinks(k.clone()), Hints { kinks: k, ..h.clone() });
        assert_eq!(h.clone().with_seams(vec![0.25]), Hints { seams: vec![0.25], ..h.clone() });
        assert_eq!(h.clone().with_reciprocal(false), Hints { reciprocal: false, ..h.clone() });
        assert_eq!(h.clone().with_smooth(true), Hints { smooth: true, ..h.clone() });
        assert!(h.has_delta() && !h.has_regular() && !h.has_diffuse() && h.lobes().is_empty());
    }

    #[test]
    fn the_horizon_guard_zeroes_a_pair_at_or_below_the_horizon_or_not_a_number_and_leaves_others() {
        let up = Vec3::new(0.0, 0.0, 1.0);
        for below in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.6, 0.0, -0.8), Vec3::new(0.0, 0.0, f64::NAN)] {
            for (wi, wo) in [(up, below), (below, up)] {
                let mut out = [7.0; 2];
                assert!(!above_horizon(wi, wo) && below_horizon(wi, wo, &mut out) && out == [0.0; 2]);
            }
        }
        let mut out = [7.0; 2];
        assert!(above_horizon(up, up) && !below_horizon(up, up, &mut out) && out == [7.0; 2]);
    }

    /// A wrapper forwards the one value: the annotated model's hints are the inner model's, every field.
    #[test]
    fn a_wrapper_forwards_the_whole_hints() {
        // An index below 1 has a critical angle: a kink.
        let inner: Arc<dyn Brdf> = Arc::new(dielectric::SmoothDielectric::new(0.8));
        let wrapped = annotated::Annotated { inner: inner.clone(), note: "note".into() };
        let h = inner.hints();
        assert!(!h.kinks.is_empty() && h.smooth, "the test needs a model with kinks that is smooth: {h:?}");
        assert_eq!(wrapped.hints(), h);
    }

    /// Every model zeroes the regular part below the horizon, Lambert's constant included.
    #[test]
    fn a_model_is_zero_below_the_horizon() {
        let l = lambert::Lambert::new(vec![0.5], Sampling::grey()).unwrap();
        let (up, down) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.6, 0.0, -0.8));
        let mut out = [7.0];
        l.eval(up, down, &mut out);
        assert_eq!(out, [0.0]);
        l.eval(up, up, &mut out);
        assert_eq!(out, [0.5 / std::f64::consts::PI]);
    }
}
