//! The document of `glossmeter topography --format json` ([`TopographyDoc`]): the map, its levelling, its
//! height and slope parameters, the slope-angle histogram and the radial PSD (docs/topography.md), from which
//! `report::schema::topography` derives its JSON Schema. Lengths are in micrometres, the PSD in nm²·µm² (the
//! unit of `optics::scatter`'s PSDs) and spatial frequencies in 1/µm.
use schemars::JsonSchema;
use serde::Serialize;

use crate::topography::analysis::Analysis;
use crate::topography::map::HeightMap;

/// Width of the slope-angle histogram's bins, degrees, and their number (the last takes every steeper cell).
pub(crate) const ANGLE_BIN_DEG: f64 = 1.0;
pub(crate) const ANGLE_BINS: usize = 45;

/// The map as read.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct TopographyMapDoc {
    /// The file (`<stdin>` for standard input).
    pub file: String,
    /// `x3p`, `sdf-text`, `sdf-binary`, `gsf`, `sur`, `text` or `array` (a NumPy array from Python).
    pub format: String,
    /// Points along x and y.
    pub points_x: usize,
    pub points_y: usize,
    /// Point spacing along x and y, µm.
    #[schemars(range(min = 0))]
    pub spacing_x_um: f64,
    #[schemars(range(min = 0))]
    pub spacing_y_um: f64,
    /// The map's extent, points × spacing, µm.
    pub size_x_um: f64,
    pub size_y_um: f64,
    /// Valid points, and points masked or not measured.
    pub valid_points: usize,
    pub invalid_points: usize,
}

/// The height parameters of ISO 25178-2 over the valid points of the levelled map, µm.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = heights_nullable)]
pub struct TopographyHeightsDoc {
    /// Root mean square height.
    #[schemars(range(min = 0))]
    pub sq_um: f64,
    /// Arithmetic mean height.
    #[schemars(range(min = 0))]
    pub sa_um: f64,
    /// Maximum peak height, maximum pit depth, maximum height (Sp + Sv).
    pub sp_um: f64,
    pub sv_um: f64,
    #[schemars(range(min = 0))]
    pub sz_um: f64,
    /// Skewness and kurtosis; null for a flat map (Sq = 0).
    pub ssk: Option<f64>,
    pub sku: Option<f64>,
}

fn heights_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["ssk", "sku"]);
}

/// One bin of the slope-angle histogram.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct AngleBinDoc {
    /// The bin's lower edge, degrees.
    pub from_deg: f64,
    /// Its upper edge, degrees (null for the last bin, which takes every steeper cell).
    pub to_deg: Option<f64>,
    /// The fraction of the cells whose slope angle atan|∇z| is in it.
    #[schemars(range(min = 0, max = 1))]
    pub fraction: f64,
}

/// The slopes of the levelled map's cells.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct TopographySlopesDoc {
    /// Root mean square gradient Sdq (dimensionless: a slope, tan of an angle).
    #[schemars(range(min = 0))]
    pub sdq: f64,
    /// The rms slopes along x and y (Sdq² = rms_x² + rms_y²).
    #[schemars(range(min = 0))]
    pub rms_x: f64,
    #[schemars(range(min = 0))]
    pub rms_y: f64,
    /// The mean slopes along x and y.
    pub mean_x: f64,
    pub mean_y: f64,
    /// Developed interfacial area ratio Sdr (a fraction, not per cent).
    #[schemars(range(min = 0))]
    pub sdr: f64,
    /// The steepest cell's slope angle, degrees.
    pub max_angle_deg: f64,
    /// The rms slope of the PSD's band, √(Σ (2π|f|)² S Δf²): Sdq without the finite difference's attenuation of
    /// the shortest waves.
    #[schemars(range(min = 0))]
    pub spectral_rms_slope: f64,
    /// The cells of four valid points the slopes are read on.
    pub cells: usize,
    /// The histogram of the slope angle.
    pub angle_histogram: Vec<AngleBinDoc>,
}

/// One annulus of the radial PSD.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct RadialPsdDoc {
    /// The mean spatial frequency |f| of the annulus's grid points, 1/µm.
    pub frequency_per_um: f64,
    /// The mean two-sided 2-D PSD over them, nm²·µm².
    #[schemars(range(min = 0))]
    pub psd_nm2_um2: f64,
    /// How many grid frequencies the annulus holds.
    pub count: usize,
}

/// The power spectral density of the levelled map.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct TopographyPsdDoc {
    /// The normalisation, in words.
    pub convention: String,
    /// The grid's frequency steps, 1/µm.
    pub step_x_per_um: f64,
    pub step_y_per_um: f64,
    /// The radial average, annuli of width max(step_x, step_y).
    pub radial: Vec<RadialPsdDoc>,
}

