//! The guard of `.xls` workbooks, run before calamine opens one (docs/instrument.md §Workbooks, "Limits").
//! calamine's `.xls` reader reads the whole file when it opens it: it follows the compound file's sector
//! chains without a bound (a chain that loops grows a buffer until memory runs out), reserves the cells a
//! DIMENSIONS record states (a reversed record wraps to hundreds of GB), and lays out every sheet's used range.
//! So the file is read here first, by the rules of [MS-CFB] and [MS-XLS], with every chain bounded and every
//! count checked:
//!
//! 1. the compound file (MS-CFB §2.2 header, §2.3 DIFAT, FAT and mini FAT, §2.6 directory entries): sector ids
//!    inside the file, chains without loops, no longer than the file, stream sizes their chains can hold;
//! 2. the `Workbook` (or `Book`) stream's BIFF records (MS-XLS §2.1.4): each record inside the stream; the
//!    sheets (BoundSheet8, §2.4.28) at most [`MAX_SHEETS`]; the shared strings (SST, §2.4.265) at most
//!    [`MAX_SHARED_STRINGS`]; each sheet's DIMENSIONS (§2.4.90) not reversed, and the used ranges of the
//!    cells (§2.4.181 Number, RK, MulRk, LabelSst, Label, BoolErr, Formula) of all sheets together at most
//!    [`MAX_CELLS`].
use super::limits::*;
use crate::{Error, Result};

const END_OF_CHAIN: u32 = 0xFFFF_FFFE;
const FREE: u32 = 0xFFFF_FFFF;
/// Sector ids at or above this are markers, not sectors (MS-CFB §2.2: MAXREGSECT = 0xFFFFFFFA).
const MAX_REGULAR: u32 = 0xFFFF_FFFA;

fn u16_at(b: &[u8], i: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(i..i + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], i: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(i..i + 4)?.try_into().ok()?))
}

/// Check an `.xls` file: its compound-file structure, then its workbook stream's records.
pub(crate) fn check(bytes: &[u8], file: &str) -> Result<()> {
    let bad = |m: String| Error::input(file, "", format!("not a readable .xls workbook: {m}"));
    let cfb = Cfb::new(bytes).map_err(bad)?;
    let stream = cfb.workbook_stream().map_err(bad)?;
    check_records(&stream).map_err(|m| Error::input(file, "Workbook stream", m))
}

/// A compound file, read by MS-CFB with every id and chain checked.
struct Cfb<'a> {
    bytes: &'a [u8],
    sector: usize,
    fat: Vec<u32>,
    /// The sectors of the file after the header.
    sectors: u32,
    mini_cutoff: u64,
    mini_fat_start: u32,
    dir_start: u32,
}

