//! MetaImage grids (ITK's format): `.mha` (header and data in one file, `ElementDataFile =
//! LOCAL`) and `.mhd` (header, with the data in a file named by `ElementDataFile`, relative to the
//! header's folder), read and written.
//!
//! The header is text, one `Key = Value` per line, ending with `ElementDataFile`; the data follows
//! it as raw values (see [`crate::raw`]), optionally zlib-compressed. Read fields:
//!
//! | field | meaning | default |
//! | --- | --- | --- |
//! | `NDims` | must be 3 | required |
//! | `DimSize` | voxels per axis | required |
//! | `ElementType` | `MET_CHAR`, `MET_UCHAR`, `MET_SHORT`, `MET_USHORT`, `MET_INT`, `MET_UINT`, `MET_LONG` (32-bit), `MET_ULONG`, `MET_LONG_LONG`, `MET_ULONG_LONG`, `MET_FLOAT`, `MET_DOUBLE` | required |
//! | `ElementNumberOfChannels` | 1 (density, grey albedo) or 3 (RGB albedo) | 1 |
//! | `BinaryDataByteOrderMSB` / `ElementByteOrderMSB` | `True` for big-endian data | `False` |
//! | `CompressedData`, `CompressedDataSize` | zlib-compressed data, and its size in bytes | `False` |
//! | `ElementSpacing` (or `ElementSize`) | distance between voxel centres per axis | 1 1 1 |
//! | `Offset` (or `Position`, `Origin`) | centre of the first voxel | 0 0 0 |
//! | `TransformMatrix` (or `Rotation`, `Orientation`) | must be the identity: volpt's grids are axis-aligned | identity |
//! | `HeaderSize` | bytes to skip before the data; -1: the data is at the end of the file | 0 |
//! | `BinaryData` | must be `True` (ASCII voxel data is not read) | `True` |
//!
//! Other fields (`ObjectType`, `AnatomicalOrientation`, `ElementMin`, ...) are ignored.
//!
//! **Geometry**: MetaImage places voxel `i`'s centre at `Offset + i * ElementSpacing`, so each voxel
//! is a cell: the grid gets [`GridConvention::Cell`] with bounds
//! `[Offset - ElementSpacing/2, Offset + (DimSize - 1/2) * ElementSpacing]` per axis. The writer
//! inverts this (and writes a vertex-centred grid with its samples where they are, on its box's
//! faces).
//!
//! **Limits**: the header is untrusted. Its size is checked (no overflow, at most
//! [`crate::raw::MAX_VALUES`] values, and for uncompressed data exactly the bytes the file holds)
//! before anything is allocated from it; compressed data must decompress to exactly the declared
//! size; every value must be finite and non-negative. Every error names the file, and header errors
//! the line and field.

use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use flate2::Compression;

use crate::description::GridDesc;
use crate::error::{GridProblem, SceneError};
use crate::raw::{self, grid_error, ByteOrder, RawLayout, ScalarType};

/// The header must end (with `ElementDataFile`) within this many bytes: real headers are a few
/// hundred bytes, and the limit keeps a binary file given by mistake from being read as text.
pub const MAX_HEADER_BYTES: u64 = 1 << 16;

/// How [`write_metaimage`] stores the values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MetaImageOptions {
    pub scalar: ScalarType,
    pub byte_order: ByteOrder,
    /// zlib-compress the data (`CompressedData = True`).
    pub compressed: bool,
}

impl Default for MetaImageOptions {
    /// Uncompressed little-endian `MET_FLOAT`, which holds any grid exactly.
    fn default() -> Self {
        Self {
            scalar: ScalarType::F32,
            byte_order: ByteOrder::Little,
            compressed: false,
        }
    }
}

