//! The limits a workbook is read within (docs/instrument.md §Workbooks, "Limits"): each is checked before the
//! workbook reader allocates anything that the file's numbers size, so that no file under the input limit
//! makes the process use more than 512 MiB (the bound measured in docs/reliability.md).
//!
//! The values are far above any instrument export (a QC sheet of 10 000 panels × 20 readings is 200 000 cells
//! and a few MB of XML) and far below what would matter to the machine: the largest allocations they allow are
//! the decompressed sheet member (64 MiB, which the XML reader may buffer as one event) and the sheet's cells
//! as text (10⁶ cells, about 24 MiB of string headers plus their text).

/// The largest decompressed size of one member of a zip workbook (`.xlsx`, `.xlsb`, `.ods`): 64 MiB.
pub(crate) const MAX_MEMBER_BYTES: u64 = 64 << 20;
/// The largest decompressed size of all members together: 256 MiB (each is read once, to check its CRC).
pub(crate) const MAX_TOTAL_BYTES: u64 = 256 << 20;
/// The largest ratio of a member's decompressed to compressed size, for members over [`RATIO_FLOOR_BYTES`]:
/// spreadsheet XML deflates 5–30×; a zip bomb of spaces deflates about 1 000×.
pub(crate) const MAX_RATIO: u64 = 200;
/// Members smaller than this (1 MiB) are not held to [`MAX_RATIO`].
pub(crate) const RATIO_FLOOR_BYTES: u64 = 1 << 20;
/// The most members a zip workbook may have.
pub(crate) const MAX_MEMBERS: usize = 10_000;
/// The most cells of a sheet's used range (rows × columns, from its first to its last non-empty cell), and
/// of all the sheets of an `.xls` together (its reader reads every sheet when it opens the file).
pub(crate) const MAX_CELLS: u64 = 1_000_000;
/// The most shared strings (`.xlsx` `uniqueCount` and `count`, `.xls` SST counts).
pub(crate) const MAX_SHARED_STRINGS: u64 = 1_000_000;
/// The most sheets of a workbook.
pub(crate) const MAX_SHEETS: u64 = 1_000;
/// The largest workbook file: the input limit of every sheet (16 MiB).
pub(crate) const MAX_FILE_BYTES: usize = 16 << 20;
