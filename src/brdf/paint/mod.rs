//! The paint model of Ďurikovič & Ágošton (2007), "Prediction of optical properties of paints",
//! Cent. Eur. J. Phys. 5(3):416, Eqs. (1)–(8), with the typesetting errors of the paper corrected and the
//! layering made physically consistent. The whole model, every formula with its source, the corrections to
//! the paper and every choice where the paper is silent are in `docs/model.md`; this folder follows it.
//!
//! Structure (exterior directions ωi, ωo; interior directions ωi' = refract(ωi), ωo' = refract(ωo)):
//!
//! ```text
//! f_r(ωi, ωo) = ρ(θi)·δ(ωo − mirror ωi)/cos θo                      clear coat (Fresnel, delta)
//!             [or F·D·G/(4 cos θi cos θo) for a rough coat]
//!             + T(θi)·T(θo)/η² · f'(ωi', ωo')                         everything under the coat
//! f'(ωi', ωo') = (1 − Am − Ap)·R_l/π · 1/(1 − r_i·R_l)                pigmented layer (KM + Saunderson)
//!             + Am·R_m(ωi'·h')·D_m(h')·G/(4 cos θi' cos θo')          metallic flakes
//!             + Ap·R_p(ωi'·h')·D_p(h')·G/(4 cos θi' cos θo')          pearlescent flakes
//! ```
//!
//! with T = 1 − ρ the Fresnel power transmittance of the air–coat interface (paper Eq. 2 with its cosine
//! ratio corrected), R_l the Kubelka–Munk reflectance of the pigmented layer over the primer (Eq. 3
//! corrected), R_m, R_p the KM reflectance of the pigment above a flake of Fresnel reflectance ρ_m (Eq. 5
//! corrected) or thin-film reflectance ρ_p (Eqs. 6–8 corrected), D normalised Beckmann distributions and G
//! the Smith height-correlated masking-shadowing function. The alternative `Form::PaperEq1` evaluates Eq. (1)
//! as printed, for comparison only.
//!
//! The folder, one idea per file (no file imports `mod.rs`; `folded.rs` imports `flake.rs`, which imports
//! `hemisphere.rs` and `memo.rs`; `spec.rs` imports none of them):
//! - `mod.rs`: the model, [`Paint`]: [`Paint::new`] (the checks and everything that does not depend on
//!   direction), the folded evaluation `Paint::eval_folded`, the [`Brdf`] impl (`eval`, `delta_reflectance`,
//!   `terms`, `smooth`, `seams`, `describe`) and [`MAX_SAMPLES`];
//! - `spec.rs`: what a paint is made of, [`PaintSpec`] and its parts ([`ClearCoat`], [`PigmentedLayer`],
//!   [`Pigment`], [`MetallicFlakes`], [`PearlescentFlakes`], [`Spread`], [`spread_to_slope`]), the readings
//!   [`Form`] and [`FlakeLight`], and the range checks `Paint::new` runs on them;
//! - `flake.rs`: one kind of flake under its cover, precomputed (`FlakeTerm`, `FlakeOptics`): ρ and its kinks,
//!   the cover's reflectance over it and its verified tables ([`TABLE_TOLERANCE`]), the split light's τ and
//!   diffuse weight;
//! - `folded.rs`: the flake tables and direction-independent sums folded for one weighted sum of the samples
//!   (`Folded`, `FoldedFlake`);
//! - `memo.rs`: [`MEMO_ENTRIES`] and the bounded process-wide memo in which `flake.rs` keeps its tables between
//!   builds, keyed by the bits of their inputs (a sweep point that changes no input of a table reuses it);
//! - `hemisphere.rs`: hemispherical means by Gauss–Legendre in the cosine ([`DIFFUSE_FRESNEL_NODES`]): the
//!   coat's [`diffuse_fresnel_reflectance`] r_e and [`internal_diffuse_reflectance`] r_i, and
//!   [`hemispherical_mean`], the rule cut at total-internal-reflection kinks.
//!
//! Two placements are choices. The hemispherical means have a file of their own rather than a place in
//! `flake.rs`: r_e and r_i are the coat's (`Paint::new` reads them, no flake does), ρ_d is the flake's, and
//! all three are the same 64-point rule, which the kink test checks on the coat's r_i against Stern's closed
//! form; so the rule sits below both users. `Paint::eval_folded` stays in `mod.rs` beside `eval`: it reads
//! the coat (its index, its rough lobe, its transmittance 1 − E(μ) or T(μ)) and the flake terms of the
//! `Paint` that holds the `Folded` tables, so in `folded.rs` it would make `folded.rs` and `mod.rs` import
//! each other; `folded.rs` holds the data it reads, built from the flake terms and the body alone.
mod flake;
mod folded;
mod hemisphere;
mod memo;
mod spec;

