//! A topography read by the Kirchhoff method (`"method": "kirchhoff"`, docs/optics.md §11): a material whose
//! aperture fluxes are the map's scalar Kirchhoff far field (`optics::kirchhoff`), handed to the planner
//! through [`Brdf::far_field`]. As a BRDF (what the planner designs its methods from, and `--explain` prints)
//! it is the smooth interface of the same index; no specimen aperture flux is integrated from it.
use super::dielectric::SmoothDielectric;
use super::{Brdf, FarField, FarFieldFlux, Hints};
use crate::optics::kirchhoff::{Aperture, KirchhoffMap, StopBox};
use crate::spectrum::Sampling;
use crate::Vec3;

#[derive(Debug)]
pub(crate) struct KirchhoffSurface {
    pub map: KirchhoffMap,
    /// The recipe file and the map's description, for refusals and `describe`.
    pub file: String,
    pub source: String,
    design: SmoothDielectric,
}

impl KirchhoffSurface {
    pub fn new(map: KirchhoffMap, file: String, source: String) -> KirchhoffSurface {
        let design = SmoothDielectric::new(map.ior);
        KirchhoffSurface { map, file, source, design }
    }
}

impl Brdf for KirchhoffSurface {
    fn sampling(&self) -> &Sampling {
        self.design.sampling()
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.design.eval(wi, wo, out)
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        self.design.delta_reflectance(wi, out)
    }

    fn hints(&self) -> Hints {
        self.design.hints()
    }

    fn far_field(&self) -> Option<&dyn FarField> {
        Some(self)
    }

    fn describe(&self) -> String {
        format!(
            "topography by the scalar Kirchhoff far field ({}, edge {}, n = {}, λ = {} nm; docs/optics.md §11)",
            self.source,
            self.map.edge.name(),
            self.map.ior,
            self.map.wavelength * 1e9
        )
    }
}

impl FarField for KirchhoffSurface {
    fn aperture_flux(
        &self,
        theta: f64,
        viewing: f64,
        source: [[f64; 2]; 2],
        receptor: [[f64; 2]; 2],
    ) -> std::result::Result<FarFieldFlux, String> {
        let a = Aperture {
            theta,
            viewing,
            source: StopBox { p: source[0], q: source[1] },
            receptor: StopBox { p: receptor[0], q: receptor[1] },
        };
        match self.map.aperture_flux(&a) {
            Ok(f) => Ok(FarFieldFlux { value: f.value, error: f.error, data_uncertainty: f.speckle() }),
            Err(e) => Err(format!("{}: /file: {e}", self.file)),
        }
    }
}
