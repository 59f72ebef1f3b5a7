//! The makers' statistics columns of a sheet (`Mean 20°`, `Std 20°`, `Min 60°`, `Max 60°`, `Range 85°`, as a
//! BYK smart-chart export or an Excel summary writes them): recognised by their header, and each value
//! checked against the series of repeated readings it summarises instead of being refused as an unknown
//! column (docs/instrument.md §Statistics columns). A statistic that disagrees with the readings is bad input:
//! the sheet was edited after export, or rows of the series are missing. This file imports nothing of the crate
//! but `error`.

/// A statistic of a series of readings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Statistic {
    Mean,
    Std,
    Min,
    Max,
    Range,
}

impl Statistic {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Statistic::Mean => "mean",
            Statistic::Std => "standard deviation",
            Statistic::Min => "minimum",
            Statistic::Max => "maximum",
            Statistic::Range => "range (max − min)",
        }
    }
}

/// The words of statistics headers (normalised as the sheet reader normalises headers: lower case, letters and
/// digits only), longest first so that `stddev` is not read as `std` + `dev`. `x̄` normalises to `x`, which is
/// not taken (it is also an axis); `s` and `r` alone are too short to be sure of.
pub(crate) const STATISTIC_WORDS: &[(&str, Statistic)] = &[
    ("standarddeviation", Statistic::Std),
    ("average", Statistic::Mean),
    ("minimum", Statistic::Min),
    ("maximum", Statistic::Max),
    ("stddev", Statistic::Std),
    ("stdabw", Statistic::Std),
    ("mittel", Statistic::Mean),
    ("range", Statistic::Range),
    ("stdev", Statistic::Std),
    ("sdev", Statistic::Std),
    ("mean", Statistic::Mean),
    ("avg", Statistic::Mean),
    ("std", Statistic::Std),
    ("min", Statistic::Min),
    ("max", Statistic::Max),
    ("sd", Statistic::Std),
];

/// A statistics header split into the statistic and the rest (the reading it is of, possibly empty): the word
/// as a prefix (`mean20` → Mean, `20`) or a suffix (`20mean`, `hazestddev`).
pub(crate) fn split(normalised: &str) -> Option<(Statistic, &str)> {
    for (w, s) in STATISTIC_WORDS {
        if let Some(rest) = normalised.strip_prefix(w) {
            return Some((*s, rest));
        }
    }
    for (w, s) in STATISTIC_WORDS {
        if let Some(rest) = normalised.strip_suffix(w) {
            return Some((*s, rest));
        }
    }
    None
}

/// What the readings of a series say.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Series {
    pub n: usize,
    pub mean: f64,
    /// Denominator n − 1 (NaN for n = 1).
    pub sample_std: f64,
    /// Denominator n.
    pub population_std: f64,
    pub min: f64,
    pub max: f64,
}

impl Series {
    pub(crate) fn of(values: &[f64]) -> Series {
        let n = values.len();
        let mean = values.iter().sum::<f64>() / n as f64;
        let ss: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
        Series {
            n,
            mean,
            sample_std: if n > 1 { (ss / (n - 1) as f64).sqrt() } else { f64::NAN },
            population_std: (ss / n as f64).sqrt(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// The decimals a number was written with (`89.13` → 2, `1.5e-3` → 4, `90` → 0).
pub(crate) fn written_decimals(text: &str) -> i32 {
    let t = text.trim().replace(',', ".");
    let (mantissa, exponent) = match t.find(['e', 'E']) {
        Some(i) => (&t[..i], t[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (t.as_str(), 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len() as i32);
    decimals - exponent
}

/// Check a stated statistic (`value`, as written in `text`) against the series: within half a unit of its last
/// written decimal (an export rounds to its display), plus 10⁻⁹ of its size for the binary arithmetic. A
/// standard deviation may be the sample's (n − 1) or the population's (n): makers and spreadsheets use both
/// (Excel STDEV and STDEV.P). Err says what the readings give.
pub(crate) fn check(stat: Statistic, value: f64, text: &str, s: &Series) -> std::result::Result<(), String> {
    let allowed = |x: f64| 0.5 * 10f64.powi(-written_decimals(text)) + 1e-9 * x.abs().max(value.abs());
    let near = |x: f64| x.is_finite() && (value - x).abs() <= allowed(x);
    // Ten significant digits: the readings' sum in binary is not news (89.12, not 89.12000000000002).
    let g = |x: f64| format!("{}", format!("{x:.9e}").parse::<f64>().unwrap_or(x));
    let (ok, computed) = match stat {
        Statistic::Mean => (near(s.mean), g(s.mean)),
        Statistic::Min => (near(s.min), g(s.min)),
        Statistic::Max => (near(s.max), g(s.max)),
        Statistic::Range => (near(s.max - s.min), g(s.max - s.min)),
        Statistic::Std if s.n == 1 => (value == 0.0, "none for one reading (only 0 is accepted)".into()),
        Statistic::Std => (
            near(s.sample_std) || near(s.population_std),
            format!("{} (n − 1) or {} (n)", g(s.sample_std), g(s.population_std)),
        ),
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "the {} stated, {text}, is not that of the {} reading(s) of the series: they give {computed} (allowed: \
             within {} of it, half a unit of the stated value's last decimal)",
            stat.name(),
            s.n,
            0.5 * 10f64.powi(-written_decimals(text)),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_and_checks() {
        assert_eq!(split("mean20"), Some((Statistic::Mean, "20")));
        assert_eq!(split("20stddev"), Some((Statistic::Std, "20")));
        assert_eq!(split("stddev"), Some((Statistic::Std, "")));
        assert_eq!(split("rangehaze"), Some((Statistic::Range, "haze")));
        assert_eq!(split("gloss60"), None);
        assert_eq!((written_decimals("89.13"), written_decimals("1.5e-3"), written_decimals("90")), (2, 4, 0));
        let s = Series::of(&[89.1, 89.3, 89.2]);
        assert!(check(Statistic::Mean, 89.2, "89.2", &s).is_ok());
        assert!(check(Statistic::Mean, 89.3, "89.3", &s).is_err());
        assert!(check(Statistic::Std, 0.1, "0.10", &s).is_ok());
        assert!(check(Statistic::Std, 0.082, "0.082", &s).is_ok(), "population std");
        assert!(check(Statistic::Std, 0.2, "0.20", &s).is_err());
        assert!(check(Statistic::Range, 0.2, "0.2", &s).is_ok());
        assert!(check(Statistic::Min, 89.1, "89.1", &s).is_ok() && check(Statistic::Max, 89.1, "89.1", &s).is_err());
        let e = check(Statistic::Mean, 90.0, "90.0", &s).unwrap_err();
        assert!(e.contains("89.2") && e.contains("3 reading(s)"), "{e}");
    }
}