pub use flake::{PaintBuild, TableBuild, TableMemo, TableWork, TABLE_TOLERANCE};
pub use hemisphere::{diffuse_fresnel_reflectance, internal_diffuse_reflectance};
pub use spec::{
    ClearCoat, FlakeLight, Form, MetallicFlakes, PaintSpec, PearlescentFlakes, Pigment, PigmentedLayer, Spread,
};

use super::{above_horizon, Brdf, Hints, Lobe, Term, TermKind};
use crate::colorimetry::weighting::Weighting;
use crate::optics::coat_albedo::{CoatAlbedo, OutOfTable, ALPHA_BREAKS, ETA_MAX, ETA_MIN};
use crate::optics::fresnel::{fr_dielectric, fresnel_dielectric, refract_into};
use crate::optics::kubelka_munk::{self, Layer};
use crate::optics::microfacet::{Distribution, Microfacet, Shadowing};
use crate::optics::tabulated::{basis, dot};
use crate::optics::thin_film::FilmLayer;
use crate::registry::{self as reg, Param, Range};
use crate::spectrum::Sampling;
use crate::{Result, Vec3};
use flake::{FlakeOptics, FlakeTerm};
use folded::{Folded, FoldedFlake};
use num_complex::Complex64;
use spec::{check_in, check_range, check_spectral, usage};
use std::f64::consts::PI;

/// Largest number of spectral samples a paint accepts. It bounds the per-evaluation work (a pearlescent
/// paint evaluates a thin-film stack per sample and direction pair); recipes with more samples are refused.
pub const MAX_SAMPLES: usize = 128;

/// The paint BRDF.
#[derive(Clone, Debug)]
pub struct Paint {
    spec: PaintSpec,
    /// Weight of the body term 1 − Am − Ap.
    body_weight: f64,
    /// R_l per sample.
    r_l: Vec<f64>,
    /// (1 − Am − Ap)·R_l/π·S per sample, S the Saunderson factor (or 1).
    body: Vec<f64>,
    r_e: f64,
    r_i: f64,
    rough_coat: Option<Microfacet>,
    /// E(μ) and Ē of the rough coat's lobe (energy-exact coupling, `optics::coat_albedo`).
    coat_albedo: Option<CoatAlbedo>,
    metallic: Option<FlakeTerm>,
    pearlescent: Option<FlakeTerm>,
    /// Prepared for the luminous row of the sampling (None if the sampling has none).
    folded: Option<Folded>,
}

impl Paint {
    /// Validate `spec` and precompute everything that does not depend on direction.
    pub fn new(spec: PaintSpec) -> Result<Paint> {
        Paint::with_table_build(spec, TableBuild::Shared)
    }

    /// [`Paint::new`] with the flake tables fitted as `tables` says ([`TableBuild`]: the same bits either way;
    /// `benches/paint_build.rs` compares the two builds' times), or with none ([`TableBuild::Direct`]: every
    /// flake reflectance evaluated directly, the reference the tables are checked against).
    pub fn with_table_build(spec: PaintSpec, tables: TableBuild) -> Result<Paint> {
        Paint::build(spec, PaintBuild { tables, ..PaintBuild::default() }).map(|(paint, _)| paint)
    }

