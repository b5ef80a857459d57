//! VTK image data, read and written through the `vtkio` crate: legacy `.vtk` files with
//! `DATASET STRUCTURED_POINTS` (ASCII or binary) and XML `.vti` files (`ImageData`).
//!
//! The grid is a point-data array: the first scalar array (`SCALARS`, `COLOR_SCALARS`, or an XML
//! `DataArray`) with 1 or 3 components, or the array of a given name. Values are converted to `f32`
//! and must be finite and non-negative.
//!
//! **Geometry**: VTK places point `(i, j, k)` at `Origin + (i, j, k) * Spacing` (for XML, `(i, j, k)`
//! runs over the `WholeExtent`), so voxel `i`'s centre is at `offset + i * spacing` with `offset`
//! the first point. As for MetaImage, each voxel is a cell: the grid gets
//! [`crate::description::GridConvention::Cell`] with bounds
//! `[offset - spacing/2, offset + (dim - 1/2) * spacing]` per axis.
//!
//! **Limits**: the file is read whole (a regular file within [`crate::limits::memory_limit`]).
//! Before `vtkio` sees it, volpt reads every size it declares (legacy: `DATASET`, which must be
//! `STRUCTURED_POINTS`, `DIMENSIONS`, `POINT_DATA`, `CELL_DATA`, every attribute array, lookup
//! table and field array; XML: `WholeExtent`, each `Piece`'s `Extent` and each `DataArray`'s
//! components and tuples) and rejects more than [`crate::raw::MAX_VALUES`] values, or more values
//! than the file has bytes, because `vtkio` reserves memory for the counts it parses.
//! zlib-compressed XML is rejected: `vtkio`
//! sizes its decompression buffer from the untrusted block headers. A file `vtkio` panics on (it
//! indexes its input by declared offsets) is reported as a decode error. Only single-piece image
//! data with an axis-aligned `Direction` (or none) is read.

use std::path::Path;

use quick_xml::events::{BytesStart, Event};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, DataArray, DataSet, ElementType, Extent, ImageDataPiece,
    Piece, Version,
};
use vtkio::{IOBuffer, Vtk};

use crate::description::{GridConvention, GridDesc};
use crate::error::{GridProblem, SceneError};
use crate::raw::{self, grid_error, RawLayout, ScalarType, MAX_VALUES};

/// Which of VTK's file formats a path holds, by its extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Legacy,
    Xml,
}

fn format_of(path: &Path) -> Result<Format, SceneError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("vtk") => Ok(Format::Legacy),
        Some("vti") => Ok(Format::Xml),
        _ => Err(grid_error(
            path,
            GridProblem::Unsupported {
                what: "this file extension".into(),
                reason: "volpt reads VTK image data from .vtk (legacy) or .vti (XML) files".into(),
            },
        )),
    }
}

/// Reads a `.vtk` or `.vti` image-data file; `array` picks a point-data array by name, `None`
/// takes the first scalar one.
pub fn read_vtk(path: &Path, array: Option<&str>) -> Result<GridDesc, SceneError> {
    let format = format_of(path)?;
    let bytes = crate::limits::read_file(path)?;
    match format {
        Format::Legacy => prescan_legacy(path, &bytes)?,
        Format::Xml => prescan_xml(path, &bytes)?,
    }
    let parsed = crate::contain::contain_panics(|| match format {
        Format::Legacy => Vtk::parse_legacy_be(bytes.as_slice()),
        Format::Xml => Vtk::parse_xml(bytes.as_slice()),
    });
    let decode = |message: String| {
        grid_error(
            path,
            GridProblem::Decode {
                what: "VTK file".into(),
                message,
            },
        )
    };
    let vtk = match parsed {
        Ok(Ok(vtk)) => vtk,
        Ok(Err(e)) => return Err(decode(e.to_string())),
        Err(_) => return Err(decode("malformed data (the vtkio parser gave up)".into())),
    };
    let DataSet::ImageData {
        extent,
        origin,
        spacing,
        pieces,
        ..
    } = vtk.data
    else {
        return Err(unsupported(
            path,
            "this VTK data set type",
            "volpt reads image data (STRUCTURED_POINTS / ImageData) only",
        ));
    };
    let (resolution, start) = dims_of(path, &extent)?;
    let mut pieces = pieces.into_iter();
    let (Some(piece), None) = (pieces.next(), pieces.next()) else {
        return Err(unsupported(
            path,
            "image data in several pieces (or none)",
            "volpt reads single-piece files",
        ));
    };
    let Piece::Inline(piece) = piece else {
        return Err(unsupported(
            path,
            "image data stored in other files",
            "volpt reads single-piece files",
        ));
    };
    let data_array = pick_array(path, piece.data.point, array)?;
    let channels = match components(&data_array.elem) {
        Some(c @ (1 | 3)) => c,
        other => {
            return Err(bad_field(
                path,
                format!("point-data array {:?}", data_array.name),
                "1 or 3 components".into(),
                other.map_or("a non-scalar array".into(), |c| format!("{c} components")),
            ))
        }
    };
    let layout = RawLayout {
        resolution,
        channels,
        scalar: ScalarType::F32,
        byte_order: raw::ByteOrder::Little,
        header_bytes: 0,
    };
    let (count, _) = layout.checked_size(path)?;
    let data = convert(path, &layout, count, &data_array)?;

    for (axis, &s) in spacing.iter().enumerate() {
        if !(s.is_finite() && s > 0.0) {
            return Err(bad_field(
                path,
                "Spacing".into(),
                "three positive numbers".into(),
                format!("{spacing:?} (axis {axis})"),
            ));
        }
    }
    let spacing = spacing.map(f64::from);
    let offset: [f64; 3] =
        std::array::from_fn(|a| f64::from(origin[a]) + start[a] as f64 * spacing[a]);
    let bounds = raw::centred_bounds(offset, spacing, resolution).ok_or_else(|| {
        bad_field(
            path,
            "Origin and Spacing".into(),
            "a box with finite f32 bounds".into(),
            format!("origin {origin:?}, spacing {spacing:?}"),
        )
    })?;
    Ok(GridDesc {
        layout: crate::description::SampleLayout::Dense,
        resolution,
        channels,
        bounds,
        convention: GridConvention::Cell,
        data,
    })
}

