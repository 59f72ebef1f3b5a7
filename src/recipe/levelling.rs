//! The `application` block of a paint's clear coat (docs/recipe-format.md §Paint, the registry's
//! [`crate::registry::APPLICATION`] entries): how the coat was applied and dried, instead of its roughness.
//! The applied texture's PSD is levelled (`optics::levelling`) and the cured spectrum's slopes become the coat's
//! facets (Beckmann α = its rms slope Sdq). Why the whole cured spectrum is facets and none of it a
//! Rayleigh–Rice halo: docs/model.md §From the cured spectrum to the coat.
use super::topography::levelled_map;
use crate::brdf::annotated::Annotated;
use crate::brdf::paint::{Paint, PaintSpec};
use crate::brdf::Brdf;
use crate::input::json::{kind, Obj};
use crate::optics::levelling::psd_transfer;
use crate::optics::levelling::{levelled_frequency, Application, CuredPsd, Flow, ViscosityPoint};
use crate::optics::microfacet::{Distribution, Microfacet};
use crate::optics::scatter::Psd;
use crate::registry as reg;
use crate::topography::psd::{psd as map_psd, Psd2};
use crate::{Error, Result};
use serde_json::Value;
use std::f64::consts::PI;
use std::sync::Arc;

const PAINT: &str = "paint";

/// The wave-scan-like bands of the spectrum that `--explain` lists, by surface wavelength in mm (the bands of
/// BYK-Gardner's wave-scan: du below 0.1 mm, Wa 0.1–0.3, Wb 0.3–1, Wc 1–3, Wd 3–10, We 10–30 mm).
pub(crate) const BANDS_MM: [(&str, f64, f64); 6] =
    [("du", 0.0, 0.1), ("Wa", 0.1, 0.3), ("Wb", 0.3, 1.0), ("Wc", 1.0, 3.0), ("Wd", 3.0, 10.0), ("We", 10.0, 30.0)];

/// The applicator's texture as applied (wet): an analytic isotropic PSD, or a measured topography's own 2-D PSD.
#[derive(Clone, Debug)]
pub(crate) enum Texture {
    Analytic(Psd),
    Measured {
        /// The levelled map's 2-D PSD (1/m, m⁴).
        psd: Psd2,
        /// The file and its levelling, for the note.
        source: String,
    },
}

/// The cured texture: the applied one after the flow, kept at v of its amplitude.
#[derive(Clone, Debug)]
pub(crate) enum Cured {
    /// An analytic texture's cured spectrum, over all frequencies.
    Analytic(CuredPsd),
    /// A measured texture's grid spectrum, each mode multiplied by the PSD transfer: over the map's band only
    /// (from 1/(its size) to its Nyquist frequency).
    Measured { psd: Psd2, volume_solids: f64, flow: Flow, source: String },
}

impl Cured {
    /// The mean-square height (nm²) of the band [a, b] (1/µm), cured (`cured`) or as applied.
    fn band_ms(&self, a: f64, b: f64, cured: bool) -> f64 {
        match self {
            Cured::Analytic(c) if cured => c.band_ms(a, b),
            Cured::Analytic(c) => {
                (2.0 * PI * (c.applied.radial_cumulative(b) - c.applied.radial_cumulative(a))).max(0.0)
            }
            Cured::Measured { psd, volume_solids, flow, .. } => {
                let w = |f: f64| if cured { psd_transfer(*volume_solids, *flow, f * 1e-6) } else { 1.0 };
                // 1/µm → 1/m; m² → nm².
                psd.weighted_moment(0, a * 1e6, b * 1e6, w) * 1e18
            }
        }
    }

    /// The cured mean-square slope, nm²/µm² (10⁻⁶ rad²).
    fn slope_ms(&self) -> f64 {
        match self {
            Cured::Analytic(c) => c.slope_ms(),
            Cured::Measured { psd, volume_solids, flow, .. } => {
                psd.weighted_moment(2, 0.0, f64::INFINITY, |f| psd_transfer(*volume_solids, *flow, f * 1e-6)) * 1e6
            }
        }
    }
}

