//! Length units as topography files and users write them: the SI metre with a prefix (`m`, `mm`, `um`/`µm`,
//! `nm`, `pm`), and a length as a number with its unit (`0.5um`, `2e-6 m`). Every reader converts to metres
//! here, so a unit is spelt the same way in every format.
/// The units known, with their value in metres (`µ` as U+00B5 MICRO SIGN or U+03BC GREEK SMALL LETTER MU).
pub(crate) const UNITS: &[(&str, f64)] =
    &[("m", 1.0), ("mm", 1e-3), ("um", 1e-6), ("µm", 1e-6), ("μm", 1e-6), ("nm", 1e-9), ("pm", 1e-12)];

/// The units' spellings, for messages.
pub fn allowed() -> String {
    "m, mm, um (µm), nm, pm".to_string()
}

/// The value in metres of a length unit (`None` if it is not one).
pub fn metres_per(unit: &str) -> Option<f64> {
    let u = unit.trim();
    UNITS.iter().find(|(name, _)| *name == u).map(|(_, f)| *f)
}

/// A length written as a number and a unit (`0.5um`, `0.5 µm`, `2e-6m`), in metres: `None` if it is not one
/// (no unit, an unknown unit, a number that is not finite).
pub(crate) fn parse_length(text: &str) -> Option<f64> {
    let t = text.trim();
    // The unit is the trailing run of letters (`2e-6m`: the `e` is the number's).
    let split = t.rfind(|c: char| !(c.is_alphabetic() || c == 'µ' || c == 'μ')).map(|i| i + 1).unwrap_or(0);
    let (value, unit) = t.split_at(split);
    if unit.is_empty() {
        return None;
    }
    let value: f64 = value.trim().parse().ok()?;
    let metres = value * metres_per(unit)?;
    metres.is_finite().then_some(metres)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_and_lengths() {
        assert_eq!(metres_per("µm"), Some(1e-6));
        assert_eq!(metres_per("μm"), Some(1e-6));
        assert_eq!(metres_per(" nm "), Some(1e-9));
        assert_eq!(metres_per("inch"), None);
        assert_eq!(parse_length("0.5um"), Some(0.5e-6));
        assert_eq!(parse_length("2e-6 m"), Some(2e-6));
        assert_eq!(parse_length("1.5 µm"), Some(1.5e-6));
        assert_eq!(parse_length("3"), None);
        assert_eq!(parse_length("3 furlongs"), None);
        assert_eq!(parse_length("1e400 m"), None);
    }
}