impl<'a> Cfb<'a> {
    fn new(bytes: &'a [u8]) -> std::result::Result<Cfb<'a>, String> {
        let h = bytes.get(..512).ok_or("shorter than a compound file's 512-byte header")?;
        let shift = u16_at(h, 30).unwrap_or(0);
        let sector = match shift {
            9 => 512usize,
            12 => 4096,
            s => return Err(format!("sector shift {s} in the header (MS-CFB allows 9 or 12)")),
        };
        if u16_at(h, 32) != Some(6) {
            return Err("mini sector shift is not 6 (MS-CFB §2.2)".into());
        }
        let sectors = bytes.len().saturating_sub(sector).div_ceil(sector) as u32;
        let mut cfb = Cfb {
            bytes,
            sector,
            fat: vec![],
            sectors,
            mini_cutoff: u32_at(h, 56).unwrap_or(0) as u64,
            mini_fat_start: u32_at(h, 60).unwrap_or(END_OF_CHAIN),
            dir_start: u32_at(h, 48).unwrap_or(END_OF_CHAIN),
        };
        let fat_sectors = cfb.difat(h)?;
        let mut fat = Vec::with_capacity(fat_sectors.len() * sector / 4);
        for id in fat_sectors {
            fat.extend(cfb.sector(id)?.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
        }
        cfb.fat = fat;
        Ok(cfb)
    }

    /// The FAT sectors: the header's 109 DIFAT entries, then the DIFAT chain's (MS-CFB §2.5), each in the file.
    fn difat(&self, h: &[u8]) -> std::result::Result<Vec<u32>, String> {
        let mut ids: Vec<u32> = (0..109).filter_map(|i| u32_at(h, 76 + 4 * i)).collect();
        let mut next = u32_at(h, 68).unwrap_or(END_OF_CHAIN);
        let mut steps = 0u32;
        while next < MAX_REGULAR {
            steps += 1;
            if steps > self.sectors {
                return Err("the DIFAT chain loops".into());
            }
            let s = self.sector(next)?;
            let n = self.sector / 4 - 1;
            ids.extend((0..n).filter_map(|i| u32_at(s, 4 * i)));
            next = u32_at(s, 4 * n).unwrap_or(END_OF_CHAIN);
        }
        let ids: Vec<u32> = ids.into_iter().filter(|&id| id != FREE && id < MAX_REGULAR).collect();
        if ids.len() as u64 > self.sectors as u64 {
            return Err("more FAT sectors than the file has sectors".into());
        }
        Ok(ids)
    }

    fn sector(&self, id: u32) -> std::result::Result<&'a [u8], String> {
        if id >= self.sectors {
            return Err(format!("sector {id} is past the end of the file ({} sectors)", self.sectors));
        }
        // The last sector may be short (calamine reads what there is).
        let start = (id as usize + 1) * self.sector;
        Ok(&self.bytes[start..(start + self.sector).min(self.bytes.len())])
    }

    /// The ids of a FAT chain, checked: each a sector of the file, no loop (no chain is longer than the file).
    fn chain(&self, start: u32, what: &str) -> std::result::Result<Vec<u32>, String> {
        walk(start, &self.fat, self.sectors, what)
    }

    /// The directory entries (MS-CFB §2.6): name, type, start, size.
    fn directory(&self) -> std::result::Result<Vec<(String, u8, u32, u64)>, String> {
        let ids = self.chain(self.dir_start, "the directory")?;
        let mut entries = vec![];
        for id in ids {
            for e in self.sector(id)?.chunks_exact(128) {
                let name_len = (u16_at(e, 64).unwrap_or(0) as usize).min(64);
                let units: Vec<u16> = e[..name_len].chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
                let name = String::from_utf16_lossy(&units).trim_end_matches('\0').to_string();
                let size = if self.sector == 512 {
                    u32_at(e, 120).unwrap_or(0) as u64
                } else {
                    u64::from_le_bytes(e[120..128].try_into().unwrap_or([0; 8]))
                };
                entries.push((name, e[66], u32_at(e, 116).unwrap_or(END_OF_CHAIN), size));
            }
        }
        if entries.first().is_none_or(|e| e.1 != 5) {
            return Err("the directory has no root entry".into());
        }
        Ok(entries)
    }

    /// The `Workbook` (or `Book`, BIFF5) stream, with the chains calamine follows to read it checked too.
    fn workbook_stream(&self) -> std::result::Result<Vec<u8>, String> {
        let dir = self.directory()?;
        let root = &dir[0];
        // The mini stream and the mini FAT, read whenever the file has a mini FAT.
        let mini_ids = self.chain(root.2, "the mini stream")?;
        let held = (mini_ids.len() * self.sector) as u64;
        let mini = gather(&mini_ids, self.sector, root.3.min(held), "the mini stream", |id| self.sector(id).ok())?;
        let mini_fat_ids = self.chain(self.mini_fat_start, "the mini FAT")?;
        let held = (mini_fat_ids.len() * self.sector) as u64;
        let mini_fat_bytes = gather(&mini_fat_ids, self.sector, held, "the mini FAT", |id| self.sector(id).ok())?;
        let mini_fat: Vec<u32> =
            mini_fat_bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let names = ["Workbook", "Book", "WORKBOOK", "BOOK"];
        let Some(entry) = names.iter().find_map(|n| dir.iter().find(|e| e.1 == 2 && e.0 == *n)) else {
            return Err("no Workbook stream (not an Excel 97–2003 file?)".into());
        };
        let (_, _, start, size) = entry;
        if *size < self.mini_cutoff {
            let ids = walk(*start, &mini_fat, (mini.len() / 64) as u32, "the Workbook stream")?;
            gather(&ids, 64, *size, "the Workbook stream", |id| mini.get(id as usize * 64..id as usize * 64 + 64))
        } else {
            let ids = self.chain(*start, "the Workbook stream")?;
            gather(&ids, self.sector, *size, "the Workbook stream", |id| self.sector(id).ok())
        }
    }
}

/// The ids of a chain in `table` from `start`: each below `count`, no loop, at most `count` long.
fn walk(start: u32, table: &[u32], count: u32, what: &str) -> std::result::Result<Vec<u32>, String> {
    let mut ids = vec![];
    let mut id = start;
    while id != END_OF_CHAIN && id != FREE {
        if id >= count || id as usize >= table.len() {
            return Err(format!("{what}'s chain points at sector {id}, past the end"));
        }
        if ids.len() as u32 >= count {
            return Err(format!("{what}'s chain loops"));
        }
        ids.push(id);
        id = table[id as usize];
    }
    Ok(ids)
}

/// The bytes of a stream of `len` bytes from a chain of `unit`-byte pieces; the chain must hold them.
fn gather<'b>(
    ids: &[u32],
    unit: usize,
    len: u64,
    what: &str,
    piece: impl Fn(u32) -> Option<&'b [u8]>,
) -> std::result::Result<Vec<u8>, String> {
    if (ids.len() as u64) * (unit as u64) < len {
        return Err(format!("{what} says {len} bytes, but its chain holds {}", ids.len() * unit));
    }
    let mut out = Vec::with_capacity(len as usize);
    for &id in ids {
        out.extend_from_slice(piece(id).ok_or_else(|| format!("{what}: piece {id} is past the end"))?);
    }
    out.truncate(len as usize);
    Ok(out)
}

