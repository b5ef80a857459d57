//! Raw voxel files: values only, with the layout (resolution, channels, element type, byte order,
//! bytes to skip) given by the caller, such as NVIDIA's `Bucky.raw` (32 x 32 x 32 `u8`).
//!
//! The MetaImage reader ([`crate::metaimage`]) is a header in front of exactly this data, so the
//! decoding, size checks and value checks live here and both formats share them.
//!
//! Values are stored x fastest, channels interleaved (`((z * res_y + y) * res_x + x) * channels +
//! c`), the order of [`GridDesc::data`]. Each voxel is a cell: the grid gets
//! [`GridConvention::Cell`] and the caller's bounds, so voxel `i`'s centre is at
//! `min + (i + 1/2) * (max - min) / res`.
//!
//! A layout is untrusted (it may come from a file header): its size is checked (no overflow, at
//! most [`MAX_VALUES`] values, exactly the bytes the file holds) before anything is allocated from
//! it, and every value must be finite and non-negative, because volpt's grids are densities and
//! albedos.

use std::fs::File;
use std::io::{BufWriter, ErrorKind, Read, Seek, SeekFrom, Write};
use std::path::Path;

use crate::description::{Bounds, GridConvention, GridDesc};
use crate::error::{GridProblem, SceneError};

/// The most values (voxels x channels) volpt reads from one grid file: 2^32, 16 GiB as `f32`,
/// more than a grid volpt can render on the machines it runs on. A header declaring more is
/// corrupt or hostile, and is rejected before anything is allocated.
pub const MAX_VALUES: u64 = 1 << 32;

/// How one value is stored (in TOML scenes: `u8`, `i8`, ... `f64`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ScalarType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl ScalarType {
    /// Every type, for round-trip tests and for listing what is accepted.
    pub const ALL: [ScalarType; 10] = [
        Self::I8,
        Self::U8,
        Self::I16,
        Self::U16,
        Self::I32,
        Self::U32,
        Self::I64,
        Self::U64,
        Self::F32,
        Self::F64,
    ];

    /// The type's name in volpt's scene files: `u8`, `i16`, `f32`, ...
    pub fn name(self) -> &'static str {
        match self {
            Self::I8 => "i8",
            Self::U8 => "u8",
            Self::I16 => "i16",
            Self::U16 => "u16",
            Self::I32 => "i32",
            Self::U32 => "u32",
            Self::I64 => "i64",
            Self::U64 => "u64",
            Self::F32 => "f32",
            Self::F64 => "f64",
        }
    }

    /// Size of one value in bytes.
    pub fn bytes(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// Decodes one value from the first [`Self::bytes`] bytes of `b` (the caller passes exactly
    /// that many). 64-bit integers above 2^53 round, as they do in every f32 grid.
    fn decode(self, b: &[u8], order: ByteOrder) -> f64 {
        match self {
            Self::I8 => f64::from(i8::from_le_bytes(ordered(b, order))),
            Self::U8 => f64::from(b[0]),
            Self::I16 => f64::from(i16::from_le_bytes(ordered(b, order))),
            Self::U16 => f64::from(u16::from_le_bytes(ordered(b, order))),
            Self::I32 => f64::from(i32::from_le_bytes(ordered(b, order))),
            Self::U32 => f64::from(u32::from_le_bytes(ordered(b, order))),
            Self::I64 => i64::from_le_bytes(ordered(b, order)) as f64,
            Self::U64 => u64::from_le_bytes(ordered(b, order)) as f64,
            Self::F32 => f64::from(f32::from_le_bytes(ordered(b, order))),
            Self::F64 => f64::from_le_bytes(ordered(b, order)),
        }
    }

    /// Appends `value` in this type, or returns `false` if the type cannot hold it exactly (a
    /// fraction or an out-of-range number for an integer type).
    fn encode(self, value: f32, order: ByteOrder, out: &mut Vec<u8>) -> bool {
        let v = f64::from(value);
        // [min, end) of each integer type, exact in f64; floats hold any f32.
        let range = match self {
            Self::I8 => Some((-128.0, 128.0)),
            Self::U8 => Some((0.0, 256.0)),
            Self::I16 => Some((-32768.0, 32768.0)),
            Self::U16 => Some((0.0, 65536.0)),
            Self::I32 => Some((-2147483648.0, 2147483648.0)),
            Self::U32 => Some((0.0, 4294967296.0)),
            Self::I64 => Some((-9223372036854775808.0, 9223372036854775808.0)),
            Self::U64 => Some((0.0, 18446744073709551616.0)),
            Self::F32 | Self::F64 => None,
        };
        if let Some((min, end)) = range {
            if !(v.fract() == 0.0 && v >= min && v < end) {
                return false;
            }
        }
        // In range and integral: the `as` casts below are exact.
        let mut bytes = match self {
            Self::I8 => (v as i8).to_le_bytes().to_vec(),
            Self::U8 => vec![v as u8],
            Self::I16 => (v as i16).to_le_bytes().to_vec(),
            Self::U16 => (v as u16).to_le_bytes().to_vec(),
            Self::I32 => (v as i32).to_le_bytes().to_vec(),
            Self::U32 => (v as u32).to_le_bytes().to_vec(),
            Self::I64 => (v as i64).to_le_bytes().to_vec(),
            Self::U64 => (v as u64).to_le_bytes().to_vec(),
            Self::F32 => value.to_le_bytes().to_vec(),
            Self::F64 => v.to_le_bytes().to_vec(),
        };
        if order == ByteOrder::Big {
            bytes.reverse();
        }
        out.extend_from_slice(&bytes);
        true
    }
}

