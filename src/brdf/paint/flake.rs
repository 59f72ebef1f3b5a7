//! The optics of one kind of flake under its cover of pigment, precomputed per sample ([`FlakeTerm`]): the
//! flake's reflectance ρ (a metal's Fresnel reflectance or the pearl's thin-film stack) and the cosines where
//! it kinks, the cover's Kubelka–Munk reflectance over it (paper Eqs. 5–8 corrected) and its verified
//! Chebyshev tables, and the split flake light's unscattered transmission τ and diffuse weight
//! (`docs/model.md` §Metallic flakes, §Pearlescent flakes, §Flake light through the pigment).
use super::hemisphere::{hemispherical_mean, hemispherical_means, DIFFUSE_FRESNEL_NODES};
use super::memo::Memo;
use crate::optics::fresnel::{critical_cosine_complex, fr_conductor};
use crate::optics::kubelka_munk::Layer;
use crate::optics::microfacet::Microfacet;
use crate::optics::tabulated::{Abscissa, ChebTable};
use crate::optics::thin_film::{stack_spectrum, FilmLayer};
use crate::quadrature::gauss_legendre;
use num_complex::Complex64;
use std::cell::Cell;
use std::f64::consts::PI;

/// Largest accepted deviation of a flake-reflectance table from the direct evaluation (absolute, on a
/// reflectance ≤ 1): far below any tolerance a reading is asked for.
pub const TABLE_TOLERANCE: f64 = 1e-12;

/// Per-kind optics of a flake.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum FlakeOptics {
    /// Relative complex index (n + ik)/η_medium per sample.
    Metal(Vec<Complex64>),
    /// The film stack TiO2 / mica / TiO2, entered from and exited into resin of index `medium`.
    Pearl { layers: [FilmLayer; 3], medium: f64 },
}

/// A flake term, precomputed.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct FlakeTerm {
    pub(super) label: &'static str,
    pub(super) area: f64,
    pub(super) facets: Microfacet,
    /// Spread below `Microfacet::SMOOTH_THRESHOLD`: evaluated as its delta limit.
    pub(super) smooth: bool,
    /// KM operator of the pigment above the flake (thickness X' or X''), per sample.
    pub(super) cover: Vec<Layer>,
    pub(super) optics: FlakeOptics,
    /// R_m or R_p (paper Eq. 5) — or, for the split flake light, the bare flake reflectance ρ — per sample as a
    /// verified Chebyshev table over the local cosine ∈ [0, 1] (max deviation from the direct evaluation ≤
    /// `TABLE_TOLERANCE` at check points), or None when no table met it.
    pub(super) table: Option<Vec<ChebTable>>,
    /// The same tables on one grid (each at the largest piece count among them: a table that met the tolerance
    /// with fewer pieces is fitted again at that count), what the folded evaluation sums coefficients over
    /// (`folded.rs`); None when `table` is None or a refit missed the tolerance.
    pub(super) grid: Option<Vec<ChebTable>>,
    /// Split flake light: per sample, the optical depth ε·X' of the cover for collimated light, ε = (K + S)/2.
    pub(super) depth: Vec<f64>,
    /// Split flake light: per sample, the diffuse part's weight R_d/(π(1 − τ̄)): R_d = KM cover over the
    /// flake's hemispherical reflectance, τ̄ = 2∫τ(μ)μ dμ. 0 where the cover does not scatter or absorb.
    pub(super) diffuse: Vec<f64>,
    pub(super) split: bool,
}

impl FlakeTerm {
    /// Flake reflectance ρ at the local cosine `at.x` for sample `k` (before the pigment above it); on a table
    /// segment at a kink, the pearl's stack takes the offset from it (`optics::thin_film::stack_spectrum`).
    #[inline]
    fn rho(&self, k: usize, at: Abscissa, wavelength_nm: f64) -> f64 {
        match &self.optics {
            FlakeOptics::Metal(eta) => fr_conductor(at.x, eta[k]),
            FlakeOptics::Pearl { layers, medium } => {
                let mut r = 1.0;
                let n = Complex64::new(*medium, 0.0);
                stack_spectrum(*medium, layers, n, at.x, at.kink, [wavelength_nm], |_, s| r = s.r());
                r
            }
        }
    }

