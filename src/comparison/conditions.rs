//! The colour conditions a sheet states (docs/instrument.md §Sheets, "Colour conditions"): a colour
//! instrument's export names the illuminant and observer its L*, a*, b* were computed under, and a prediction
//! under others is not comparable with them (CIELAB is relative to the illuminant's white, and the observers'
//! colour-matching functions differ: docs/colour.md). So a sheet with colour rows that states its conditions is
//! compared only with predictions under the same ones; any other request is refused, naming what to ask for.
//!
//! Read from the sheet's metadata (`# key: value` lines and title rows above the header): a key `illuminant`
//! (`D65`, or with the observer, `D65/10°`, `D65 10°`), a key `observer` (`10°`, `2`, `CIE 1964`), or one key
//! naming both (`illuminant/observer`, `ill./obs.`: `D65/10°`); from the headers of the colour columns,
//! bracketed after the quantity as exports write them (`L* (D65/10°)`, `a*[A/2]`, `b*(D50)`); and from columns
//! that state them row by row (`Illuminant`, `Observer`). Every place that states a condition must state the
//! same one.
use super::sheet::{normalise, Layout, Sheet, CONDITION_TEXTS, LAB_COLUMNS};
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

/// The conditions the sheet states, in its metadata, its colour columns' headers and its condition columns. A
/// stated illuminant or observer that glossmeter does not compute under (`F11`, `CIE 2006`) is an error naming
/// the file and the place: no prediction could be compared with it; so is a place that contradicts another.
pub(crate) fn stated(sheet: &Sheet) -> Result<Stated> {
    let mut out = Stated::default();
    from_metadata(sheet, &mut out)?;
    from_headers(sheet, &mut out)?;
    from_columns(sheet, &mut out)?;
    Ok(out)
}

/// The conditions of the metadata lines, into `out`.
fn from_metadata(sheet: &Sheet, out: &mut Stated) -> Result<()> {
    for (key, value) in &sheet.metadata {
        let key = key.replace(' ', "");
        let said = format!("{key}: {value}");
        let (wants_illuminant, wants_observer) = match key.as_str() {
            "illuminant" | "ill." | "ill" | "lightsource" => (true, false),
            "observer" | "obs." | "obs" => (false, true),
            "illuminant/observer" | "ill./obs." | "ill/obs" | "illuminant/obs." | "ill./observer" => (true, true),
            _ => continue,
        };
        state(sheet, out, (wants_illuminant, wants_observer), value, &said)?;
    }
    Ok(())
}

/// The conditions of the columns that state them row by row (`Illuminant`, `Observer`, `Ill./Obs.`), into `out`:
/// every row must state the same (the sheet keeps each column's first two distinct cells).
fn from_columns(sheet: &Sheet, out: &mut Stated) -> Result<()> {
    for (line, j, text) in &sheet.condition_cells {
        if sheet.condition_cells.iter().filter(|(_, c, _)| c == j).count() > CONDITION_TEXTS {
            return Err(Error::input(
                &sheet.file,
                sheet.cell(sheet.header_line, Some(*j), "colour"),
                format!(
                    "the column states the colour conditions in more than {CONDITION_TEXTS} different ways; one \
                     sheet's colour readings are compared under one illuminant and observer"
                ),
            ));
        }
        let wants = match normalise(&sheet.headers[*j]).as_str() {
            "illuminant" | "ill" | "lightsource" => (true, false),
            "observer" | "obs" => (false, true),
            _ => (true, true),
        };
        state(sheet, out, wants, text, &sheet.cell(*line, Some(*j), "colour"))?;
    }
    Ok(())
}

