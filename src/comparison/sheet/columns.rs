//! The sheet reader's first stages (docs/instrument.md §Sheets): what a header names (the alias tables, the
//! header roles) and which layout the roles make (colour, long or wide).
use super::*;

/// A reading column an instrument writes, and the glossmeter reading it stands for. `not_predicted` is set for
/// readings whose formula is not public (they are reported as "not predicted", never dropped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ReadingColumn {
    /// Normalised header names (lower case, only letters and digits; see [`normalise`]).
    pub names: &'static [&'static str],
    /// The geometry id and the reading (a reading name or a quantity of that geometry).
    pub geometry: &'static str,
    pub reading: &'static str,
    pub not_predicted: Option<&'static str>,
    /// Where the mapping comes from (shown in the docs table).
    pub source: &'static str,
}

pub(super) const NOT_PUBLIC: &str = "the maker's formula is not public";

/// Header aliases of the readings other than plain gloss (for gloss see [`gloss_angle`]). To add a reading
/// (e.g. colour columns), add a row; the docs table in docs/instrument.md §Sheets lists the same rows.
pub(crate) const READING_COLUMNS: &[ReadingColumn] = &[
    ReadingColumn {
        names: &["haze", "hu", "haze20", "20haze", "hazehu"],
        geometry: IQ,
        reading: "haze",
        not_predicted: None,
        source: "Rhopoint IQ / Elcometer 408 haze on the 20° pixel array (ASTM E430 windows; `rhopoint-iq-20`, \
                 docs/instrument.md §1.9)",
    },
    ReadingColumn {
        names: &["loghaze", "hulog", "hazelog", "loghu", "loghaze20", "hazeloghu"],
        geometry: IQ,
        reading: "log-haze",
        not_predicted: None,
        source: "Rhopoint IQ HU_LOG / Elcometer 408 HULog on the 20° pixel array (`rhopoint-iq-20`, §1.9)",
    },
    ReadingColumn {
        names: &["hazeiso13803", "iso13803haze", "iso13803"],
        geometry: "iso-13803-20",
        reading: "haze",
        not_predicted: None,
        source: "ISO 13803 20° haze of a gloss-haze meter with fixed haze detectors (BYK haze-gloss class)",
    },
    ReadingColumn {
        names: &["loghazeiso13803", "iso13803loghaze"],
        geometry: "iso-13803-20",
        reading: "log-haze",
        not_predicted: None,
        source: "ISO 13803 log haze of a gloss-haze meter with fixed haze detectors (docs/instrument.md §1.6)",
    },
    ReadingColumn {
        names: &["hazenarrow", "narrowhaze", "hazen"],
        geometry: "astm-e430-30",
        reading: "haze-narrow",
        not_predicted: None,
        source: "ASTM E430 narrow-angle haze at 30°",
    },
    ReadingColumn {
        names: &["hazewide", "widehaze", "hazew"],
        geometry: "astm-e430-30",
        reading: "haze-wide",
        not_predicted: None,
        source: "ASTM E430 wide-angle haze at 30°",
    },
    ReadingColumn {
        names: &["doi", "distinctnessofimage", "doi20"],
        geometry: IQ,
        reading: "doi",
        not_predicted: None,
        source: "Rhopoint IQ / Elcometer 408 DOI on the 20° profile (`rhopoint-iq-20`, docs/instrument.md §1.9)",
    },
    ReadingColumn {
        names: &["doi30", "doie430", "e430doi"],
        geometry: "astm-e430-30",
        reading: "doi",
        not_predicted: None,
        source: "ASTM E430 DOI (Hunter/Dorigon form) at 30°",
    },
    ReadingColumn {
        names: &["hazeindex", "d4039", "hazeindexgu"],
        geometry: "astm-d4039",
        reading: "haze-index",
        not_predicted: None,
        source: "ASTM D4039 haze index G60 − G20",
    },
    ReadingColumn {
        names: &["rspec", "rspec20"],
        geometry: IQ,
        reading: "rspec",
        not_predicted: None,
        source: "Rhopoint IQ peak specular reflectance, ±0.0991° of the 20° array (`rhopoint-iq-20`, §1.9)",
    },
    ReadingColumn {
        names: &["riq", "reflectedimagequality"],
        geometry: IQ,
        reading: "riq",
        not_predicted: Some(NOT_PUBLIC),
        source: "Rhopoint IQ reflected image quality",
    },
    ReadingColumn {
        names: &["doic", "doicomp", "doicompensated", "compensateddoi", "doicomp20"],
        geometry: IQ,
        reading: "doi-compensated",
        not_predicted: Some(NOT_PUBLIC),
        source: "makers' compensated DOI",
    },
];

