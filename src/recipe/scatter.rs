//! The `scatter` object of a recipe → a [`Halo`] (docs/recipe-format.md §Near-specular scatter; the
//! physics: docs/optics.md §Near-specular scatter). One object form at three places (the registry's
//! [`crate::registry::PAINT_SCATTER`], [`crate::registry::CT_SCATTER`], [`crate::registry::MICROFACET_SCATTER`]):
//!
//! * `"psd": "k-correlation"` with `rms_roughness_nm` + `correlation_length_um` (+ `c`, default 2), or with
//!   `a_nm2_um` + `b_um` (+ `c`);
//! * `"psd": "gaussian"` with `rms_roughness_nm` + `correlation_length_um`.
//!
//! Beyond the registry's ranges, the rms roughness (given or implied by A, B, C) must satisfy the
//! smooth-surface bound at the shortest sampled wavelength; the error names the field that sets it.
use crate::brdf::halo::Halo;
use crate::input::json::Obj;
use crate::optics::scatter::{Psd, MAX_PHASE};
use crate::registry::ScatterParams;
use crate::spectrum::Sampling;
use crate::Result;
use num_complex::Complex64;

/// Read the scatter object `o` of a `model` recipe (entries `params`) into the halo of an interface of
/// index `index` (one per sample of `sampling`).
pub(crate) fn parse_scatter(
    o: &Obj,
    params: &ScatterParams,
    model: &str,
    index: &[Complex64],
    sampling: &Sampling,
) -> Result<Halo> {
    o.deny_unknown_in(model)?;
    match o.get("notes") {
        None | Some(serde_json::Value::String(_)) => {}
        Some(serde_json::Value::Array(a)) if a.iter().all(serde_json::Value::is_string) => {}
        Some(_) => return Err(o.err("notes", "expected a string or an array of strings")),
    }
    let psd_key = o.param_key(&params.psd);
    let kind = o.str(&psd_key)?;
    let sigma = o.opt_param(&params.sigma)?;
    let ell = o.opt_param(&params.ell)?;
    let c = o.opt_param(&params.c)?;
    let a = o.opt_param(&params.a)?;
    let b = o.opt_param(&params.b)?;
    let both = |x: &str, y: &str| o.err(x, format!("give either {x} or {y}, not both"));
    let missing = |x: &str, y: &str| o.err(x, format!("missing; {x} is required with {y}"));
    let (psd, sigma_field) = match kind {
        "k-correlation" => {
            let c = c.unwrap_or(2.0);
            match (sigma, ell, a, b) {
                (Some(_), _, Some(_), _) => return Err(both("a_nm2_um", "rms_roughness_nm")),
                (_, Some(_), _, Some(_)) => return Err(both("b_um", "correlation_length_um")),
                (Some(s), Some(l), None, None) => (Psd::k_correlation(s, l, c), "rms_roughness_nm"),
                (None, None, Some(a), Some(b)) => (Psd::KCorrelation { a, b, c }, "a_nm2_um"),
                (Some(_), None, ..) => return Err(missing("correlation_length_um", "rms_roughness_nm")),
                (None, Some(_), ..) => return Err(missing("rms_roughness_nm", "correlation_length_um")),
                (None, None, Some(_), None) => return Err(missing("b_um", "a_nm2_um")),
                (None, None, None, Some(_)) => return Err(missing("a_nm2_um", "b_um")),
                (None, None, None, None) => {
                    return Err(o.err(
                        "rms_roughness_nm",
                        "missing; give rms_roughness_nm with correlation_length_um, or a_nm2_um with b_um",
                    ))
                }
            }
        }
        "gaussian" => {
            for (v, key) in [(c.is_some(), "c"), (a.is_some(), "a_nm2_um"), (b.is_some(), "b_um")] {
                if v {
                    return Err(o.err(
                        key,
                        "a K-correlation parameter; a Gaussian PSD takes rms_roughness_nm and correlation_length_um",
                    ));
                }
            }
            match (sigma, ell) {
                (Some(s), Some(l)) => (Psd::Gaussian { sigma: s, ell: l }, "rms_roughness_nm"),
                (None, _) => return Err(missing("rms_roughness_nm", "a Gaussian PSD")),
                (_, None) => return Err(missing("correlation_length_um", "a Gaussian PSD")),
            }
        }
        other => {
            return Err(o.err(&psd_key, format!("unknown PSD {other:?}; allowed: \"k-correlation\", \"gaussian\"")))
        }
    };
    let sigma_max = Halo::sigma_max(sampling);
    let s = psd.sigma();
    if !(s.is_finite() && s <= sigma_max) {
        let lambda_min = sampling.wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min);
        let what = if sigma_field == "a_nm2_um" {
            let Psd::KCorrelation { b, c, .. } = psd else { unreachable!() };
            let a_max = match Psd::k_correlation(sigma_max, b / (2.0 * std::f64::consts::PI), c) {
                Psd::KCorrelation { a, .. } => a,
                Psd::Gaussian { .. } => f64::NAN,
            };
            // σ overflows for an A near the largest double: say so rather than print a non-finite number.
            let sigma = if s.is_finite() {
                format!("σ = {} nm", crate::error::number(s))
            } else {
                "a σ beyond double precision".to_string()
            };
            format!(
                "A = {} nm²·µm gives {sigma}; allowed with this B and C: A ≤ {} nm²·µm",
                crate::error::number(psd_a(&psd)),
                crate::error::number(a_max)
            )
        } else {
            format!("σ = {} nm; allowed: σ ≤ {} nm", crate::error::number(s), crate::error::number(sigma_max))
        };
        return Err(o.err(
            sigma_field,
            format!(
                "{what}: the smooth-surface (Rayleigh–Rice) theory needs 4πσ/λ ≤ {MAX_PHASE} at the shortest \
                 sampled wavelength, {lambda_min} nm (docs/optics.md §8, Validity)"
            ),
        ));
    }
    Halo::new(psd, index, sampling).map_err(|e| o.err(sigma_field, e.to_string()))
}

