//! The colour conditions a sheet states (docs/instrument.md §Sheets, "Colour conditions"): a colour
//! instrument's export names the illuminant and observer its L*, a*, b* were computed under, and a prediction
//! under others is not comparable with them (CIELAB is relative to the illuminant's white, and the observers'
//! colour-matching functions differ: docs/colour.md). So a sheet with colour rows that states its conditions is
//! compared only with predictions under the same ones; any other request is refused, naming what to ask for.
//!
//! Read from the sheet's metadata (`# key: value` lines and title rows above the header): a key `illuminant`
//! (`D65`, or with the observer, `D65/10°`, `D65 10°`), a key `observer` (`10°`, `2`, `CIE 1964`), or one key
//! naming both (`illuminant/observer`, `ill./obs.`: `D65/10°`).
use super::sheet::Sheet;
use crate::colorimetry::{Conditions, Illuminant, Observer};
use crate::error::Words;
use crate::instrument::reading::ColourQuantity;
use crate::{Error, Result};

/// What a sheet states: each condition with the metadata line it came from (`illuminant: D65/10°`).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Stated {
    pub(crate) illuminant: Option<(Illuminant, String)>,
    pub(crate) observer: Option<(Observer, String)>,
}

/// The conditions the sheet's metadata states. A stated illuminant or observer that glossmeter does not compute
/// under (`F11`, `CIE 2006`) is an error naming the file and the line: no prediction could be compared with it.
pub(crate) fn stated(sheet: &Sheet) -> Result<Stated> {
    let mut out = Stated::default();
    for (key, value) in &sheet.metadata {
        let key = key.replace(' ', "");
        let said = format!("{key}: {value}");
        let (wants_illuminant, wants_observer) = match key.as_str() {
            "illuminant" | "ill." | "ill" | "lightsource" => (true, false),
            "observer" | "obs." | "obs" => (false, true),
            "illuminant/observer" | "ill./obs." | "ill/obs" | "illuminant/obs." | "ill./observer" => (true, true),
            _ => continue,
        };
        let tokens: Vec<&str> = value
            .split(|c: char| c == '/' || c == ',' || c == ';' || c.is_whitespace())
            .map(|t| t.trim_matches(|c: char| c == '(' || c == ')'))
            .filter(|t| !t.is_empty() && !t.eq_ignore_ascii_case("cie"))
            .collect();
        let refused = |what: &str, allowed: &str| {
            Error::input(
                &sheet.file,
                said.clone(),
                format!(
                    "the sheet states its colour under {what} {value:?}, which glossmeter does not compute colour \
                     under (allowed: {allowed}); no prediction could be compared with these colour readings"
                ),
            )
        };
        if wants_illuminant {
            let found = tokens.iter().find_map(|t| Illuminant::parse(t).ok());
            match found {
                Some(i) => out.illuminant = Some((i, said.clone())),
                None => return Err(refused("the illuminant", "D65, D50, A, C")),
            }
        }
        // The observer: `10°`, `10`, `1964`, ... (in a combined value, any token after the illuminant).
        let observer = tokens.iter().find_map(|t| Observer::parse(t).ok());
        match (wants_observer, observer) {
            (_, Some(o)) if wants_observer || wants_illuminant => out.observer = Some((o, said.clone())),
            (true, None) => return Err(refused("the observer", "2 (CIE 1931 2°), 10 (CIE 1964 10°)")),
            _ => {}
        }
    }
    Ok(out)
}

/// Whether a reading name is a colour reading's (X, Y, Z, L*, a*, b*, C*, h).
pub(crate) fn is_colour_reading(name: &str) -> bool {
    ColourQuantity::ALL.iter().any(|q| q.name() == name)
}

/// Whether the sheet has a colour reading in any row.
fn has_colour_rows(sheet: &Sheet) -> bool {
    sheet.rows.iter().any(|r| is_colour_reading(&r.reading))
}