/// The geometry of a Rhopoint IQ-class meter's 20° pixel-array readings: an IQ sheet's Haze, Log Haze, DOI,
/// Rspec and RIQ columns are readings of it (its 20°, 60° and 85° gloss columns are the ISO 2813 / D523 gloss
/// the maker says they follow, [`GLOSS_ANGLES`]).
pub(crate) const IQ: &str = "rhopoint-iq-20";

/// Columns that say which sample a row is.
pub(crate) const SAMPLE_COLUMNS: &[&str] =
    &["sample", "samplename", "sampleid", "specimen", "name", "id", "panel", "probe", "probenname", "muster"];
/// Columns that state each row's colour conditions (normalised; colour software exports them per measurement:
/// `Illuminant` `D65`, `Observer` `10°`): read by `comparison::conditions`, never compared.
pub(crate) const CONDITION_COLUMNS: &[&str] =
    &["illuminant", "observer", "illuminantobserver", "illobs", "lightsource", "ill", "obs"];
/// The most distinct texts a condition column may hold (`D65`, `D65 `, `d65`, … all one illuminant); a column
/// with more is refused rather than read in part.
pub(crate) const CONDITION_TEXTS: usize = 32;
/// Columns kept by the reader but not compared (bookkeeping that instruments add to each row).
pub(crate) const INFO_COLUMNS: &[&str] = &[
    "date",
    "datum",
    "time",
    "datetime",
    "timestamp",
    "operator",
    "user",
    "comment",
    "comments",
    "note",
    "notes",
    "no",
    "nr",
    "number",
    "index",
    "unit",
    "units",
    "batch",
    "lot",
];
/// The long layout's columns.
pub(crate) const GEOMETRY_COLUMNS: &[&str] = &["geometry", "geometryid"];
pub(crate) const QUANTITY_COLUMNS: &[&str] = &["quantity", "reading", "readingname"];
pub(crate) const VALUE_COLUMNS: &[&str] = &["value", "measured", "measurement"];
pub(crate) const UNCERTAINTY_COLUMNS: &[&str] = &["uncertainty", "u", "unc"];
/// The colour layout's columns (normalised) and the readings they give: L*, a*, b*.
pub(crate) const LAB_COLUMNS: &[(&[&str], &str)] =
    &[(&["l", "lstar", "cielabl"], "L*"), (&["a", "astar", "cielaba"], "a*"), (&["b", "bstar", "cielabb"], "b*")];
/// A colour reading as a long-layout `quantity` (lower-cased) and its reading name.
pub(super) const COLOUR_QUANTITIES: &[(&str, &str)] =
    &[("x", "X"), ("y", "Y"), ("z", "Z"), ("l*", "L*"), ("a*", "a*"), ("b*", "b*"), ("c*", "C*"), ("h", "h")];

/// The gloss angles instruments write, and the shipped geometry read at each.
pub(crate) const GLOSS_ANGLES: &[(&str, &str)] = &[
    ("20", "astm-d523-20"),
    ("45", "astm-d2457-45"),
    ("60", "astm-d523-60"),
    ("75", "tappi-t480-75"),
    ("85", "astm-d523-85"),
];

/// A header as the alias tables spell it: without parenthesised units, lower case, only letters and
/// digits, without a trailing `deg`/`degree(s)`. `Gloss 60° (GU)` → `gloss60`, `HU_LOG` → `hulog`.
pub(crate) fn normalise(header: &str) -> String {
    let mut s = String::new();
    let mut depth = 0usize;
    for c in header.chars() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth = depth.saturating_sub(1),
            c if depth == 0 && c.is_alphanumeric() => s.extend(c.to_lowercase()),
            _ => {}
        }
    }
    for suffix in ["degrees", "degree", "deg"] {
        if let Some(t) = s.strip_suffix(suffix) {
            if t.ends_with(|c: char| c.is_ascii_digit()) {
                return t.to_string();
            }
        }
    }
    s
}

