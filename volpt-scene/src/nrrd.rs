//! NRRD grids (Teem's format, written by 3D Slicer, ITK and pynrrd): `.nrrd` (header and data in
//! one file) and `.nhdr` (header, with the data in the file named by `data file`, relative to the
//! header's folder), read.
//!
//! Read with volpt's own header parser rather than a crate: the header is a few text lines, the
//! data the raw values volpt's other formats share ([`crate::raw`]), optionally gzip-compressed
//! (flate2, which the MetaImage reader already uses); crates.io's `nrrd` readers are unmaintained
//! or pull in an n-dimensional array library for what is here one loop.
//!
//! The header starts with `NRRD000x`, then one `field: value` per line up to a blank line (or the
//! end of a `.nhdr`); `#` lines are comments and `key:=value` lines are ignored. Read fields:
//!
//! | field | meaning | default |
//! | --- | --- | --- |
//! | `dimension` | must be 3 | required |
//! | `sizes` | samples per axis, the first fastest | required |
//! | `type` | `int8`/`uchar`/... `uint64`, `float`, `double` (every spelling the format allows) | required |
//! | `encoding` | `raw` or `gzip` (`gz`); `ascii`, `hex` and `bzip2` are refused by name | required |
//! | `endian` | `little` or `big` | required for types wider than a byte |
//! | `space directions` | each axis's step between sample centres, `(x,y,z)`: axis-aligned, possibly mirrored or permuted ([`crate::orient`]) | from `spacings` |
//! | `space origin` | the first sample's centre `(x,y,z)` | `(0,0,0)` |
//! | `spacings` | steps along x, y, z when there are no `space directions` | `1 1 1` |
//! | `space dimension` (or `space`) | must be 3 (any named 3D space: volpt keeps the file's coordinates) | 3 |
//! | `data file` (`datafile`) | the data's file for a detached header | the header's own file |
//! | `line skip`, `byte skip` | lines then bytes to skip before the data; `byte skip: -1` (raw only): the data ends the file | 0 |
//!
//! Other fields (`kinds`, `centerings`, `space units`, `measurement frame`, ...) are ignored.
//!
//! **Geometry**: sample `(i, j, k)` is centred at `space origin + i d0 + j d1 + k d2`, each sample a
//! cell, as MetaImage's voxels are: a file and the `.mha` of the same samples read as the same grid.
//!
//! **Limits**: as [`crate::metaimage`]: the header within [`MAX_HEADER_BYTES`], the size checked
//! against overflow, [`crate::raw::MAX_VALUES`] and the memory limit before anything is allocated,
//! raw data exactly the declared bytes, gzip data at most [`crate::limits::DEFLATE_MAX_RATIO`]
//! times smaller than declared and decompressing to exactly it; every value finite and >= 0.

use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use flate2::read::MultiGzDecoder;

use crate::description::GridDesc;
use crate::error::{GridProblem, SceneError};
use crate::raw::{self, grid_error, ByteOrder, RawLayout, ScalarType};

/// The header must end within this many bytes (real headers are under a kilobyte).
pub const MAX_HEADER_BYTES: u64 = 1 << 16;

/// Whether `path` names an NRRD file by its extension (`.nrrd`, `.nhdr`).
pub fn is_nrrd(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("nrrd") || e.eq_ignore_ascii_case("nhdr"))
}

