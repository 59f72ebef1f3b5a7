//! The pictures as files: PNG or SVG, chosen by the file name, drawn in memory by the drawing code of
//! `report::pictures` and written whole or not at all; a file is never overwritten (but with `--force`).
use std::path::Path;

use super::output::Existing;
use crate::instrument::convergence::Sweep;
pub(crate) use crate::report::pictures::{draw_sweep, register_font, PlotSummary};
use crate::{Error, Result};

/// The picture formats, from the file name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFormat {
    Svg,
    Png,
}

/// The format of a plot file from its extension; anything but `.svg` / `.png` is a usage error. An existing
/// file, or a missing directory, is refused before any work (glossmeter never overwrites a file); `option`
/// names the flag in the message; `existing` is `--force`'s answer.
pub fn check_plot_path(path: &Path, option: &str, existing: Existing) -> Result<PlotFormat> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let format = match ext.as_deref() {
        Some("svg") => PlotFormat::Svg,
        Some("png") => PlotFormat::Png,
        _ => {
            return Err(Error::Usage(format!(
                "{option} {}: the plot file name must end in .svg or .png (the format is taken from it)",
                path.display()
            )))
        }
    };
    super::output::check_new_file(path, option, existing)?;
    Ok(format)
}

/// Encode an 8-bit RGB raster as PNG bytes.
pub fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgb, w, h, image::ColorType::Rgb8)
        .map_err(|e| Error::Numeric(format!("PNG encoding failed: {e}")))?;
    Ok(png)
}

/// Draw with `$draw` (a closure taking a `DrawingArea`, written once and expanded for each backend) into a new
/// file at `$path`, PNG or SVG by its name, of `$size` pixels; evaluates to the closure's `Result`. The picture
/// is drawn in memory and written with `output::write_new_file`, so the file appears whole or not at all and
/// an existing file is never overwritten unless `$existing` (an `output::Existing`) replaces it (`$option` names
/// the flag in the messages).
#[macro_export]
#[doc(hidden)]
macro_rules! render_plot {
    ($path:expr, $option:expr, $existing:expr, $size:expr, $draw:expr) => {{
        let path: &std::path::Path = $path;
        let existing: $crate::cli::output::Existing = $existing;
        let size: (u32, u32) = $size;
        match $crate::cli::plot::check_plot_path(path, $option, existing) {
            Err(e) => Err(e),
            Ok(format) => {
                $crate::cli::plot::register_font();
                let drawn = match format {
                    $crate::cli::plot::PlotFormat::Svg => {
                        let mut svg = String::new();
                        let out = {
                            let root = plotters::prelude::IntoDrawingArea::into_drawing_area(
                                plotters::prelude::SVGBackend::with_string(&mut svg, size),
                            );
                            ($draw)(root)
                        };
                        out.map(|v| (v, svg.into_bytes()))
                    }
                    $crate::cli::plot::PlotFormat::Png => {
                        let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
                        let out = {
                            let root = plotters::prelude::IntoDrawingArea::into_drawing_area(
                                plotters::prelude::BitMapBackend::with_buffer(&mut rgb, size),
                            );
                            ($draw)(root)
                        };
                        out.and_then(|v| $crate::cli::plot::encode_png(&rgb, size).map(|png| (v, png)))
                    }
                };
                drawn.and_then(|(v, bytes)| $crate::cli::output::write_new_file(path, &bytes, existing).map(|_| v))
            }
        }
    }};
}

/// Render the sweep to a new PNG or SVG file (by its name; refusing to overwrite one).
pub fn write_plot(sweep: &Sweep, title: &str, path: &Path, existing: Existing) -> Result<PlotSummary> {
    crate::render_plot!(path, "--plot", existing, (1000, 720), |root| draw_sweep(root, sweep, title))
}