/// What a coat's application gives: the levelling, the cured spectrum and the facets' roughness.
#[derive(Clone, Debug)]
pub(crate) struct LevelledCoat {
    pub application: Application,
    /// The flow's integrals: L (µm⁴), which levels, and the surface-tension gradient's M (µm²).
    pub flow: Flow,
    /// The cured texture (with the applied one).
    pub cured: Cured,
    /// The facets' Beckmann α: the cured spectrum's rms slope Sdq; 0 below the smooth limit.
    pub roughness: f64,
}

/// Read the `application` object `o` (at `/clear_coat/application`) into the application and the applied texture.
pub(crate) fn parse_application(o: &Obj) -> Result<(Application, Texture)> {
    o.deny_unknown_in(PAINT)?;
    notes(o)?;
    let t = o.obj("texture")?;
    t.deny_unknown_in(PAINT)?;
    notes(&t)?;
    let applied = parse_texture(&t)?;
    let key = o.param_key(&reg::APP_VISCOSITY);
    let mut viscosity = Vec::new();
    for (i, v) in o.array(&key)?.iter().enumerate() {
        let p = Obj::new(o.file, o.element(&key, i), v)?;
        p.deny_unknown_in(PAINT)?;
        viscosity
            .push(ViscosityPoint { t_s: p.param(&reg::APP_VISCOSITY_T)?, eta_pa_s: p.param(&reg::APP_VISCOSITY_ETA)? });
    }
    let app = Application {
        wet_film_um: o.param(&reg::APP_WET_FILM)?,
        volume_solids: o.param(&reg::APP_VOLUME_SOLIDS)?,
        surface_tension_mn_m: o.param(&reg::APP_SURFACE_TENSION)?,
        flash_off_s: o.opt_param(&reg::APP_FLASH_OFF)?.unwrap_or(0.0),
        viscosity,
        surface_tension_gradient_mn_m_per_um: o.opt_param(&reg::APP_SURFACE_TENSION_GRADIENT)?.unwrap_or(0.0),
    };
    // The model's own checks (order of the table, the viscosity not falling, a rise it resolves, a gradient
    // the linear model holds for) name the field relative to the block.
    app.validate().map_err(|e| Error::input(o.file, format!("{}/{}", o.path, e.field), e.to_string()))?;
    Ok((app, applied))
}

/// The `texture` object: a PSD (`psd` with its numbers) or a measured topography (`file`, `levelling`), exactly one.
fn parse_texture(t: &Obj) -> Result<Texture> {
    let psd_key = t.param_key(&reg::APP_TEXTURE_PSD);
    let file_key = t.param_key(&reg::APP_TEXTURE_FILE);
    match (t.get(&psd_key).is_some(), t.get(&file_key).is_some()) {
        (true, true) => {
            return Err(t.err(&file_key, "give either `psd` (an analytic texture) or `file` (a measured one), not both"))
        }
        (false, false) => {
            return Err(t.err(
                &psd_key,
                "missing required field: the texture is a PSD (`psd`: \"k-correlation\" or \"gaussian\", with its \
                 rms_roughness_nm and correlation_length_um) or a measured topography (`file`)",
            ))
        }
        (false, true) => {
            for key in ["rms_roughness_nm", "correlation_length_um", "c"] {
                if t.get(key).is_some() {
                    return Err(
                        t.err(key, "a PSD's number; a measured texture (`file`) takes its heights from the map")
                    );
                }
            }
            let (map, levelled, how) = levelled_map(t, &reg::APP_TEXTURE_FILE, &reg::APP_TEXTURE_LEVELLING)?;
            let psd = map_psd(&levelled.z, map.nx, map.ny, map.dx, map.dy);
            // Flat: the levelled rms height is at the rounding of the heights (the mean taken from a constant).
            let scale = map.z.iter().filter(|z| z.is_finite()).fold(0.0f64, |m, z| m.max(z.abs()));
            if !(psd.weighted_moment(0, 0.0, f64::INFINITY, |_| 1.0).sqrt() > 1e-12 * scale) {
                return Err(
                    t.err(&file_key, format!("{}: the levelled map is flat: a texture with no energy", map.file))
                );
            }
            return Ok(Texture::Measured { psd, source: format!("{}, levelling {}", map.file, how.name()) });
        }
        (true, false) => {
            if t.get(&t.param_key(&reg::APP_TEXTURE_LEVELLING)).is_some() {
                return Err(t.err("levelling", "the levelling of a measured texture (`file`); a PSD has none"));
            }
        }
    }
    let sigma = t.param(&reg::APP_TEXTURE_SIGMA)?;
    let ell = t.param(&reg::APP_TEXTURE_ELL)?;
    let c = t.opt_param(&reg::APP_TEXTURE_C)?;
    Ok(Texture::Analytic(match t.str(&psd_key)? {
        "k-correlation" => Psd::k_correlation(sigma, ell, c.unwrap_or(2.0)),
        "gaussian" => {
            if c.is_some() {
                return Err(t.err(
                    "c",
                    "a K-correlation parameter; a Gaussian texture takes rms_roughness_nm and correlation_length_um",
                ));
            }
            Psd::Gaussian { sigma, ell }
        }
        other => {
            return Err(t.err(&psd_key, format!("unknown PSD {other:?}; allowed: \"k-correlation\", \"gaussian\"")))
        }
    }))
}

