//! Writes `assets/coat-albedo-table.bin` and its provenance `assets/coat-albedo-table.json`: the rough clear
//! coat's directional albedo E(μ; distribution, α, η) as a tensor Chebyshev series, from the reference rule
//! (`glossmeter::optics::coat_albedo`, module docs; docs/model.md §Energy-exact rough clear coat).
//!
//! Run (by hand, not by CI; a few minutes on 2 cores):
//!   cargo run --release --example make_coat_albedo_table
//!
//! For each distribution, α piece and (α node, η node) of the tensor Chebyshev–Gauss grid (ln α within the
//! piece, η on [1.3, 1.8]), `CoatAlbedo::from_rule` gives the per-paint function's μ-Chebyshev coefficients;
//! a 2-D Chebyshev transform over the (α, η) nodes turns each μ coefficient into a series in (ln α, η). Each
//! row (distribution, α piece, μ piece, α term, η term) keeps its leading μ coefficients; the trailing ones
//! below a threshold τ are dropped, τ the largest for which the dropped coefficients of the
//! (distribution, α piece, μ piece) block sum to at most TRUNCATION_BUDGET.
// The transforms index a (α term, η term, μ term) tensor by all three indices at once.
#![allow(clippy::needless_range_loop)]
use glossmeter::optics::coat_albedo::*;
use glossmeter::optics::microfacet::Microfacet;
use glossmeter::optics::tabulated::{coefficients, node_on};
use rayon::prelude::*;
use std::io::Write;

