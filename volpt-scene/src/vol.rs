//! Mitsuba's `.vol` grid format (version 3), read and written.
//!
//! Layout, all little-endian: the bytes `VOL`, a `u8` version (3), an `i32` encoding (1 = float32,
//! 2 = float16, 3 = uint8 normalised by 1/255), `i32` resolutions x, y, z, an `i32` channel count,
//! six `f32` (bounding box min x y z, max x y z), then the values with x fastest and channels
//! interleaved: `data[((z * res_y + y) * res_x + x) * channels + c]`.
//!
//! A header is untrusted input: every size derived from it is checked (positive, no overflow, and
//! exactly the number of bytes the file holds) before anything is allocated from it, so a corrupt
//! or hostile file yields an error, never an abort or a huge allocation.

use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::Path;

use crate::description::Bounds;
use crate::error::{SceneError, VolProblem};

/// Size of the fixed header in bytes.
pub const VOL_HEADER_BYTES: u64 = 48;

/// A grid as stored in a `.vol` file, values decoded to `f32`.
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    pub resolution: [u32; 3],
    pub channels: u32,
    /// The bounding box the file declares (its meaning depends on the Mitsuba version reading it).
    pub bbox: Bounds,
    /// `data[((z * res_y + y) * res_x + x) * channels + c]`.
    pub data: Vec<f32>,
}

impl VolGrid {
    /// Number of values a grid of this shape holds, or `None` if it overflows `usize`.
    pub fn value_count(resolution: [u32; 3], channels: u32) -> Option<usize> {
        let mut count = channels as usize;
        for r in resolution {
            count = count.checked_mul(r as usize)?;
        }
        Some(count)
    }

    /// The voxel and channel of a flat index into `data`.
    pub fn voxel_of(&self, index: usize) -> ([u32; 3], u32) {
        voxel_of(self.resolution, self.channels, index)
    }

    /// Checks the grid can serve as a density (extinction) grid: one channel or three (a density
    /// per channel), values >= 0
    /// (finiteness is already guaranteed by [`read_vol`]). `path` is the file, for the message.
    pub fn check_density(&self, path: &Path) -> Result<(), SceneError> {
        if self.channels != 1 && self.channels != 3 {
            return Err(vol_error(
                path,
                VolProblem::WrongChannels {
                    role: "density",
                    expected: "1 channel (grey) or 3 (a density per channel)",
                    found: self.channels,
                },
            ));
        }
        self.check_values(path, "a finite value >= 0", |v| v.is_finite() && v >= 0.0)
    }

    /// Checks the grid can serve as an albedo grid: 1 (grey) or 3 (RGB) channels, values in [0, 1].
    pub fn check_albedo(&self, path: &Path) -> Result<(), SceneError> {
        if self.channels != 1 && self.channels != 3 {
            return Err(vol_error(
                path,
                VolProblem::WrongChannels {
                    role: "albedo",
                    expected: "1 or 3 channels",
                    found: self.channels,
                },
            ));
        }
        self.check_values(path, "a value in [0, 1]", |v| (0.0..=1.0).contains(&v))
    }

    fn check_values(
        &self,
        path: &Path,
        expected: &'static str,
        ok: impl Fn(f32) -> bool,
    ) -> Result<(), SceneError> {
        match self.data.iter().position(|&v| !ok(v)) {
            None => Ok(()),
            Some(index) => {
                let (voxel, channel) = self.voxel_of(index);
                let value = self.data[index];
                Err(vol_error(
                    path,
                    VolProblem::BadValue {
                        voxel,
                        channel,
                        value,
                        expected,
                    },
                ))
            }
        }
    }
}

/// How the values are stored on disk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Float32,
    Float16,
    UInt8,
}

impl Encoding {
    fn from_code(code: i32) -> Option<Self> {
        match code {
            1 => Some(Self::Float32),
            2 => Some(Self::Float16),
            3 => Some(Self::UInt8),
            _ => None,
        }
    }

    fn bytes_per_value(self) -> usize {
        match self {
            Self::Float32 => 4,
            Self::Float16 => 2,
            Self::UInt8 => 1,
        }
    }

    fn decode(self, bytes: &[u8]) -> f32 {
        match self {
            Self::Float32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
            Self::Float16 => f16_to_f32(u16::from_le_bytes([bytes[0], bytes[1]])),
            Self::UInt8 => f32::from(bytes[0]) / 255.0,
        }
    }
}

/// A validated header.
struct Header {
    encoding: Encoding,
    resolution: [u32; 3],
    channels: u32,
    bbox: Bounds,
    value_count: usize,
    data_bytes: u64,
}