/// Record what `value`, stated at `place`, says: an illuminant (`wants.0`), an observer (`wants.1`), or both.
fn state(sheet: &Sheet, out: &mut Stated, wants: (bool, bool), value: &str, place: &str) -> Result<()> {
    let (wants_illuminant, wants_observer) = wants;
    let tokens = tokens(value);
    let refused = |what: &str, allowed: &str| {
        Error::input(
            &sheet.file,
            place,
            format!(
                "the sheet states its colour under {what} {value:?}, which glossmeter does not compute colour \
                 under (allowed: {allowed}); no prediction could be compared with these colour readings"
            ),
        )
    };
    if wants_illuminant {
        let found = tokens.iter().find_map(|t| Illuminant::parse(t).ok());
        match found {
            Some(i) => put_illuminant(sheet, out, i, place)?,
            None => return Err(refused("the illuminant", ILLUMINANTS)),
        }
    }
    // The observer: `10°`, `10`, `1964`, ... (in a combined value, any token after the illuminant).
    let observer = tokens.iter().find_map(|t| Observer::parse(t).ok());
    match (wants_observer, observer) {
        (_, Some(o)) if wants_observer || wants_illuminant => put_observer(sheet, out, o, place),
        (true, None) => Err(refused("the observer", OBSERVERS)),
        _ => Ok(()),
    }
}

/// What glossmeter computes colour under, for messages.
const ILLUMINANTS: &str = "D65, D50, A, C";
const OBSERVERS: &str = "2 (CIE 1931 2°), 10 (CIE 1964 10°)";

/// The words of a stated condition: split at `/`, `,`, `;` and spaces, brackets and a `CIE` dropped.
fn tokens(value: &str) -> Vec<&str> {
    value
        .split(|c: char| c == '/' || c == ',' || c == ';' || c.is_whitespace())
        .map(|t| t.trim_matches(|c: char| matches!(c, '(' | ')' | '[' | ']')))
        .filter(|t| !t.is_empty() && !t.eq_ignore_ascii_case("cie"))
        .collect()
}

/// Whether a word names an illuminant, one glossmeter computes under or another an export may write: the CIE
/// daylights (D50, D55, D65, D75), A, B, C, E and the fluorescent F1–F12 of CIE 15:2018's tables, and the
/// store lamps of colour-matching cabinets (TL83, TL84, CWF, U30, U35). Only to tell a condition from other
/// bracketed words in a colour column's header (`L* (mean)`).
fn names_an_illuminant(word: &str) -> bool {
    let w = word.to_ascii_uppercase();
    let digits =
        |s: &str, n: std::ops::RangeInclusive<usize>| n.contains(&s.len()) && s.bytes().all(|b| b.is_ascii_digit());
    matches!(w.as_str(), "A" | "B" | "C" | "E" | "TL83" | "TL84" | "CWF" | "U30" | "U35")
        || w.strip_prefix('D').is_some_and(|d| digits(d, 2..=2))
        || w.strip_prefix('F').is_some_and(|d| digits(d, 1..=2))
}

/// The conditions of the colour columns' headers, into `out`: the bracketed part after the quantity
/// (`L* (D65/10°)`) when it names an illuminant; an observer there only beside an illuminant (a bare `(2)` is a
/// repeat number elsewhere in a sheet, `60° (2)`). A column skipped on request states nothing.
fn from_headers(sheet: &Sheet, out: &mut Stated) -> Result<()> {
    if sheet.layout != Layout::Colour {
        return Ok(());
    }
    let lab = |n: &str| LAB_COLUMNS.iter().any(|(names, _)| names.contains(&n));
    for (j, header) in sheet.headers.iter().enumerate() {
        let skipped = sheet.ignored_columns.contains(header);
        let Some(inner) = bracketed(header).filter(|_| lab(&normalise(header)) && !skipped) else { continue };
        let words = tokens(inner);
        if !words.iter().any(|w| names_an_illuminant(w)) {
            continue;
        }
        // An illuminant named (else refused as one glossmeter does not compute), an observer beside it if any.
        state(sheet, out, (true, false), inner, &sheet.cell(sheet.header_line, Some(j), "colour"))?;
    }
    Ok(())
}

/// The text between the first `(` or `[` of a header and its closing bracket.
fn bracketed(header: &str) -> Option<&str> {
    let open = header.find(['(', '['])?;
    let close = if header[open..].starts_with('(') { ')' } else { ']' };
    let rest = &header[open + 1..];
    Some(&rest[..rest.find(close)?])
}

/// Record the illuminant stated at `place`; a sheet stating two different ones is refused, naming both places.
fn put_illuminant(sheet: &Sheet, out: &mut Stated, i: Illuminant, place: &str) -> Result<()> {
    put(sheet, &mut out.illuminant, i, place, |i| format!("illuminant {}", i.id()))
}