/// Reads a `.mha` or `.mhd` file (see the module docs for the fields and checks).
pub fn read_metaimage(path: &Path) -> Result<GridDesc, SceneError> {
    let (file, _) = crate::limits::open_regular(path)?;
    let mut reader = BufReader::new(file);
    let (fields, header_len) = read_fields(path, &mut reader)?;
    let header = Header::parse(path, &fields)?;
    let (_, data_bytes) = header.layout.checked_size(path)?;
    let bounds = raw::centred_bounds(header.offset, header.spacing, header.layout.resolution)
        .ok_or_else(|| {
            bad(
                None,
                "ElementSpacing and Offset",
                "a box with finite f32 bounds",
                format!("spacing {:?}, offset {:?}", header.spacing, header.offset),
            )
            .at(path)
        })?;

    let (mut data_file, data_path, region_start) = match &header.data_file {
        None => (reader.into_inner(), path.to_path_buf(), header_len),
        Some(name) => {
            let data_path = path.parent().unwrap_or(Path::new("")).join(name);
            let (file, _) = crate::limits::open_regular(&data_path)?;
            (file, data_path, 0)
        }
    };
    let data_io = |error| SceneError::Io {
        path: data_path.clone(),
        error,
    };
    let file_len = data_file.metadata().map_err(data_io)?.len();
    let region = file_len.saturating_sub(region_start);
    let stored = if header.compressed {
        header.compressed_size
    } else {
        Some(data_bytes)
    };
    let what = |s: &str| format!("{s} in {}", data_path.display());
    let stored_name = if header.compressed {
        "compressed data"
    } else {
        "voxel data"
    };
    let mismatch = |expected_bytes| {
        grid_error(
            path,
            GridProblem::SizeMismatch {
                what: what(stored_name),
                expected_bytes,
                actual_bytes: region,
            },
        )
    };
    let (skip, stored) = match (header.header_size, stored) {
        (HeaderSize::AtEnd, Some(stored)) if stored > region => return Err(mismatch(stored)),
        (HeaderSize::AtEnd, Some(stored)) => (region - stored, stored),
        (HeaderSize::AtEnd, None) => {
            return Err(grid_error(
                path,
                GridProblem::MissingField {
                    field: "CompressedDataSize",
                    expected: "the compressed size, to find data at the end (HeaderSize = -1)",
                },
            ))
        }
        (HeaderSize::Skip(skip), stored) => {
            let stored = stored.unwrap_or(region.saturating_sub(skip));
            let needed = skip.saturating_add(stored);
            if needed > region {
                return Err(mismatch(needed));
            }
            if needed < region {
                return Err(grid_error(
                    path,
                    GridProblem::ExcessData {
                        what: what(stored_name),
                        expected_bytes: needed,
                    },
                ));
            }
            (skip, stored)
        }
    };
    // Deflate cannot expand past its own ratio: a header declaring more data than the stored
    // bytes can hold is refused before anything is reserved for it.
    if header.compressed && data_bytes > stored.saturating_mul(crate::limits::DEFLATE_MAX_RATIO) {
        return Err(grid_error(
            path,
            GridProblem::SizeMismatch {
                what: format!(
                    "{} (at most {} times the compressed size, zlib's limit)",
                    what("decompressed voxel data"),
                    crate::limits::DEFLATE_MAX_RATIO
                ),
                expected_bytes: data_bytes,
                actual_bytes: stored.saturating_mul(crate::limits::DEFLATE_MAX_RATIO),
            },
        ));
    }
    data_file
        .seek(SeekFrom::Start(region_start + skip))
        .map_err(data_io)?;

    let data = if header.compressed {
        let mut decoder = ZlibDecoder::new(data_file.take(stored));
        raw::read_values(
            &mut decoder,
            &header.layout,
            data_bytes,
            path,
            &data_path,
            &what("decompressed voxel data"),
        )?
    } else {
        raw::read_values(
            &mut data_file,
            &header.layout,
            data_bytes,
            path,
            &data_path,
            &what("voxel data"),
        )?
    };
    Ok(GridDesc {
        layout: crate::description::SampleLayout::Dense,
        resolution: header.layout.resolution,
        channels: header.layout.channels,
        bounds,
        convention: crate::description::GridConvention::Cell,
        data,
    })
}

