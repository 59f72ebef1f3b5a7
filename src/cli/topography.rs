//! `glossmeter topography FILE`: a measured topography (X3P, SDF, GSF, or a text matrix with its calibration)
//! read, levelled and described: the map, the ISO 25178-2 height and slope parameters, the slope-angle
//! distribution and the radial PSD (docs/topography.md), as a table for people or the JSON document
//! (`report::topography`), and optionally a picture of the levelled height map and the radial PSD
//! (`report::pictures::topography`). The computation is `request::TopographyRequest::read`; this module parses, formats
//! and writes.
use std::path::PathBuf;

use super::common::pad_table;
use super::output::{Existing, OutputTarget};
use crate::report::pictures::topography::draw;
use crate::report::topography::TopographyDoc;
use crate::request::TopographyRequest;
use crate::topography::map::MAX_FILE_BYTES;
use crate::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TopographyFormat {
    Table,
    Json,
}

/// Arguments of `glossmeter topography`.
#[derive(clap::Args, Debug)]
pub struct TopographyArgs {
    /// The topography: ISO 25178-72 .x3p, ISO 25178-71 .sdf (text or binary), Gwyddion .gsf, Digital Surf
    /// .sur, or a text/CSV matrix of heights (one row per line; give --pixel-size and --height-unit).
    pub file: PathBuf,
    /// Output: an aligned table or JSON (`schema --output-format topography`).
    #[arg(long, value_enum, default_value_t = TopographyFormat::Table)]
    pub format: TopographyFormat,
    /// The reference surface removed before the statistics: mean, plane (least squares), poly2 … poly5.
    #[arg(long, default_value = "plane")]
    pub levelling: String,
    /// A text matrix's point spacing, with its unit (e.g. 0.5um); along x, and along y unless --pixel-size-y.
    #[arg(long, value_name = "LENGTH")]
    pub pixel_size: Option<String>,
    /// A text matrix's point spacing between rows, with its unit.
    #[arg(long, value_name = "LENGTH")]
    pub pixel_size_y: Option<String>,
    /// A text matrix's height unit: m, mm, um, nm or pm.
    #[arg(long, value_name = "UNIT")]
    pub height_unit: Option<String>,
    /// Write the result to this new file instead of stdout (refuses to overwrite).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Also draw the levelled height map and the radial PSD to this new .svg or .png file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

/// The request of a command line (the one place where `topography`'s arguments become the library's).
pub fn request(a: &TopographyArgs) -> TopographyRequest {
    TopographyRequest {
        levelling: Some(a.levelling.clone()),
        pixel_size: a.pixel_size.clone(),
        pixel_size_y: a.pixel_size_y.clone(),
        height_unit: a.height_unit.clone(),
    }
}

pub fn run(args: TopographyArgs, existing: Existing) -> Result<()> {
    let req = request(&args);
    // The arguments are checked before the file is read.
    req.levelling()?;
    req.calibration()?;
    let target = OutputTarget::new(args.output.as_deref(), "--output", existing)?;
    if let Some(p) = &args.plot {
        super::plot::check_plot_path(p, "--plot", existing)?;
        if args.output.as_deref() == Some(p.as_path()) {
            return Err(Error::Usage(format!("--plot and --output name the same file {}", p.display())));
        }
    }
    let source = crate::input::Stdin::default().open(&args.file, "topography", MAX_FILE_BYTES)?;
    let (file, bytes) = (source.name(), source.bytes_limited("topography", MAX_FILE_BYTES)?);
    let ext = args.file.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let (map, analysis) = req.read(&bytes, &file, &ext)?;
    let doc = TopographyDoc::new(&map, &analysis);
    let text = match args.format {
        TopographyFormat::Json => doc.text(),
        TopographyFormat::Table => table(&doc),
    };
    if let Some(p) = &args.plot {
        let title = format!("{} ({}, levelling {})", map.file, map.format.name(), doc.levelling);
        crate::render_plot!(p, "--plot", existing, (1200, 560), |root| draw(root, &map, &analysis, &doc, &title))?;
        eprintln!("plot: {} ({} × {} points)", p.display(), map.nx, map.ny);
    }
    target.write(&text)
}

/// The parameters for people: one per line, with its unit.
pub fn table(d: &TopographyDoc) -> String {
    let g = |v: f64| format!("{v:.4}");
    let opt = |v: Option<f64>| v.map(g).unwrap_or_else(|| "—".into());
    let m = &d.map;
    let mut rows = vec![vec!["parameter".to_string(), "value".into(), "unit".into()]];
    let mut row = |p: &str, v: String, u: &str| rows.push(vec![p.to_string(), v, u.to_string()]);
    row("points", format!("{} × {}", m.points_x, m.points_y), "");
    row("spacing", format!("{} × {}", g(m.spacing_x_um), g(m.spacing_y_um)), "µm");
    row("size", format!("{} × {}", g(m.size_x_um), g(m.size_y_um)), "µm");
    row("invalid points", m.invalid_points.to_string(), "");
    row("levelling", d.levelling.clone(), "");
    row("tilt removed", format!("{:.3e}, {:.3e}", d.tilt_x, d.tilt_y), "dz/dx, dz/dy");
    row("Sq", g(d.heights.sq_um), "µm");
    row("Sa", g(d.heights.sa_um), "µm");
    row("Sz", g(d.heights.sz_um), "µm");
    row("Ssk", opt(d.heights.ssk), "");
    row("Sku", opt(d.heights.sku), "");
    row("Sdq", format!("{:.5}", d.slopes.sdq), "");
    row("rms slope x, y", format!("{:.5}, {:.5}", d.slopes.rms_x, d.slopes.rms_y), "");
    row("Sdr", format!("{:.4e}", d.slopes.sdr), "");
    row("steepest slope", format!("{:.2}", d.slopes.max_angle_deg), "°");
    row("spectral rms slope", format!("{:.5}", d.slopes.spectral_rms_slope), "");
    for w in &d.waves.bands {
        let what = format!("{} ({}–{} mm, rms)", w.name, w.from_mm, w.to_mm);
        row(&what, w.rms_um.map(g).unwrap_or_else(|| "—".into()), "µm");
    }
    let mut s = format!("{}: {} topography\n", m.file, m.format);
    s.push_str(&pad_table(&rows, &[1]));
    s
}