    /// [`Paint::new`] built as `build` says (how the flake tables are fitted, and the memo they are kept in, or
    /// none), with the film-stack work this build did ([`TableWork`]: none for tables the memo had).
    pub fn build(spec: PaintSpec, build: PaintBuild<'_>) -> Result<(Paint, TableWork)> {
        let n = spec.sampling.len();
        if n == 0 || n > MAX_SAMPLES {
            return Err(usage(format!("{n} spectral samples; a paint takes 1 to {MAX_SAMPLES}")));
        }
        // The ranges are the registry's (`crate::registry`), the same the recipe parser checks.
        let c = &spec.coat;
        check_range(&reg::COAT_INDEX, c.index)?;
        check_range(&reg::COAT_THICKNESS, c.thickness_um)?;
        check_range(&reg::COAT_ROUGHNESS, c.roughness)?;
        let l = &spec.layer;
        check_range(&reg::LAYER_THICKNESS, l.thickness_mm)?;
        check_spectral(&reg::LAYER_PRIMER, &l.primer_reflectance, n)?;
        for p in &l.pigments {
            check_range(&reg::PIGMENT_CONCENTRATION, p.concentration)?;
            check_spectral(&reg::PIGMENT_K, &p.k_per_mm, n)?;
            check_spectral(&reg::PIGMENT_S, &p.s_per_mm, n)?;
        }
        let am = spec.metallic.as_ref().map_or(0.0, |m| m.area_ratio);
        let ap = spec.pearlescent.as_ref().map_or(0.0, |p| p.area_ratio);
        let depth = |p: &Param, d: f64| check_in(p.pointer, d, Range::closed(0.0, l.thickness_mm));
        if let Some(m) = &spec.metallic {
            check_spectral(&reg::METALLIC_N, &m.n, n)?;
            check_spectral(&reg::METALLIC_K, &m.k, n)?;
            m.spread.check(&reg::METALLIC_SPREAD, &reg::METALLIC_SPREAD_SLOPE)?;
            check_range(&reg::METALLIC_AREA, m.area_ratio)?;
            depth(&reg::METALLIC_DEPTH, m.depth_mm)?;
        }
        if let Some(p) = &spec.pearlescent {
            p.spread.check(&reg::PEARL_SPREAD, &reg::PEARL_SPREAD_SLOPE)?;
            check_range(&reg::PEARL_AREA, p.area_ratio)?;
            depth(&reg::PEARL_DEPTH, p.depth_mm)?;
            check_range(&reg::PEARL_TIO2_THICKNESS, p.tio2_thickness_nm)?;
            check_range(&reg::PEARL_TIO2_INDEX, p.tio2_index)?;
            check_range(&reg::PEARL_MICA_THICKNESS, p.mica_thickness_nm)?;
            check_range(&reg::PEARL_MICA_INDEX, p.mica_index)?;
        }
        if am + ap > 1.0 {
            return Err(usage(format!("area ratios Am + Ap = {} exceed 1", am + ap)));
        }

        let eta = c.index;
        // Pigmented layer: Duncan mixing, then the KM layer over the primer (Eq. 3 corrected).
        let mut k_mix = vec![0.0; n];
        let mut s_mix = vec![0.0; n];
        for j in 0..n {
            let (k, s) = kubelka_munk::mix(l.pigments.iter().map(|p| (p.concentration, p.k_per_mm[j], p.s_per_mm[j])));
            k_mix[j] = k;
            s_mix[j] = s;
        }
        let r_l: Vec<f64> = (0..n)
            .map(|j| kubelka_munk::layer(k_mix[j], s_mix[j], l.thickness_mm).over(l.primer_reflectance[j]))
            .collect();
        let rough_coat =
            (c.roughness >= Microfacet::SMOOTH_THRESHOLD).then(|| Microfacet::new(c.distribution, c.roughness));
        // A rough coat lets in 1 − E(θ) and reflects back inside r_i = 1 − (1 − Ē)/η² (Kelemen &
        // Szirmay-Kalos 2001); a smooth one T(θ) = 1 − F(θ) and r_i = 1 − (1 − r_e)/η², its limit.
        // E comes from the shipped table (`optics::coat_albedo`), which covers roughness [10⁻⁷, 1] and the
        // whole index range; a rough coat outside it is refused, naming the field.
        let coat_albedo = match &rough_coat {
            Some(mf) => Some(CoatAlbedo::new(mf, eta).map_err(|why| {
                let (lo, hi) = (ALPHA_BREAKS[0], ALPHA_BREAKS[ALPHA_BREAKS.len() - 1]);
                match why {
                    OutOfTable::Roughness => usage(format!(
                        "{} = {}: a rough clear coat's roughness must lie in [{lo}, {hi}], the range of its \
                         directional-albedo table (docs/model.md §Energy-exact rough clear coat); below {} \
                         the coat is smooth",
                        reg::COAT_ROUGHNESS.pointer,
                        c.roughness,
                        Microfacet::SMOOTH_THRESHOLD
                    )),
                    OutOfTable::Index => usage(format!(
                        "{} = {}: a rough clear coat's index must lie in [{ETA_MIN}, {ETA_MAX}], the range of its \
                         directional-albedo table",
                        reg::COAT_INDEX.pointer,
                        c.index
                    )),
                }
            })?),
            None => None,
        };
        let r_e = coat_albedo.as_ref().map_or_else(|| diffuse_fresnel_reflectance(eta), |a| a.mean);
        let r_i = 1.0 - (1.0 - r_e) / (eta * eta);
        let body_weight = (1.0 - am - ap).max(0.0);
        let use_saunderson = spec.internal_reflection && spec.form == Form::Physical;
        let body: Vec<f64> = r_l
            .iter()
            .map(|&r| {
                let s = if use_saunderson { 1.0 / (1.0 - r_i * r) } else { 1.0 };
                body_weight * r / PI * s
            })
            .collect();
        let cover =
            |depth: f64| -> Vec<Layer> { (0..n).map(|j| kubelka_munk::layer(k_mix[j], s_mix[j], depth)).collect() };
        let split = spec.form == Form::Physical && spec.flake_light == FlakeLight::Split;
        let work = std::cell::Cell::new(TableWork::default());
        let flake = |label, spread: Spread, area, depth, optics| {
            let facets = Microfacet::new(Distribution::Beckmann, spread.slope());
            let mut term = FlakeTerm {
                label,
                area,
                facets,
                smooth: facets.effectively_smooth(),
                cover: cover(depth),
                optics,
                table: None,
                grid: None,
                depth: vec![0.0; n],
                diffuse: vec![0.0; n],
                split,
            };
            work.set(work.get() + term.prepare(&k_mix, &s_mix, depth, &spec.sampling.wavelengths_nm, build));
            term
        };
        let metallic = spec.metallic.as_ref().filter(|m| m.area_ratio > 0.0).map(|m| {
            let rel = (0..n).map(|j| Complex64::new(m.n[j], m.k[j]) / eta).collect();
            flake("metallic flakes", m.spread, m.area_ratio, m.depth_mm, FlakeOptics::Metal(rel))
        });
        let pearlescent = spec.pearlescent.as_ref().filter(|p| p.area_ratio > 0.0).map(|p| {
            let tio2 =
                FilmLayer { n: Complex64::new(p.tio2_index, 0.0), thickness_nm: p.tio2_thickness_nm, coherent: true };
            let mica =
                FilmLayer { n: Complex64::new(p.mica_index, 0.0), thickness_nm: p.mica_thickness_nm, coherent: false };
            let optics = FlakeOptics::Pearl { layers: [tio2, mica, tio2], medium: eta };
            flake("pearlescent flakes", p.spread, p.area_ratio, p.depth_mm, optics)
        });
        let mut paint = Paint {
            spec,
            body_weight,
            r_l,
            body,
            r_e,
            r_i,
            rough_coat,
            coat_albedo,
            metallic,
            pearlescent,
            folded: None,
        };
        let luminous = Weighting::luminous(&paint.spec.sampling).ok().and_then(|w| w.rows.into_iter().next());
        paint.folded =
            luminous.map(|w| Folded::new(paint.metallic.as_ref(), paint.pearlescent.as_ref(), &paint.body, &w));
        Ok((paint, work.get()))
    }