/// Level the applied texture (docs/model.md §From the cured spectrum to the coat): the facets' α is the
/// cured spectrum's rms slope, Sdq = (∫∫ (2π|f|)² S_c d²f)^{1/2}.
pub(crate) fn level(app: &Application, applied: Texture) -> LevelledCoat {
    let flow = app.flow();
    let cured = match applied {
        Texture::Analytic(psd) => Cured::Analytic(CuredPsd::new(psd, app.volume_solids, flow)),
        Texture::Measured { psd, source } => Cured::Measured { psd, volume_solids: app.volume_solids, flow, source },
    };
    let alpha = cured.slope_ms().sqrt() * 1e-3;
    let roughness = if alpha >= Microfacet::SMOOTH_THRESHOLD { alpha } else { 0.0 };
    LevelledCoat { application: app.clone(), flow, cured, roughness }
}

impl LevelledCoat {
    /// The cured rms height Sq, nm.
    pub(crate) fn sq_nm(&self) -> f64 {
        self.cured.band_ms(0.0, f64::INFINITY, true).sqrt()
    }

    /// The cured rms slope Sdq (rad) over the whole spectrum.
    pub(crate) fn sdq(&self) -> f64 {
        self.cured.slope_ms().sqrt() * 1e-3
    }

    /// The rms height (nm) of the applied and the cured texture in each of [`BANDS_MM`].
    pub(crate) fn bands(&self) -> Vec<(&'static str, f64, f64)> {
        BANDS_MM
            .iter()
            .map(|&(name, lo_mm, hi_mm)| {
                // Surface wavelengths Λ in [lo, hi] mm are frequencies f in [1/hi, 1/lo] per µm·10⁻³.
                let f_lo = 1e-3 / hi_mm;
                let f_hi = if lo_mm > 0.0 { 1e-3 / lo_mm } else { f64::INFINITY };
                let applied = self.cured.band_ms(f_lo, f_hi, false);
                (name, applied.sqrt(), self.cured.band_ms(f_lo, f_hi, true).sqrt())
            })
            .collect()
    }

