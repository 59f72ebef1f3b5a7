//! Measured surface topographies as an input: height maps read from the files profilometers, confocal
//! microscopes and interferometers write, levelled, and described by the ISO 25178-2 parameters, the slope
//! distribution and the power spectral density (docs/topography.md). A topography is read the way every input
//! is: within stated limits checked before anything is allocated ([`map`]), its units and calibration from
//! the file, and every bad value an error naming the file and the field.
//!
//! The folder, one idea a file:
//! * [`map`]: the height map ([`map::HeightMap`], metres, NaN for invalid points), its [`map::Format`] and the
//!   limits ([`map::MAX_FILE_BYTES`], [`map::MAX_POINTS`]);
//! * [`units`]: length units and lengths as files and users write them;
//! * the readers, one per format: [`x3p`] (ISO 25178-72), [`sdf`] (ISO 25178-71, text and binary), [`gsf`]
//!   (Gwyddion Simple Field), [`sur`] (Digital Surf), [`text`] (plain text and CSV matrices, with a [`text::Calibration`] given);
//! * [`level`]: the reference surface removed (mean, plane, polynomial);
//! * [`heights`]: Sq, Sa, Sp, Sv, Sz, Ssk, Sku;
//! * [`slopes`]: the cells' slopes, Sdq, Sdr and the slope-angle histogram;
//! * [`psd`]: the 2-D PSD and its radial average;
//! * [`waves`]: the orange-peel bands (Wa…We, SW, LW) of the profiles along x;
//! * [`synthetic`]: seeded random-phase maps from a PSD family (Gaussian, ABC, fractal, orange peel) and the
//!   SplitMix64 generator they draw phases from;
//! * [`memory`]: maps held in memory under a label a recipe names as a file (the Python package's arrays);
//! * [`analysis`]: the one call that levels a map and computes all of it;
//! * `mod.rs` (this): [`load`] and [`from_bytes`], which tell the format from the file's first bytes.
pub mod analysis;
pub mod gsf;
pub mod heights;
pub mod level;
pub mod map;
pub mod memory;
pub mod psd;
pub mod sdf;
pub mod slopes;
pub mod sur;
pub mod synthetic;
pub mod text;
pub mod units;
pub mod waves;
pub mod x3p;

use std::path::Path;

use crate::{Error, Result};
use map::{HeightMap, MAX_FILE_BYTES};
use text::Calibration;

/// Read a topography file (at most [`MAX_FILE_BYTES`]); `calibration` is used by a plain matrix only.
pub fn load(path: &Path, calibration: Option<Calibration>) -> Result<HeightMap> {
    let file = path.display().to_string();
    let bytes = crate::input::read_bytes_limited(path, "topography", MAX_FILE_BYTES)?;
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    from_bytes(&bytes, &file, &ext, calibration)
}

fn is_sdf(bytes: &[u8]) -> bool {
    bytes.len() >= 4 && matches!(bytes[0], b'a' | b'b') && matches!(&bytes[1..4], b"ISO" | b"BCR")
}

fn is_sur(bytes: &[u8]) -> bool {
    bytes.starts_with(sur::MAGIC) || bytes.starts_with(sur::MAGIC_COMPRESSED)
}

/// Whether a file's first bytes announce one of the calibrated formats (X3P, GSF, SDF, SUR; [`from_bytes`])
/// rather than a plain matrix, whose calibration only its caller can give (docs/topography.md §Plain text
/// matrices).
pub(crate) fn announces_calibrated_format(head: &[u8]) -> bool {
    head.starts_with(b"PK\x03\x04") || head.starts_with(gsf::MAGIC) || is_sdf(head) || is_sur(head)
}

/// The format of a file, from its first bytes: a zip archive is X3P, `Gwyddion Simple Field 1.0` GSF,
/// `aISO`/`bISO` (or the older `aBCR`/`bBCR`) SDF, `DIGITAL SURF` (or `DSCOMPRESSED`) SUR, anything else a
/// plain matrix. An extension that names a
/// format the bytes are not is an error (a damaged file, or the wrong one).
pub fn from_bytes(bytes: &[u8], file: &str, ext: &str, calibration: Option<Calibration>) -> Result<HeightMap> {
    let not = |what: &str| {
        Error::input(file, "", format!("a .{ext} file is {what}, but this one is not (damaged, or not that format)"))
    };
    if bytes.starts_with(b"PK\x03\x04") {
        x3p::read(bytes, file)
    } else if bytes.starts_with(gsf::MAGIC) {
        gsf::read(bytes, file)
    } else if is_sdf(bytes) {
        sdf::read(bytes, file)
    } else if is_sur(bytes) {
        sur::read(bytes, file)
    } else {
        match ext {
            "x3p" => Err(not("a zip archive (ISO 25178-72)")),
            "gsf" => Err(not("a Gwyddion Simple Field, beginning `Gwyddion Simple Field 1.0`")),
            "sdf" => Err(not("an ISO 25178-71 file, beginning `aISO-1.0` or `bISO-1.0`")),
            "sur" => Err(not("a Digital Surf file, beginning `DIGITAL SURF`")),
            _ => {
                let text = std::str::from_utf8(bytes).map_err(|e| {
                    Error::input(
                        file,
                        "",
                        format!(
                            "not a topography this program reads: neither X3P, SDF, GSF, SUR nor a text matrix (invalid \
                             UTF-8 at offset {})",
                            e.valid_up_to()
                        ),
                    )
                })?;
                text::read(text, file, calibration)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_format_is_told_from_the_bytes() {
        let cal = Some(Calibration { dx: 1e-6, dy: 1e-6, z_unit: 1e-9 });
        assert_eq!(from_bytes(b"1 2\n3 4\n", "t.txt", "txt", cal).unwrap().format, map::Format::Text);
        let e = from_bytes(b"1 2\n3 4\n", "t.x3p", "x3p", cal).unwrap_err().to_string();
        assert!(e.contains("zip archive"), "{e}");
        let e = from_bytes(b"1 2\n3 4\n", "t.sur", "sur", cal).unwrap_err().to_string();
        assert!(e.contains("DIGITAL SURF"), "{e}");
        assert!(from_bytes(&[0xff, 0xfe, 0], "t.bin", "bin", cal).unwrap_err().to_string().contains("UTF-8"));
    }
}