    /// R_m or R_p: the KM reflectance of the pigment above the flake over the flake (Eqs. 5, 8 corrected),
    /// from the verified table when there is one.
    #[inline]
    pub(super) fn reflectance(&self, k: usize, cos_local: f64, wavelength_nm: f64) -> f64 {
        match &self.table {
            Some(t) => t[k].eval(cos_local),
            None => self.reflectance_direct(k, cos_local, wavelength_nm),
        }
    }

    /// What the lobe carries per unit D·G/(4 cos cos), evaluated directly (no table): R_m or R_p (paper Eq. 5),
    /// or the bare flake reflectance ρ for the split flake light (the cover's attenuation is applied by the
    /// caller, it depends on both directions).
    pub(super) fn reflectance_direct(&self, k: usize, cos_local: f64, wavelength_nm: f64) -> f64 {
        self.reflectance_at(k, Abscissa { x: cos_local, kink: None }, wavelength_nm)
    }

    /// [`FlakeTerm::reflectance_direct`] at a point a table asks for ([`Abscissa`]).
    fn reflectance_at(&self, k: usize, at: Abscissa, wavelength_nm: f64) -> f64 {
        self.lobe_part(k, self.rho(k, at, wavelength_nm).clamp(0.0, 1.0))
    }

    /// What the lobe carries for sample `k` given its clamped flake reflectance ρ: ρ for the split light,
    /// else the cover over it (R_m or R_p).
    #[inline]
    fn lobe_part(&self, k: usize, rho: f64) -> f64 {
        if self.split {
            rho
        } else {
            self.cover[k].over(rho)
        }
    }

    /// The clamped flake reflectance ρ of the samples `which` at the local cosine `cos_local`, into `out`
    /// (each the bits of `self.rho(k, …).clamp(0, 1)`): the pearl's stack at every wavelength at once
    /// (`optics::thin_film::stack_spectrum`: its angles and interface amplitudes computed once), a metal's
    /// Fresnel reflectance per sample. `work` counts the stack set-ups and the reflectances.
    fn rho_each(&self, at: Abscissa, which: &[usize], wavelengths_nm: &[f64], out: &mut [f64], work: &Work) {
        work.count(1, which.len());
        match &self.optics {
            FlakeOptics::Metal(eta) => {
                for (o, &k) in out.iter_mut().zip(which) {
                    *o = fr_conductor(at.x, eta[k]).clamp(0.0, 1.0);
                }
            }
            FlakeOptics::Pearl { layers, medium } => {
                let lambdas = which.iter().map(|&k| wavelengths_nm[k]);
                let n = Complex64::new(*medium, 0.0);
                stack_spectrum(*medium, layers, n, at.x, at.kink, lambdas, |i, r| out[i] = r.r().clamp(0.0, 1.0));
            }
        }
    }

    /// [`FlakeTerm::reflectance_at`] of the samples `which` at once ([`FlakeTerm::rho_each`]).
    fn reflectance_each(&self, at: Abscissa, which: &[usize], wavelengths_nm: &[f64], out: &mut [f64], work: &Work) {
        self.rho_each(at, which, wavelengths_nm, out, work);
        for (o, &k) in out.iter_mut().zip(which) {
            *o = self.lobe_part(k, *o);
        }
    }

    /// Unscattered transmission τ = exp(−ε X'/μ) of the cover along an interior direction of cosine μ.
    #[inline]
    pub(super) fn tau(&self, k: usize, mu: f64) -> f64 {
        if mu <= 0.0 {
            0.0
        } else {
            (-self.depth[k] / mu).exp()
        }
    }

    /// e = τ − 1 = expm1(−ε X'/μ) (−1 where μ ≤ 0, τ = 0 there): τ = 1 + e and 1 − τ = −e from one call.
    #[inline]
    pub(super) fn expm1_tau(&self, k: usize, mu: f64) -> f64 {
        if mu <= 0.0 {
            -1.0
        } else {
            (-self.depth[k] / mu).exp_m1()
        }
    }