/// Reads a `.nrrd` or `.nhdr` file (see the module docs for the fields and checks).
pub fn read_nrrd(path: &Path) -> Result<GridDesc, SceneError> {
    let (file, _) = crate::limits::open_regular(path)?;
    let mut reader = BufReader::new(file);
    let (fields, header_len) = read_fields(path, &mut reader)?;
    let header = Header::parse(path, &fields)?;
    let (_, data_bytes) = header.layout.checked_size(path)?;

    let (data_file, data_path, region_start) = match &header.data_file {
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
    let mut data_file = BufReader::new(data_file);
    data_file
        .seek(SeekFrom::Start(region_start))
        .map_err(data_io)?;
    let mut skipped = 0u64;
    let mut line = Vec::new();
    for _ in 0..header.line_skip {
        line.clear();
        let n = (&mut data_file)
            .take(MAX_HEADER_BYTES)
            .read_until(b'\n', &mut line)
            .map_err(data_io)?;
        if n == 0 || !line.ends_with(b"\n") {
            return Err(bad(
                "line skip",
                &format!(
                    "at most the lines of {} (each under 64 KiB)",
                    data_path.display()
                ),
                header.line_skip.to_string(),
            )
            .at(path));
        }
        skipped += n as u64;
    }
    let file_len = data_file.get_ref().metadata().map_err(data_io)?.len();
    let region = file_len.saturating_sub(region_start + skipped);
    let what = |s: &str| format!("{s} in {}", data_path.display());
    let stored_name = if header.gzip {
        "gzip data"
    } else {
        "voxel data"
    };
    let skip = match header.byte_skip {
        ByteSkip::AtEnd if data_bytes > region => {
            return Err(grid_error(
                path,
                GridProblem::SizeMismatch {
                    what: what(stored_name),
                    expected_bytes: data_bytes,
                    actual_bytes: region,
                },
            ))
        }
        ByteSkip::AtEnd => region - data_bytes,
        ByteSkip::Bytes(skip) if skip > region => {
            return Err(grid_error(
                path,
                GridProblem::SizeMismatch {
                    what: what("byte skip and data"),
                    expected_bytes: skip,
                    actual_bytes: region,
                },
            ))
        }
        ByteSkip::Bytes(skip) => skip,
    };
    let stored = region - skip;
    if !header.gzip && stored != data_bytes {
        let problem = if stored < data_bytes {
            GridProblem::SizeMismatch {
                what: what(stored_name),
                expected_bytes: data_bytes,
                actual_bytes: stored,
            }
        } else {
            GridProblem::ExcessData {
                what: what(stored_name),
                expected_bytes: data_bytes,
            }
        };
        return Err(grid_error(path, problem));
    }
    // Deflate cannot expand past its own ratio: a header declaring more data than the stored
    // bytes can hold is refused before anything is reserved for it.
    let most = stored.saturating_mul(crate::limits::DEFLATE_MAX_RATIO);
    if header.gzip && data_bytes > most {
        return Err(grid_error(
            path,
            GridProblem::SizeMismatch {
                what: format!(
                    "{} (at most {} times the compressed size, deflate's limit)",
                    what("decompressed voxel data"),
                    crate::limits::DEFLATE_MAX_RATIO
                ),
                expected_bytes: data_bytes,
                actual_bytes: most,
            },
        ));
    }
    data_file
        .seek(SeekFrom::Start(region_start + skipped + skip))
        .map_err(data_io)?;
    let data = if header.gzip {
        let mut decoder = Corrupt(MultiGzDecoder::new(data_file.take(stored)));
        let what = what("decompressed voxel data");
        raw::read_values(
            &mut decoder,
            &header.layout,
            data_bytes,
            path,
            &data_path,
            &what,
        )?
    } else {
        let what = what("voxel data");
        raw::read_values(
            &mut data_file,
            &header.layout,
            data_bytes,
            path,
            &data_path,
            &what,
        )?
    };
    crate::orient::place(
        path,
        header.steps_field,
        header.layout.resolution,
        1,
        data,
        header.origin,
        header.steps,
    )
}

/// A decoder whose early end is corrupt data, not a failed read: its error names the data.
struct Corrupt<R>(R);

impl<R: Read> Read for Corrupt<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.0.read(buf).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => {
                std::io::Error::new(std::io::ErrorKind::InvalidData, e)
            }
            _ => e,
        })
    }
}

/// One `field: value` line of a header.
struct Field {
    key: String,
    value: String,
    line: usize,
}

#[derive(Clone, Copy)]
enum ByteSkip {
    Bytes(u64),
    /// `byte skip: -1`: the data ends the file.
    AtEnd,
}

/// A validated header.
struct Header {
    layout: RawLayout,
    gzip: bool,
    /// Each file axis's step between sample centres, and the field that gave them.
    steps: [[f64; 3]; 3],
    steps_field: &'static str,
    origin: [f64; 3],
    line_skip: u64,
    byte_skip: ByteSkip,
    /// `None`: the data follows the header.
    data_file: Option<PathBuf>,
}

