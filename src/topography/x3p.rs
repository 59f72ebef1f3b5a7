//! ISO 25178-72 XML 3D surface profiles (`.x3p`): a zip archive holding `main.xml` (the axes, the grid and
//! where the data are) and, for a binary map, `bindata/data.bin` and optionally a mask of valid points
//! (docs/topography.md §ISO 25178-72 X3P; the schema: openGPS ISO5436_2.xsd).
//!
//! Read: a surface (`FeatureType` SUR) on an incremental x–y grid (`AxisType` I, with its `Increment`, metres),
//! heights of data type I (i16), L (i32), F (f32) or D (f64), little-endian, x fastest, scaled as
//! z = Offset + Increment·value (both optional: 0 and 1); invalid points are NaN in F and D data, the cleared
//! bits of the `ValidPointsLink` mask (one bit per point, least significant bit first), or empty `Datum`
//! elements of a `DataList`. Not read: profiles (PRF), point clouds (PCL), absolute x or y axes, more than one
//! layer (SizeZ > 1); the `Rotation` of the axes is ignored. The zip members' CRC-32 is checked as they are
//! inflated; the MD5 sums are not.
use std::io::{Cursor, Read};

use quick_xml::events::Event;

use super::map::{check_dimensions, check_spacing, Format, HeightMap, MAX_FILE_BYTES};
use crate::error::number;
use crate::{Error, Result};

type Archive<'a> = zip::ZipArchive<Cursor<&'a [u8]>>;

/// What `main.xml` says, by element path below the root (`Record1/Axes/CX/Increment`).
struct Main {
    values: Vec<(String, String)>,
    /// The `Datum` elements of `Record3/DataList`, in order (`None`: an empty one, an invalid point).
    data_list: Option<Vec<Option<String>>>,
}

impl Main {
    fn get(&self, path: &str) -> Option<&str> {
        self.values.iter().find(|(p, _)| p == path).map(|(_, v)| v.trim())
    }
}