/// Whether a header is one of the columns to skip: the same normalised header; or, for an entry with a
/// bracketed part, the same with its brackets' words kept (`L* (A/10°)` skips that column and not `L* (D65/10°)`).
fn is_ignored(header: &str, ignore: &[String]) -> bool {
    let keep = |h: &str| h.chars().filter(|c| c.is_alphanumeric()).flat_map(char::to_lowercase).collect::<String>();
    let same = |i: &String| match i.contains(['(', '[']) {
        true => keep(i) == keep(header),
        false => normalise(i) == normalise(header),
    };
    ignore.iter().any(same)
}

/// The gloss geometry of a header such as `20`, `20°`, `G60`, `Gloss 85°`, `60 gloss`, `GU 20`.
pub(crate) fn gloss_angle(normalised: &str) -> Option<&'static str> {
    let mut h = normalised;
    for p in ["gloss", "gu", "g"] {
        if let Some(t) = h.strip_prefix(p) {
            h = t;
            break;
        }
    }
    for s in ["gloss", "gu"] {
        if let Some(t) = h.strip_suffix(s) {
            h = t;
            break;
        }
    }
    GLOSS_ANGLES.iter().find(|(a, _)| *a == h).map(|(_, g)| *g)
}

/// A repeat suffix `#N`, `(N)` or `[N]` at the end of a header, and the header without it.
pub(super) fn split_repeat(header: &str) -> (&str, Option<u32>) {
    let t = header.trim_end();
    let try_num = |inner: &str| inner.trim().parse::<u32>().ok();
    if let Some(i) = t.rfind('#') {
        if let Some(n) = try_num(&t[i + 1..]) {
            return (t[..i].trim_end(), Some(n));
        }
    }
    for (open, close) in [('(', ')'), ('[', ']')] {
        if t.ends_with(close) {
            if let Some(i) = t.rfind(open) {
                if let Some(n) = try_num(&t[i + 1..t.len() - 1]) {
                    return (t[..i].trim_end(), Some(n));
                }
            }
        }
    }
    (t, None)
}

/// What a header column is.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Role {
    Sample,
    Info,
    /// An illuminant and/or observer column ([`CONDITION_COLUMNS`]).
    Condition,
    Geometry,
    Quantity,
    Value,
    Uncertainty,
    /// An L*, a*, b* column of the colour layout (0, 1, 2).
    Lab(usize),
    /// A maker's statistics column, of a named reading (geometry, reading) or of the row's reading.
    Statistic {
        stat: Statistic,
        of: Option<(&'static str, &'static str)>,
    },
    /// A reading column of the wide layout: geometry, reading, repeat index, not-predicted reason.
    Reading {
        geometry: &'static str,
        reading: &'static str,
        repeat: Option<u32>,
        not_predicted: Option<&'static str>,
    },
    Ignored,
}

pub(super) fn role(header: &str, ignore: &[String]) -> Option<Role> {
    let n = normalise(header);
    if is_ignored(header, ignore) {
        return Some(Role::Ignored);
    }
    let is = |list: &[&str]| list.contains(&n.as_str());
    if is(SAMPLE_COLUMNS) {
        return Some(Role::Sample);
    }
    if is(INFO_COLUMNS) {
        return Some(Role::Info);
    }
    if is(CONDITION_COLUMNS) {
        return Some(Role::Condition);
    }
    if is(GEOMETRY_COLUMNS) {
        return Some(Role::Geometry);
    }
    if is(QUANTITY_COLUMNS) {
        return Some(Role::Quantity);
    }
    if is(VALUE_COLUMNS) {
        return Some(Role::Value);
    }
    if is(UNCERTAINTY_COLUMNS) {
        return Some(Role::Uncertainty);
    }
    if let Some(i) = LAB_COLUMNS.iter().position(|(names, _)| is(names)) {
        return Some(Role::Lab(i));
    }
    let (base, repeat) = split_repeat(header);
    let b = normalise(base);
    if let Some(g) = gloss_angle(&b) {
        return Some(Role::Reading { geometry: g, reading: "gloss", repeat, not_predicted: None });
    }
    if let Some(c) = READING_COLUMNS.iter().find(|c| c.names.contains(&b.as_str())) {
        return Some(Role::Reading {
            geometry: c.geometry,
            reading: c.reading,
            repeat,
            not_predicted: c.not_predicted,
        });
    }
    // A statistics column: `Mean 20°`, `20° Std`, `Range Haze`, or a bare `Mean` (of the row's reading).
    let (stat, rest) = series::split(&n)?;
    if rest.is_empty() {
        return Some(Role::Statistic { stat, of: None });
    }
    let of = match gloss_angle(rest) {
        Some(g) => (g, "gloss"),
        None => READING_COLUMNS.iter().find(|c| c.names.contains(&rest)).map(|c| (c.geometry, c.reading))?,
    };
    Some(Role::Statistic { stat, of: Some(of) })
}

