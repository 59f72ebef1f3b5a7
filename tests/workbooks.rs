//! Workbook sheets (docs/instrument.md §Workbooks, §Statistics columns): the shipped BYK smart-chart style
//! export (`fixtures/sheets/byk-smart-chart-export.xlsx`, made by tools/make_xlsx_fixture.py) compares with exit
//! 0, its statistics columns checked against the readings; `fit --sheet` reads it; bad workbooks (not a
//! workbook, a missing sheet, a statistic that disagrees with its readings, options that do not apply) exit 2
//! with errors naming the file, the sheet and the row and cell.
mod common;
use common::gm;

use serde_json::Value;

const GLASS: &str = "fixtures/recipes/glass-n1.5.json";
const BOOK: &str = "fixtures/sheets/byk-smart-chart-export.xlsx";

#[test]
fn the_shipped_export_with_statistics_columns_compares_with_exit_0() {
    let (code, out, err) = gm(&["compare", GLASS, BOOK]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains(r#"(sheet "Measurements")"#), "{out}");
    assert!(out.contains("statistics: 9 stated value(s)"), "{out}");
    assert!(out.contains("# instrument: BYK micro-TRI-gloss"), "metadata row: {out}");
    let (code, json, _) = gm(&["compare", GLASS, BOOK, "--format", "json"]);
    assert_eq!(code, 0);
    let doc: Value = serde_json::from_str(&json).unwrap();
    let c = doc["comparisons"].as_array().unwrap();
    assert_eq!(c.len(), 3);
    // Five readings per angle from the rows 3 to 7; the 60° mean is 89.12 (the sheet's `Mean 60°` says 89.1).
    assert_eq!(c[1]["n"], 5);
    assert!((c[1]["mean"].as_f64().unwrap() - 89.12).abs() < 1e-12);
    assert_eq!(doc["sheet"]["encoding"], "xlsx workbook");
    // The same readings as the CSV export of the same series.
    let (_, csv_json, _) =
        gm(&["compare", GLASS, "fixtures/sheets/byk-semicolon-decimal-comma.csv", "--format", "json"]);
    let csv_doc: Value = serde_json::from_str(&csv_json).unwrap();
    for (a, b) in c.iter().zip(csv_doc["comparisons"].as_array().unwrap()) {
        assert_eq!(
            (a["mean"].as_f64(), a["std"].as_f64(), a["predicted"].as_f64()),
            (b["mean"].as_f64(), b["std"].as_f64(), b["predicted"].as_f64())
        );
    }
    // `fit --sheet` reads the workbook.
    let (code, out, err) = gm(&["fit", GLASS, "--free", "/ior=1.3..1.8", "--sheet", BOOK, "--format", "json"]);
    assert_eq!(code, 0, "{out}{err}");
    let fit: Value = serde_json::from_str(&out).unwrap();
    let ior = fit["parameters"][0]["value"].as_f64().unwrap();
    assert!((ior - 1.5).abs() < 0.01, "{ior}");
}

#[test]
fn bad_workbooks_name_the_file_sheet_row_and_cell() {
    // A statistic that disagrees with its readings.
    let (code, _, err) = gm(&["compare", GLASS, "fixtures/sheets/bad/workbook-wrong-mean.xlsx"]);
    assert_eq!(code, 2, "{err}");
    for w in ["workbook-wrong-mean.xlsx", r#"sheet "Measurements", row 7, cell H7 (Mean 60°)"#, "89.4", "89.12"] {
        assert!(err.contains(w), "{w}: {err}");
    }
    // A sheet the workbook does not have: the sheets it has are listed.
    let (code, _, err) = gm(&["compare", GLASS, BOOK, "--sheet-name", "Readings"]);
    assert_eq!(code, 2);
    assert!(err.contains(r#"no sheet "Readings""#) && err.contains(r#""Measurements", "Instrument""#), "{err}");
    // The other sheet is read by the same rules: its first row is not a header glossmeter knows.
    let (code, _, err) = gm(&["compare", GLASS, BOOK, "--sheet-name", "Instrument"]);
    assert_eq!(code, 2);
    assert!(err.contains(r#"sheet "Instrument", row 1, cell A1 (Instrument)"#), "{err}");
    // Not a workbook although it starts like one (a truncated download).
    let d = common::tmp_dir("workbooks");
    std::fs::create_dir_all(&d).unwrap();
    let broken = d.join("truncated.xlsx");
    let bytes = std::fs::read(BOOK).unwrap();
    std::fs::write(&broken, &bytes[..bytes.len() / 2]).unwrap();
    let (code, _, err) = gm(&["compare", GLASS, broken.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("truncated.xlsx") && err.contains("not a readable workbook"), "{err}");
    // Options that do not apply.
    let (code, _, err) = gm(&["compare", GLASS, BOOK, "--delimiter", ";"]);
    assert_eq!(code, 2);
    assert!(err.contains("--delimiter") && err.contains("workbook"), "{err}");
    let (code, _, err) = gm(&["compare", GLASS, "fixtures/sheets/repeat-columns.csv", "--sheet-name", "x"]);
    assert_eq!(code, 2);
    assert!(err.contains("--sheet-name") && err.contains("text sheet"), "{err}");
}

#[test]
fn statistics_columns_in_text_sheets_are_checked_too() {
    let d = common::tmp_dir("stats");
    std::fs::create_dir_all(&d).unwrap();
    let cases: [(&str, &str, i32, &[&str]); 4] = [
        // A series in one row, Excel summary columns (population std accepted as well as the sample's).
        (
            "ok.csv",
            "sample,60° #1,60° #2,60° #3,Mean 60°,Std. Dev. 60°,Range 60°\ng,89.1,89.2,89.0,89.10,0.10,0.2\n",
            0,
            &[],
        ),
        // A bare `Mean` is of the sheet's one reading.
        ("bare.csv", "sample,60°,Mean\ng,89.1,\ng,89.2,\ng,89.0,89.1\n", 0, &[]),
        (
            "bad-std.csv",
            "sample,60° #1,60° #2,60° #3,Std 60°\ng,89.1,89.2,89.0,0.30\n",
            2,
            &["line 2, column 5 (Std 60°)", "standard deviation", "0.1 (n − 1)"],
        ),
        ("ambiguous.csv", "sample,20°,60°,Mean\ng,82,89.1,89.1\n", 2, &["column 4 (Mean)", "name it"]),
    ];
    for (name, text, status, wants) in cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let (code, out, err) = gm(&["compare", GLASS, p.to_str().unwrap(), "--tolerance", "0.5"]);
        assert_eq!(code, status, "{name}: {out}{err}");
        for w in wants {
            assert!(err.contains(w), "{name}: {w}: {err}");
        }
    }
}

/// The reproducers of docs/reliability.md §Workbooks (crafted and mutated books that made the reader panic,
/// abort on a huge allocation, inflate a zip bomb or pass a bad CRC): each ends with exit 2 and an error naming
/// the file, through `compare` and `fit --sheet` alike.
#[test]
fn hostile_workbooks_end_in_exit_2_naming_the_file() {
    for (name, path) in &common::hostile_workbooks() {
        for args in [vec!["compare", GLASS, &path], vec!["fit", GLASS, "--sheet", &path, "--free", "/ior=1.3..1.8"]] {
            let (code, out, err) = gm(&args);
            assert_eq!(code, 2, "{args:?}: {out}{err}");
            assert!(err.contains("error:") && err.contains(name.as_str()), "{args:?}: {err}");
            assert!(!err.contains("panicked"), "{args:?}: {err}");
        }
    }
}