/// Read an X3P file's bytes; `file` names it in messages.
pub fn read(bytes: &[u8], file: &str) -> Result<HeightMap> {
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| {
        Error::input(file, "", format!("not a readable X3P file: its zip archive is damaged or truncated ({e})"))
    })?;
    let folder = root_folder(&zip, file)?;
    let xml = member(&mut zip, file, &format!("{folder}main.xml"), MAX_FILE_BYTES, None)?;
    let main = parse_main(&xml, file)?;
    let field = |p: &str| format!("main.xml/{p}");
    let bad = |p: &str, m: String| Error::input(file, field(p), m);
    let need = |p: &str| main.get(p).ok_or_else(|| bad(p, "missing".into()));
    let feature = need("Record1/FeatureType")?;
    if feature != "SUR" {
        return Err(bad(
            "Record1/FeatureType",
            format!("`{feature}`: only surfaces are read; allowed: SUR (not PRF, a profile, nor PCL, a point cloud)"),
        ));
    }
    let mut spacing = [0.0; 2];
    for (i, axis) in ["CX", "CY"].iter().enumerate() {
        let at = format!("Record1/Axes/{axis}/AxisType");
        let kind = need(&at)?;
        if kind != "I" {
            return Err(bad(
                &at,
                format!("`{kind}`: the map has no lateral calibration this reader takes; allowed: I (incremental, with its Increment)"),
            ));
        }
        let at = format!("Record1/Axes/{axis}/Increment");
        let v =
            main.get(&at).ok_or_else(|| bad(&at, "missing: without it the map has no lateral calibration".into()))?;
        let d: f64 = v.parse().map_err(|_| bad(&at, format!("`{v}` is not a number")))?;
        spacing[i] = check_spacing(file, &field(&at), d)?;
    }
    let real = |p: &str, default: f64| -> Result<f64> {
        match main.get(p) {
            None => Ok(default),
            Some(v) => match v.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(bad(p, format!("`{v}` is not a finite number"))),
            },
        }
    };
    let z_scale = real("Record1/Axes/CZ/Increment", 1.0)?;
    let z_offset = real("Record1/Axes/CZ/Offset", 0.0)?;
    if z_scale == 0.0 {
        return Err(bad("Record1/Axes/CZ/Increment", "0 is not a height scale; allowed: a non-zero number".into()));
    }
    let dim = |k: &str| -> Result<u64> {
        let p = format!("Record3/MatrixDimension/{k}");
        let v = need(&p)?;
        v.parse::<u64>().map_err(|_| bad(&p, format!("`{v}` is not a whole number of points")))
    };
    let (nx, ny, nz) = (dim("SizeX")?, dim("SizeY")?, dim("SizeZ")?);
    if nz != 1 {
        return Err(bad("Record3/MatrixDimension/SizeZ", format!("{nz} layers; allowed: 1 (one height per point)")));
    }
    let n = check_dimensions(file, &field("Record3/MatrixDimension/SizeX"), nx, ny)?;
    let raw: Vec<f64> = match &main.data_list {
        Some(list) => {
            if list.len() != n {
                return Err(bad(
                    "Record3/DataList",
                    format!("{} Datum elements, but SizeX × SizeY = {nx} × {ny} = {n}", list.len()),
                ));
            }
            list.iter()
                .enumerate()
                .map(|(k, d)| match d {
                    None => Ok(f64::NAN),
                    Some(t) => t
                        .trim()
                        .parse::<f64>()
                        .map_err(|_| bad("Record3/DataList", format!("Datum {k} is `{}`, not a number", t.trim()))),
                })
                .collect::<Result<_>>()?
        }
        None => {
            let link = "Record3/DataLink/PointDataLink";
            let name = need(link)?;
            let ty = need("Record1/Axes/CZ/DataType")?;
            let size = match ty {
                "I" => 2,
                "L" | "F" => 4,
                "D" => 8,
                other => {
                    return Err(bad(
                        "Record1/Axes/CZ/DataType",
                        format!("`{other}`; allowed: I (i16), L (i32), F (f32), D (f64)"),
                    ))
                }
            };
            let data = member(&mut zip, file, &format!("{folder}{name}"), (n * size) as u64, Some(&field(link)))?;
            data.chunks_exact(size)
                .map(|c| match ty {
                    "I" => i16::from_le_bytes([c[0], c[1]]) as f64,
                    "L" => i32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64,
                    "F" => f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64,
                    _ => f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]),
                })
                .collect()
        }
    };
    let mut z: Vec<f64> = Vec::with_capacity(n);
    for (k, v) in raw.into_iter().enumerate() {
        if v.is_infinite() {
            return Err(bad(
                "Record3",
                format!(
                    "the height at point ({}, {}) is infinite; allowed: a number, or NaN for an invalid point",
                    k as u64 % nx,
                    k as u64 / nx
                ),
            ));
        }
        z.push(z_offset + z_scale * v);
    }
    if let Some(name) = main.get("Record3/DataLink/ValidPointsLink") {
        let link = field("Record3/DataLink/ValidPointsLink");
        let mask = member(&mut zip, file, &format!("{folder}{name}"), n.div_ceil(8) as u64, Some(&link))?;
        for (k, v) in z.iter_mut().enumerate() {
            if mask[k / 8] & (1 << (k % 8)) == 0 {
                *v = f64::NAN;
            }
        }
    }
    let data_field = if main.data_list.is_some() { "Record3/DataList" } else { "Record3/DataLink/PointDataLink" };
    // The scale is part of what a height's message should say.
    let note = format!(" (CZ Increment {}, Offset {})", number(z_scale), number(z_offset));
    let (nx, ny) = (nx as usize, ny as usize);
    HeightMap::with_height_note(file, Format::X3p, nx, ny, spacing[0], spacing[1], z, &field(data_field), &note)
}

/// Where the archive's `main.xml` is: at its root (`""`, as ISO 25178-72 places it), or in the one top folder
/// that holds every member (`"land/"`, as zipping a folder gives; a `__MACOSX/` folder of resource forks is
/// not a member of the file); the links of `main.xml` are relative to it (docs/topography.md §ISO 25178-72 X3P).
fn root_folder(zip: &Archive, file: &str) -> Result<String> {
    if zip.index_for_name("main.xml").is_some() {
        return Ok(String::new());
    }
    let found: Vec<&str> = zip
        .file_names()
        .filter(|n| !n.starts_with("__MACOSX/"))
        .filter(|n| n.strip_suffix("main.xml").is_some_and(|d| d.ends_with('/') && d.matches('/').count() == 1))
        .collect();
    match found.as_slice() {
        [one] => Ok(one.trim_end_matches("main.xml").to_string()),
        [] => Err(Error::input(
            file,
            "main.xml",
            "the archive has no member `main.xml` (allowed: at the archive's root, or in one top folder)",
        )),
        many => Err(Error::input(
            file,
            "main.xml",
            format!("the archive has {} top folders with a `main.xml` ({}); allowed: one", many.len(), many.join(", ")),
        )),
    }
}