    /// R_l per sample: the KM reflectance of the pigmented layer over the primer.
    pub fn pigmented_reflectance(&self) -> &[f64] {
        &self.r_l
    }

    /// r_e, the diffuse reflectance of the air–coat interface from outside.
    pub fn external_diffuse_reflectance(&self) -> f64 {
        self.r_e
    }

    /// r_i, the diffuse reflectance of the coat–air interface from inside.
    pub fn internal_diffuse_reflectance(&self) -> f64 {
        self.r_i
    }

    /// Power that crosses the coat at exterior cosine μ (either way): 1 − E(μ) for a rough coat, the
    /// Fresnel transmittance T(μ) for a smooth one.
    fn coat_transmittance(&self, mu: f64) -> f64 {
        match &self.coat_albedo {
            Some(a) => 1.0 - a.at(mu),
            None => fresnel_dielectric(mu.min(1.0), self.spec.coat.index).t(),
        }
    }

    /// Per flake term (metallic first): its label, whether its reflectance is read from verified tables
    /// (`docs/model.md` §Evaluation cost) for every sample and on one grid for the folded evaluation, and the
    /// largest deviation found at the tables' check points (None where the flake is evaluated directly).
    pub fn flake_tables(&self) -> Vec<(&'static str, Option<f64>)> {
        self.flakes()
            .map(|f| {
                let on_grid = f.table.is_some() && f.grid.is_some();
                let worst = f.table.iter().flatten().map(|t| t.max_error).fold(0.0, f64::max);
                (f.label, on_grid.then_some(worst))
            })
            .collect()
    }

    fn flakes(&self) -> impl Iterator<Item = &FlakeTerm> {
        self.metallic.iter().chain(self.pearlescent.iter())
    }