/// The used range of one sheet's cells, growing as records are read.
#[derive(Default)]
struct Extent(Option<(u32, u32, u32, u32)>);

impl Extent {
    fn add(&mut self, row: u32, first_col: u32, last_col: u32) {
        self.0 = Some(match self.0 {
            None => (row, row, first_col, last_col),
            Some((r0, r1, c0, c1)) => (r0.min(row), r1.max(row), c0.min(first_col), c1.max(last_col)),
        });
    }

    fn cells(&self) -> u64 {
        self.0.map_or(0, |(r0, r1, c0, c1)| (r1 - r0 + 1) as u64 * (c1.saturating_sub(c0) + 1) as u64)
    }
}

/// The workbook stream's records (MS-XLS §2.1.4): the globals' counts, then each sheet's substream from the
/// position its BoundSheet8 record gives, to its EOF record.
fn check_records(stream: &[u8]) -> std::result::Result<(), String> {
    let mut positions = vec![];
    for (typ, data) in records(stream, 0) {
        let data = data?;
        match typ {
            0x0085 => {
                positions.push(u32_at(data, 0).ok_or("a BoundSheet8 record shorter than 4 bytes")? as usize);
                if positions.len() as u64 > MAX_SHEETS {
                    return Err(format!("more than {MAX_SHEETS} sheets"));
                }
            }
            0x00FC => {
                let (total, unique) = (u32_at(data, 0).unwrap_or(0) as u64, u32_at(data, 4).unwrap_or(0) as u64);
                if total.max(unique) > MAX_SHARED_STRINGS {
                    return Err(format!(
                        "the shared-string table (SST) says {} strings; at most {MAX_SHARED_STRINGS} are read",
                        total.max(unique)
                    ));
                }
            }
            0x000A => break,
            _ => {}
        }
    }
    let mut cells = 0u64;
    for &pos in &positions {
        if pos >= stream.len() {
            return Err(format!("a sheet starts at byte {pos}, past the stream's end ({} bytes)", stream.len()));
        }
        cells = cells.saturating_add(sheet_cells(stream, pos)?);
        if cells > MAX_CELLS {
            return Err(format!(
                "the sheets' used ranges (and their DIMENSIONS records) come to {cells} cells; at most {MAX_CELLS} \
                 are read"
            ));
        }
    }
    Ok(())
}

/// The cells a sheet's substream makes calamine hold: its DIMENSIONS record's area (reserved) and its cells'
/// used range (laid out).
fn sheet_cells(stream: &[u8], pos: usize) -> std::result::Result<u64, String> {
    let mut extent = Extent::default();
    let mut reserved = 0u64;
    for (typ, data) in records(stream, pos) {
        let data = data?;
        let rc = || -> std::result::Result<(u32, u32), String> {
            match (u16_at(data, 0), u16_at(data, 2)) {
                (Some(r), Some(c)) => Ok((r as u32, c as u32)),
                _ => Err(format!("a cell record (type {typ:#06x}) shorter than 4 bytes")),
            }
        };
        match typ {
            0x0200 => reserved = reserved.max(dimensions(data)?),
            0x0203 | 0x027E | 0x00FD | 0x0204 | 0x0205 | 0x0006 => {
                let (r, c) = rc()?;
                extent.add(r, c, c);
            }
            0x00BD => {
                let (r, c) = rc()?;
                let last = u16_at(data, data.len().saturating_sub(2)).unwrap_or(0) as u32;
                extent.add(r, c, last.max(c));
            }
            0x000A => break,
            _ => {}
        }
    }
    Ok(reserved.saturating_add(extent.cells()))
}