    /// 1 − τ without cancellation.
    #[inline]
    pub(super) fn one_minus_tau(&self, k: usize, mu: f64) -> f64 {
        if mu <= 0.0 {
            1.0
        } else {
            -(-self.depth[k] / mu).exp_m1()
        }
    }

    /// The cosines in (0, 1) at which the flake reflectance ρ(μ) of sample `k` has a kink: the critical angles
    /// of total internal reflection (docs/model.md §Pearlescent flakes). Light in the resin of index η_r meets
    /// every layer of the stack at the same Snell invariant η_r sin θ, so a lossless layer of index n < η_r
    /// reflects totally below cos θc = √(1 − (n/η_r)²) (`optics::fresnel::critical_cosine`), and a metal whose
    /// relative index is real and below 1 likewise; an absorbing layer has no kink. Sorted, distinct.
    pub(super) fn rho_kinks(&self, k: usize) -> Vec<f64> {
        let mut kinks: Vec<f64> = match &self.optics {
            FlakeOptics::Metal(eta) => critical_cosine_complex(eta[k]).into_iter().collect(),
            FlakeOptics::Pearl { layers, medium } => {
                layers.iter().filter_map(|l| critical_cosine_complex(l.n / *medium)).collect()
            }
        };
        kinks.retain(|&c| c > 0.0 && c < 1.0);
        kinks.sort_by(f64::total_cmp);
        kinks.dedup();
        kinks
    }

    /// Precompute the split flake light's per-sample constants (`depth`, `diffuse`): one sample at a time
    /// (`per_sample`, the engine before `docs/model.md` §Evaluation cost "shared across samples") or every
    /// sample with the same kinks at once; the same bits either way.
    fn split_constants(
        &mut self,
        k_mix: &[f64],
        s_mix: &[f64],
        depth_mm: f64,
        wavelengths_nm: &[f64],
        per_sample: bool,
        work: &Work,
    ) {
        let (x, w) = gauss_legendre(DIFFUSE_FRESNEL_NODES);
        let n = self.cover.len();
        self.depth = (0..n).map(|j| 0.5 * (k_mix[j] + s_mix[j]) * depth_mm).collect();
        // ρ_d = 2∫ρ(μ)μ dμ (split at ρ's kinks), by Gauss–Legendre in μ.
        let kinks: Vec<Vec<f64>> = (0..n).map(|j| self.rho_kinks(j)).collect();
        let mut rho_d = vec![0.0; n];
        if per_sample {
            for (j, r) in rho_d.iter_mut().enumerate() {
                *r = hemispherical_mean(
                    |mu| {
                        work.count(1, 1);
                        self.rho(j, Abscissa { x: mu, kink: None }, wavelengths_nm[j]).clamp(0.0, 1.0)
                    },
                    &kinks[j],
                );
            }
        } else {
            for group in same_kinks(&kinks) {
                let means = hemispherical_means(
                    |mu, out| self.rho_each(Abscissa { x: mu, kink: None }, &group, wavelengths_nm, out, work),
                    group.len(),
                    &kinks[group[0]],
                );
                for (&i, m) in group.iter().zip(means) {
                    rho_d[i] = m;
                }
            }
        }
        self.diffuse = (0..n)
            .map(|j| {
                // 1 − τ̄ = 2∫(1 − τ(μ))μ dμ (smooth on [0, 1]).
                let mut one_minus_tau_bar = 0.0;
                for (&xi, &wi) in x.iter().zip(&w) {
                    let mu = 0.5 * (xi + 1.0);
                    one_minus_tau_bar += wi * mu * self.one_minus_tau(j, mu);
                }
                if one_minus_tau_bar <= 0.0 {
                    return 0.0;
                }
                self.cover[j].over(rho_d[j].clamp(0.0, 1.0)) / (PI * one_minus_tau_bar)
            })
            .collect();
    }

