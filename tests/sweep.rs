//! `glossmeter sweep` and batch `measure`: shards whose concatenation is the unsharded run byte for byte,
//! invalid points reported in their row, bad sweeps refused (exit 2), and results that do not depend on the
//! thread count or on how many recipes are measured together.
mod common;
use common::{fresh_dir, gm};
use std::process::Command;

fn gm_env(args: &[&str], threads: Option<&str>) -> (i32, String, String) {
    let mut c = common::glossmeter();
    c.args(args);
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t);
    }
    let out = c.output().expect("run glossmeter");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const T: &str = "fixtures/recipes/rgb-lambert.json";

#[test]
fn shards_concatenate_to_the_whole_run() {
    for (design, shards) in [
        (&["--vary", "/albedo/0=0.2..1.2:3", "--vary", "/albedo/1=0.1..0.5:2"][..], 4u32),
        (&["--vary", "/albedo/0=0.05..0.9", "--log", "/albedo/0", "--lhs", "7", "--seed", "3"], 3),
    ] {
        for format in ["csv", "jsonl"] {
            let mut base = vec!["sweep", T, "-g", "astm-d523-60", "--no-timing", "--format", format];
            base.extend(design);
            let (code, whole, err) = gm(&base);
            assert_eq!(code, 0, "{err}");
            assert!(err.is_empty(), "no progress bar when stderr is not a terminal: {err}");
            let mut joined = String::new();
            for k in 1..=shards {
                let s = format!("{k}/{shards}");
                let mut a = base.clone();
                a.extend(["--shard", &s]);
                let (code, part, _) = gm(&a);
                assert_eq!(code, 0);
                joined.push_str(&part);
            }
            assert_eq!(joined, whole, "{design:?} {format}");
            // Same bytes on one thread.
            assert_eq!(gm_env(&base, Some("1")).1, whole);
        }
    }
}

#[test]
fn rows_carry_values_errors_and_invalid_points() {
    let (code, out, _) =
        gm(&["sweep", T, "--vary", "/albedo/0=0.2..1.2:3", "-g", "astm-d523-60", "--no-timing", "--format", "csv"]);
    assert_eq!(code, 0);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "index,/albedo/0,astm-d523-60 gloss (GU),astm-d523-60 gloss error,problem");
    assert_eq!(lines.len(), 4);
    assert!(lines[1].starts_with("0,0.2,"));
    // Albedo 1.2 is out of range: the row says why, and the sweep goes on.
    assert!(lines[3].starts_with("2,1.2,,,") && lines[3].contains("albedo"), "{}", lines[3]);
    // The diffuse flux in the gloss receptor, and so the reading, grows with the albedo.
    let g = |l: &str| l.split(',').nth(2).unwrap().parse::<f64>().unwrap();
    assert!(g(lines[2]) > g(lines[1]));
}

#[test]
fn bad_sweeps_exit_2() {
    for (args, want) in [
        (&["--vary", "/no/such=0..1:2"][..], "/no/such"),
        (&["--vary", "/albedo/0=0.5..0.5:2"], "LO must be below HI"),
        (&["--vary", "/albedo/0=0..1:0"], "N must be at least 1"),
        (&["--vary", "/albedo/0=0..1:2", "--shard", "3/2"], "K/M"),
        (&["--vary", "/albedo/0=0..1:2", "--log", "/albedo/0"], "LO > 0"),
        (&["--vary", "/albedo/0=0..1"], ":N"),
        (&["--vary", "/model=0..1:2"], "number"),
        (&["--vary", "/albedo/0=0..1:2", "--shard", "0/2"], "K/M"),
        (&["--vary", "/albedo/0=0..1", "--lhs", "0"], "at least 1"),
        (&["--vary", "/albedo/7=0..1:2"], "/albedo/7"),
    ] {
        let mut a = vec!["sweep", T];
        a.extend(args);
        let (code, out, err) = gm(&a);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty() && err.contains(want), "{args:?}: {err}");
    }
}

