//! A model with a note on where its parameters came from: every evaluation is the inner model's, bit for bit;
//! only [`Brdf::describe`] adds the note. The recipe parser wraps a paint whose coat was derived from its
//! application (docs/model.md §From the cured spectrum to the coat) so that `--explain` shows the cured
//! spectrum, Sq and Sdq beside the model they produced.
use super::{Brdf, Hints};
use crate::spectrum::Sampling;
use crate::Vec3;
use std::sync::Arc;

/// `inner`, described with `note` after its own description.
#[derive(Clone, Debug)]
pub(crate) struct Annotated {
    pub inner: Arc<dyn Brdf>,
    pub note: String,
}

impl Brdf for Annotated {
    fn sampling(&self) -> &Sampling {
        self.inner.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.inner.eval(wi, wo, out)
    }
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.inner.eval_batch(wi, wo, out)
    }
    fn folds(&self, w: &[f64]) -> bool {
        self.inner.folds(w)
    }
    fn eval_batch_folded(&self, w: &[f64], wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) -> bool {
        self.inner.eval_batch_folded(w, wi, wo, out)
    }
    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        self.inner.delta_reflectance(wi, out)
    }
    fn tail_majorant(&self, psi: f64) -> Option<f64> {
        self.inner.tail_majorant(psi)
    }
    fn hints(&self) -> Hints {
        self.inner.hints()
    }
    fn coarser(&self) -> Vec<Arc<dyn Brdf>> {
        self.inner.coarser()
    }
    fn describe(&self) -> String {
        format!("{}; {}", self.inner.describe(), self.note)
    }
}