/// Byte order of multi-byte values (in TOML scenes: `little`, the default, or `big`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ByteOrder {
    #[default]
    Little,
    Big,
}

/// How a raw file stores its grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawLayout {
    pub resolution: [u32; 3],
    /// Values per voxel, interleaved: 1 (density, grey albedo) or 3 (RGB albedo).
    pub channels: u32,
    pub scalar: ScalarType,
    pub byte_order: ByteOrder,
    /// Bytes before the data (a header volpt does not interpret).
    pub header_bytes: u64,
}

impl RawLayout {
    /// The number of values and of data bytes, checked against overflow and [`MAX_VALUES`];
    /// `path` names the file in the error.
    pub fn checked_size(&self, path: &Path) -> Result<(usize, u64), SceneError> {
        if self.resolution.contains(&0) || self.channels == 0 {
            let [x, y, z] = self.resolution;
            return Err(grid_error(
                path,
                GridProblem::BadField {
                    line: None,
                    field: "resolution x channels".into(),
                    expected: "at least 1 on every axis and at least 1 channel".into(),
                    found: format!("{x} x {y} x {z} x {}", self.channels),
                },
            ));
        }
        let too_large = || {
            grid_error(
                path,
                GridProblem::TooLarge {
                    resolution: self.resolution,
                    channels: self.channels,
                    limit: MAX_VALUES,
                },
            )
        };
        // Four u32 factors can overflow u64: check each step.
        let values = self
            .resolution
            .iter()
            .try_fold(u64::from(self.channels), |acc, &r| {
                acc.checked_mul(u64::from(r))
            })
            .filter(|&v| v <= MAX_VALUES)
            .ok_or_else(too_large)?;
        let count = usize::try_from(values).map_err(|_| too_large())?;
        crate::limits::check_grid_memory(path, self.resolution, self.channels, values)?;
        // At most 2^32 values of at most 8 bytes: no overflow.
        Ok((count, values * self.scalar.bytes() as u64))
    }
}

/// Reads a raw grid with the given layout; `bounds` is where the grid sits in world space.
/// The file must hold exactly `header_bytes` plus the data, and every value must be finite and
/// non-negative.
pub fn read_raw(path: &Path, layout: &RawLayout, bounds: Bounds) -> Result<GridDesc, SceneError> {
    let (mut file, data_bytes) = open_raw(path, layout)?;
    let what = format!("voxel data in {}", path.display());
    let data = read_values(&mut file, layout, data_bytes, path, path, &what)?;
    Ok(GridDesc {
        layout: crate::description::SampleLayout::Dense,
        resolution: layout.resolution,
        channels: layout.channels,
        bounds,
        convention: GridConvention::Cell,
        data,
    })
}