/// Writes a grid as `.mha` (one file) or `.mhd` (the header, and the data beside it in
/// `<stem>.raw`, or `<stem>.zraw` when compressed), chosen by `path`'s extension. Integer element
/// types must hold every value exactly.
pub fn write_metaimage(
    path: &Path,
    grid: &GridDesc,
    options: &MetaImageOptions,
) -> Result<(), SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let local = match extension.as_deref() {
        Some("mha") => true,
        Some("mhd") => false,
        _ => {
            return Err(grid_error(
                path,
                GridProblem::Unsupported {
                    what: "this file extension".into(),
                    reason: "a MetaImage file is .mha (one file) or .mhd (header + data file)"
                        .into(),
                },
            ))
        }
    };
    if grid.channels != 1 && grid.channels != 3 {
        return Err(bad(None, "channels", "1 or 3", grid.channels.to_string()).at(path));
    }
    let mut data = raw::encode_values(path, grid, options.scalar, options.byte_order)?;
    if options.compressed {
        let mut encoder = ZlibEncoder::new(Vec::new(), Compression::default());
        let compressed = encoder.write_all(&data).and_then(|()| encoder.finish());
        data = compressed.map_err(|error| SceneError::Io {
            path: path.to_path_buf(),
            error,
        })?;
    }

    let (offset, spacing) = raw::centres_of(grid);
    let triple = |v: [f64; 3]| format!("{} {} {}", v[0], v[1], v[2]);
    let [x, y, z] = grid.resolution;
    let data_name = if local {
        "LOCAL".to_string()
    } else {
        let stem = path.file_stem().unwrap_or_default().to_string_lossy();
        format!("{stem}.{}", if options.compressed { "zraw" } else { "raw" })
    };
    let mut header = format!(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = {}\n\
         CompressedData = {}\n",
        title_bool(options.byte_order == ByteOrder::Big),
        title_bool(options.compressed),
    );
    if options.compressed {
        header += &format!("CompressedDataSize = {}\n", data.len());
    }
    header += &format!(
        "TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = {}\nElementSpacing = {}\n\
         DimSize = {x} {y} {z}\nElementNumberOfChannels = {}\nElementType = {}\n\
         ElementDataFile = {data_name}\n",
        triple(offset),
        triple(spacing),
        grid.channels,
        met_name(options.scalar),
    );

    if local {
        let mut bytes = header.into_bytes();
        bytes.extend_from_slice(&data);
        raw::write_file(path, &bytes)
    } else {
        raw::write_file(&path.with_file_name(&data_name), &data)?;
        raw::write_file(path, header.as_bytes())
    }
}

/// One `Key = Value` line of a header.
struct Field {
    key: String,
    value: String,
    line: usize,
}

/// Where the data starts, relative to where it could start.
#[derive(Clone, Copy)]
enum HeaderSize {
    Skip(u64),
    /// `HeaderSize = -1`: the data ends the file.
    AtEnd,
}

/// A validated header.
struct Header {
    layout: RawLayout,
    spacing: [f64; 3],
    offset: [f64; 3],
    compressed: bool,
    compressed_size: Option<u64>,
    header_size: HeaderSize,
    /// `None` for `LOCAL`, else the data file's name as written.
    data_file: Option<PathBuf>,
}

