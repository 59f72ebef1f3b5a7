//! A topography's description in one call: the map levelled, then its height parameters, its slopes and their
//! distribution, its PSD and its orange-peel bands (docs/topography.md).
use super::heights::{heights, Heights};
use super::level::{level, Levelling};
use super::map::HeightMap;
use super::psd::{psd, Psd2};
use super::slopes::{slopes, SlopeStats, Slopes};
use super::waves::{band_rms, BandRms};
use crate::Result;

/// Everything `glossmeter topography` says of a map.
#[derive(Clone, Debug)]
pub struct Analysis {
    pub levelling: Levelling,
    /// The tilt removed (dz/dx, dz/dy).
    pub tilt: [f64; 2],
    /// The levelled heights, metres (NaN: invalid), as the map's.
    pub levelled: Vec<f64>,
    pub heights: Heights,
    pub slopes: Slopes,
    pub slope_stats: SlopeStats,
    pub psd: Psd2,
    /// The orange-peel bands' rms heights along x (docs/topography.md §Orange-peel bands).
    pub waves: Vec<BandRms>,
}

/// Level `map` and describe it.
pub fn analyse(map: &HeightMap, levelling: Levelling) -> Result<Analysis> {
    let l = level(map, levelling)?;
    let h = heights(&l.z, &map.file)?;
    let s = slopes(&l.z, map.nx, map.ny, map.dx, map.dy, &map.file)?;
    let p = psd(&l.z, map.nx, map.ny, map.dx, map.dy);
    let waves = band_rms(&l.z, map.nx, map.ny, map.dx);
    Ok(Analysis {
        levelling,
        tilt: l.tilt,
        levelled: l.z,
        heights: h,
        slope_stats: s.stats(),
        slopes: s,
        psd: p,
        waves,
    })
}