    /// Σ_j w_j f_j(ωi, ωo) for the prepared row: the terms of [`Brdf::eval`] with the same formulas, summed
    /// over the samples once where they do not depend on direction (`docs/model.md` §Folded evaluation). It
    /// equals Σ_j w_j·eval_j to rounding (the summation order differs; `tests/paint.rs` bounds the difference).
    fn eval_folded(&self, fo: &Folded, wi: Vec3, wo: Vec3) -> f64 {
        if !above_horizon(wi, wo) {
            return 0.0;
        }
        let eta = self.spec.coat.index;
        let mut coat = 0.0;
        if let Some(mf) = &self.rough_coat {
            let h = (wi + wo).normalize();
            let v = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), eta)
                * mf.d(h)
                * mf.g(wi, wo, h, Shadowing::SmithHeightCorrelated)
                / (4.0 * wi.z * wo.z);
            if v.is_finite() && v > 0.0 {
                coat = v * fo.coat;
            }
        }
        let flakes = [self.metallic.as_ref(), self.pearlescent.as_ref()];
        let mut folded = fo.flakes.iter();
        let terms: [Option<(&FlakeTerm, &FoldedFlake)>; 2] =
            flakes.map(|f| f.map(|f| (f, folded.next().expect("one folded term per flake term"))));
        match self.spec.form {
            Form::Physical => {
                let (Some(wi_in), Some(wo_in)) = (refract_into(wi, eta), refract_into(wo, eta)) else {
                    return coat;
                };
                let (t_i, t_o) = (self.coat_transmittance(wi.z), self.coat_transmittance(wo.z));
                let factor = t_i * t_o / (eta * eta);
                let h = (wi_in + wo_in).normalize();
                let cos_local = wi_in.dot(h).clamp(0.0, 1.0);
                let (mu_i, mu_o) = (wi_in.z, wo_in.z);
                let geo = |fl: &FlakeTerm| -> f64 {
                    if fl.smooth {
                        return 0.0;
                    }
                    let g = fl.facets.d(h) * fl.facets.g(wi_in, wo_in, h, Shadowing::SmithHeightCorrelated)
                        / (4.0 * wi_in.z * wo_in.z);
                    if g.is_finite() && g > 0.0 {
                        g
                    } else {
                        0.0
                    }
                };
                let mut sum = fo.body;
                // Per-sample sums of the flake terms whose factors depend on direction and sample (split light
                // under a coloured cover): the diffuse part Σ w_j d_j (1 − τ_i)(1 − τ_o) and the lobe's
                // Σ w_j τ_i τ_o R_j. With τ = 1 + e and e = expm1(−ε_j X'/μ), 1 − τ = −e: two expm1 per
                // sample and cover, shared by the two flake terms when their covers have the same depths. Each
                // R_j is one dot product of its piece's coefficients with the Chebyshev basis at cos_local,
                // computed once for both terms when their tables share a grid.
                let mut diffuse = [0.0; 2];
                let mut lobe_sum = [0.0; 2];
                let mut lobe = [0.0; 2];
                let mut located = [(0usize, 0.0); 2];
                let mut bases = [[0.0; crate::optics::tabulated::N]; 2];
                let mut have_basis = false;
                for (f, t) in terms.iter().enumerate() {
                    if let Some((fl, ff)) = t {
                        lobe[f] = geo(fl);
                        if let Some(g) = ff.grid.as_deref().or(ff.table.as_ref().map(std::slice::from_ref)) {
                            located[f] = g[0].locate(cos_local);
                            // The basis depends on t alone: the second term reuses the first's at the same t.
                            bases[f] = if f == 1 && have_basis && located[1].1.to_bits() == located[0].1.to_bits() {
                                bases[0]
                            } else {
                                basis(located[f].1)
                            };
                            have_basis = true;
                        }
                    }
                }
                let joint = fo.shared_depth && terms[0].is_some_and(|(_, ff)| !ff.grey_cover);
                const TERMS: [usize; 2] = [0, 1];
                for f in 0..2 {
                    let Some((fl, ff)) = terms[f] else { continue };
                    if !fl.split || (joint && f == 1) {
                        continue; // not split (no per-sample factor), or summed with term 0
                    }
                    if ff.grey_cover {
                        let (ei, eo) = (fl.expm1_tau(0, mu_i), fl.expm1_tau(0, mu_o));
                        diffuse[f] = ei * eo * ff.diffuse.iter().sum::<f64>();
                        if lobe[f] > 0.0 {
                            lobe_sum[f] = (1.0 + ei) * (1.0 + eo) * self.unattenuated(fl, ff, fo, cos_local, &bases[f]);
                        }
                        continue;
                    }
                    let members: &[usize] = if joint { &TERMS } else { std::slice::from_ref(&TERMS[f]) };
                    for (j, &w) in fo.weights.iter().enumerate() {
                        let (ei, eo) = (fl.expm1_tau(j, mu_i), fl.expm1_tau(j, mu_o));
                        let att = w * (1.0 + ei) * (1.0 + eo);
                        for &m in members {
                            let Some((mfl, mff)) = terms[m] else { continue };
                            diffuse[m] += mff.diffuse[j] * (ei * eo);
                            if lobe[m] > 0.0 {
                                let r = match &mff.grid {
                                    Some(g) => dot(g[j].piece(located[m].0), &bases[m]),
                                    None => mfl.reflectance(j, cos_local, self.lambda(j)),
                                };
                                lobe_sum[m] += att * r;
                            }
                        }
                    }
                }
                for (f, t) in terms.iter().enumerate() {
                    let Some((fl, ff)) = t else { continue };
                    sum += fl.area * diffuse[f];
                    if lobe[f] <= 0.0 {
                        continue;
                    }
                    let r = if fl.split { lobe_sum[f] } else { self.unattenuated(fl, ff, fo, cos_local, &bases[f]) };
                    sum += fl.area * lobe[f] * r;
                }
                coat + factor * sum
            }
            Form::PaperEq1 => {
                // Eq. (1) as printed: the smooth-interface transmittance on the way in only.
                let t_i = fresnel_dielectric(wi.z.min(1.0), eta).t();
                let h = (wi + wo).normalize();
                let cos_local = wi.dot(h).clamp(0.0, 1.0);
                let mut sum = fo.body;
                for (fl, ff) in terms.iter().flatten() {
                    if fl.smooth {
                        continue;
                    }
                    let d_ct = PI * fl.facets.d(h);
                    let geo = d_ct * fl.facets.g(wi, wo, h, Shadowing::VCavity) / (PI * wi.z * wo.z);
                    if !geo.is_finite() || geo <= 0.0 {
                        continue;
                    }
                    let b = ff.table.as_ref().map(|t| basis(t.locate(cos_local).1)).unwrap_or_default();
                    sum += fl.area * geo * self.unattenuated(fl, ff, fo, cos_local, &b);
                }
                coat + t_i * sum
            }
        }
    }

    /// Σ_j w_j R_j(cos_local) of a flake whose lobe has no per-sample factor in front of its tables (`b`: the
    /// Chebyshev basis at cos_local's position in the folded table's piece).
    fn unattenuated(
        &self,
        fl: &FlakeTerm,
        ff: &FoldedFlake,
        fo: &Folded,
        cos_local: f64,
        b: &[f64; crate::optics::tabulated::N],
    ) -> f64 {
        match &ff.table {
            Some(t) => dot(t.piece(t.locate(cos_local).0), b),
            None => fo.weights.iter().enumerate().map(|(j, w)| w * fl.reflectance(j, cos_local, self.lambda(j))).sum(),
        }
    }

    #[inline]
    fn lambda(&self, j: usize) -> f64 {
        self.spec.sampling.wavelengths_nm[j]
    }
}