impl Header {
    fn parse(path: &Path, fields: &[Field]) -> Result<Self, SceneError> {
        let get = |keys: &[&str]| {
            keys.iter()
                .find_map(|k| fields.iter().find(|f| f.key.eq_ignore_ascii_case(k)))
        };
        let require = |key: &'static str, expected: &'static str| {
            get(&[key]).ok_or_else(|| {
                grid_error(
                    path,
                    GridProblem::MissingField {
                        field: key,
                        expected,
                    },
                )
            })
        };
        let at = |e: Bad| e.at(path);

        let dimension = require("dimension", "3")?;
        if dimension.value != "3" {
            // A 4D file is a vector (RGB, a tensor) or a time series of volumes: which channel
            // or time is the density is the user's choice.
            return Err(at(bad_at(
                dimension,
                "3 (a scalar volume: a 4D file, RGB, vector or time series, is not read; extract \
                 one channel or time first, e.g. `unu slice -a 0 -p 0 -i in.nrrd -o out.nrrd`)",
            )));
        }
        if let Some(f) = get(&["space dimension"]) {
            if f.value != "3" {
                return Err(at(bad_at(f, "3")));
            }
        }
        let sizes = require("sizes", "three positive integers")?;
        let resolution = three::<u32>(sizes)
            .filter(|v| !v.contains(&0))
            .ok_or_else(|| at(bad_at(sizes, "three positive integers below 2^32")))?;
        let type_field = require("type", "a sample type such as uint8 or float")?;
        let scalar = scalar_of(&type_field.value).ok_or_else(|| {
            at(bad_at(
                type_field,
                "one of int8, uint8, int16, uint16, int32, uint32, int64, uint64, float, double \
                 (or another spelling NRRD allows)",
            ))
        })?;
        let encoding = require("encoding", "raw or gzip")?;
        let gzip = match encoding.value.to_ascii_lowercase().as_str() {
            "raw" => false,
            "gzip" | "gz" => true,
            other => {
                return Err(grid_error(
                    path,
                    GridProblem::Unsupported {
                        what: format!("line {}: encoding: {other}", encoding.line),
                        reason: "volpt reads raw and gzip NRRD data (re-save it with one of \
                                 those, e.g. `unu save -e gzip`)"
                            .into(),
                    },
                ))
            }
        };
        let byte_order = match get(&["endian"]) {
            Some(f) => match f.value.to_ascii_lowercase().as_str() {
                "little" => ByteOrder::Little,
                "big" => ByteOrder::Big,
                _ => return Err(at(bad_at(f, "little or big"))),
            },
            None if scalar.bytes() == 1 => ByteOrder::Little,
            None => {
                return Err(grid_error(
                    path,
                    GridProblem::MissingField {
                        field: "endian",
                        expected: "little or big (the type is wider than a byte)",
                    },
                ))
            }
        };
        let origin = match get(&["space origin"]) {
            Some(f) => vectors(&f.value)
                .and_then(|v| <[[f64; 3]; 1]>::try_from(v).ok())
                .map(|[o]| o)
                .ok_or_else(|| at(bad_at(f, "(x,y,z) with finite numbers")))?,
            None => [0.0; 3],
        };
        let (steps, steps_field) = match (get(&["space directions"]), get(&["spacings"])) {
            (Some(f), _) => (
                vectors(&f.value)
                    .and_then(|v| <[[f64; 3]; 3]>::try_from(v).ok())
                    .ok_or_else(|| {
                        at(bad_at(
                            f,
                            "three vectors (x,y,z) of finite numbers, one per axis",
                        ))
                    })?,
                "space directions",
            ),
            (None, Some(f)) => {
                let s = three::<f64>(f)
                    .filter(|s| s.iter().all(|v| v.is_finite() && *v != 0.0))
                    .ok_or_else(|| at(bad_at(f, "three finite non-zero numbers")))?;
                (
                    [[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]],
                    "spacings",
                )
            }
            (None, None) => (
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                "spacings",
            ),
        };
        let line_skip = match get(&["line skip", "lineskip"]) {
            Some(f) => f
                .value
                .parse::<u64>()
                .map_err(|_| at(bad_at(f, "a line count")))?,
            None => 0,
        };
        let byte_skip = match get(&["byte skip", "byteskip"]) {
            Some(f) => match f.value.parse::<i64>() {
                Ok(-1) if !gzip => ByteSkip::AtEnd,
                Ok(n) if n >= 0 => ByteSkip::Bytes(n as u64),
                _ => {
                    return Err(at(bad_at(
                        f,
                        "a byte count, or -1 (raw data at the end of the file)",
                    )))
                }
            },
            None => ByteSkip::Bytes(0),
        };
        let data_file = match get(&["data file", "datafile"]) {
            None => None,
            Some(f) if f.value.starts_with("LIST") || f.value.contains('%') => {
                return Err(grid_error(
                    path,
                    GridProblem::Unsupported {
                        what: format!("line {}: data file: {}", f.line, f.value),
                        reason: "volpt reads the data from one file".into(),
                    },
                ))
            }
            Some(f) if f.value.is_empty() => return Err(at(bad_at(f, "a file name"))),
            Some(f) => Some(PathBuf::from(&f.value)),
        };
        Ok(Header {
            layout: RawLayout {
                resolution,
                channels: 1,
                scalar,
                byte_order,
                header_bytes: 0,
            },
            gzip,
            steps,
            steps_field,
            origin,
            line_skip,
            byte_skip,
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

fn bad(field: &str, expected: &str, found: impl Into<String>) -> Bad {
    Bad(GridProblem::BadField {
        line: None,
        field: field.into(),
        expected: expected.into(),
        found: found.into(),
    })
}

fn bad_at(f: &Field, expected: &str) -> Bad {
    Bad(GridProblem::BadField {
        line: Some(f.line),
        field: f.key.clone(),
        expected: expected.into(),
        found: f.value.clone(),
    })
}

/// Reads the magic line and the fields up to the blank line that ends the header (or the end of
/// a detached header); returns them and the header's length in bytes (where attached data starts).
fn read_fields(path: &Path, reader: &mut impl BufRead) -> Result<(Vec<Field>, u64), SceneError> {
    let mut fields: Vec<Field> = Vec::new();
    let mut consumed = 0u64;
    let mut bytes = Vec::new();
    for line in 1.. {
        bytes.clear();
        let n = reader
            .take(MAX_HEADER_BYTES - consumed)
            .read_until(b'\n', &mut bytes)
            .map_err(|error| SceneError::Io {
                path: path.to_path_buf(),
                error,
            })?;
        consumed += n as u64;
        if n == 0 {
            // The end of the file: a detached header may end here, attached data may not.
            break;
        }
        if !bytes.ends_with(b"\n") && consumed >= MAX_HEADER_BYTES {
            return Err(bad(
                "header",
                "a header ending with a blank line within its first 65536 bytes",
                format!("{consumed} bytes without one"),
            )
            .at(path));
        }
        let Ok(text) = std::str::from_utf8(&bytes) else {
            return Err(bad(
                &format!("line {line}"),
                "text lines `field: value`",
                String::from_utf8_lossy(&bytes).trim_end(),
            )
            .at(path));
        };
        let text = text.trim_end_matches(['\n', '\r']);
        if line == 1 {
            if !text.starts_with("NRRD000") {
                return Err(bad(
                    "line 1",
                    "the magic NRRD0001 .. NRRD0005",
                    text.chars().take(16).collect::<String>(),
                )
                .at(path));
            }
            continue;
        }
        if text.is_empty() {
            break;
        }
        if text.starts_with('#') || text.contains(":=") {
            continue;
        }
        let Some((key, value)) = text.split_once(": ") else {
            return Err(bad(&format!("line {line}"), "a line `field: value`", text).at(path));
        };
        let key = key.trim().to_ascii_lowercase();
        if let Some(first) = fields.iter().find(|f| f.key == key) {
            return Err(bad(
                &format!("line {line}: {key}"),
                &format!("the field once (it is already on line {})", first.line),
                value,
            )
            .at(path));
        }
        fields.push(Field {
            key,
            value: value.trim().to_string(),
            line,
        });
    }
    Ok((fields, consumed))
}

fn scalar_of(name: &str) -> Option<ScalarType> {
    Some(match name.trim() {
        "signed char" | "int8" | "int8_t" => ScalarType::I8,
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => ScalarType::U8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            ScalarType::I16
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            ScalarType::U16
        }
        "int" | "signed int" | "int32" | "int32_t" => ScalarType::I32,
        "uint" | "unsigned int" | "uint32" | "uint32_t" => ScalarType::U32,
        "longlong"
        | "long long"
        | "long long int"
        | "signed long long"
        | "signed long long int"
        | "int64"
        | "int64_t" => ScalarType::I64,
        "ulonglong" | "unsigned long long" | "unsigned long long int" | "uint64" | "uint64_t" => {
            ScalarType::U64
        }
        "float" => ScalarType::F32,
        "double" => ScalarType::F64,
        _ => return None,
    })
}

/// Exactly three whitespace-separated values.
fn three<T: std::str::FromStr + Copy>(f: &Field) -> Option<[T; 3]> {
    let v = f
        .value
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<Vec<T>, _>>()
        .ok()?;
    <[T; 3]>::try_from(v).ok()
}

/// The `(x,y,z)` vectors of a value such as `(1,0,0) (0,1.5,0) (0,0,2)`, each of finite numbers;
/// `None` for anything else (`none` for a non-spatial axis included: volpt's grids have three).
fn vectors(value: &str) -> Option<Vec<[f64; 3]>> {
    let mut out = Vec::new();
    let mut rest = value.trim();
    while !rest.is_empty() {
        let inner = rest.strip_prefix('(')?;
        let close = inner.find(')')?;
        let numbers = inner[..close]
            .split(',')
            .map(|s| s.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<Vec<f64>>>()?;
        out.push(<[f64; 3]>::try_from(numbers).ok()?);
        rest = inner[close + 1..].trim_start();
    }
    Some(out)
}