/// The statistic a cell names alone (`Mean`, `Std. dev.`, `Min`, `Max`, `Range`, `x̄` is not read).
pub(super) fn statistics_label(cell: &str) -> Option<Statistic> {
    match series::split(&normalise(cell)) {
        Some((stat, "")) => Some(stat),
        _ => None,
    }
}

/// The statistic of a statistics row: its first non-empty cell names one, in the sample column, an info column
/// or the first column.
pub(super) fn statistics_row(rec: &csv::StringRecord, roles: &[Role]) -> Option<Statistic> {
    let (j, cell) = rec.iter().enumerate().find(|(_, f)| !f.is_empty())?;
    let labelled = j == 0 || matches!(roles.get(j), Some(Role::Sample | Role::Info));
    labelled.then(|| statistics_label(cell)).flatten()
}

/// Stage 1, the header's roles: what each column is ([`role`]), refused when empty, unknown or duplicated.
pub(super) fn header_roles(
    headers: &[String],
    hline: usize,
    file: &str,
    options: &SheetOptions,
    place: &Place,
) -> Result<Vec<Role>> {
    let mut roles = Vec::new();
    for (j, h) in headers.iter().enumerate() {
        if h.is_empty() {
            return Err(Error::input(file, at(place, hline, j, "empty"), "empty column header"));
        }
        match role(h, &options.ignore_columns) {
            Some(r) => roles.push(r),
            None => {
                return Err(Error::input(
                    file,
                    at(place, hline, j, h),
                    Words::from(format!(
                        "unrecognised column `{}` (the columns glossmeter reads are listed in docs/instrument.md \
                         §Sheets; pass ",
                        short(h)
                    ))
                    .and_argument("ignore_columns")
                    .and(format!(" '{}' to skip it)", short(h))),
                ))
            }
        }
    }
    // Duplicate headers: two columns of the same role (other than info, ignored and colour conditions, which
    // must agree where they are read) are ambiguous.
    for j in 0..roles.len() {
        for i in 0..j {
            if roles[i] == roles[j] && matches!(roles[j], Role::Lab(_)) {
                // An export with colour under several illuminants (`L* (D65/10°)`, `L* (A/10°)`).
                return Err(Error::input(
                    file,
                    at(place, hline, j, &headers[j]),
                    Words::from(format!(
                        "duplicate column: `{}` is the same quantity as column {} (`{}`); a sheet's colour is \
                         compared under one illuminant and observer at a time (docs/instrument.md §Sheets): pass ",
                        headers[j],
                        i + 1,
                        headers[i]
                    ))
                    .and_argument("ignore_columns")
                    .and(" with the headers of the columns under the others"),
                ));
            }
            if roles[i] == roles[j] && !matches!(roles[j], Role::Info | Role::Ignored | Role::Condition) {
                return Err(Error::input(
                    file,
                    at(place, hline, j, &headers[j]),
                    format!(
                        "duplicate column: `{}` means the same as column {} (`{}`); number repeated readings \
                         as `60° #1`, `60° #2`",
                        headers[j],
                        i + 1,
                        headers[i]
                    ),
                ));
            }
        }
    }
    Ok(roles)
}