/// Writes a grid as image data with one `f32` point-data array named `array`: binary legacy for
/// `.vtk`, XML for `.vti`. A vertex-centred grid is written with its samples where they are, on
/// its box's faces.
pub fn write_vtk(path: &Path, grid: &GridDesc, array: &str) -> Result<(), SceneError> {
    let format = format_of(path)?;
    raw::check_data_length(path, grid)?;
    if grid.channels != 1 && grid.channels != 3 {
        return Err(bad_field(
            path,
            "channels".into(),
            "1 or 3".into(),
            grid.channels.to_string(),
        ));
    }
    let (offset, spacing) = raw::centres_of(grid);
    let [x, y, z] = grid.resolution.map(|r| r as i32 - 1);
    let extent = match format {
        Format::Legacy => Extent::Dims(grid.resolution),
        Format::Xml => Extent::Ranges([0..=x, 0..=y, 0..=z]),
    };
    let point = vec![Attribute::DataArray(DataArray {
        name: array.to_string(),
        elem: ElementType::Scalars {
            num_comp: grid.channels,
            lookup_table: None,
        },
        data: IOBuffer::F32(grid.data.clone()),
    })];
    let vtk = Vtk {
        version: Version::new(if format == Format::Legacy {
            (4, 2)
        } else {
            (1, 0)
        }),
        title: "volpt grid".into(),
        byte_order: ByteOrder::BigEndian,
        file_path: None,
        data: DataSet::ImageData {
            extent: extent.clone(),
            origin: offset.map(|v| v as f32),
            spacing: spacing.map(|v| v as f32),
            meta: None,
            pieces: vec![Piece::Inline(Box::new(ImageDataPiece {
                extent,
                data: Attributes {
                    point,
                    cell: Vec::new(),
                },
            }))],
        },
    };
    vtk.export(path).map_err(|e| {
        grid_error(
            path,
            GridProblem::Decode {
                what: "writing the VTK file".into(),
                message: e.to_string(),
            },
        )
    })
}

/// The resolution and the index of the first point per axis.
fn dims_of(path: &Path, extent: &Extent) -> Result<([u32; 3], [i64; 3]), SceneError> {
    let (dims, start) = match extent {
        Extent::Dims(d) => (d.map(i64::from), [0; 3]),
        Extent::Ranges(r) => (
            std::array::from_fn(|a| i64::from(*r[a].end()) - i64::from(*r[a].start()) + 1),
            std::array::from_fn(|a| i64::from(*r[a].start())),
        ),
    };
    let resolution = dims.map(|d| u32::try_from(d).unwrap_or(0));
    if resolution.contains(&0) {
        return Err(bad_field(
            path,
            "extent".into(),
            "at least one point on every axis".into(),
            format!("{} x {} x {} points", dims[0], dims[1], dims[2]),
        ));
    }
    Ok((resolution, start))
}