/// Reads a `.vol` file. Rejects malformed headers, a data size that differs from the file's, and
/// non-finite values (naming the first bad voxel).
pub fn read_vol(path: &Path) -> Result<VolGrid, SceneError> {
    let io = |error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    };
    let (mut file, file_bytes) = crate::limits::open_regular(path)?;
    if file_bytes < VOL_HEADER_BYTES {
        return Err(vol_error(
            path,
            VolProblem::TruncatedHeader {
                expected_bytes: VOL_HEADER_BYTES,
                actual_bytes: file_bytes,
            },
        ));
    }
    let mut raw = [0u8; VOL_HEADER_BYTES as usize];
    file.read_exact(&mut raw).map_err(io)?;
    let header =
        parse_header(&raw, file_bytes - VOL_HEADER_BYTES).map_err(|p| vol_error(path, p))?;
    let values = header.value_count as u64;
    crate::limits::check_grid_memory(path, header.resolution, header.channels, values)?;

    let mut data = Vec::new();
    if data.try_reserve_exact(header.value_count).is_err() {
        let [x, y, z] = header.resolution;
        return Err(vol_error(
            path,
            VolProblem::TooLarge {
                resolution: [x as i32, y as i32, z as i32],
                channels: header.channels as i32,
            },
        ));
    }
    read_values(&mut file, &header, &mut data).map_err(io)?;
    if let Some(index) = data.iter().position(|v| !v.is_finite()) {
        let (voxel, channel) = voxel_of(header.resolution, header.channels, index);
        let value = data[index];
        return Err(vol_error(
            path,
            VolProblem::BadValue {
                voxel,
                channel,
                value,
                expected: "a finite number",
            },
        ));
    }
    Ok(VolGrid {
        resolution: header.resolution,
        channels: header.channels,
        bbox: header.bbox,
        data,
    })
}

/// Writes a grid as a float32 `.vol` file.
pub fn write_vol(path: &Path, grid: &VolGrid) -> Result<(), SceneError> {
    let expected = VolGrid::value_count(grid.resolution, grid.channels);
    if expected != Some(grid.data.len()) {
        return Err(vol_error(
            path,
            VolProblem::DataLength {
                expected: expected.unwrap_or(usize::MAX),
                found: grid.data.len(),
            },
        ));
    }
    // The header stores sizes as i32: refuse shapes that would not read back.
    let as_i32 = |v: u32| i32::try_from(v).ok().filter(|&v| v > 0);
    let (Some(x), Some(y), Some(z)) = (
        as_i32(grid.resolution[0]),
        as_i32(grid.resolution[1]),
        as_i32(grid.resolution[2]),
    ) else {
        let [x, y, z] = grid.resolution;
        return Err(vol_error(
            path,
            VolProblem::BadResolution {
                found: [x as i32, y as i32, z as i32],
            },
        ));
    };
    if grid.channels == 0 || grid.channels > i32::MAX as u32 {
        return Err(vol_error(
            path,
            VolProblem::BadChannels {
                found: grid.channels as i32,
            },
        ));
    }

    let io = |error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    };
    let mut out = BufWriter::new(File::create(path).map_err(io)?);
    let mut header = Vec::with_capacity(VOL_HEADER_BYTES as usize);
    header.extend_from_slice(b"VOL");
    header.push(3);
    for v in [1, x, y, z, grid.channels as i32] {
        header.extend_from_slice(&v.to_le_bytes());
    }
    for v in grid.bbox.min.iter().chain(&grid.bbox.max) {
        header.extend_from_slice(&v.to_le_bytes());
    }
    out.write_all(&header).map_err(io)?;
    for v in &grid.data {
        out.write_all(&v.to_le_bytes()).map_err(io)?;
    }
    out.flush().map_err(io)
}