fn psd_a(p: &Psd) -> f64 {
    match *p {
        Psd::KCorrelation { a, .. } => a,
        Psd::Gaussian { .. } => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use crate::recipe::parse_str;

    fn err(text: &str) -> (String, String) {
        match parse_str(text, "r.json") {
            Err(crate::Error::Input { field, message, .. }) => (field, message.to_string()),
            other => panic!("expected an input error, got {other:?}"),
        }
    }

    const BASE: &str =
        r#"{"model": "microfacet", "distribution": "ggx", "roughness": 0, "ior": 1.5, "scatter": SCATTER}"#;

    fn with(s: &str) -> String {
        BASE.replace("SCATTER", s)
    }

    #[test]
    fn bad_scatter_names_its_field() {
        let cases = [
            (
                r#"{"psd": "k-correlation", "rms_roughness_nm": 0, "correlation_length_um": 5}"#,
                "/scatter/rms_roughness_nm",
            ),
            (
                r#"{"psd": "k-correlation", "rms_roughness_nm": -2, "correlation_length_um": 5}"#,
                "/scatter/rms_roughness_nm",
            ),
            (
                r#"{"psd": "k-correlation", "rms_roughness_nm": 50, "correlation_length_um": 5}"#,
                "/scatter/rms_roughness_nm",
            ),
            (
                r#"{"psd": "k-correlation", "rms_roughness_nm": 2, "correlation_length_um": 0}"#,
                "/scatter/correlation_length_um",
            ),
            (
                r#"{"psd": "k-correlation", "rms_roughness_nm": 2, "correlation_length_um": 1e5}"#,
                "/scatter/correlation_length_um",
            ),
            (r#"{"psd": "k-correlation", "rms_roughness_nm": 2, "correlation_length_um": 5, "c": 1}"#, "/scatter/c"),
            (r#"{"psd": "k-correlation", "rms_roughness_nm": 2, "correlation_length_um": 5, "c": 0.5}"#, "/scatter/c"),
            (r#"{"psd": "k-correlation", "a_nm2_um": -1, "b_um": 30}"#, "/scatter/a_nm2_um"),
            (r#"{"psd": "k-correlation", "a_nm2_um": 1e9, "b_um": 30}"#, "/scatter/a_nm2_um"),
            (r#"{"psd": "k-correlation", "a_nm2_um": 10, "b_um": 0}"#, "/scatter/b_um"),
            (r#"{"psd": "k-correlation", "a_nm2_um": 10}"#, "/scatter/b_um"),
            (r#"{"psd": "k-correlation", "rms_roughness_nm": 2}"#, "/scatter/correlation_length_um"),
            (
                r#"{"psd": "k-correlation", "rms_roughness_nm": 2, "correlation_length_um": 5, "a_nm2_um": 3}"#,
                "/scatter/a_nm2_um",
            ),
            (r#"{"psd": "gaussian", "rms_roughness_nm": 2, "correlation_length_um": 5, "c": 3}"#, "/scatter/c"),
            (r#"{"psd": "lorentz", "rms_roughness_nm": 2, "correlation_length_um": 5}"#, "/scatter/psd"),
            (r#"{"rms_roughness_nm": 2, "correlation_length_um": 5}"#, "/scatter/psd"),
            (r#"{"psd": "gaussian", "rms_roughness_nm": 2, "correlation_length_um": 5, "sigma": 3}"#, "/scatter/sigma"),
        ];
        for (s, field) in cases {
            let (f, m) = err(&with(s));
            assert_eq!(f, field, "{s}: {m}");
        }
        let (_, m) = err(&with(r#"{"psd": "k-correlation", "rms_roughness_nm": 50, "correlation_length_um": 5}"#));
        assert!(m.contains("allowed: σ ≤ 22.28") && m.contains("4πσ/λ ≤ 0.5"), "{m}");
        let (_, m) = err(&with(r#"{"psd": "k-correlation", "a_nm2_um": 1e9, "b_um": 30}"#));
        assert!(m.contains("allowed with this B and C: A ≤"), "{m}");
        // An A whose σ overflows names the overflow, never a printed "inf" (the 10⁶-case fuzz, case 58125).
        let (f, m) = err(&with(r#"{"psd": "k-correlation", "a_nm2_um": 1e308, "b_um": 30}"#));
        assert_eq!(f, "/scatter/a_nm2_um");
        assert!(m.contains("beyond double precision") && !m.contains("inf"), "{m}");
        let (_, m) =
            err(&with(r#"{"psd": "k-correlation", "rms_roughness_nm": 2, "correlation_length_um": 5, "c": 1}"#));
        assert!(m.contains("(1, 10]"), "{m}");
    }

    #[test]
    fn a_halo_needs_a_mirror() {
        // A rough microfacet interface with a halo is the two-scale surface (brdf/two_scale.rs, docs/optics.md
        // §9): its facets keep 1 − g, the halo is added.
        let t = r#"{"model": "microfacet", "distribution": "ggx", "roughness": 0.1, "ior": 1.5,
                    "scatter": {"psd": "gaussian", "rms_roughness_nm": 2, "correlation_length_um": 5}}"#;
        let m = parse_str(t, "r.json").unwrap();
        assert!(m.brdf.describe().contains("halo") && !m.brdf.has_delta(), "{}", m.brdf.describe());
        let t = r#"{"model": "cook-torrance-lobes", "kd": 0.1, "lobes": [{"ks": 0.1, "r": 0.5, "m": 0.2}],
                    "scatter": {"psd": "gaussian", "rms_roughness_nm": 2, "correlation_length_um": 5}}"#;
        assert_eq!(err(t).0, "/scatter");
    }
}