/// [`read_raw`]'s values, streamed straight into the caller's `out` (for instance page-locked
/// memory a GPU reads), which must hold exactly the layout's number of values: no second copy of
/// the grid is ever made. The same checks and errors as [`read_raw`]; after an error `out` holds
/// the values read so far.
pub fn read_raw_into(path: &Path, layout: &RawLayout, out: &mut [f32]) -> Result<(), SceneError> {
    let (count, _) = layout.checked_size(path)?;
    if out.len() != count {
        let [x, y, z] = layout.resolution;
        return Err(grid_error(
            path,
            GridProblem::BadField {
                line: None,
                field: "the caller's buffer".into(),
                expected: format!("{count} values ({x} x {y} x {z} x {})", layout.channels),
                found: format!("{} values", out.len()),
            },
        ));
    }
    let (mut file, data_bytes) = open_raw(path, layout)?;
    let what = format!("voxel data in {}", path.display());
    stream_values(&mut file, layout, data_bytes, path, path, &what, |i, v| {
        out[i] = v;
    })
}

/// Opens a raw file, checks that it holds exactly the header and the layout's data, and leaves it
/// at the data; returns it with the data's length in bytes.
fn open_raw(path: &Path, layout: &RawLayout) -> Result<(File, u64), SceneError> {
    let (_, data_bytes) = layout.checked_size(path)?;
    let io = |error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    };
    let (mut file, file_bytes) = crate::limits::open_regular(path)?;
    let what = || {
        format!(
            "{} header bytes + data of {} x {} x {} voxels x {} channels x {} bytes",
            layout.header_bytes,
            layout.resolution[0],
            layout.resolution[1],
            layout.resolution[2],
            layout.channels,
            layout.scalar.bytes()
        )
    };
    let expected = layout.header_bytes.saturating_add(data_bytes);
    if file_bytes < expected {
        return Err(grid_error(
            path,
            GridProblem::SizeMismatch {
                what: what(),
                expected_bytes: expected,
                actual_bytes: file_bytes,
            },
        ));
    }
    if file_bytes > expected {
        return Err(grid_error(
            path,
            GridProblem::ExcessData {
                what: what(),
                expected_bytes: expected,
            },
        ));
    }
    file.seek(SeekFrom::Start(layout.header_bytes))
        .map_err(io)?;
    Ok((file, data_bytes))
}

/// Writes a grid's values (no header) in the given type and byte order. Integer types must hold
/// every value exactly (integral and in range); the bounds are not stored.
pub fn write_raw(
    path: &Path,
    grid: &GridDesc,
    scalar: ScalarType,
    byte_order: ByteOrder,
) -> Result<(), SceneError> {
    let bytes = encode_values(path, grid, scalar, byte_order)?;
    write_file(path, &bytes)
}

/// Reads `data_bytes` bytes of values of `layout` from `reader` (sized by
/// [`RawLayout::checked_size`]), checking each value and that the stream holds exactly that many
/// bytes. `path` is the file errors are about, `source` the file read (the data file of a `.mhd`),
/// and `what` names the data in size errors.
pub(crate) fn read_values(
    reader: &mut impl Read,
    layout: &RawLayout,
    data_bytes: u64,
    path: &Path,
    source: &Path,
    what: &str,
) -> Result<Vec<f32>, SceneError> {
    let count = (data_bytes / layout.scalar.bytes() as u64) as usize; // checked_size made it fit
    let mut data = Vec::new();
    if data.try_reserve_exact(count).is_err() {
        return Err(grid_error(
            path,
            GridProblem::TooLarge {
                resolution: layout.resolution,
                channels: layout.channels,
                limit: MAX_VALUES,
            },
        ));
    }
    stream_values(reader, layout, data_bytes, path, source, what, |_, v| {
        data.push(v)
    })?;
    Ok(data)
}

/// [`read_values`] into `sink(index, value)`, value by value, each checked.
fn stream_values(
    reader: &mut impl Read,
    layout: &RawLayout,
    data_bytes: u64,
    path: &Path,
    source: &Path,
    what: &str,
    mut sink: impl FnMut(usize, f32),
) -> Result<(), SceneError> {
    const CHUNK: usize = 1 << 16; // a multiple of every value size
    let decode_error = |error: std::io::Error, path: &Path, what: &str| match error.kind() {
        // What a corrupt zlib stream reports.
        ErrorKind::InvalidInput | ErrorKind::InvalidData => grid_error(
            path,
            GridProblem::Decode {
                what: what.to_string(),
                message: error.to_string(),
            },
        ),
        _ => SceneError::Io {
            path: source.to_path_buf(),
            error,
        },
    };
    let size = layout.scalar.bytes();
    let mut index = 0;
    let mut buffer = vec![0u8; CHUNK];
    let mut done = 0u64;
    while done < data_bytes {
        let n = (data_bytes - done).min(CHUNK as u64) as usize;
        let got = read_full(reader, &mut buffer[..n]).map_err(|e| decode_error(e, path, what))?;
        if got < n {
            return Err(grid_error(
                path,
                GridProblem::SizeMismatch {
                    what: what.to_string(),
                    expected_bytes: data_bytes,
                    actual_bytes: done + got as u64,
                },
            ));
        }
        for bytes in buffer[..n].chunks_exact(size) {
            let value = layout.scalar.decode(bytes, layout.byte_order);
            sink(index, checked_value(path, layout, index, value)?);
            index += 1;
        }
        done += n as u64;
    }
    if read_full(reader, &mut buffer[..1]).map_err(|e| decode_error(e, path, what))? != 0 {
        return Err(grid_error(
            path,
            GridProblem::ExcessData {
                what: what.to_string(),
                expected_bytes: data_bytes,
            },
        ));
    }
    Ok(())
}