    /// Build the per-sample tables; all or none. Each is cut at its ρ's kinks ([`FlakeTerm::rho_kinks`],
    /// [`ChebTable::fit_kinked`]; without kinks the uniform table of before). `per_sample`: each sample's table
    /// fitted alone (the engine before), else all samples with the same kinks at once
    /// ([`ChebTable::fit_each_kinked`], the same tables to the bit).
    fn tabulate(&mut self, wavelengths_nm: &[f64], per_sample: bool, work: &Work) {
        let n = self.cover.len();
        let kinks: Vec<Vec<f64>> = (0..n).map(|k| self.rho_kinks(k)).collect();
        self.table = if per_sample {
            (0..n)
                .map(|k| {
                    let f = |at, _: &[usize], v: &mut [f64]| {
                        work.count(1, 1);
                        v[0] = self.reflectance_at(k, at, wavelengths_nm[k])
                    };
                    ChebTable::fit_each_kinked(f, 1, 0.0, 1.0, &kinks[k], TABLE_TOLERANCE).pop().flatten()
                })
                .collect()
        } else {
            let mut tables = vec![None; n];
            for group in same_kinks(&kinks) {
                let f = |c, which: &[usize], out: &mut [f64]| {
                    let which: Vec<usize> = which.iter().map(|&i| group[i]).collect();
                    self.reflectance_each(c, &which, wavelengths_nm, out, work)
                };
                let fits = ChebTable::fit_each_kinked(f, group.len(), 0.0, 1.0, &kinks[group[0]], TABLE_TOLERANCE);
                for (&k, t) in group.iter().zip(fits) {
                    tables[k] = t;
                }
            }
            tables.into_iter().collect()
        };
    }

    /// The tables on one grid ([`FlakeTerm::grid`]): a table with fewer pieces than the most among them is
    /// fitted again at that count (alone, or all such at once as in [`FlakeTerm::tabulate`]).
    /// Samples whose ρ kinks at different cosines have tables cut differently, which share no grid: None.
    fn on_one_grid(&self, wavelengths_nm: &[f64], per_sample: bool, work: &Work) -> Option<Vec<ChebTable>> {
        let t = self.table.as_ref()?;
        let kinks = self.rho_kinks(0);
        if (1..t.len()).any(|k| bits(&self.rho_kinks(k)) != bits(&kinks)) {
            return None;
        }
        let pieces = t.iter().map(ChebTable::pieces).max()?;
        if per_sample {
            return t
                .iter()
                .enumerate()
                .map(|(k, tk)| match tk.pieces() == pieces {
                    true => Some(tk.clone()),
                    false => ChebTable::fit_each_kinked_with_pieces(
                        |at, _, v| {
                            work.count(1, 1);
                            v[0] = self.reflectance_at(k, at, wavelengths_nm[k])
                        },
                        &[0],
                        0.0,
                        1.0,
                        &kinks,
                        pieces,
                        TABLE_TOLERANCE,
                    )
                    .pop()
                    .flatten(),
                })
                .collect();
        }
        let refit: Vec<usize> = (0..t.len()).filter(|&k| t[k].pieces() != pieces).collect();
        let f = |c, which: &[usize], out: &mut [f64]| self.reflectance_each(c, which, wavelengths_nm, out, work);
        let mut again =
            ChebTable::fit_each_kinked_with_pieces(f, &refit, 0.0, 1.0, &kinks, pieces, TABLE_TOLERANCE).into_iter();
        t.iter().map(|tk| if tk.pieces() == pieces { Some(tk.clone()) } else { again.next().flatten() }).collect()
    }

    /// Everything the term computes from its optics, its cover and the samples: the tables ([`FlakeTerm::table`],
    /// [`FlakeTerm::grid`]) and, for the split flake light, its constants ([`FlakeTerm::split_constants`]) —
    /// taken from the build's memo ([`PaintBuild::memo`]) when a build before had the same inputs to the bit (what
    /// a sweep point that varies an area ratio, a spread, the primer or the coat's roughness meets), else computed
    /// and kept there. `build.tables` says how tables the memo does not have are fitted (the bits are the same
    /// either way). Returns the work this build did: none when the memo had the tables.
    pub(super) fn prepare(
        &mut self,
        k_mix: &[f64],
        s_mix: &[f64],
        depth_mm: f64,
        wavelengths_nm: &[f64],
        build: PaintBuild<'_>,
    ) -> TableWork {
        let mut work = TableWork::default();
        let mut compute = || {
            let (made, w) = self.compute(k_mix, s_mix, depth_mm, wavelengths_nm, build.tables);
            work = w;
            made
        };
        let made = match build.memo {
            Some(memo) => {
                let mut key = self.key(k_mix, s_mix, depth_mm, wavelengths_nm);
                key.push((build.tables == TableBuild::Direct) as u64);
                memo.0.get_or_make(key, compute)
            }
            None => std::sync::Arc::new(compute()),
        };
        self.table = made.table.clone();
        self.grid = made.grid.clone();
        self.depth = made.depth.clone();
        self.diffuse = made.diffuse.clone();
        work
    }