/// The paint's hints (`Brdf::hints`), one fact each.
impl Paint {
    /// The terms in evaluation order (the coat, the body, the split flake light, the flakes).
    fn terms(&self) -> Vec<Term> {
        let mut t = Vec::new();
        match &self.rough_coat {
            None => t.push(Term { label: "clear coat (Fresnel, delta)".into(), kind: TermKind::Delta }),
            Some(mf) => t.push(Term {
                label: "clear coat (rough, microfacet)".into(),
                kind: TermKind::Lobe(Lobe::of_facets(mf, 1.0, "clear coat".into())),
            }),
        }
        if self.body_weight > 0.0 {
            t.push(Term { label: "pigmented layer (Kubelka–Munk, diffuse)".into(), kind: TermKind::Diffuse });
        }
        let medium = match self.spec.form {
            Form::Physical => self.spec.coat.index,
            Form::PaperEq1 => 1.0,
        };
        for fl in self.flakes().filter(|f| f.split && f.diffuse.iter().any(|&d| d > 0.0)) {
            t.push(Term {
                label: format!("{}, light scattered by the pigment above them (diffuse)", fl.label),
                kind: TermKind::Diffuse,
            });
        }
        for fl in self.flakes() {
            let kind = if fl.smooth {
                TermKind::Delta
            } else {
                TermKind::Lobe(Lobe {
                    slope_width: fl.facets.alpha,
                    medium_eta: medium,
                    label: fl.label.into(),
                    tail: super::Tail::Gaussian,
                })
            };
            t.push(Term { label: fl.label.into(), kind });
        }
        t
    }

    /// Smooth in the physical form under a smooth (delta) coat: Fresnel T(θ) of the air → coat interface
    /// (η ≥ 1.3, so refraction into the coat never meets total internal reflection and ωi', ωo' are analytic
    /// in ωi, ωo over the whole upper hemisphere: the interior critical angle bounds which interior directions
    /// are reached, it is no cutoff in the exterior directions the instrument integrates over), the
    /// Kubelka–Munk body (a constant), the split light's τ = exp(−εX'/μ') (μ' ≥ √(1 − 1/η²)), and the flake
    /// lobes' Beckmann D with the Smith height-correlated G (erfc, no min). The flake reflectances are read
    /// from piecewise Chebyshev tables of smooth functions verified within `TABLE_TOLERANCE` (10⁻¹²) of the
    /// direct evaluation, so a seam is a jump of at most ~2·10⁻¹², far below the tolerances a reading is asked
    /// for. Not smooth: a rough coat (E(μ) from a table held constant below μ₀, measured dishonest when
    /// checked, `docs/accuracy.md` §5.1) and the paper's Eq. (1) form (V-cavity G, a min()).
    ///
    /// Nor is a flake whose reflectance ρ kinks at a critical angle of total internal reflection (mica below
    /// the resin's index, `FlakeTerm::rho_kinks`): its table is cut there (`docs/model.md` §Evaluation cost,
    /// "Tables cut at the kinks") and so reproduces the kink, ρ is not smooth at the local cosine μc, which is
    /// no [`Kink`] of the exterior directions.
    fn smooth(&self) -> bool {
        self.spec.form == Form::Physical
            && self.rough_coat.is_none()
            && self.flakes().all(|f| (0..f.cover.len()).all(|k| f.rho_kinks(k).is_empty()))
    }