/// A decoded value as `f32`, or the error naming its voxel: volpt's grids are densities and
/// albedos, so a value must be finite and non-negative (also after narrowing to `f32`).
pub(crate) fn checked_value(
    path: &Path,
    layout: &RawLayout,
    index: usize,
    value: f64,
) -> Result<f32, SceneError> {
    let narrow = value as f32;
    if value >= 0.0 && narrow.is_finite() {
        return Ok(narrow);
    }
    let (voxel, channel) = voxel_of(layout.resolution, layout.channels, index);
    Err(grid_error(
        path,
        GridProblem::BadValue {
            voxel,
            channel,
            value,
            expected: "a finite value >= 0 (and below f32's maximum)",
        },
    ))
}

/// The grid's values in `scalar` and `byte_order`, checking the data length first.
pub(crate) fn encode_values(
    path: &Path,
    grid: &GridDesc,
    scalar: ScalarType,
    byte_order: ByteOrder,
) -> Result<Vec<u8>, SceneError> {
    check_data_length(path, grid)?;
    let mut out = Vec::with_capacity(grid.data.len() * scalar.bytes());
    for (index, &value) in grid.data.iter().enumerate() {
        if !scalar.encode(value, byte_order, &mut out) {
            let (voxel, channel) = voxel_of(grid.resolution, grid.channels, index);
            return Err(grid_error(
                path,
                GridProblem::BadValue {
                    voxel,
                    channel,
                    value: f64::from(value),
                    expected: "a value the element type holds exactly",
                },
            ));
        }
    }
    Ok(out)
}

/// Checks that an in-memory grid's data length matches its resolution and channels.
pub(crate) fn check_data_length(path: &Path, grid: &GridDesc) -> Result<(), SceneError> {
    let expected = grid
        .resolution
        .iter()
        .try_fold(grid.channels as usize, |acc, &r| {
            acc.checked_mul(r as usize)
        });
    if expected != Some(grid.data.len()) || grid.data.is_empty() {
        return Err(grid_error(
            path,
            GridProblem::DataLength {
                expected: expected.unwrap_or(usize::MAX),
                found: grid.data.len(),
            },
        ));
    }
    Ok(())
}

/// Bounds of a grid whose voxel `i` is centred at `offset + i * spacing` (each voxel a cell):
/// `[offset - spacing/2, offset + (res - 1/2) * spacing]`. `None` if a bound is not finite in
/// `f32` or the box is empty.
pub(crate) fn centred_bounds(
    offset: [f64; 3],
    spacing: [f64; 3],
    resolution: [u32; 3],
) -> Option<Bounds> {
    let mut min = [0.0f32; 3];
    let mut max = [0.0f32; 3];
    for a in 0..3 {
        min[a] = (offset[a] - 0.5 * spacing[a]) as f32;
        max[a] = (offset[a] + (f64::from(resolution[a]) - 0.5) * spacing[a]) as f32;
        if !(min[a].is_finite() && max[a].is_finite() && min[a] < max[a]) {
            return None;
        }
    }
    Some(Bounds { min, max })
}