impl Header {
    fn parse(path: &Path, fields: &[Field]) -> Result<Self, SceneError> {
        let get = |keys: &[&str]| {
            keys.iter()
                .find_map(|k| fields.iter().find(|f| f.key.eq_ignore_ascii_case(k)))
        };
        let parse_err = |e: Bad| e.at(path);

        if let Some(f) = get(&["ObjectType"]) {
            if !f.value.eq_ignore_ascii_case("Image") {
                return Err(parse_err(bad(
                    Some(f.line),
                    "ObjectType",
                    "Image",
                    &f.value,
                )));
            }
        }
        let ndims = get(&["NDims"]).ok_or(missing(path, "NDims", "3"))?;
        if ndims.value.trim() != "3" {
            return Err(parse_err(bad(Some(ndims.line), "NDims", "3", &ndims.value)));
        }
        let dims = get(&["DimSize"]).ok_or(missing(path, "DimSize", "three positive integers"))?;
        let resolution = three::<u32>(dims, "three positive integers below 2^32")
            .and_then(|v| {
                if v.contains(&0) {
                    Err(bad(
                        Some(dims.line),
                        "DimSize",
                        "three positive integers below 2^32",
                        &dims.value,
                    ))
                } else {
                    Ok(v)
                }
            })
            .map_err(parse_err)?;
        let element = get(&["ElementType"]).ok_or(missing(
            path,
            "ElementType",
            "a MET_ type such as MET_UCHAR or MET_FLOAT",
        ))?;
        let scalar = scalar_of(&element.value).ok_or_else(|| {
            parse_err(bad(
                Some(element.line),
                "ElementType",
                "one of MET_CHAR, MET_UCHAR, MET_SHORT, MET_USHORT, MET_INT, MET_UINT, \
                 MET_LONG, MET_ULONG, MET_LONG_LONG, MET_ULONG_LONG, MET_FLOAT, MET_DOUBLE",
                &element.value,
            ))
        })?;
        let channels = match get(&["ElementNumberOfChannels"]) {
            None => 1,
            Some(f) => match f.value.trim() {
                "1" => 1,
                "3" => 3,
                _ => {
                    return Err(parse_err(bad(
                        Some(f.line),
                        "ElementNumberOfChannels",
                        "1 or 3",
                        &f.value,
                    )))
                }
            },
        };
        if let Some(f) = get(&["BinaryData"]) {
            if !boolean(f).map_err(parse_err)? {
                return Err(grid_error(
                    path,
                    GridProblem::Unsupported {
                        what: "BinaryData = False".into(),
                        reason: "volpt reads binary voxel data only".into(),
                    },
                ));
            }
        }
        let msb = [
            get(&["BinaryDataByteOrderMSB"]),
            get(&["ElementByteOrderMSB"]),
        ];
        let mut big = None;
        for f in msb.into_iter().flatten() {
            let value = boolean(f).map_err(parse_err)?;
            if big.is_some_and(|b| b != value) {
                return Err(parse_err(bad(
                    Some(f.line),
                    &f.key,
                    "the same byte order as the other MSB field",
                    &f.value,
                )));
            }
            big = Some(value);
        }
        let byte_order = if big == Some(true) {
            ByteOrder::Big
        } else {
            ByteOrder::Little
        };
        let compressed = match get(&["CompressedData"]) {
            Some(f) => boolean(f).map_err(parse_err)?,
            None => false,
        };
        let compressed_size = match get(&["CompressedDataSize"]) {
            Some(f) => Some(
                values::<u64>(f, "a byte count")
                    .and_then(|v| one(f, v, "a byte count"))
                    .map_err(parse_err)?,
            ),
            None => None,
        };
        let spacing = match get(&["ElementSpacing", "ElementSize"]) {
            Some(f) => {
                let v = floats(f, "three positive numbers").map_err(parse_err)?;
                if v.iter().any(|&s| s <= 0.0) {
                    return Err(parse_err(bad(
                        Some(f.line),
                        &f.key,
                        "three positive numbers",
                        &f.value,
                    )));
                }
                v
            }
            None => [1.0; 3],
        };
        let offset = match get(&["Offset", "Position", "Origin"]) {
            Some(f) => floats(f, "three finite numbers").map_err(parse_err)?,
            None => [0.0; 3],
        };
        if let Some(f) = get(&["TransformMatrix", "Rotation", "Orientation"]) {
            check_identity(path, f)?;
        }
        let header_size = match get(&["HeaderSize"]) {
            None => HeaderSize::Skip(0),
            Some(f) => {
                let expected = "a byte count, or -1 (data at the end of the file)";
                match values::<i64>(f, expected).and_then(|v| one(f, v, expected)) {
                    Ok(-1) => HeaderSize::AtEnd,
                    Ok(n) if n >= 0 => HeaderSize::Skip(n as u64),
                    _ => {
                        return Err(parse_err(bad(
                            Some(f.line),
                            "HeaderSize",
                            expected,
                            &f.value,
                        )))
                    }
                }
            }
        };
        // `read_fields` stops at this field, so it is present.
        let data = get(&["ElementDataFile"]).ok_or(missing(
            path,
            "ElementDataFile",
            "LOCAL or a file name",
        ))?;
        let data_file = match data.value.as_str() {
            v if v.eq_ignore_ascii_case("LOCAL") => None,
            v if v.eq_ignore_ascii_case("LIST") || v.contains('%') || v.is_empty() => {
                return Err(grid_error(
                    path,
                    GridProblem::Unsupported {
                        what: format!("ElementDataFile = {v:?}"),
                        reason: "volpt reads LOCAL data or one data file".into(),
                    },
                ))
            }
            v => Some(PathBuf::from(v)),
        };
        Ok(Header {
            layout: RawLayout {
                resolution,
                channels,
                scalar,
                byte_order,
                header_bytes: 0,
            },
            spacing,
            offset,
            compressed,
            compressed_size,
            header_size,
            data_file,
        })
    }
}