    /// The rough coat's E(μ) (`optics::coat_albedo`) changes Chebyshev piece at its μ breaks and is held at
    /// E(μ₀) below μ₀: the coat transmittance 1 − E(μ) of both directions seams there.
    fn seams(&self) -> Vec<f64> {
        if self.coat_albedo.is_none() {
            return Vec::new();
        }
        crate::optics::coat_albedo::BREAKS.iter().copied().filter(|&c| c > 0.0 && c < 1.0).collect()
    }

    /// Physical: T(θi)T(θo) symmetric, f' symmetric (h' and ωi'·h' = ωo'·h' are). Paper Eq. 1 applies τ(θi)
    /// once, which breaks the symmetry whenever anything lies under the coat.
    fn is_reciprocal(&self) -> bool {
        match self.spec.form {
            Form::Physical => true,
            Form::PaperEq1 => self.body_weight == 0.0 && self.metallic.is_none() && self.pearlescent.is_none(),
        }
    }
}

impl Brdf for Paint {
    fn sampling(&self) -> &Sampling {
        &self.spec.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let n = self.spec.sampling.len();
        let out = &mut out[..n];
        out.fill(0.0);
        if !above_horizon(wi, wo) {
            return;
        }
        let eta = self.spec.coat.index;
        let lambdas = &self.spec.sampling.wavelengths_nm;
        // Rough clear coat: a microfacet reflection lobe on the air side (medium 1).
        if let Some(mf) = &self.rough_coat {
            let h = (wi + wo).normalize();
            let v = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), eta)
                * mf.d(h)
                * mf.g(wi, wo, h, Shadowing::SmithHeightCorrelated)
                / (4.0 * wi.z * wo.z);
            if v.is_finite() && v > 0.0 {
                out.iter_mut().for_each(|o| *o += v);
            }
        }
        match self.spec.form {
            Form::Physical => {
                let (Some(wi_in), Some(wo_in)) = (refract_into(wi, eta), refract_into(wo, eta)) else {
                    return;
                };
                let (t_i, t_o) = (self.coat_transmittance(wi.z), self.coat_transmittance(wo.z));
                let factor = t_i * t_o / (eta * eta);
                for (o, b) in out.iter_mut().zip(&self.body) {
                    *o += factor * b;
                }
                let h = (wi_in + wo_in).normalize();
                let cos_local = wi_in.dot(h).clamp(0.0, 1.0);
                for fl in self.flakes() {
                    if fl.split {
                        // The light the cover scatters: a reciprocal diffuse term whose interior albedo is
                        // A·R_d·(1 − τ(θi')) (docs/model.md §Flake light through the pigment).
                        let w = factor * fl.area;
                        for (k, o) in out.iter_mut().enumerate() {
                            *o += w * fl.diffuse[k] * fl.one_minus_tau(k, wi_in.z) * fl.one_minus_tau(k, wo_in.z);
                        }
                    }
                    if fl.smooth {
                        continue;
                    }
                    let geo = fl.facets.d(h) * fl.facets.g(wi_in, wo_in, h, Shadowing::SmithHeightCorrelated)
                        / (4.0 * wi_in.z * wo_in.z);
                    if !geo.is_finite() || geo <= 0.0 {
                        continue;
                    }
                    let w = factor * fl.area * geo;
                    for (k, o) in out.iter_mut().enumerate() {
                        let att = if fl.split { fl.tau(k, wi_in.z) * fl.tau(k, wo_in.z) } else { 1.0 };
                        *o += w * att * fl.reflectance(k, cos_local, lambdas[k]);
                    }
                }
            }
            Form::PaperEq1 => {
                // Eq. (1) as printed: the smooth-interface transmittance on the way in only.
                let t_i = fresnel_dielectric(wi.z.min(1.0), eta).t();
                let tau = t_i;
                for (o, b) in out.iter_mut().zip(&self.body) {
                    *o += tau * b;
                }
                let h = (wi + wo).normalize();
                let cos_local = wi.dot(h).clamp(0.0, 1.0);
                for fl in self.flakes().filter(|f| !f.smooth) {
                    // Cook–Torrance 1982: D_CT = π·D (their Beckmann has no 1/π), divided by π cos θi cos θo.
                    let d_ct = PI * fl.facets.d(h);
                    let geo = d_ct * fl.facets.g(wi, wo, h, Shadowing::VCavity) / (PI * wi.z * wo.z);
                    if !geo.is_finite() || geo <= 0.0 {
                        continue;
                    }
                    let w = tau * fl.area * geo;
                    for (k, o) in out.iter_mut().enumerate() {
                        *o += w * fl.reflectance(k, cos_local, lambdas[k]);
                    }
                }
            }
        }
    }

    fn folds(&self, w: &[f64]) -> bool {
        self.folded.as_ref().is_some_and(|f| f.weights == w)
    }

    fn eval_batch_folded(&self, w: &[f64], wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) -> bool {
        let Some(fo) = self.folded.as_ref().filter(|f| f.weights == w) else {
            return false;
        };
        for ((a, b), o) in wi.iter().zip(wo).zip(out.iter_mut()) {
            *o = self.eval_folded(fo, *a, *b);
        }
        true
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        let smooth_flakes = self.flakes().any(|f| f.smooth);
        if self.rough_coat.is_some() && !smooth_flakes {
            return false;
        }
        let n = self.spec.sampling.len();
        let out = &mut out[..n];
        out.fill(0.0);
        if wi.z.is_nan() || wi.z <= 0.0 {
            return true;
        }
        let eta = self.spec.coat.index;
        let cos_i = wi.z.min(1.0);
        if self.rough_coat.is_none() {
            let rho = fr_dielectric(cos_i, eta);
            out.iter_mut().for_each(|o| *o = rho);
        }
        let lambdas = &self.spec.sampling.wavelengths_nm;
        let t_i = match self.spec.form {
            Form::Physical => self.coat_transmittance(cos_i),
            Form::PaperEq1 => fresnel_dielectric(cos_i, eta).t(),
        };
        for fl in self.flakes().filter(|f| f.smooth) {
            // Mirror geometry: h = n, θo = θi. Physical: interior delta A·R·δ(ωo' − mirror ωi')/cos θo' maps
            // to the exterior delta with weight T(θi)·T(θo)·A·R (docs/model.md §Delta limit of the flakes).
            // Paper Eq. 1: A·R·D_CT·G/(π cos θi cos θo) → 4·τ·A·R (G_V-cavity = 1 at h = n).
            let (w, cos_local) = match self.spec.form {
                Form::Physical => match refract_into(wi, eta) {
                    Some(w_in) => (t_i * t_i * fl.area, w_in.z.min(1.0)),
                    None => continue,
                },
                Form::PaperEq1 => (4.0 * t_i * fl.area, cos_i),
            };
            for (k, o) in out.iter_mut().enumerate() {
                // Split flake light: the mirror path goes in and out at θi', attenuated τ(θi')² by the cover.
                let att = if fl.split { fl.tau(k, cos_local).powi(2) } else { 1.0 };
                *o += w * att * fl.reflectance(k, cos_local, lambdas[k]);
            }
        }
        true
    }

    fn hints(&self) -> Hints {
        Hints::new(self.terms())
            .with_seams(self.seams())
            .with_reciprocal(self.is_reciprocal())
            .with_smooth(self.smooth())
    }

    fn describe(&self) -> String {
        let s = &self.spec;
        let form = match s.form {
            Form::Physical => "physical form",
            Form::PaperEq1 => "paper Eq. 1 as printed",
        };
        let coat = match &self.rough_coat {
            None => format!("smooth coat η = {}", s.coat.index),
            Some(mf) => format!(
                "rough coat η = {} ({:?} {}; energy-exact coupling, directional albedo from the shipped table)",
                s.coat.index, mf.distribution, mf.alpha
            ),
        };
        let mut d = format!(
            "paint (Ďurikovič & Ágošton 2007, {form}): {coat}, KM layer X = {} mm with {} pigment(s)",
            s.layer.thickness_mm,
            s.layer.pigments.len()
        );
        if s.internal_reflection && s.form == Form::Physical {
            d.push_str(&format!(", Saunderson r_i = {:.4}", self.r_i));
        }
        if s.form == Form::Physical && self.flakes().next().is_some() {
            d.push_str(match s.flake_light {
                FlakeLight::Split => ", flake light split (lobe × cover transmission, scattered part diffuse)",
                FlakeLight::PaperEq5 => ", flake light as the paper's Eq. 5 (cover reflectance in the lobe)",
            });
        }
        for fl in self.flakes() {
            let table = match &fl.table {
                Some(t) => format!(
                    ", reflectance tabulated ({} pieces{}, max deviation {:.0e})",
                    t[0].pieces(),
                    if t[0].kinked() { " cut at the critical cosine" } else { "" },
                    t.iter().map(|x| x.max_error).fold(0.0, f64::max)
                ),
                None => String::new(),
            };
            d.push_str(&format!(
                ", {} A = {} m = {:.3e}{}{table}",
                fl.label,
                fl.area,
                fl.facets.alpha,
                if fl.smooth { " (delta)" } else { "" }
            ));
        }
        d
    }
}