fn main() {
    let started = std::time::Instant::now();
    let pieces_a = ALPHA_BREAKS.len() - 1;
    // One task per (distribution, α piece, α node, η node): the per-paint function at that grid point.
    let tasks: Vec<(usize, usize, usize, usize)> = (0..DISTRIBUTIONS.len())
        .flat_map(|d| {
            (0..pieces_a)
                .flat_map(move |ap| (0..ALPHA_NODES).flat_map(move |i| (0..ETA_NODES).map(move |j| (d, ap, i, j))))
        })
        .collect();
    let results: Vec<(Vec<f64>, usize)> = tasks
        .par_iter()
        .map(|&(d, ap, i, j)| {
            let la = node_on(i, ALPHA_NODES, ALPHA_BREAKS[ap].ln(), ALPHA_BREAKS[ap + 1].ln());
            let eta = node_on(j, ETA_NODES, ETA_MIN, ETA_MAX);
            let a = CoatAlbedo::from_rule(&Microfacet::new(DISTRIBUTIONS[d], la.exp()), eta)
                .unwrap_or_else(|| panic!("non-finite E at {:?} α {} η {eta}", DISTRIBUTIONS[d], la.exp()));
            (a.coefficients().to_vec(), a.evaluations)
        })
        .collect();
    let evaluations: usize = results.iter().map(|r| r.1).sum();
    let at = |d: usize, ap: usize, i: usize, j: usize| -> &Vec<f64> {
        &results[((d * pieces_a + ap) * ALPHA_NODES + i) * ETA_NODES + j].0
    };
    let mut out: Vec<u8> = TABLE_MAGIC.to_vec();
    for c in [DISTRIBUTIONS.len(), pieces_a, ALPHA_NODES, ETA_NODES, PIECES, NODES] {
        out.extend((c as u32).to_le_bytes());
    }
    for v in ALPHA_BREAKS.iter().chain(&[ETA_MIN, ETA_MAX]).chain(&BREAKS) {
        out.extend(v.to_le_bytes());
    }
    let (mut kept, mut worst_dropped, mut worst_last_a, mut worst_last_e) = (0usize, 0.0f64, 0.0f64, 0.0f64);
    for d in 0..DISTRIBUTIONS.len() {
        for ap in 0..pieces_a {
            for mp in 0..PIECES {
                // coef[ka][ke][kμ] = 2-D Chebyshev transform over the (α, η) nodes of the kμ-th μ coefficient.
                let mut coef = vec![vec![vec![0.0; NODES]; ETA_NODES]; ALPHA_NODES];
                for km in 0..NODES {
                    // Transform in η for each α node, then in α.
                    let by_eta: Vec<Vec<f64>> = (0..ALPHA_NODES)
                        .map(|i| {
                            coefficients(&(0..ETA_NODES).map(|j| at(d, ap, i, j)[mp * NODES + km]).collect::<Vec<_>>())
                        })
                        .collect();
                    for ke in 0..ETA_NODES {
                        let c = coefficients(&(0..ALPHA_NODES).map(|i| by_eta[i][ke]).collect::<Vec<_>>());
                        for ka in 0..ALPHA_NODES {
                            coef[ka][ke][km] = c[ka];
                        }
                    }
                }
                // Each row keeps its coefficients up to the last one of magnitude ≥ τ; τ is the largest (by
                // bisection in ln τ) whose dropped coefficients sum to ≤ TRUNCATION_BUDGET over the block.
                let kept_len = |row: &[f64], tau: f64| -> (usize, f64) {
                    let mut len = NODES;
                    let mut dropped = 0.0;
                    while len > 0 && row[len - 1].abs() < tau {
                        dropped += row[len - 1].abs();
                        len -= 1;
                    }
                    (len, dropped)
                };
                let block_dropped =
                    |tau: f64| -> f64 { coef.iter().flat_map(|r| r.iter()).map(|row| kept_len(row, tau).1).sum() };
                let (mut lo, mut hi) = ((1e-30f64).ln(), (1e-6f64).ln());
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    if block_dropped(mid.exp()) <= TRUNCATION_BUDGET {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let tau = lo.exp();
                let mut dropped_block = 0.0;
                for ka in 0..ALPHA_NODES {
                    for ke in 0..ETA_NODES {
                        let row = &coef[ka][ke];
                        if ka + 1 == ALPHA_NODES {
                            worst_last_a = worst_last_a.max(row.iter().fold(0.0, |m, v| m.max(v.abs())));
                        }
                        if ke + 1 == ETA_NODES {
                            worst_last_e = worst_last_e.max(row.iter().fold(0.0, |m, v| m.max(v.abs())));
                        }
                        let (len, dropped) = kept_len(row, tau);
                        dropped_block += dropped;
                        out.push(len as u8);
                        for v in &row[..len] {
                            out.extend(v.to_le_bytes());
                        }
                        kept += len;
                    }
                }
                worst_dropped = worst_dropped.max(dropped_block);
            }
        }
    }
    std::fs::write("assets/coat-albedo-table.bin", &out).expect("write table");
    let commit = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    let prov = serde_json::json!({
        "file": "assets/coat-albedo-table.bin",
        "what": "directional albedo E(mu) of a rough dielectric interface's single-scattering reflection lobe (height-correlated Smith, Beckmann and GGX), as the per-paint function's mu-Chebyshev coefficients in a tensor Chebyshev series in (ln alpha, eta); read by src/optics/coat_albedo.rs (format: parse_table)",
        "generated_by": "cargo run --release --example make_coat_albedo_table (examples/make_coat_albedo_table.rs)",
        "generated_from_commit": commit,
        "reference_rule": {"phi_nodes": PHI_NODES, "core_nodes": CORE_NODES, "tail_nodes": TAIL_NODES,
            "checked": "against 16/64/32 nodes and against scipy (tools/ref_coat_albedo.py, fixtures/reference/coat-albedo.json) in tests/paint.rs"},
        "alpha_breaks": ALPHA_BREAKS, "alpha_terms_per_piece": ALPHA_NODES,
        "eta_range": [ETA_MIN, ETA_MAX], "eta_terms": ETA_NODES,
        "mu_breaks": BREAKS, "mu_terms_per_piece": NODES,
        "truncation_budget_per_block": TRUNCATION_BUDGET,
        "largest_dropped_sum_per_block": worst_dropped,
        "largest_last_alpha_term": worst_last_a,
        "largest_last_eta_term": worst_last_e,
        "coefficients_kept": kept,
        "coefficients_dense": DISTRIBUTIONS.len() * pieces_a * PIECES * ALPHA_NODES * ETA_NODES * NODES,
        "bytes": out.len(),
        "lobe_evaluations": evaluations,
        "generation_seconds": (started.elapsed().as_secs_f64() * 10.0).round() / 10.0,
    });
    let mut f = std::fs::File::create("assets/coat-albedo-table.json").expect("provenance");
    writeln!(f, "{}", serde_json::to_string_pretty(&prov).expect("json")).expect("write");
    println!("{}", serde_json::to_string_pretty(&prov).expect("json"));
}