    /// What [`FlakeTerm::prepare`] computes when the memo does not have it, with the film-stack work it did.
    fn compute(
        &self,
        k_mix: &[f64],
        s_mix: &[f64],
        depth_mm: f64,
        wavelengths_nm: &[f64],
        build: TableBuild,
    ) -> (Prepared, TableWork) {
        let per_sample = build == TableBuild::PerSample;
        let work = Work::default();
        let mut t = self.clone();
        if build != TableBuild::Direct {
            t.tabulate(wavelengths_nm, per_sample, &work);
            t.grid = t.on_one_grid(wavelengths_nm, per_sample, &work);
        }
        if t.split {
            t.split_constants(k_mix, s_mix, depth_mm, wavelengths_nm, per_sample, &work);
        }
        let counted = match t.optics {
            FlakeOptics::Pearl { .. } => {
                TableWork { stack_setups: work.setups.get(), stack_evaluations: work.evaluations.get() }
            }
            FlakeOptics::Metal(_) => TableWork::default(),
        };
        (Prepared { table: t.table, grid: t.grid, depth: t.depth, diffuse: t.diffuse }, counted)
    }

    /// The bits of every input [`FlakeTerm::prepare`] reads: the optics, the cover per sample, whether the light
    /// is split, the wavelengths, the table tolerance, and for the split light the pigment mix and the depth.
    fn key(&self, k_mix: &[f64], s_mix: &[f64], depth_mm: f64, wavelengths_nm: &[f64]) -> Vec<u64> {
        let mut key = vec![TABLE_TOLERANCE.to_bits(), self.split as u64];
        match &self.optics {
            FlakeOptics::Metal(eta) => {
                key.push(1);
                key.extend(eta.iter().flat_map(|e| [e.re.to_bits(), e.im.to_bits()]));
            }
            FlakeOptics::Pearl { layers, medium } => {
                key.push(2);
                for l in layers {
                    key.extend([l.n.re.to_bits(), l.n.im.to_bits(), l.thickness_nm.to_bits(), l.coherent as u64]);
                }
                key.push(medium.to_bits());
            }
        }
        key.extend(self.cover.iter().flat_map(|c| [c.r0.to_bits(), c.t.to_bits()]));
        key.extend(wavelengths_nm.iter().map(|w| w.to_bits()));
        if self.split {
            key.push(depth_mm.to_bits());
            key.extend(k_mix.iter().chain(s_mix).map(|x| x.to_bits()));
        }
        key
    }
}

/// The bits of a list of cosines.
fn bits(k: &[f64]) -> Vec<u64> {
    k.iter().map(|c| c.to_bits()).collect()
}

/// The samples grouped by their kinks (the same to the bit), each group in increasing order, the groups in
/// the order of their first sample.
fn same_kinks(kinks: &[Vec<f64>]) -> Vec<Vec<usize>> {
    let n = kinks.len();
    let mut done = vec![false; n];
    let mut groups = Vec::new();
    for j in 0..n {
        if done[j] {
            continue;
        }
        let group: Vec<usize> = (j..n).filter(|&i| !done[i] && bits(&kinks[i]) == bits(&kinks[j])).collect();
        group.iter().for_each(|&i| done[i] = true);
        groups.push(group);
    }
    groups
}