/// The member `name`, inflated: exactly `size` bytes if `linked` (a data file whose size the grid fixes, named
/// by the field that links it), else at most `size`; its CRC-32 checked by the zip reader.
fn member(zip: &mut Archive, file: &str, name: &str, size: u64, linked: Option<&str>) -> Result<Vec<u8>> {
    let field = linked.unwrap_or(name);
    let bad = |m: String| Error::input(file, field, m);
    let mut m = zip.by_name(name).map_err(|_| bad(format!("the archive has no member `{name}`")))?;
    let declared = m.size();
    match linked {
        Some(_) if declared != size => {
            return Err(bad(format!(
                "the member `{name}` holds {declared} bytes, but the grid needs {size} (dimensions that do not match \
                 the data, or a truncated file)"
            )))
        }
        None if declared > size => {
            return Err(bad(format!("the member `{name}` inflates to {declared} bytes; at most {size} are read")))
        }
        _ => {}
    }
    let mut out = Vec::with_capacity(declared as usize);
    (&mut m)
        .take(size + 1)
        .read_to_end(&mut out)
        .map_err(|e| bad(format!("the member `{name}` cannot be inflated: {e} (a damaged or truncated file)")))?;
    if out.len() as u64 != declared {
        return Err(bad(format!(
            "the member `{name}` inflates to {} bytes, but the archive says {declared}",
            out.len()
        )));
    }
    Ok(out)
}

/// The elements of `main.xml` this reader needs, by path below the root; the `Datum`s of a `DataList`.
fn parse_main(xml: &[u8], file: &str) -> Result<Main> {
    let mut r = quick_xml::Reader::from_reader(xml);
    let mut buf = Vec::new();
    let mut stack: Vec<String> = Vec::new();
    let mut main = Main { values: Vec::new(), data_list: None };
    let mut text = String::new();
    let path = |stack: &[String]| stack.iter().skip(1).cloned().collect::<Vec<_>>().join("/");
    loop {
        let ev = r.read_event_into(&mut buf).map_err(|e| {
            Error::input(file, "main.xml", format!("not well-formed XML at byte {}: {e}", r.buffer_position()))
        })?;
        match ev {
            Event::Start(e) => {
                stack.push(String::from_utf8_lossy(e.local_name().as_ref()).into_owned());
                text.clear();
                if path(&stack) == "Record3/DataList" {
                    main.data_list = Some(Vec::new());
                }
            }
            Event::Empty(e) => {
                stack.push(String::from_utf8_lossy(e.local_name().as_ref()).into_owned());
                if path(&stack) == "Record3/DataList/Datum" {
                    main.data_list.get_or_insert_with(Vec::new).push(None);
                }
                stack.pop();
            }
            Event::Text(t) => text.push_str(&t.decode().unwrap_or_default()),
            Event::CData(t) => text.push_str(&String::from_utf8_lossy(&t)),
            Event::End(_) => {
                let p = path(&stack);
                if p == "Record3/DataList/Datum" {
                    let t = text.trim();
                    main.data_list.get_or_insert_with(Vec::new).push(if t.is_empty() {
                        None
                    } else {
                        Some(t.to_string())
                    });
                } else if !text.trim().is_empty() && main.values.len() < 4096 {
                    main.values.push((p, text.trim().to_string()));
                }
                text.clear();
                stack.pop();
            }
            Event::Eof => break,
            _ => {}
        }
        buf.clear();
    }
    Ok(main)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::io::Write;

    /// The `main.xml` of a binary map: `ty` the CZ data type, the valid-points link if `mask`.
    pub(crate) fn main_xml(nx: usize, ny: usize, dx: &str, ty: &str, record3: &str) -> String {
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">
 <Record1><Revision>ISO5436 - 2000</Revision><FeatureType>SUR</FeatureType>
  <Axes>
   <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx}</Increment><Offset>0</Offset></CX>
   <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx}</Increment><Offset>0</Offset></CY>
   <CZ><AxisType>A</AxisType><DataType>{ty}</DataType><Increment>1e-9</Increment><Offset>0</Offset></CZ>
  </Axes>
 </Record1>
 <Record3><MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>{record3}</Record3>
 <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>