/// Check that a sheet's colour rows are compared under the conditions the sheet states: `Ok` when it has no
/// colour rows, states nothing, or states what `colour` is; otherwise an error naming the sheet's line and the
/// arguments that would ask for its conditions.
pub(crate) fn check(sheet: &Sheet, colour: Conditions) -> Result<()> {
    if !has_colour_rows(sheet) {
        return Ok(());
    }
    let s = stated(sheet)?;
    let illuminant_differs = s.illuminant.as_ref().is_some_and(|(i, _)| *i != colour.illuminant);
    let observer_differs = s.observer.as_ref().is_some_and(|(o, _)| *o != colour.observer);
    if !(illuminant_differs || observer_differs) {
        return Ok(());
    }
    // The line that differs names the place; the message names every condition the sheet states.
    let differing =
        if illuminant_differs { s.illuminant.as_ref().map(|x| &x.1) } else { s.observer.as_ref().map(|x| &x.1) };
    let said = differing.cloned().unwrap_or_default();
    let theirs: Vec<String> = [
        s.illuminant.as_ref().map(|(i, _)| format!("illuminant {}", i.id())),
        s.observer.as_ref().map(|(o, _)| format!("the {} observer", o.describe())),
    ]
    .into_iter()
    .flatten()
    .collect();
    let ours = format!("illuminant {} and the {} observer", colour.illuminant.id(), colour.observer.describe());
    let mut words = Words::from(format!(
        "the sheet's colour readings are under {}, but the prediction was asked under {ours}: they are not \
         comparable; give",
        theirs.join(" and ")
    ));
    if let Some((i, _)) = &s.illuminant {
        words = words.and(" ").and_argument("illuminant").and(format!(" {}", i.id()));
    }
    if let Some((o, _)) = &s.observer {
        words = words.and(" ").and_argument("observer").and(format!(" {}", o.id()));
    }
    Err(Error::input(&sheet.file, said, words.and(" (the sheet's)")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::comparison::sheet::{parse, SheetOptions};

    fn sheet(head: &str) -> Sheet {
        let text = format!("{head}sample,geometry,L*,a*,b*\np,astm-e2194-45,50,1,2\n");
        parse(&text, "s.csv", &SheetOptions::default()).unwrap()
    }

    fn conditions(i: Illuminant, o: Observer) -> Conditions {
        Conditions { illuminant: i, observer: o }
    }

    #[test]
    fn the_usual_ways_of_stating_them_are_read() {
        use Illuminant::*;
        use Observer::*;
        for (head, i, o) in [
            ("# illuminant: D65\n", Some(D65), None),
            ("# Illuminant: D65/10°\n", Some(D65), Some(Cie1964)),
            ("# illuminant/observer: A/2°\n", Some(A), Some(Cie1931)),
            ("# Ill./Obs.: D50 / 2\n", Some(D50), Some(Cie1931)),
            ("# observer: CIE 1964 10°\n", None, Some(Cie1964)),
            ("Illuminant: C,Observer: 2°\n", Some(C), Some(Cie1931)),
            ("# instrument: BYK-mac i\n", None, None),
        ] {
            let s = stated(&sheet(head)).unwrap();
            assert_eq!((s.illuminant.map(|x| x.0), s.observer.map(|x| x.0)), (i, o), "{head}");
        }
    }

    #[test]
    fn conditions_glossmeter_cannot_compute_are_refused_by_their_line() {
        for head in ["# illuminant: F11\n", "# observer: 45°\n"] {
            let e = stated(&sheet(head)).unwrap_err().to_string();
            assert!(e.contains("s.csv") && e.contains("allowed") && e.contains("not compute"), "{e}");
        }
    }

    #[test]
    fn a_colour_sheet_is_compared_only_under_its_own_conditions() {
        let s = sheet("# illuminant/observer: A/2°\n");
        assert!(check(&s, conditions(Illuminant::A, Observer::Cie1931)).is_ok());
        let e = check(&s, Conditions::default()).unwrap_err();
        let text = e.naming(&|a| format!("--{a}"));
        assert!(text.contains("illuminant A") && text.contains("--illuminant A --observer 2 (the sheet's)"), "{text}");
        let e = check(&s, conditions(Illuminant::A, Observer::Cie1964)).unwrap_err();
        assert!(e.naming(&|a| format!("--{a}")).contains("--illuminant A --observer 2"), "{e}");
        let e = check(&sheet("# observer: 2\n"), Conditions::default()).unwrap_err();
        let text = e.naming(&|a| format!("--{a}"));
        assert!(text.contains("field `observer: 2`") && text.contains("give --observer 2 (the sheet's)"), "{text}");
        // Nothing stated, or no colour rows: nothing to check.
        assert!(check(&sheet(""), conditions(Illuminant::C, Observer::Cie1931)).is_ok());
        let gloss =
            parse("# illuminant: A\nsample,geometry,value\np,astm-d523-60,90\n", "g.csv", &SheetOptions::default());
        assert!(check(&gloss.unwrap(), Conditions::default()).is_ok());
    }
}