    /// The line `--explain` prints after the model: the levelling, the cured Sq and Sdq and the
    /// levelled spectrum band by band.
    pub(crate) fn note(&self) -> String {
        let e = crate::error::number;
        let fe = levelled_frequency(self.flow.l_um4);
        let gradient = if self.flow.m_um2 != 0.0 {
            format!(
                ", surface-tension gradient γ' = {} mN/m per µm: M = {} µm², largest growth ×{}",
                e(self.application.surface_tension_gradient_mn_m_per_um),
                e(sig(self.flow.m_um2)),
                e(sig(self.application.largest_growth()))
            )
        } else {
            String::new()
        };
        let bands: Vec<String> =
            self.bands().iter().map(|(n, a, c)| format!("{n} {} → {} nm", e(sig(*a)), e(sig(*c)))).collect();
        let texture = match &self.cured {
            Cured::Measured { source, psd, .. } => format!(
                "; the applied texture measured ({source}; surface wavelengths {}–{} mm, the map's band)",
                e(sig(1e3 / (0.5 * (psd.nx as f64 * psd.dfx).min(psd.ny as f64 * psd.dfy)))),
                e(sig(1e3 / psd.dfx.min(psd.dfy)))
            ),
            Cured::Analytic(_) => String::new(),
        };
        format!(
            "coat levelled from its application (docs/model.md §From the cured spectrum to the coat){texture}: wet film {} µm, \
             dry {} µm, L = {} µm⁴, amplitude 1/e at Λ = {} µm{}; cured Sq = {} nm, Sdq = {} rad: the coat's facets, \
             Beckmann α = {}; band rms applied → cured: {}",
            e(self.application.wet_film_um),
            e(sig(self.application.dry_film_um())),
            e(sig(self.flow.l_um4)),
            e(sig(1.0 / fe)),
            gradient,
            e(sig(self.sq_nm())),
            e(sig(self.sdq())),
            e(sig(self.roughness)),
            bands.join(", ")
        )
    }
}

/// Four significant digits, for the note.
fn sig(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let p = 10f64.powi(3 - x.abs().log10().floor() as i32);
    (x * p).round() / p
}

/// A paint whose coat is given by its application (`app`, the block at `/clear_coat/application` of the
/// coat object `coat`): `spec` as read, its coat's roughness the levelled texture's Sdq. An explicit `roughness`, `scatter` or a `distribution` other than Beckmann
/// beside it is refused.
pub(crate) fn parse_levelled_paint(root: &Obj, coat: &Obj, app: &Obj, mut spec: PaintSpec) -> Result<Arc<dyn Brdf>> {
    for key in ["roughness", "scatter"] {
        if coat.get(key).is_some() {
            return Err(coat.err(
                "application",
                format!(
                    "give either `application` (the coat's texture from how it was applied and dried) or `{key}`, \
                     not both: the application determines the coat's roughness"
                ),
            ));
        }
    }
    if let Some(d) = coat.get("distribution") {
        if d.as_str() != Some("beckmann") {
            return Err(coat.err(
                "distribution",
                format!(
                    "with `application` the facets are Beckmann (a levelled texture, a sum of many independent \
                     modes, has Gaussian slopes); allowed: \"beckmann\" or absent, got {}",
                    match d {
                        Value::String(s) => format!("{s:?}"),
                        v => kind(v).to_string(),
                    }
                ),
            ));
        }
    }
    let (application, applied) = parse_application(app)?;
    if !application.levelling_integral_um4().is_finite() {
        return Err(Error::input(
            app.file,
            app.field(&app.param_key(&reg::APP_VISCOSITY)),
            "the levelling integral L = γ∫h³/η dt overflows double precision: the viscosities are too small for \
             this film and time (allowed: a table whose L is finite, e.g. viscosities of mPa·s and above)",
        ));
    }
    let lc = level(&application, applied);
    if !(lc.roughness <= 1.0) {
        let sdq = if lc.roughness.is_finite() {
            crate::error::number(lc.roughness)
        } else {
            "beyond double precision".to_string()
        };
        return Err(coat.err(
            "application",
            format!(
                "the cured texture's rms slope Sdq is {sdq} (the coat's Beckmann α), beyond the coat's facet model \
                 (allowed: at most 1); a smoother texture or more levelling is needed"
            ),
        ));
    }
    spec.coat.roughness = lc.roughness;
    spec.coat.distribution = Distribution::Beckmann;
    let paint: Arc<dyn Brdf> =
        Arc::new(Paint::new(spec).map_err(|e| Error::input(root.file, root.path.clone(), e.to_string()))?);
    Ok(Arc::new(Annotated { inner: paint, note: lc.note() }))
}

/// `notes` is free text: a string or an array of strings.
fn notes(o: &Obj) -> Result<()> {
    match o.get("notes") {
        None | Some(Value::String(_)) => Ok(()),
        Some(Value::Array(a)) if a.iter().all(Value::is_string) => Ok(()),
        Some(v) => Err(o.err("notes", format!("expected a string or an array of strings, got {}", kind(v)))),
    }
}