#[test]
fn a_batch_reads_the_same_bits_as_one_recipe_at_a_time() {
    let files =
        ["fixtures/recipes/glass-n1.5.json", "fixtures/recipes/phong.json", "fixtures/recipes/rgb-lambert.json"];
    let mut args = vec!["measure", "--format", "json", "--no-timing"];
    args.extend(files);
    let (code, out, err) = gm(&args);
    assert_eq!(code, 0, "{err}");
    let batch: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(batch["materials"].as_array().unwrap().len(), 3);
    let mut k = 0;
    for f in files {
        let (_, one, _) = gm_env(&["measure", f, "--format", "json", "--no-timing"], Some("1"));
        let one: serde_json::Value = serde_json::from_str(&one).unwrap();
        for r in one["readings"].as_array().unwrap() {
            let b = &batch["readings"][k];
            assert_eq!(b["file"], f);
            for key in ["geometry", "name", "value", "error_estimate", "evaluations"] {
                assert_eq!(b[key], r[key], "{f} {key}");
            }
            k += 1;
        }
    }
    assert_eq!(k, batch["readings"].as_array().unwrap().len());
    // A directory is its *.json files; the table and CSV have a material column.
    let (code, table, _) = gm(&["measure", "fixtures/materials/guenther-2005", "-g", "astm-d523-60", "--no-timing"]);
    assert_eq!(code, 0);
    assert!(table.contains("8 recipe(s)") && table.starts_with("8 recipe(s)"), "{table}");
    let (_, csv, _) = gm(&["measure", "fixtures/materials/guenther-2005", "-g", "astm-d523-60", "--format", "csv"]);
    assert!(csv.starts_with("material,file,geometry"), "{csv}");
    assert_eq!(csv.lines().count(), 9);
    // One bad recipe fails the batch before any work, naming its file.
    let (code, _, err) = gm(&["measure", "fixtures/recipes/glass-n1.5.json", "fixtures/bad/negative-albedo.json"]);
    assert_eq!(code, 2);
    assert!(err.contains("fixtures/bad/negative-albedo.json"), "{err}");
}

