//! The paint's flake tables and direction-independent sums folded for one weighted sum of its samples
//! ([`Folded`], [`FoldedFlake`]): what the luminous row's evaluation `Paint::eval_folded` reads
//! (`docs/model.md` §Folded evaluation).
use super::flake::FlakeTerm;
use crate::optics::tabulated::ChebTable;

/// The paint prepared for one weighted sum of its samples, Σ_j w_j f_j (the luminous row of its sampling:
/// what gloss, haze and DOI read; `Brdf::eval_batch_folded`). Everything that does not depend on direction is
/// summed over the samples once, here, so an evaluation does one sample's work where the per-sample path
/// does n (`docs/model.md` §Folded evaluation).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Folded {
    /// The row w it was prepared for.
    pub(super) weights: Vec<f64>,
    /// Σ_j w_j: the weight of the rough coat's grey lobe.
    pub(super) coat: f64,
    /// Σ_j w_j·body_j.
    pub(super) body: f64,
    /// One per flake term, in the order of `Paint::flakes`.
    pub(super) flakes: Vec<FoldedFlake>,
    /// The second flake term's cover has the same optical depths as the first's (the same pigment at the same
    /// depth): the transmissions computed for the first serve the second.
    pub(super) shared_depth: bool,
}

/// A flake term prepared for a weighted sum.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct FoldedFlake {
    /// Split light: w_j·(the diffuse weight of sample j).
    pub(super) diffuse: Vec<f64>,
    /// The lobe's reflectance folded into one table, Σ_j w_j·T_j, when the per-sample factors in front of the
    /// tables do not depend on direction (light not split, or a grey cover: one τ for every sample).
    pub(super) table: Option<ChebTable>,
    /// Otherwise the samples' tables on one grid: an evaluation sums their coefficients with the weights
    /// w_j·τ_j(θi')·τ_j(θo') and runs one Clenshaw recurrence (the interpolant is linear in its coefficients).
    pub(super) grid: Option<Vec<ChebTable>>,
    /// Split light with a grey cover: every sample's τ is sample 0's.
    pub(super) grey_cover: bool,
}

impl Folded {
    /// Prepare a paint for the row `w` (n weights): its flake terms (`metallic`, `pearlescent`), its body term
    /// per sample.
    pub(super) fn new(
        metallic: Option<&FlakeTerm>,
        pearlescent: Option<&FlakeTerm>,
        body: &[f64],
        w: &[f64],
    ) -> Folded {
        let flakes = metallic
            .into_iter()
            .chain(pearlescent)
            .map(|fl| {
                let grey_cover = fl.depth.iter().all(|d| d.to_bits() == fl.depth[0].to_bits());
                // The tables on one grid were made with the flake term (`FlakeTerm::grid`).
                let grid = fl.grid.clone();
                let constant = !fl.split || grey_cover;
                let table = grid.as_ref().filter(|_| constant).and_then(|g| ChebTable::combine(g, w));
                FoldedFlake {
                    diffuse: fl.diffuse.iter().zip(w).map(|(d, w)| w * d).collect(),
                    grid: if table.is_some() { None } else { grid },
                    table,
                    grey_cover,
                }
            })
            .collect();
        let shared_depth = match (metallic, pearlescent) {
            (Some(a), Some(b)) => {
                a.split && b.split && a.depth.iter().zip(&b.depth).all(|(x, y)| x.to_bits() == y.to_bits())
            }
            _ => false,
        };
        Folded {
            weights: w.to_vec(),
            coat: w.iter().sum(),
            body: body.iter().zip(w).map(|(b, w)| w * b).sum(),
            flakes,
            shared_depth,
        }
    }
}