/// The named point-data array, or the first scalar one.
fn pick_array(
    path: &Path,
    point: Vec<Attribute>,
    name: Option<&str>,
) -> Result<DataArray, SceneError> {
    let mut names = Vec::new();
    for attribute in point {
        if let Attribute::DataArray(a) = attribute {
            let wanted = match name {
                Some(n) => a.name == n,
                None => components(&a.elem).is_some(),
            };
            if wanted {
                return Ok(a);
            }
            names.push(a.name);
        }
    }
    Err(bad_field(
        path,
        "point data".into(),
        match name {
            Some(n) => format!("an array named {n:?}"),
            None => "a scalar array".into(),
        },
        if names.is_empty() {
            "no arrays (truncated or malformed attribute data?)".into()
        } else {
            format!("arrays {names:?}")
        },
    ))
}

/// Components per point of a scalar-like array; `None` for vectors, normals, tensors.
fn components(elem: &ElementType) -> Option<u32> {
    match elem {
        ElementType::Scalars { num_comp, .. } => Some(*num_comp),
        ElementType::ColorScalars(n) | ElementType::Generic(n) => Some(*n),
        _ => None,
    }
}

/// The array's values as checked `f32`s, exactly `count` of them.
fn convert(
    path: &Path,
    layout: &RawLayout,
    count: usize,
    array: &DataArray,
) -> Result<Vec<f32>, SceneError> {
    macro_rules! values {
        ($($variant:ident),*) => {
            match &array.data {
                $(IOBuffer::$variant(v) => (v.len(), Box::new(v.iter().map(|&x| x as f64))
                    as Box<dyn Iterator<Item = f64> + '_>),)*
                IOBuffer::Bit(_) => {
                    return Err(unsupported(path, "a bit array", "volpt reads numeric arrays"))
                }
            }
        };
    }
    let (len, values) = values!(U8, I8, U16, I16, U32, I32, U64, I64, F32, F64);
    if len != count {
        let what = format!(
            "point-data array {:?} ({} x {} x {} points x {} components)",
            array.name,
            layout.resolution[0],
            layout.resolution[1],
            layout.resolution[2],
            layout.channels
        );
        let bytes = |n: usize| n as u64 * array.data.scalar_size() as u64;
        return Err(grid_error(
            path,
            if len < count {
                GridProblem::SizeMismatch {
                    what,
                    expected_bytes: bytes(count),
                    actual_bytes: bytes(len),
                }
            } else {
                GridProblem::ExcessData {
                    what,
                    expected_bytes: bytes(count),
                }
            },
        ));
    }
    values
        .enumerate()
        .map(|(index, v)| raw::checked_value(path, layout, index, v))
        .collect()
}

/// Checks every size a legacy file declares before `vtkio` reserves memory for it (see the module
/// docs). The scan is by whitespace-separated tokens, as `vtkio` parses (a count may sit on the
/// next line), over the whole file, binary data included: a keyword inside binary data would be
/// there by accident, and its count is only compared with the file's length, which a real file's
/// data never exceeds.
fn prescan_legacy(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let file_bytes = bytes.len() as u64;
    let mut tokens: Vec<(usize, &[u8])> = Vec::new();
    let mut start = None;
    for (i, b) in bytes.iter().enumerate() {
        match (b.is_ascii_whitespace(), start) {
            (true, Some(s)) => {
                tokens.push((s, &bytes[s..i]));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        tokens.push((s, &bytes[s..]));
    }
    // The points (or cells) each attribute array has one entry per.
    let mut elements: Option<u64> = None;
    for (index, &(offset, token)) in tokens.iter().enumerate() {
        let number = |k: usize| {
            tokens
                .get(index + k)
                .and_then(|(_, t)| std::str::from_utf8(t).ok())
                .and_then(|t| t.parse::<u64>().ok())
        };
        let per_element = |n: Option<u64>| elements.map(|e| e.saturating_mul(n.unwrap_or(1)));
        let line = || 1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count();
        let keyword = token.to_ascii_uppercase();
        let declared = match keyword.as_slice() {
            b"DATASET" => {
                let kind = tokens.get(index + 1).map_or(&b""[..], |(_, t)| t);
                if !kind.eq_ignore_ascii_case(b"STRUCTURED_POINTS") {
                    return Err(unsupported(
                        path,
                        &format!("line {}: DATASET {}", line(), String::from_utf8_lossy(kind)),
                        "volpt reads image data (DATASET STRUCTURED_POINTS) only",
                    ));
                }
                None
            }
            b"DIMENSIONS" => {
                let dims = [number(1), number(2), number(3)];
                if let [Some(x), Some(y), Some(z)] = dims {
                    let resolution = [x, y, z].map(|d| u32::try_from(d).unwrap_or(u32::MAX));
                    let values = x.checked_mul(y).and_then(|v| v.checked_mul(z));
                    if values.is_none_or(|v| v > MAX_VALUES) {
                        return Err(grid_error(
                            path,
                            GridProblem::TooLarge {
                                resolution,
                                channels: 1,
                                limit: MAX_VALUES,
                            },
                        ));
                    }
                    values
                } else {
                    None // vtkio reports the malformed line
                }
            }
            b"POINT_DATA" | b"CELL_DATA" => {
                elements = number(1);
                elements
            }
            b"SCALARS" => per_element(number(3)),
            b"COLOR_SCALARS" | b"TEXTURE_COORDINATES" => per_element(number(2)),
            b"VECTORS" | b"NORMALS" => per_element(Some(3)),
            b"TENSORS" => per_element(Some(9)),
            // `LOOKUP_TABLE name size` defines a table of `size` RGBA colours; `LOOKUP_TABLE
            // default` after `SCALARS` only names one.
            b"LOOKUP_TABLE" => number(2).map(|n| n.saturating_mul(4)),
            // `FIELD name arrays`; `METADATA` / `INFORMATION count`.
            b"FIELD" | b"METADATA" | b"INFORMATION" => number(2).or(number(1)),
            // A field array, `name components tuples type`: checked at its type.
            _ if index >= 2 && is_data_type(token) => {
                let before = |k: usize| {
                    std::str::from_utf8(tokens[index - k].1)
                        .ok()
                        .and_then(|t| t.parse::<u64>().ok())
                };
                match (before(2), before(1)) {
                    (Some(components), Some(tuples)) => Some(components.saturating_mul(tuples)),
                    _ => None,
                }
            }
            _ => None,
        };
        if declared.is_some_and(|values| values > file_bytes) {
            let keyword = String::from_utf8_lossy(&keyword).into_owned();
            check_declared(path, line(), &keyword, declared, file_bytes)?;
        }
    }
    Ok(())
}

/// A legacy VTK data type name (`float`, `unsigned_char`, ...).
fn is_data_type(token: &[u8]) -> bool {
    const TYPES: [&str; 13] = [
        "bit",
        "unsigned_char",
        "char",
        "unsigned_short",
        "short",
        "unsigned_int",
        "int",
        "unsigned_long",
        "long",
        "float",
        "double",
        "vtktypeint64",
        "vtktypeuint64",
    ];
    TYPES
        .iter()
        .any(|t| t.as_bytes().eq_ignore_ascii_case(token))
}

/// Every declared value takes at least one byte of the file.
fn check_declared(
    path: &Path,
    line: usize,
    keyword: &str,
    declared: Option<u64>,
    file_bytes: u64,
) -> Result<(), SceneError> {
    match declared {
        Some(values) if values > file_bytes => Err(grid_error(
            path,
            GridProblem::SizeMismatch {
                what: format!(
                    "line {line}: {keyword} declares {values} values, at least one byte each"
                ),
                expected_bytes: values,
                actual_bytes: file_bytes,
            },
        )),
        _ => Ok(()),
    }
}

/// Checks an XML file's compressor, direction and extents before `vtkio` reads its data.
fn prescan_xml(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let file_bytes = bytes.len() as u64;
    // Points of the current piece, which its arrays have one tuple per.
    let mut points: Option<u64> = None;
    let mut reader = quick_xml::Reader::from_reader(bytes);
    let mut buffer = Vec::new();
    loop {
        let element = match reader.read_event_into(&mut buffer) {
            Ok(Event::Start(e)) | Ok(Event::Empty(e)) => e,
            Ok(Event::Eof) | Err(_) => return Ok(()), // vtkio reports malformed XML
            Ok(_) => {
                buffer.clear();
                continue;
            }
        };
        let line = bytes[..reader.buffer_position() as usize]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        match element.name().as_ref() {
            b"VTKFile" => {
                if let Some(c) = attribute(&element, b"compressor").filter(|c| !c.is_empty()) {
                    return Err(unsupported(
                        path,
                        &format!("line {line}: compressor {c:?}"),
                        "volpt reads uncompressed VTK XML (vtkio sizes its decompression \
                         buffers from unchecked headers); save the file uncompressed",
                    ));
                }
            }
            b"ImageData" => {
                if let Some(d) = attribute(&element, b"Direction") {
                    let identity = d
                        .split_whitespace()
                        .map(str::parse::<f64>)
                        .collect::<Result<Vec<_>, _>>()
                        .is_ok_and(|v| {
                            v.len() == 9
                                && v.iter().enumerate().all(|(i, &x)| {
                                    (x - if i % 4 == 0 { 1.0 } else { 0.0 }).abs() <= 1e-6
                                })
                        });
                    if !identity {
                        return Err(unsupported(
                            path,
                            &format!("line {line}: Direction {d:?}"),
                            "volpt's grids are axis-aligned: expected the identity matrix",
                        ));
                    }
                }
                let extent = attribute(&element, b"WholeExtent");
                points = extent.as_deref().and_then(extent_points);
                check_extent(path, line, extent, file_bytes)?;
            }
            b"Piece" => {
                let extent = attribute(&element, b"Extent");
                points = extent.as_deref().and_then(extent_points);
                check_extent(path, line, extent, file_bytes)?
            }
            // vtkio reserves components x tuples values for an array before reading it.
            b"DataArray" => {
                let number =
                    |name: &[u8]| attribute(&element, name).map(|v| v.trim().parse::<u64>().ok());
                let components = number(b"NumberOfComponents").unwrap_or(Some(1));
                let tuples = number(b"NumberOfTuples").unwrap_or(points);
                let declared = match (components, tuples) {
                    (Some(c), Some(t)) => Some(c.saturating_mul(t)),
                    // A count that is not a number: vtkio reports it.
                    _ => None,
                };
                check_declared(path, line, "DataArray", declared, file_bytes)?
            }
            // Raw appended data is not XML: stop before it.
            b"AppendedData" => return Ok(()),
            _ => {}
        }
        buffer.clear();
    }
}

fn attribute(element: &BytesStart, name: &[u8]) -> Option<String> {
    element
        .try_get_attribute(name)
        .ok()
        .flatten()
        .map(|a| String::from_utf8_lossy(&a.value).into_owned())
}

/// An XML extent `x0 x1 y0 y1 z0 z1` must declare at most [`MAX_VALUES`] points, and no more
/// than the file has bytes.
fn check_extent(
    path: &Path,
    line: usize,
    extent: Option<String>,
    file_bytes: u64,
) -> Result<(), SceneError> {
    let Some(extent) = extent else {
        return Ok(());
    };
    let numbers: Option<Vec<i64>> = extent
        .split_whitespace()
        .map(|t| t.parse::<i64>().ok())
        .collect();
    let Some(&[x0, x1, y0, y1, z0, z1]) = numbers.as_deref() else {
        return Err(bad_field(
            path,
            format!("line {line}: extent"),
            "six integers x0 x1 y0 y1 z0 z1".into(),
            extent,
        ));
    };
    // Saturating: a hostile extent must not overflow; a huge one is refused below.
    let dims =
        [(x0, x1), (y0, y1), (z0, z1)].map(|(lo, hi)| hi.saturating_sub(lo).saturating_add(1));
    if dims.iter().any(|&d| d <= 0) {
        return Err(bad_field(
            path,
            format!("line {line}: extent"),
            "x0 <= x1, y0 <= y1, z0 <= z1".into(),
            extent,
        ));
    }
    let values = dims
        .iter()
        .try_fold(1u64, |acc, &d| acc.checked_mul(d as u64));
    if values.is_none_or(|v| v > MAX_VALUES) {
        return Err(grid_error(
            path,
            GridProblem::TooLarge {
                resolution: dims.map(|d| u32::try_from(d).unwrap_or(u32::MAX)),
                channels: 1,
                limit: MAX_VALUES,
            },
        ));
    }
    check_declared(path, line, "extent", values, file_bytes)
}

/// The points an extent `x0 x1 y0 y1 z0 z1` spans, if it is well-formed.
fn extent_points(extent: &str) -> Option<u64> {
    let numbers: Option<Vec<i64>> = extent
        .split_whitespace()
        .map(|t| t.parse::<i64>().ok())
        .collect();
    let &[x0, x1, y0, y1, z0, z1] = numbers?.as_slice() else {
        return None;
    };
    [(x0, x1), (y0, y1), (z0, z1)]
        .iter()
        .try_fold(1u64, |acc, &(lo, hi)| {
            let points = hi.checked_sub(lo)?.checked_add(1)?;
            acc.checked_mul(u64::try_from(points).ok()?)
        })
}

fn unsupported(path: &Path, what: &str, reason: &str) -> SceneError {
    grid_error(
        path,
        GridProblem::Unsupported {
            what: what.into(),
            reason: reason.into(),
        },
    )
}

fn bad_field(path: &Path, field: String, expected: String, found: String) -> SceneError {
    grid_error(
        path,
        GridProblem::BadField {
            line: None,
            field,
            expected,
            found,
        },
    )
}