/// Flake tables kept between paint builds ([`FlakeTerm::prepare`]), keyed by the bits of every input they are
/// computed from, so a kept entry is what a rebuild would give to the bit. [`TableMemo::process`] is the one
/// every front end's build reads ([`Paint::new`](super::Paint::new)): a cache, not a switch; it stays
/// process-wide because a sweep or fit point is built anew from its recipe text and finds its neighbour's
/// tables only there (`docs/model.md` §Evaluation cost, "Tables kept between builds"; `docs/performance.md`
/// §"Paint rebuilds in sweeps"). A bench or a test that compares builds passes its own memo, or none
/// ([`PaintBuild`]), instead of clearing this one.
pub struct TableMemo(Memo<Prepared>);

impl TableMemo {
    /// An empty memo of its own (at most [`super::MEMO_ENTRIES`] entries).
    pub const fn new() -> TableMemo {
        TableMemo(Memo::new())
    }

    /// The memo of the process, what [`PaintBuild::default`] reads.
    pub(crate) fn process() -> &'static TableMemo {
        static TABLES: TableMemo = TableMemo::new();
        &TABLES
    }
}

impl Default for TableMemo {
    fn default() -> TableMemo {
        TableMemo::new()
    }
}

impl std::fmt::Debug for TableMemo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TableMemo")
    }
}

/// How a paint is built ([`super::Paint::build`]): how its flake tables are fitted, and the memo its tables are
/// looked up in and kept in (None: computed by this build alone, neither read nor kept). The default is what
/// [`super::Paint::new`] does: [`TableBuild::Shared`] and [`TableMemo::process`].
#[derive(Clone, Copy, Debug)]
pub struct PaintBuild<'a> {
    pub tables: TableBuild,
    pub memo: Option<&'a TableMemo>,
}

impl Default for PaintBuild<'_> {
    fn default() -> Self {
        PaintBuild { tables: TableBuild::Shared, memo: Some(TableMemo::process()) }
    }
}

/// The film-stack work one paint build did for its pearl flake tables (exact counts, what
/// `benches/paint_build.rs` reports beside its times; zero when the memo had the tables, and for metal flakes):
/// `stack_setups`, angles of incidence at which a stack's angles and interface amplitudes were computed;
/// `stack_evaluations`, reflectances ρ(μ, λ) computed. Per sample, one of each per evaluation; shared, one
/// set-up serves every sample at its angle (`docs/model.md` §Evaluation cost).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TableWork {
    pub stack_setups: u64,
    pub stack_evaluations: u64,
}

impl std::ops::Add for TableWork {
    type Output = TableWork;
    fn add(self, o: TableWork) -> TableWork {
        TableWork {
            stack_setups: self.stack_setups + o.stack_setups,
            stack_evaluations: self.stack_evaluations + o.stack_evaluations,
        }
    }
}

/// What [`FlakeTerm::prepare`] computes and the memo keeps.
struct Prepared {
    table: Option<Vec<ChebTable>>,
    grid: Option<Vec<ChebTable>>,
    depth: Vec<f64>,
    diffuse: Vec<f64>,
}

/// How a paint's flake tables are fitted ([`super::Paint::with_table_build`]): all samples at once
/// ([`TableBuild::Shared`], what [`super::Paint::new`] does) or one sample at a time
/// ([`TableBuild::PerSample`]: the engine before `docs/model.md` §Evaluation cost "shared across samples", what
/// `benches/paint_build.rs` times as "before"), or none fitted ([`TableBuild::Direct`]). The tables are the
/// same bits either way (`tests/paint.rs`), so the memo serves both; `Direct` has entries of its own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TableBuild {
    #[default]
    Shared,
    PerSample,
    /// No tables: every flake reflectance evaluated directly (the reference the tables are checked against,
    /// `tests/paint.rs`; not the same bits, and far slower).
    Direct,
}
/// Counts of one table build, as it goes ([`TableWork`] when it is done).
#[derive(Default)]
struct Work {
    setups: Cell<u64>,
    evaluations: Cell<u64>,
}

impl Work {
    fn count(&self, setups: usize, evaluations: usize) {
        self.setups.set(self.setups.get() + setups as u64);
        self.evaluations.set(self.evaluations.get() + evaluations as u64);
    }
}