/// A header-field error before the path is known to the helper that found it.
struct Bad(GridProblem);

impl Bad {
    fn at(self, path: &Path) -> SceneError {
        grid_error(path, self.0)
    }
}

fn bad(line: Option<usize>, field: &str, expected: &str, found: impl Into<String>) -> Bad {
    Bad(GridProblem::BadField {
        line,
        field: field.into(),
        expected: expected.into(),
        found: found.into(),
    })
}

fn missing(path: &Path, field: &'static str, expected: &'static str) -> SceneError {
    grid_error(path, GridProblem::MissingField { field, expected })
}

/// Reads the header's lines up to and including `ElementDataFile`; returns them and the header's
/// length in bytes (where `LOCAL` data starts).
fn read_fields(path: &Path, reader: &mut impl BufRead) -> Result<(Vec<Field>, u64), SceneError> {
    let mut fields: Vec<Field> = Vec::new();
    let mut consumed = 0u64;
    let mut line_bytes = Vec::new();
    for line in 1.. {
        line_bytes.clear();
        let n = reader
            .take(MAX_HEADER_BYTES - consumed)
            .read_until(b'\n', &mut line_bytes)
            .map_err(|error| SceneError::Io {
                path: path.to_path_buf(),
                error,
            })?;
        consumed += n as u64;
        if n == 0 || !line_bytes.ends_with(b"\n") && consumed >= MAX_HEADER_BYTES {
            let expected = if n == 0 {
                "a header ending with ElementDataFile = LOCAL or a file name"
            } else {
                "a header ending with ElementDataFile within its first 65536 bytes"
            };
            return Err(missing(path, "ElementDataFile", expected));
        }
        let Ok(text) = std::str::from_utf8(&line_bytes) else {
            return Err(bad(
                Some(line),
                "header",
                "text lines `Key = Value`",
                String::from_utf8_lossy(&line_bytes).trim_end(),
            )
            .at(path));
        };
        let text = text.trim();
        if text.is_empty() {
            continue;
        }
        let Some((key, value)) = text.split_once('=') else {
            return Err(bad(Some(line), "header", "a line `Key = Value`", text).at(path));
        };
        let (key, value) = (key.trim(), value.trim());
        if let Some(first) = fields.iter().find(|f| f.key.eq_ignore_ascii_case(key)) {
            return Err(bad(
                Some(line),
                key,
                &format!("the field once (it is already on line {})", first.line),
                value,
            )
            .at(path));
        }
        fields.push(Field {
            key: key.to_string(),
            value: value.to_string(),
            line,
        });
        if key.eq_ignore_ascii_case("ElementDataFile") {
            break;
        }
    }
    Ok((fields, consumed))
}