/// A DIMENSIONS record's area (MS-XLS §2.4.90: first row, last row + 1, first column, last column + 1), refused
/// when reversed.
fn dimensions(r: &[u8]) -> std::result::Result<u64, String> {
    let (rf, rl, cf, cl) = match r.len() {
        10 => (u16_at(r, 0).unwrap_or(0) as u64, u16_at(r, 2).unwrap_or(0) as u64, u16_at(r, 4), u16_at(r, 6)),
        14 => (u32_at(r, 0).unwrap_or(0) as u64, u32_at(r, 4).unwrap_or(0) as u64, u16_at(r, 8), u16_at(r, 10)),
        n => return Err(format!("a DIMENSIONS record of {n} bytes (MS-XLS: 10 or 14)")),
    };
    let (cf, cl) = (cf.unwrap_or(0) as u64, cl.unwrap_or(0) as u64);
    // calamine reads a first column over 0xFF or after the last as 0.
    let cf = if cf > 0xFF || cl < cf { 0 } else { cf };
    if rl >= 1 && rl < rf {
        return Err(format!("a reversed DIMENSIONS record: rows {rf} to {}", rl as i64 - 1));
    }
    if rl == 0 || cl == 0 {
        return Ok(1);
    }
    let area = (rl - rf).saturating_mul(cl - cf);
    if area > MAX_CELLS {
        return Err(format!(
            "a DIMENSIONS record of {} rows × {} columns ({area} cells); at most {MAX_CELLS} are read",
            rl - rf,
            cl - cf
        ));
    }
    Ok(area)
}

/// The records from `pos`: (type, data), an error for one that runs past the stream.
fn records(stream: &[u8], pos: usize) -> impl Iterator<Item = (u16, std::result::Result<&[u8], String>)> {
    let mut p = pos;
    std::iter::from_fn(move || {
        let typ = u16_at(stream, p)?;
        let len = u16_at(stream, p + 2)? as usize;
        let start = p + 4;
        p = start + len;
        match stream.get(start..start + len) {
            Some(d) => Some((typ, Ok(d))),
            None => {
                p = stream.len();
                Some((typ, Err(format!("a record (type {typ:#06x}) at byte {} runs past the stream's end", start - 4))))
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dim(rf: u32, rl: u32, cf: u16, cl: u16) -> Vec<u8> {
        [&rf.to_le_bytes()[..], &rl.to_le_bytes(), &cf.to_le_bytes(), &cl.to_le_bytes(), &[0, 0]].concat()
    }

    #[test]
    fn dimensions_records() {
        assert_eq!(dimensions(&dim(0, 10, 0, 4)), Ok(40));
        assert!(dimensions(&dim(10, 2, 0, 4)).unwrap_err().contains("reversed"));
        assert!(dimensions(&dim(0, 1_000_000, 0, 255)).unwrap_err().contains("at most 1000000"));
        assert_eq!(dimensions(&dim(0, 0, 0, 0)), Ok(1));
        assert!(dimensions(&[0; 7]).is_err());
    }

    #[test]
    fn chains_that_loop_or_leave_the_file_are_refused() {
        // 0 → 1 → 0: a loop.
        assert!(walk(0, &[1, 0], 2, "x").unwrap_err().contains("loops"));
        assert!(walk(0, &[5], 1, "x").unwrap_err().contains("past the end"));
        assert_eq!(walk(0, &[1, END_OF_CHAIN], 2, "x"), Ok(vec![0, 1]));
        let records = [&0x0200u16.to_le_bytes()[..], &14u16.to_le_bytes(), &dim(0, 3, 0, 2)].concat();
        assert_eq!(sheet_cells(&records, 0), Ok(6));
        assert!(sheet_cells(&records[..10], 0).unwrap_err().contains("runs past"));
    }
}