/// One orange-peel band of the profiles along x (docs/topography.md §Orange-peel bands).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = waves_nullable)]
pub struct WaveBandDoc {
    /// `Wa` … `We`, `SW` or `LW`.
    pub name: String,
    /// The band's wavelengths, mm (from inclusive, to exclusive).
    pub from_mm: f64,
    pub to_mm: f64,
    /// The rms height of the profiles' components in the band, µm; null when the map cannot resolve it.
    #[schemars(range(min = 0))]
    pub rms_um: Option<f64>,
    /// Why there is no value (the map too short or too coarse, or no complete row); null with a value.
    pub problem: Option<String>,
}

fn waves_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["rms_um", "problem"]);
}

/// The orange-peel bands.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct TopographyWavesDoc {
    /// What the values are, in words: not the 0–100 scale of a wave-scan instrument.
    pub convention: String,
    pub bands: Vec<WaveBandDoc>,
}

/// `topography --format json`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct TopographyDoc {
    pub map: TopographyMapDoc,
    /// The reference surface removed: `mean`, `plane` or `poly2` … `poly5`.
    pub levelling: String,
    /// The tilt removed, dz/dx and dz/dy (0 for `mean`).
    pub tilt_x: f64,
    pub tilt_y: f64,
    pub heights: TopographyHeightsDoc,
    pub slopes: TopographySlopesDoc,
    pub psd: TopographyPsdDoc,
    pub waves: TopographyWavesDoc,
}

const UM: f64 = 1e6;

impl TopographyDoc {
    pub fn new(map: &HeightMap, a: &Analysis) -> TopographyDoc {
        let valid = a.heights.points;
        let h = &a.heights;
        let s = &a.slope_stats;
        let histogram = a.slopes.angle_histogram(ANGLE_BIN_DEG, ANGLE_BINS);
        TopographyDoc {
            map: TopographyMapDoc {
                file: map.file.clone(),
                format: map.format.name().into(),
                points_x: map.nx,
                points_y: map.ny,
                spacing_x_um: map.dx * UM,
                spacing_y_um: map.dy * UM,
                size_x_um: map.nx as f64 * map.dx * UM,
                size_y_um: map.ny as f64 * map.dy * UM,
                valid_points: valid,
                invalid_points: map.nx * map.ny - valid,
            },
            levelling: a.levelling.name(),
            tilt_x: a.tilt[0],
            tilt_y: a.tilt[1],
            heights: TopographyHeightsDoc {
                sq_um: h.sq * UM,
                sa_um: h.sa * UM,
                sp_um: h.sp * UM,
                sv_um: h.sv * UM,
                sz_um: h.sz * UM,
                ssk: h.ssk,
                sku: h.sku,
            },
            slopes: TopographySlopesDoc {
                sdq: s.sdq,
                rms_x: s.rms_x,
                rms_y: s.rms_y,
                mean_x: s.mean_x,
                mean_y: s.mean_y,
                sdr: s.sdr,
                max_angle_deg: s.max_angle_deg,
                spectral_rms_slope: a.psd.rms_slope(),
                cells: s.cells,
                angle_histogram: histogram
                    .iter()
                    .enumerate()
                    .map(|(k, &fraction)| AngleBinDoc {
                        from_deg: k as f64 * ANGLE_BIN_DEG,
                        to_deg: (k + 1 < ANGLE_BINS).then(|| (k + 1) as f64 * ANGLE_BIN_DEG),
                        fraction,
                    })
                    .collect(),
            },
            psd: TopographyPsdDoc {
                convention: "two-sided 2-D PSD S(f) = Δx·Δy·|DFT(z)|²/(Nx·Ny), invalid points at the reference \
                             surface and the power scaled by N/N_valid, no window; Σ S·Δfx·Δfy = Sq² (docs/topography.md \
                             §Power spectral density)"
                    .into(),
                step_x_per_um: a.psd.dfx / UM,
                step_y_per_um: a.psd.dfy / UM,
                radial: a
                    .psd
                    .radial()
                    .iter()
                    .map(|b| RadialPsdDoc {
                        frequency_per_um: b.f / UM,
                        // m⁴ → nm²·µm²: 10¹⁸ · 10¹².
                        psd_nm2_um2: b.s * 1e30,
                        count: b.count,
                    })
                    .collect(),
            },
            waves: TopographyWavesDoc {
                convention: "rms height of the levelled profiles along x in each band, from each complete row's \
                             periodogram (docs/topography.md §Orange-peel bands); the bands are the wave-scan \
                             instruments', the values are not their 0–100 scale (unpublished)"
                    .into(),
                bands: a
                    .waves
                    .iter()
                    .map(|w| WaveBandDoc {
                        name: w.band.name.into(),
                        from_mm: w.band.shortest * 1e3,
                        to_mm: w.band.longest * 1e3,
                        rms_um: w.rms.as_ref().ok().map(|v| v * UM),
                        problem: w.rms.as_ref().err().cloned(),
                    })
                    .collect(),
            },
        }
    }

    /// The JSON text (pretty, keys in alphabetical order, a final newline).
    pub(crate) fn text(&self) -> String {
        super::pretty(&super::to_json(self))
    }
}