/// The inverse of [`centred_bounds`]: the first voxel's centre and the spacing of a grid's
/// samples, in either convention (a vertex-centred grid's samples lie on its box's faces).
pub(crate) fn centres_of(grid: &GridDesc) -> ([f64; 3], [f64; 3]) {
    let mut offset = [0.0; 3];
    let mut spacing = [0.0; 3];
    for a in 0..3 {
        let min = f64::from(grid.bounds.min[a]);
        let extent = f64::from(grid.bounds.max[a]) - min;
        let res = f64::from(grid.resolution[a].max(1));
        match grid.convention {
            GridConvention::Cell => {
                spacing[a] = extent / res;
                offset[a] = min + 0.5 * spacing[a];
            }
            GridConvention::Vertex => {
                // One sample has no spacing to speak of: give it the box's extent.
                spacing[a] = if res > 1.0 {
                    extent / (res - 1.0)
                } else {
                    extent
                };
                offset[a] = min;
            }
        }
    }
    (offset, spacing)
}

/// Creates `path` and writes `bytes` to it.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let io = |error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    };
    let mut out = BufWriter::new(File::create(path).map_err(io)?);
    out.write_all(bytes).map_err(io)?;
    out.flush().map_err(io)
}

pub(crate) fn grid_error(path: &Path, problem: GridProblem) -> SceneError {
    SceneError::Grid {
        path: path.to_path_buf(),
        problem,
    }
}

/// Reads until `buffer` is full or the stream ends; returns the bytes read.
pub(crate) fn read_full(reader: &mut impl Read, buffer: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buffer.len() {
        match reader.read(&mut buffer[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// The first `N` bytes of `b` in little-endian order.
fn ordered<const N: usize>(b: &[u8], order: ByteOrder) -> [u8; N] {
    let mut a = [0u8; N];
    a.copy_from_slice(&b[..N]);
    if order == ByteOrder::Big {
        a.reverse();
    }
    a
}

/// The voxel and channel of a flat index into a grid's data.
fn voxel_of(resolution: [u32; 3], channels: u32, index: usize) -> ([u32; 3], u32) {
    let channels = channels.max(1) as usize;
    let [rx, ry, _] = resolution.map(|r| r.max(1) as usize);
    let voxel = index / channels;
    let x = voxel % rx;
    let y = (voxel / rx) % ry;
    let z = voxel / (rx * ry);
    ([x as u32, y as u32, z as u32], (index % channels) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_type_decodes_what_it_encodes_in_both_orders() {
        for scalar in ScalarType::ALL {
            for order in [ByteOrder::Little, ByteOrder::Big] {
                let mut out = Vec::new();
                assert!(scalar.encode(100.0, order, &mut out));
                assert_eq!(out.len(), scalar.bytes());
                assert_eq!(scalar.decode(&out, order), 100.0, "{scalar:?} {order:?}");
            }
        }
    }

    #[test]
    fn big_endian_is_most_significant_byte_first() {
        let mut out = Vec::new();
        assert!(ScalarType::U16.encode(258.0, ByteOrder::Big, &mut out));
        assert_eq!(out, [1, 2]);
        assert_eq!(ScalarType::U16.decode(&[1, 2], ByteOrder::Little), 513.0);
    }

    #[test]
    fn integer_types_refuse_values_they_cannot_hold() {
        let mut out = Vec::new();
        assert!(!ScalarType::U8.encode(256.0, ByteOrder::Little, &mut out));
        assert!(!ScalarType::U8.encode(0.5, ByteOrder::Little, &mut out));
        assert!(!ScalarType::U64.encode(-1.0, ByteOrder::Little, &mut out));
        assert!(!ScalarType::U64.encode(2f32.powi(64), ByteOrder::Little, &mut out));
        assert!(out.is_empty());
    }

    #[test]
    fn centred_bounds_invert() {
        let bounds = centred_bounds([1.0, 2.0, 3.0], [0.5, 1.0, 2.0], [4, 2, 1]).unwrap();
        assert_eq!(bounds.min, [0.75, 1.5, 2.0]);
        assert_eq!(bounds.max, [2.75, 3.5, 4.0]);
        let grid = GridDesc {
            layout: crate::description::SampleLayout::Dense,
            resolution: [4, 2, 1],
            channels: 1,
            bounds,
            convention: GridConvention::Cell,
            data: vec![0.0; 8],
        };
        assert_eq!(centres_of(&grid), ([1.0, 2.0, 3.0], [0.5, 1.0, 2.0]));
    }

    #[test]
    fn voxel_indices_are_x_fastest() {
        assert_eq!(voxel_of([4, 3, 2], 3, 5), ([1, 0, 0], 2));
        assert_eq!(voxel_of([4, 3, 2], 1, 12 + 4 + 1), ([1, 1, 1], 0));
    }
}