/// Stage 2, the layout: colour, long or wide from the columns' roles, with the columns that do not belong to it
/// refused; and the wide layout's one reading, when it has one (the reading of a bare statistics column).
pub(super) fn layout_of(
    roles: &[Role],
    headers: &[String],
    hline: usize,
    file: &str,
    place: &Place,
) -> Result<(Layout, Option<(&'static str, &'static str)>)> {
    let find = |r: &Role| roles.iter().position(|x| x == r);
    let (geo_c, val_c) = (find(&Role::Geometry), find(&Role::Value));
    let reading_cols: Vec<usize> = (0..roles.len()).filter(|&j| matches!(roles[j], Role::Reading { .. })).collect();
    let lab_cols: Vec<Option<usize>> = (0..3).map(|i| find(&Role::Lab(i))).collect();
    let layout = match (geo_c, val_c) {
        (Some(_), None) if lab_cols.iter().all(Option::is_some) => Layout::Colour,
        (Some(_), Some(_)) => Layout::Long,
        (Some(_), None) => {
            return Err(Error::input(
                file,
                format!("{} (header)", place.line(hline)),
                "the long layout needs a `value` column",
            ))
        }
        (None, Some(v)) => {
            return Err(Error::input(
                file,
                at(place, hline, v, &headers[v]),
                "the long layout needs a `geometry` column",
            ))
        }
        (None, None) if reading_cols.is_empty() => {
            return Err(Error::input(
                file,
                format!("{} (header)", place.line(hline)),
                "no reading columns: expected `geometry` and `value` (long layout) or reading columns such as \
                 20°, 60°, 85°, Haze, DOI (wide layout)",
            ))
        }
        (None, None) => Layout::Wide,
    };
    if layout != Layout::Colour {
        if let Some(j) = roles.iter().position(|r| matches!(r, Role::Lab(_))) {
            return Err(Error::input(
                file,
                at(place, hline, j, &headers[j]),
                "an L*, a* or b* column belongs to the colour layout: a `geometry` column with all three of `L*`, \
                 `a*`, `b*` and no `value` column",
            ));
        }
    }
    if layout == Layout::Colour {
        if let Some(j) = roles.iter().position(|r| {
            matches!(r, Role::Quantity | Role::Uncertainty | Role::Reading { .. } | Role::Statistic { .. })
        }) {
            return Err(Error::input(
                file,
                at(place, hline, j, &headers[j]),
                "a colour-layout sheet (`geometry` with `L*`, `a*`, `b*`) has no other reading, quantity, \
                 uncertainty or statistics columns",
            ));
        }
    } else if layout == Layout::Long {
        if let Some(&j) = reading_cols.first() {
            return Err(Error::input(
                file,
                at(place, hline, j, &headers[j]),
                "a reading column in a long-layout sheet (one with `geometry` and `value`): use one layout",
            ));
        }
    } else if let Some(j) = roles.iter().position(|r| matches!(r, Role::Quantity | Role::Uncertainty)) {
        return Err(Error::input(
            file,
            at(place, hline, j, &headers[j]),
            "`quantity` and `uncertainty` belong to the long layout (with `geometry` and `value`)",
        ));
    }
    // A statistics column without a reading in its name (`Mean`) is of the row's reading: in the wide layout
    // there must be just one.
    let mut wide_reading: Option<(&'static str, &'static str)> = None;
    if layout == Layout::Wide {
        for &c in &reading_cols {
            if let Role::Reading { geometry, reading, .. } = roles[c] {
                match wide_reading {
                    Some(r) if r != (geometry, reading) => {
                        if let Some(j) = roles.iter().position(|r| matches!(r, Role::Statistic { of: None, .. })) {
                            return Err(Error::input(
                                file,
                                at(place, hline, j, &headers[j]),
                                format!(
                                    "a statistics column without a reading in its name is of the sheet's one reading, \
                                     but this sheet has several (`{}`, `{}`): name it, e.g. `{} {}`",
                                    headers[reading_cols[0]], headers[c], headers[j], headers[reading_cols[0]]
                                ),
                            ));
                        }
                    }
                    _ => wide_reading = Some((geometry, reading)),
                }
            }
        }
    }
    Ok((layout, wide_reading))
}