#[test]
fn a_measure_baseline_fails_readings_that_moved() {
    let dir = fresh_dir("baseline");
    let base = dir.join("glass.json");
    let b = base.to_str().unwrap();
    let glass = "fixtures/recipes/glass-n1.5.json";
    assert_eq!(gm(&["measure", glass, "-g", "astm-d523-60", "--format", "json", "-o", b]).0, 0);
    let (code, out, _) = gm(&["measure", glass, "-g", "astm-d523-60", "--baseline", b]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("baseline: 1 reading(s) checked, 0 moved"), "{out}");
    let moved = dir.join("moved.json");
    let text = std::fs::read_to_string(b).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let x = v["readings"][0]["value"].as_f64().unwrap();
    v["readings"][0]["value"] = serde_json::json!(x + 0.001);
    std::fs::write(&moved, v.to_string()).unwrap();
    let (code, out, _) = gm(&[
        "measure",
        "fixtures/recipes/glass-n1.5.json",
        "-g",
        "astm-d523-60",
        "--baseline",
        moved.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(out.contains("1 moved"), "{out}");
}

/// The batch's bytes do not depend on the thread count (integrals never split across threads; `docs/instrument.md`
/// §Many recipes).
#[test]
fn a_batch_is_bit_identical_on_one_and_two_threads() {
    let args = [
        "measure",
        "fixtures/recipes",
        "-g",
        "astm-d523-20",
        "-g",
        "astm-e430-30",
        "--format",
        "json",
        "--no-timing",
        "--allow-unconverged",
    ];
    let (c1, one, e1) = gm_env(&args, Some("1"));
    let (c2, two, _) = gm_env(&args, Some("2"));
    assert_eq!((c1, c2), (0, 0), "{e1}");
    assert!(one.len() > 10_000, "all shipped recipes: {}", one.len());
    assert_eq!(one, two);
}

/// Paths go through the parameter registry: an unknown one is named as a JSON Pointer with examples; an
/// optional parameter the template lacks is added at every point; `-o` streams into a file that appears whole.
#[test]
fn sweep_paths_come_from_the_registry() {
    let dir = fresh_dir("registry");
    let t = dir.join("phong-no-kd.json");
    std::fs::write(&t, r#"{"model": "phong", "exponent": 200, "ks": 0.04}"#).unwrap();
    let t = t.to_str().unwrap();
    let (code, _, err) = gm(&["sweep", t, "--vary", "/exponentt=1..2:2"]);
    assert_eq!(code, 2);
    assert!(err.contains("/exponentt") && err.contains("not a parameter of a `phong` recipe"), "{err}");
    assert!(err.contains("/exponent"), "examples listed: {err}");
    let (code, _, err) = gm(&["sweep", t, "--vary", "/name=1..2:2"]);
    assert_eq!(code, 2);
    assert!(err.contains("not a number"), "{err}");
    let out = dir.join("kd.csv");
    let o = out.to_str().unwrap();
    let args = ["sweep", t, "--vary", "/kd=0..0.5:3", "-g", "astm-d523-60", "--no-timing", "-o", o];
    let (code, stdout, err) = gm(&args);
    assert_eq!((code, stdout.as_str()), (0, ""), "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    let g: Vec<f64> = text.lines().skip(1).map(|l| l.split(',').nth(2).unwrap().parse().unwrap()).collect();
    assert_eq!(g.len(), 3);
    assert!(g[0] < g[1] && g[1] < g[2], "the diffuse term adds to the gloss reading: {g:?}");
    // The file exists now: a second run is refused before any work, and the file is untouched.
    let (code, _, err) = gm(&args);
    assert_eq!(code, 2);
    assert!(err.contains("already exists"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), text);
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names.len(), 2, "no temporary file left: {names:?}");
}

/// The progress bar's terminal path: under a pseudo-terminal (util-linux `script`, which runs the command with
/// stdin, stdout and stderr on a pty) the bar is drawn on the terminal, and the file written with `-o` holds
/// the same bytes as a run without a terminal (the bar never reaches the output). Opt-in: `script` is not on
/// every machine with Rust (`.ci/run` runs it with `cargo test --test sweep -- --ignored`).
#[test]
#[ignore = "needs util-linux `script` for a pseudo-terminal; .ci/run runs it with `cargo test --test sweep -- --ignored`"]
fn the_progress_bar_is_drawn_on_a_terminal_only() {
    if Command::new("script").arg("--version").output().is_err() {
        panic!("util-linux `script` is needed to give the sweep a terminal (apt-get install util-linux)");
    }
    let d = fresh_dir("pty");
    let (plain, on_tty) = (d.join("plain.csv"), d.join("tty.csv"));
    let exe = env!("CARGO_BIN_EXE_glossmeter");
    let args = ["sweep", T, "-g", "astm-d523-60", "--no-timing", "--vary", "/albedo/0=0.2..1.2:40"];
    let (code, _, err) = gm(&[&args[..], &["-o", plain.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "no bar without a terminal: {err}");
    // One shell word per argument (no argument here holds a quote).
    let cmd = [&[exe][..], &args[..], &["-o", on_tty.to_str().unwrap()]]
        .concat()
        .iter()
        .map(|a| format!("'{a}'"))
        .collect::<Vec<_>>()
        .join(" ");
    let out = Command::new("script").args(["-q", "-e", "-c", &cmd, "/dev/null"]).output().expect("run script");
    let terminal = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{terminal}");
    // The bar's template is "{bar:40} {pos}/{len} points, …": the terminal saw it (with its escape codes).
    assert!(terminal.contains("/40 points"), "no progress bar on the terminal: {terminal:?}");
    assert_eq!(std::fs::read(&on_tty).unwrap(), std::fs::read(&plain).unwrap());
    let _ = std::fs::remove_dir_all(&d);
}

/// A sweep's rows (plans compiled in parallel by one planner, integrals in one flat loop per chunk) are
/// those of its points measured one by one, an invalid point included, on 1 and 2 threads.
#[test]
fn sweep_rows_are_those_of_points_run_alone() {
    use glossmeter::instrument::plan::PlanOptions;
    use glossmeter::sweep::{parse_vary, Sweep, SweepDesign};
    let template: serde_json::Value =
        serde_json::from_str(r#"{"model": "microfacet", "distribution": "ggx", "roughness": 0.1, "ior": 1.5}"#)
            .unwrap();
    let geos = glossmeter::resolve_geometries(&["astm-d523-20", "astm-e430-30"], &[] as &[&str]).unwrap();
    let axes = vec![parse_vary("/roughness=-0.05..0.5:12").unwrap()];
    let opts = PlanOptions { rtol: 1e-5, ..Default::default() };
    let s = Sweep::new(template, "t.json", axes, SweepDesign::Grid, geos, opts).unwrap();
    let alone: String = (0..s.len()).map(|i| s.csv_row(&s.run_point(i), false)).collect();
    assert!(alone.contains("out of range"), "point 0 is invalid: {alone}");
    for k in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().unwrap();
        let mut rows = String::new();
        pool.install(|| {
            s.run(0..s.len(), |r| {
                rows.push_str(&s.csv_row(&r, false));
                Ok(())
            })
        })
        .unwrap();
        assert_eq!(rows, alone, "{k} thread(s)");
    }
}

/// The last shard of a Latin hypercube of 2⁶⁴ − 1 points holds one point and ends (its chunk's end once
/// wrapped around u64::MAX and the loop never ended): bounded by a watchdog, not by trust.
#[test]
fn the_last_shard_of_a_two_to_the_64_hypercube_ends() {
    let n = u64::MAX.to_string();
    let shard = format!("{n}/{n}");
    let mut child = common::glossmeter()
        .args(["sweep", "fixtures/recipes/bench-b2-beckmann-0.1.json", "--vary", "/roughness=0.01..0.5"])
        .args(["--lhs", &n, "--seed", "1", "--shard", &shard, "-g", "astm-d523-60", "--no-timing"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed().as_secs() > 60 {
            child.kill().unwrap();
            panic!("the last shard did not end in 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(status.success(), "{status:?} {}", String::from_utf8_lossy(&out.stderr));
    // The one point (a later shard has no header: the shards concatenate into the whole run).
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(text.starts_with(&format!("{},", u64::MAX - 1)), "{text}");
}

/// A table recipe has no numeric parameter: the refusal says so instead of listing nothing.
#[test]
fn a_table_recipe_has_nothing_to_vary_and_says_so() {
    let (code, _, err) =
        gm(&["sweep", "fixtures/materials/rgl/beckmann-iso-32.json", "-g", "astm-d523-60", "--vary", "/x=0..1:2"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("has no numeric parameter to vary") && !err.contains("include ;"), "{err}");
}

/// A sweep reads colour under `--illuminant` and `--observer` as `measure` does: every point's colour readings are
/// the bits of `measure --illuminant A --observer 2` on the recipe at that point, and differ from D65 / 10°'s.
#[test]
fn a_sweep_reads_colour_under_the_given_conditions_as_measure_does() {
    let pearl = "fixtures/recipes/white-pearl-spectral.json";
    let sweep = |colour: &[&str]| -> Vec<serde_json::Value> {
        let mut a = vec!["sweep", pearl, "--vary", "/pearlescent_flakes/tio2_thickness_nm=60..69:2"];
        a.extend(["-g", "astm-e2194-15", "--format", "jsonl", "--no-timing"]);
        a.extend(colour);
        let (code, out, err) = gm(&a);
        assert_eq!(code, 0, "{err}");
        out.lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    };
    let (a2, d65) = (sweep(&["--illuminant", "A", "--observer", "2"]), sweep(&[]));
    assert_eq!(a2.len(), 2);
    let dir = fresh_dir("sweep-colour");
    let mut recipe: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(pearl).unwrap()).unwrap();
    for (point, other) in a2.iter().zip(&d65) {
        let t = &point["parameters"]["/pearlescent_flakes/tio2_thickness_nm"];
        recipe["pearlescent_flakes"]["tio2_thickness_nm"] = t.clone();
        let file = dir.join(format!("at-{t}.json"));
        std::fs::write(&file, recipe.to_string()).unwrap();
        let f = file.to_str().unwrap();
        let (code, out, err) = gm(&[
            "measure",
            f,
            "-g",
            "astm-e2194-15",
            "--illuminant",
            "A",
            "--observer",
            "2",
            "--format",
            "json",
            "--no-timing",
        ]);
        assert_eq!(code, 0, "{err}");
        let measured: serde_json::Value = serde_json::from_str(&out).unwrap();
        let readings = point["readings"].as_array().unwrap();
        for m in measured["readings"].as_array().unwrap() {
            let r = readings.iter().find(|r| r["name"] == m["name"]).unwrap();
            assert_eq!(r["value"], m["value"], "{t} {}", m["name"]);
            assert_eq!(r["error_estimate"], m["error_estimate"], "{t} {}", m["name"]);
        }
        let b = |p: &serde_json::Value| {
            p["readings"].as_array().unwrap().iter().find(|r| r["name"] == "b*").unwrap()["value"].clone()
        };
        assert_ne!(b(point), b(other), "{t}: b* the same under A / 2° as under D65 / 10°");
    }
}
