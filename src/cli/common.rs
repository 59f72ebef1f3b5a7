//! What the subcommands share: the `--format` and colour arguments ([`Format`], [`ColourArgs`]), the check of
//! `--rtol`, the flags of the arguments library errors name ([`flag`]), the verdict on a set of readings (the
//! exit status), and the text table's padding.
use clap::ValueEnum;

use crate::colorimetry::Conditions;
use crate::instrument::plan::PlanOptions;
use crate::request::{PlanRequest, DEFAULT_ILLUMINANT, DEFAULT_OBSERVER};
use crate::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Table,
    Json,
    Csv,
}

/// The conditions of colour readings (colour geometries only; gloss is luminous whatever they say).
#[derive(clap::Args, Debug, Clone)]
pub struct ColourArgs {
    /// Illuminant of colour readings: D65, D50, A or C.
    #[arg(long, default_value = DEFAULT_ILLUMINANT)]
    pub illuminant: String,
    /// Observer of colour readings: 10 (CIE 1964 10°) or 2 (CIE 1931 2°).
    #[arg(long, default_value = DEFAULT_OBSERVER)]
    pub observer: String,
}

impl ColourArgs {
    pub fn conditions(&self) -> Result<Conditions> {
        self.plan(None, PlanOptions::default().max_evals).colour()
    }

    /// The plan's request of a command: these conditions, the tolerance `rtol` (`None`: the request's default)
    /// and the evaluation budget of each aperture integral (every plan command's `--max-evals`).
    pub fn plan(&self, rtol: Option<f64>, max_evals: usize) -> PlanRequest {
        PlanRequest {
            rtol,
            max_evals: Some(max_evals),
            illuminant: Some(self.illuminant.clone()),
            observer: Some(self.observer.clone()),
        }
    }
}

/// The verdict on a set of readings (docs/instrument.md §Exit statuses): an error (exit 1) if one has no
/// finite value, or did not converge (unless allowed).
pub fn readings_status(readings: &[crate::Reading], allow_unconverged: bool) -> Result<()> {
    // The hue of a neutral colour has no value by definition, not by failure (`Reading::undefined`).
    let missing = readings.iter().filter(|r| r.value.is_none() && !r.undefined()).count();
    if missing > 0 {
        return Err(Error::Numeric(format!(
            "{missing} of {} reading(s) have no finite value (see the notes in the output)",
            readings.len()
        )));
    }
    let unconverged = readings.iter().filter(|r| !r.converged).count();
    if unconverged > 0 && !allow_unconverged {
        return Err(Error::Check(format!(
            "{unconverged} of {} reading(s) did not converge to the tolerance within the budgets (evaluations \
             or wall-clock time; their values are best estimates; --allow-unconverged exits 0 anyway)",
            readings.len()
        )));
    }
    Ok(())
}

/// `--rtol` in (0, 1), checked before any work (`request::check_rtol`, written with the flag's name).
pub fn check_rtol(rtol: f64) -> Result<()> {
    crate::request::check_rtol(rtol).map(|_| ())
}

/// The flag of an argument that a library error names ([`crate::error::Words`]): the library says `tolerance`,
/// the command line `--tolerance` (the library never names a flag; the parser adds it, as ripgrep's does).
pub fn flag(argument: &'static str) -> String {
    match argument {
        "k" => "-k".into(),
        "ignore_columns" => "--ignore-column".into(),
        "per_sample" => "--recipe".into(),
        // free, lhs, log, sample, shard, sheet, target, tolerance, vary: the flag is the name.
        name => format!("--{}", name.replace('_', "-")),
    }
}

/// A text table: a header row, a rule, then the rows; columns listed in `right` are right-aligned. Padding
/// is done by hand (a `format!` width is limited to 65 535).
pub fn pad_table(rows: &[Vec<String>], right: &[usize]) -> String {
    let ncol = rows.first().map(|r| r.len()).unwrap_or(0);
    let w: Vec<usize> = (0..ncol).map(|i| rows.iter().map(|r| r[i].chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for (k, r) in rows.iter().enumerate() {
        let cells: Vec<String> = r
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let pad = " ".repeat(w[i] - v.chars().count());
                if right.contains(&i) {
                    format!("{pad}{v}")
                } else {
                    format!("{v}{pad}")
                }
            })
            .collect();
        s.push_str(cells.join("  ").trim_end());
        s.push('\n');
        if k == 0 {
            s.push_str(&w.iter().map(|n| "-".repeat(*n)).collect::<Vec<_>>().join("  "));
            s.push('\n');
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Words;

    #[test]
    fn the_arguments_library_errors_name_are_written_as_flags() {
        let words = ["ignore_columns", "k", "per_sample", "tolerance"]
            .iter()
            .fold(Words::default(), |w, a| w.and(" ").and_argument(a));
        let e = Error::Argument(words);
        assert_eq!(e.naming(&flag), " --ignore-column -k --recipe --tolerance");
        assert_eq!(e.to_string(), " `ignore_columns` `k` `per_sample` `tolerance`");
    }
}