/// Validates a raw header against the number of bytes that follow it in the file.
fn parse_header(
    raw: &[u8; VOL_HEADER_BYTES as usize],
    data_bytes: u64,
) -> Result<Header, VolProblem> {
    let magic = [raw[0], raw[1], raw[2]];
    if &magic != b"VOL" {
        return Err(VolProblem::BadMagic { found: magic });
    }
    if raw[3] != 3 {
        return Err(VolProblem::UnsupportedVersion { found: raw[3] });
    }
    let int = |i: usize| i32::from_le_bytes([raw[i], raw[i + 1], raw[i + 2], raw[i + 3]]);
    let float = |i: usize| f32::from_le_bytes([raw[i], raw[i + 1], raw[i + 2], raw[i + 3]]);

    let code = int(4);
    let encoding =
        Encoding::from_code(code).ok_or(VolProblem::UnsupportedEncoding { found: code })?;
    let res = [int(8), int(12), int(16)];
    if res.iter().any(|&r| r <= 0) {
        return Err(VolProblem::BadResolution { found: res });
    }
    let channels = int(20);
    if channels != 1 && channels != 3 {
        return Err(VolProblem::BadChannels { found: channels });
    }
    let min = [float(24), float(28), float(32)];
    let max = [float(36), float(40), float(44)];
    if min.iter().chain(&max).any(|v| !v.is_finite()) {
        return Err(VolProblem::BadBounds { min, max });
    }

    // All positive, so the casts are exact; u64 products of four i32 may still overflow.
    let too_large = VolProblem::TooLarge {
        resolution: res,
        channels,
    };
    let resolution = res.map(|r| r as u32);
    let values = resolution
        .iter()
        .try_fold(channels as u64, |acc, &r| acc.checked_mul(u64::from(r)))
        .ok_or(too_large.clone())?;
    let expected_bytes = values
        .checked_mul(encoding.bytes_per_value() as u64)
        .ok_or(too_large.clone())?;
    if expected_bytes != data_bytes {
        return Err(VolProblem::SizeMismatch {
            resolution,
            channels: channels as u32,
            expected_bytes,
            actual_bytes: data_bytes,
        });
    }
    let value_count = usize::try_from(values).map_err(|_| too_large)?;
    Ok(Header {
        encoding,
        resolution,
        channels: channels as u32,
        bbox: Bounds { min, max },
        value_count,
        data_bytes: expected_bytes,
    })
}

/// Decodes the data section in fixed-size chunks, so memory stays at one copy of the grid.
fn read_values(file: &mut File, header: &Header, data: &mut Vec<f32>) -> std::io::Result<()> {
    const CHUNK: usize = 1 << 16; // a multiple of every value size
    let size = header.encoding.bytes_per_value();
    let mut buffer = vec![0u8; CHUNK];
    let mut remaining = header.data_bytes;
    while remaining > 0 {
        let n = remaining.min(CHUNK as u64) as usize;
        file.read_exact(&mut buffer[..n])?;
        data.extend(
            buffer[..n]
                .chunks_exact(size)
                .map(|b| header.encoding.decode(b)),
        );
        remaining -= n as u64;
    }
    Ok(())
}

fn voxel_of(resolution: [u32; 3], channels: u32, index: usize) -> ([u32; 3], u32) {
    let channels = channels.max(1) as usize;
    let [rx, ry, _] = resolution.map(|r| r.max(1) as usize);
    let channel = index % channels;
    let voxel = index / channels;
    let x = voxel % rx;
    let y = (voxel / rx) % ry;
    let z = voxel / (rx * ry);
    ([x as u32, y as u32, z as u32], channel as u32)
}

fn vol_error(path: &Path, problem: VolProblem) -> SceneError {
    SceneError::Vol {
        path: path.to_path_buf(),
        problem,
    }
}

/// IEEE 754 binary16 to binary32 (exact: every half is representable as a float).
fn f16_to_f32(h: u16) -> f32 {
    let negative = h & 0x8000 != 0;
    let sign = u32::from(h >> 15) << 31;
    let exponent = u32::from((h >> 10) & 0x1f);
    let mantissa = u32::from(h & 0x3ff);
    match exponent {
        // Zero and subnormals: mantissa * 2^-24, which is a normal (or zero) float.
        0 => {
            let magnitude = mantissa as f32 * f32::powi(2.0, -24);
            if negative {
                -magnitude
            } else {
                magnitude
            }
        }
        // Infinities and NaNs keep their payload.
        0x1f => f32::from_bits(sign | 0x7f80_0000 | (mantissa << 13)),
        _ => f32::from_bits(sign | ((exponent + 127 - 15) << 23) | (mantissa << 13)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats_decode() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3800), 0.5);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), f32::powi(2.0, -24));
        assert_eq!(f16_to_f32(0x8001), -f32::powi(2.0, -24));
        assert!(f16_to_f32(0x7c00).is_infinite());
        assert!(f16_to_f32(0x7e00).is_nan());
        assert_eq!(f16_to_f32(0x8000).to_bits(), (-0.0f32).to_bits());
    }

    #[test]
    fn voxel_indices_are_x_fastest() {
        assert_eq!(voxel_of([4, 3, 2], 3, 0), ([0, 0, 0], 0));
        assert_eq!(voxel_of([4, 3, 2], 3, 5), ([1, 0, 0], 2));
        assert_eq!(voxel_of([4, 3, 2], 1, 4), ([0, 1, 0], 0));
        assert_eq!(voxel_of([4, 3, 2], 1, 12 + 4 + 1), ([1, 1, 1], 0));
    }
}