</p:ISO5436_2>"#
        )
    }

    pub(crate) fn zip_of(members: &[(&str, &[u8])]) -> Vec<u8> {
        let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
        for (name, bytes) in members {
            w.start_file(*name, zip::write::SimpleFileOptions::default()).unwrap();
            w.write_all(bytes).unwrap();
        }
        w.finish().unwrap().into_inner()
    }

    const LINK: &str = "<DataLink><PointDataLink>bindata/data.bin</PointDataLink></DataLink>";

    #[test]
    fn a_binary_map_with_a_mask_reads() {
        let data: Vec<u8> = [1i16, 2, 3, 4, 5, 6].iter().flat_map(|v| v.to_le_bytes()).collect();
        let link = "<DataLink><PointDataLink>bindata/data.bin</PointDataLink><ValidPointsLink>bindata/valid.bin</ValidPointsLink></DataLink>";
        let x = main_xml(3, 2, "2e-6", "I", link);
        let mask = [0b0001_1111u8];
        let m = read(
            &zip_of(&[("main.xml", x.as_bytes()), ("bindata/data.bin", &data), ("bindata/valid.bin", &mask)]),
            "t.x3p",
        )
        .unwrap();
        assert_eq!((m.nx, m.ny, m.dx, m.dy), (3, 2, 2e-6, 2e-6));
        assert_eq!(m.z[4], 5e-9);
        assert!(m.z[5].is_nan());
    }

    #[test]
    fn a_data_list_reads_with_empty_datums_invalid() {
        let list = "<DataList><Datum>1</Datum><Datum/><Datum>3</Datum><Datum>4</Datum></DataList>";
        let x = main_xml(2, 2, "1e-6", "D", list);
        let m = read(&zip_of(&[("main.xml", x.as_bytes())]), "t.x3p").unwrap();
        assert!(m.z[1].is_nan() && m.z[3] == 4e-9);
    }

    #[test]
    fn a_map_zipped_as_one_folder_reads_from_it() {
        let data: Vec<u8> = [1.0f64, 2.0, 3.0, 4.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let x = main_xml(2, 2, "1e-6", "D", LINK);
        let members = [
            ("__MACOSX/land/._main.xml", &b"resource fork"[..]),
            ("land/main.xml", x.as_bytes()),
            ("land/bindata/data.bin", &data),
        ];
        let m = read(&zip_of(&members), "t.x3p").unwrap();
        assert_eq!(m.z[3], 4e-9);
        let two = [("a/main.xml", x.as_bytes()), ("b/main.xml", x.as_bytes())];
        assert!(read(&zip_of(&two), "t.x3p").unwrap_err().to_string().contains("2 top folders"));
        let deep = [("a/b/main.xml", x.as_bytes())];
        assert!(read(&zip_of(&deep), "t.x3p").unwrap_err().to_string().contains("no member `main.xml`"));
    }

    #[test]
    fn float_nan_is_an_invalid_point() {
        let data: Vec<u8> = [1.0f64, f64::NAN, 3.0, 4.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let x = main_xml(2, 2, "1e-6", "D", LINK);
        let m = read(&zip_of(&[("main.xml", x.as_bytes()), ("bindata/data.bin", &data)]), "t.x3p").unwrap();
        assert!(m.z[1].is_nan() && m.valid() == 3);
    }

    #[test]
    fn bad_files_name_the_field() {
        let data: Vec<u8> = [1.0f64; 4].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = |x: String, d: &[u8]| {
            read(&zip_of(&[("main.xml", x.as_bytes()), ("bindata/data.bin", d)]), "t.x3p").unwrap_err().to_string()
        };
        let ok = main_xml(2, 2, "1e-6", "D", LINK);
        assert!(e(ok.clone(), &data[..24]).contains("field `main.xml/Record3/DataLink/PointDataLink`"));
        assert!(e(main_xml(3, 2, "1e-6", "D", LINK), &data).contains("do not match"));
        assert!(e(ok.replace("<Increment>1e-6</Increment>", ""), &data).contains("Record1/Axes/CX/Increment"));
        assert!(e(ok.replace("SUR", "PRF"), &data).contains("FeatureType"));
        assert!(e(ok.replace(">D</DataType><Increment>1e-9", ">X</DataType><Increment>1e-9"), &data)
            .contains("CZ/DataType"));
        assert!(e(main_xml(2, 2, "0", "D", LINK), &data).contains("lateral calibration"));
        let nan: Vec<u8> = [f64::NAN; 4].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert!(e(ok.clone(), &nan).contains("every point"));
        // A height beyond the limit: the message says the scale it was read with (CZ's increment, offset).
        let far: Vec<u8> = [1.0, 2.0, 3.0, 2e9f64].iter().flat_map(|v| v.to_le_bytes()).collect();
        let m = e(ok.clone(), &far);
        assert!(m.contains("the height at point (1, 1)") && m.contains("error) (CZ Increment 1e-9, Offset 0)"), "{m}");
        assert!(read(b"PK\x03\x04 truncated", "t.x3p").unwrap_err().to_string().contains("damaged or truncated"));
        let full = zip_of(&[("main.xml", ok.as_bytes()), ("bindata/data.bin", &data)]);
        assert!(read(&full[..full.len() / 2], "t.x3p").is_err());
    }
}