fn scalar_of(name: &str) -> Option<ScalarType> {
    Some(match name.trim().to_ascii_uppercase().as_str() {
        "MET_CHAR" => ScalarType::I8,
        "MET_UCHAR" => ScalarType::U8,
        "MET_SHORT" => ScalarType::I16,
        "MET_USHORT" => ScalarType::U16,
        // MetaIO's MET_LONG and MET_ULONG are 32-bit, as ITK writes them.
        "MET_INT" | "MET_LONG" => ScalarType::I32,
        "MET_UINT" | "MET_ULONG" => ScalarType::U32,
        "MET_LONG_LONG" => ScalarType::I64,
        "MET_ULONG_LONG" => ScalarType::U64,
        "MET_FLOAT" => ScalarType::F32,
        "MET_DOUBLE" => ScalarType::F64,
        _ => return None,
    })
}

fn met_name(scalar: ScalarType) -> &'static str {
    match scalar {
        ScalarType::I8 => "MET_CHAR",
        ScalarType::U8 => "MET_UCHAR",
        ScalarType::I16 => "MET_SHORT",
        ScalarType::U16 => "MET_USHORT",
        ScalarType::I32 => "MET_INT",
        ScalarType::U32 => "MET_UINT",
        ScalarType::I64 => "MET_LONG_LONG",
        ScalarType::U64 => "MET_ULONG_LONG",
        ScalarType::F32 => "MET_FLOAT",
        ScalarType::F64 => "MET_DOUBLE",
    }
}

fn title_bool(b: bool) -> &'static str {
    if b {
        "True"
    } else {
        "False"
    }
}

fn boolean(f: &Field) -> Result<bool, Bad> {
    match f.value.to_ascii_lowercase().as_str() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => Err(bad(Some(f.line), &f.key, "True or False", &f.value)),
    }
}

/// The field's whitespace-separated values.
fn values<T: std::str::FromStr>(f: &Field, expected: &str) -> Result<Vec<T>, Bad> {
    f.value
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<Vec<T>, _>>()
        .map_err(|_| bad(Some(f.line), &f.key, expected, &f.value))
}

/// Exactly three values.
fn three<T: std::str::FromStr + Copy>(f: &Field, expected: &str) -> Result<[T; 3], Bad> {
    match values::<T>(f, expected)?.as_slice() {
        &[x, y, z] => Ok([x, y, z]),
        _ => Err(bad(Some(f.line), &f.key, expected, &f.value)),
    }
}

/// The only value of a one-number field.
fn one<T: Copy>(f: &Field, values: Vec<T>, expected: &str) -> Result<T, Bad> {
    match values.as_slice() {
        [v] => Ok(*v),
        _ => Err(bad(Some(f.line), &f.key, expected, &f.value)),
    }
}

/// Three finite numbers.
fn floats(f: &Field, expected: &str) -> Result<[f64; 3], Bad> {
    let v = three::<f64>(f, expected)?;
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(bad(Some(f.line), &f.key, expected, &f.value))
    }
}

fn check_identity(path: &Path, f: &Field) -> Result<(), SceneError> {
    let expected = "nine numbers (a 3x3 matrix)";
    let matrix = values::<f64>(f, expected)
        .ok()
        .filter(|v| v.len() == 9)
        .ok_or_else(|| bad(Some(f.line), &f.key, expected, &f.value).at(path))?;
    let identity = matrix.iter().enumerate().all(|(i, &v)| {
        let want = if i % 4 == 0 { 1.0 } else { 0.0 };
        (v - want).abs() <= 1e-6
    });
    if identity {
        Ok(())
    } else {
        Err(grid_error(
            path,
            GridProblem::Unsupported {
                what: format!("line {}: {} = {}", f.line, f.key, f.value),
                reason: "volpt's grids are axis-aligned: expected the identity matrix".into(),
            },
        ))
    }
}