/// Record the observer stated at `place`, as [`put_illuminant`].
fn put_observer(sheet: &Sheet, out: &mut Stated, o: Observer, place: &str) -> Result<()> {
    put(sheet, &mut out.observer, o, place, |o| format!("the {} observer", o.describe()))
}

/// Record `value`, stated at `place`, in `slot`: the first place that states it is kept, and a place that
/// states another value is refused, naming both.
fn put<T: Copy + PartialEq>(
    sheet: &Sheet,
    slot: &mut Option<(T, String)>,
    value: T,
    place: &str,
    describe: impl Fn(T) -> String,
) -> Result<()> {
    match slot {
        Some((old, at)) if *old != value => Err(Error::input(
            &sheet.file,
            place,
            format!(
                "the sheet states its colour under {} here but under {} at `{at}`: a sheet's colour readings are \
                 compared under one illuminant and observer, so one sheet must state one pair (split a sheet \
                 measured under several into one per pair)",
                describe(value),
                describe(*old)
            ),
        )),
        Some(_) => Ok(()),
        None => {
            *slot = Some((value, place.to_string()));
            Ok(())
        }
    }
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
        words = words.and(" ").and_setting("illuminant", i.id());
    }
    if let Some((o, _)) = &s.observer {
        words = words.and(" ").and_setting("observer", o.id());
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

    fn with_header(head: &str, ignore: &[&str]) -> Result<Sheet> {
        // One row: a value in every column after the sample and the geometry.
        let columns = head.lines().last().map_or(0, |h| h.split(',').count());
        let values = ["50", "1", "2"].iter().cycle().take(columns.saturating_sub(2)).copied().collect::<Vec<_>>();
        let text = format!("{head}\np,astm-e2194-45,{}\n", values.join(","));
        let o = SheetOptions { ignore_columns: ignore.iter().map(|s| s.to_string()).collect(), ..Default::default() };
        parse(&text, "h.csv", &o)
    }

    #[test]
    fn the_colour_columns_headers_state_them_too() {
        use Illuminant::*;
        use Observer::*;
        for (head, i, o) in [
            ("sample,geometry,L* (D65/10°),a* (D65/10°),b* (D65/10°)", Some(D65), Some(Cie1964)),
            ("sample,geometry,L*[A/2],a*,b*", Some(A), Some(Cie1931)),
            ("sample,geometry,L*(D50),a*(D50),b*(D50)", Some(D50), None),
            ("sample,geometry,L* (C 2°),a*,b*", Some(C), Some(Cie1931)),
            // Bracketed words that are no condition, and a bare number (a repeat elsewhere), state nothing.
            ("sample,geometry,L* (mean),a* [CIELAB],b* (2)", None, None),
        ] {
            let s = stated(&with_header(head, &[]).unwrap()).unwrap();
            assert_eq!((s.illuminant.map(|x| x.0), s.observer.map(|x| x.0)), (i, o), "{head}");
        }
        // The place is the header's cell; a refusal names it.
        let sh = with_header("sample,geometry,L* (A/2°),a* (A/2°),b* (A/2°)", &[]).unwrap();
        let text = check(&sh, Conditions::default()).unwrap_err().naming(&|a| format!("--{a}"));
        assert!(text.contains("line 1, column 3 (L* (A/2°))"), "{text}");
        assert!(text.contains("give --illuminant A --observer 2 (the sheet's)"), "{text}");
        assert!(check(&sh, conditions(Illuminant::A, Observer::Cie1931)).is_ok());
    }

    #[test]
    fn places_that_disagree_and_illuminants_not_computed_are_refused() {
        // The metadata against a header, and two headers.
        let both = with_header("# illuminant: D65/10°\nsample,geometry,L* (A/10°),a*,b*", &[]).unwrap();
        let e = stated(&both).unwrap_err().naming(&|a| format!("--{a}"));
        assert!(e.contains("illuminant A here but under illuminant D65 at `illuminant: D65/10°`"), "{e}");
        assert!(e.contains("split a sheet"), "{e}");
        let e = stated(&with_header("sample,geometry,L* (D65/10°),a* (D65/2°),b*", &[]).unwrap()).unwrap_err();
        assert!(e.to_string().contains("CIE 1931 2° observer here"), "{e}");
        let e = stated(&with_header("sample,geometry,L* (F11/10°),a*,b*", &[]).unwrap()).unwrap_err().to_string();
        assert!(e.contains("h.csv") && e.contains("L* (F11/10°)") && e.contains("allowed: D65, D50, A, C"), "{e}");
        // An export under two illuminants: refused as duplicate columns, read once the others are skipped.
        let two = "sample,geometry,L* (D65/10°),a* (D65/10°),b* (D65/10°),L* (A/10°),a* (A/10°),b* (A/10°)";
        let e = with_header(two, &[]).unwrap_err().naming(&|a| format!("--{a}"));
        assert!(e.contains("one illuminant and observer at a time") && e.contains("--ignore_columns"), "{e}");
        let one = with_header(two, &["L* (A/10°)", "a* (A/10°)", "b* (A/10°)"]).unwrap();
        let s = stated(&one).unwrap();
        assert_eq!(
            (s.illuminant.map(|x| x.0), s.observer.map(|x| x.0)),
            (Some(Illuminant::D65), Some(Observer::Cie1964))
        );
    }

    #[test]
    fn columns_state_them_row_by_row() {
        use Illuminant::*;
        use Observer::*;
        let o = SheetOptions::default();
        let read = |text: &str| parse(text, "r.csv", &o).map(|s| stated(&s));
        let head = "sample,geometry,Illuminant,Observer,L*,a*,b*\n";
        let s = read(&format!("{head}p,astm-e2194-15,D65,10°,50,1,2\np,astm-e2194-45,D65,10°,40,1,2\n")).unwrap();
        let s = s.unwrap();
        assert_eq!((s.illuminant.map(|x| x.0), s.observer.map(|x| x.0)), (Some(D65), Some(Cie1964)));
        let s = read("sample,geometry,Ill./Obs.,L*,a*,b*\np,astm-e2194-15,A/2°,50,1,2\n").unwrap().unwrap();
        assert_eq!((s.illuminant.map(|x| x.0), s.observer.map(|x| x.0)), (Some(A), Some(Cie1931)));
        // The long layout too.
        let s = read("sample,geometry,quantity,value,light source\np,d8-sce,L*,50,C\n").unwrap().unwrap();
        assert_eq!((s.illuminant.map(|x| x.0), s.observer.map(|x| x.0)), (Some(C), None));
        // Texts of one illuminant in several spellings, then another: the third text is still read.
        let spelt = format!(
            "{head}p,astm-e2194-15,D65,10,50,1,2\np,astm-e2194-25,d65,10,50,1,2\np,astm-e2194-45,A,10,50,1,2\n"
        );
        let e = read(&spelt).unwrap().unwrap_err().to_string();
        assert!(e.contains("line 4, column 3 (Illuminant)") && e.contains("illuminant A here"), "{e}");
        // Rows under two illuminants: refused at the second, naming the first.
        let two = format!("{head}p,astm-e2194-15,D65,10°,50,1,2\np,astm-e2194-15,A,10°,40,1,2\n");
        let e = read(&two).unwrap().unwrap_err().to_string();
        assert!(e.contains("line 3, column 3 (Illuminant)") && e.contains("line 2, column 3 (Illuminant)"), "{e}");
        assert!(e.contains("split a sheet"), "{e}");
        let e = read(&format!("{head}p,astm-e2194-15,F11,10°,50,1,2\n")).unwrap().unwrap_err().to_string();
        assert!(e.contains("F11") && e.contains("allowed: D65, D50, A, C"), "{e}");
        // A column that states them in more than CONDITION_TEXTS ways is refused, not read in part.
        let many: String = (0..=CONDITION_TEXTS).map(|k| format!("p,astm-e2194-15,D65 r{k},10,50,1,2\n")).collect();
        let e = read(&format!("{head}{many}")).unwrap().unwrap_err().to_string();
        assert!(e.contains("line 1, column 3 (Illuminant)") && e.contains("more than 32 different ways"), "{e}");
        // A gloss sheet may carry the column; nothing is checked without colour rows.
        let gloss = parse("sample,60°,Illuminant\np,90,F11\n", "g.csv", &o).unwrap();
        assert!(check(&gloss, Conditions::default()).is_ok());
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
