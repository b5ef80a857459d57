//! DICOM series (CT, micro-CT): a folder of single-frame slices of one series, or one slice file,
//! read as one grid.
//!
//! Parsed by `dicom-object` (dicom-rs: maintained, pure Rust, the standard dictionary and every
//! transfer syntax's data-set encoding). The pixels of the native (uncompressed) syntaxes are
//! decoded here, a few lines, so that dicom-pixeldata's image codecs (JPEG, JPEG 2000, ...) stay
//! out of volpt's build; a compressed syntax is refused by name.
//!
//! - **Files**: every regular, non-hidden file of the folder but `DICOMDIR`; a file without the
//!   `DICM` magic is skipped with a warning. All slices must belong to one `SeriesInstanceUID`
//!   and share `Rows`, `Columns`, `PixelSpacing`, `ImageOrientationPatient` and the pixel format.
//! - **Transfer syntaxes**: implicit VR little endian, explicit VR little and big endian, deflated
//!   explicit VR little endian. Others (JPEG, JPEG-LS, JPEG 2000, RLE, ...) are refused with their
//!   name: convert them first (`gdcmconv --raw`, `dcmdjpeg`).
//! - **Pixels**: one sample (`MONOCHROME1`/`MONOCHROME2`), one frame, `BitsAllocated` 8, 16 or 32,
//!   `BitsStored` bits of each (sign-extended when `PixelRepresentation` is 1), times
//!   `RescaleSlope` plus `RescaleIntercept` (defaults 1 and 0): Hounsfield units for CT.
//! - **Values**: for `Modality` CT, `max(0, HU + 1000)`: proportional to the X-ray attenuation
//!   coefficient, `mu = mu_water (1 + HU / 1000)`, so air is 0, water 1000 and bone about 2000, a
//!   density as volpt's grids hold (a transfer function's points are in these units: HU + 1000);
//!   values below air (the scanner's padding outside its field of view) are empty. Other
//!   modalities keep the rescaled value, which must be >= 0.
//! - **Geometry**: slices ordered by `ImagePositionPatient` along the slice normal (the cross
//!   product of `ImageOrientationPatient`'s row and column directions), evenly spaced (within
//!   [`SPACING_TOLERANCE`]; a missing or duplicated slice is an error naming the files); the slice
//!   spacing from the positions (one slice: `SpacingBetweenSlices`, else `SliceThickness`, else
//!   the pixel spacing). Pixel `(column i, row j)` of slice `k` is centred at
//!   `position_0 + i PixelSpacing[1] row + j PixelSpacing[0] column + k spacing normal`, in the
//!   patient frame's millimetres; orientations along the patient axes (axial, coronal, sagittal,
//!   mirrored or not) are placed by [`crate::orient`], tilted ones refused.
//! - **Limits**: each file is a regular file within the memory limit; the grid's size is checked
//!   against [`crate::raw::MAX_VALUES`] and the memory limit before it is allocated, from the
//!   headers alone (read without their pixel data).

use std::path::{Path, PathBuf};

use dicom_object::file::ReadPreamble;
use dicom_object::{DefaultDicomObject, OpenFileOptions, Tag};

use crate::description::GridDesc;
use crate::error::{GridProblem, SceneError};
use crate::raw::{checked_value, grid_error, ByteOrder, RawLayout, ScalarType};

/// How unevenly slices may be spaced, relative to their mean spacing: scanners round positions to
/// a few digits; a missing slice doubles one gap.
pub const SPACING_TOLERANCE: f64 = 0.01;

/// The offset that makes Hounsfield units a density: air (-1000 HU) becomes 0.
pub const AIR_HU: f64 = -1000.0;

const PIXEL_DATA: Tag = Tag(0x7FE0, 0x0010);
const MODALITY: Tag = Tag(0x0008, 0x0060);
const SERIES_UID: Tag = Tag(0x0020, 0x000E);
const POSITION: Tag = Tag(0x0020, 0x0032);
const ORIENTATION: Tag = Tag(0x0020, 0x0037);
const SLICE_THICKNESS: Tag = Tag(0x0018, 0x0050);
const SPACING_BETWEEN_SLICES: Tag = Tag(0x0018, 0x0088);
const SAMPLES_PER_PIXEL: Tag = Tag(0x0028, 0x0002);
const NUMBER_OF_FRAMES: Tag = Tag(0x0028, 0x0008);
const ROWS: Tag = Tag(0x0028, 0x0010);
const COLUMNS: Tag = Tag(0x0028, 0x0011);
const PIXEL_SPACING: Tag = Tag(0x0028, 0x0030);
const BITS_ALLOCATED: Tag = Tag(0x0028, 0x0100);
const BITS_STORED: Tag = Tag(0x0028, 0x0101);
const PIXEL_REPRESENTATION: Tag = Tag(0x0028, 0x0103);
const RESCALE_INTERCEPT: Tag = Tag(0x0028, 0x1052);
const RESCALE_SLOPE: Tag = Tag(0x0028, 0x1053);

/// The transfer syntaxes whose pixel data is stored as plain values.
const NATIVE_SYNTAXES: [&str; 4] = [
    "1.2.840.10008.1.2",
    "1.2.840.10008.1.2.1",
    "1.2.840.10008.1.2.2",
    DEFLATED,
];

/// Whether `path` names a DICOM file by its extension (`.dcm`, `.dicom`).
pub fn is_dicom(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("dcm") || e.eq_ignore_ascii_case("dicom"))
}

/// The regular, non-hidden files of a folder, in the natural order of their names.
pub fn folder_files(dir: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let io = |error| SceneError::Io {
        path: dir.to_path_buf(),
        error,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let entry = entry.map_err(io)?;
        let hidden = entry.file_name().to_string_lossy().starts_with('.');
        if !hidden && entry.file_type().map_err(io)?.is_file() {
            files.push(entry.path());
        }
    }
    let name = |p: &PathBuf| {
        p.file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string()
    };
    files.sort_by(|a, b| crate::tiff_stack::natural_order(&name(a), &name(b)));
    Ok(files)
}

/// Reads a folder holding one DICOM series, or one DICOM file (see the module docs).
pub fn read_dicom_series(path: &Path) -> Result<GridDesc, SceneError> {
    let files = if path.is_dir() {
        folder_files(path)?
            .into_iter()
            .filter(|p| p.file_name().is_none_or(|n| n != "DICOMDIR"))
            .collect()
    } else {
        vec![path.to_path_buf()]
    };
    let mut slices = Vec::new();
    for file in files {
        match read_slice_header(&file)? {
            Some(slice) => slices.push(slice),
            None => {
                tracing::warn!(file = %file.display(), "skipped: not a DICOM file (no DICM magic)")
            }
        }
    }
    let Some(first) = slices.first() else {
        return Err(grid_error(
            path,
            GridProblem::MissingField {
                field: "slices",
                expected: "DICOM files (with the DICM magic)",
            },
        ));
    };
    for s in &slices {
        s.check_like(first)?;
    }
    let normal = cross(first.row, first.column);
    let key = |s: &Slice| dot(s.position, normal);
    slices.sort_by(|a, b| key(a).total_cmp(&key(b)));
    let first = &slices[0];
    let n = slices.len();
    let spacing = if n > 1 {
        series_spacing(&slices, normal)?
    } else {
        first.single_spacing
    };

    let resolution = [
        first.columns,
        first.rows,
        u32::try_from(n).unwrap_or(u32::MAX),
    ];
    let layout = RawLayout {
        resolution,
        channels: 1,
        scalar: ScalarType::F32,
        byte_order: ByteOrder::Little,
        header_bytes: 0,
    };
    let (count, _) = layout.checked_size(path)?;
    let mut data = Vec::new();
    if data.try_reserve_exact(count).is_err() {
        return Err(crate::limits::check_memory(path, "the DICOM series", None).unwrap_err());
    }
    for (k, slice) in slices.iter().enumerate() {
        slice.read_pixels(&layout, k, &mut data)?;
    }
    let [dy, dx] = first.pixel_spacing;
    let steps = [
        first.row.map(|c| c * dx),
        first.column.map(|c| c * dy),
        normal.map(|c| c * spacing),
    ];
    crate::orient::place(
        path,
        "ImageOrientationPatient",
        resolution,
        1,
        data,
        first.position,
        steps,
    )
}

/// The spacing of sorted slices from their positions, checked even and along the normal.
fn series_spacing(slices: &[Slice], normal: [f64; 3]) -> Result<f64, SceneError> {
    let n = slices.len();
    let key = |s: &Slice| dot(s.position, normal);
    let (first, last) = (&slices[0], &slices[n - 1]);
    let spacing = (key(last) - key(first)) / (n - 1) as f64;
    for pair in slices.windows(2) {
        let gap = key(&pair[1]) - key(&pair[0]);
        if !(spacing > 0.0 && (gap - spacing).abs() <= SPACING_TOLERANCE * spacing) {
            return Err(grid_error(
                &pair[1].path,
                GridProblem::BadField {
                    line: None,
                    field: format!(
                        "ImagePositionPatient (after {})",
                        pair[0]
                            .path
                            .file_name()
                            .unwrap_or_default()
                            .to_string_lossy()
                    ),
                    expected: format!(
                        "evenly spaced slices, {spacing} mm apart along the slice normal \
                         (a missing or duplicated slice, or two series in one folder?)"
                    ),
                    found: format!("{gap} mm from the previous slice"),
                },
            ));
        }
    }
    // The positions must advance along the normal: sideways is a tilted (sheared) series.
    let along = key(last) - key(first);
    let offset = [0, 1, 2].map(|a| last.position[a] - first.position[a] - along * normal[a]);
    if dot(offset, offset).sqrt() > SPACING_TOLERANCE * along {
        return Err(grid_error(
            &last.path,
            GridProblem::Unsupported {
                what: format!(
                    "ImagePositionPatient moving {offset:?} mm sideways from {}",
                    first.path.display()
                ),
                reason: "volpt's grids are axis-aligned: a tilted (gantry-tilt) series needs \
                         resampling first"
                    .into(),
            },
        ));
    }
    Ok(spacing)
}

/// One slice's header: what ordering, checking and decoding it needs.
struct Slice {
    path: PathBuf,
    series: String,
    ct: bool,
    rows: u32,
    columns: u32,
    /// `PixelSpacing`: between rows, between columns.
    pixel_spacing: [f64; 2],
    /// Unit row and column directions (`ImageOrientationPatient`).
    row: [f64; 3],
    column: [f64; 3],
    position: [f64; 3],
    /// The slice spacing when it is the only one.
    single_spacing: f64,
    bits_allocated: u32,
    bits_stored: u32,
    signed: bool,
    slope: f64,
    intercept: f64,
}

/// Reads a DICOM file (within the memory limit) from its `DICM` magic on, with every element's
/// declared length checked against the bytes that follow it; `None` if it has no magic.
fn open_dicom(path: &Path) -> Result<Option<Vec<u8>>, SceneError> {
    let mut bytes = crate::limits::read_file(path)?;
    let start = if bytes.len() >= 132 && &bytes[128..132] == b"DICM" {
        128
    } else if bytes.starts_with(b"DICM") {
        0
    } else {
        return Ok(None);
    };
    bytes.drain(..start);
    check_lengths(path, &bytes[4..])?;
    Ok(Some(bytes))
}

/// Refuses a data set whose element (or item) declares more bytes than follow it: dicom-object
/// allocates a value's declared length before reading it, so a corrupt or hostile length (up to
/// 4 GiB) must not reach it. Walks the file meta group (explicit VR little endian) and the data set
/// in its transfer syntax's encoding, into sequences and items; a deflated data set (explicit VR
/// little endian, raw deflate) is inflated first, within the memory limit, and walked the same
/// way. Stops at encapsulated pixel data (not decoded).
fn check_lengths(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    check_element_lengths(path, bytes, true)
}

/// [`check_lengths`] of `bytes`, which start with the file meta group if `in_meta`, else with
/// an explicit VR little endian data set.
fn check_element_lengths(path: &Path, bytes: &[u8], in_meta: bool) -> Result<(), SceneError> {
    const EXPLICIT_LE: (bool, bool) = (true, false);
    let mut at = 0usize;
    let mut encoding = EXPLICIT_LE; // (explicit VR, big endian)
    let mut in_meta = in_meta;
    while at + 8 <= bytes.len() {
        let u16_at = |i: usize, big: bool| {
            let b = [bytes[i], bytes[i + 1]];
            if big {
                u16::from_be_bytes(b)
            } else {
                u16::from_le_bytes(b)
            }
        };
        let u32_at = |i: usize, big: bool| {
            let b = [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]];
            if big {
                u32::from_be_bytes(b)
            } else {
                u32::from_le_bytes(b)
            }
        };
        if in_meta && u16_at(at, false) != 0x0002 {
            in_meta = false;
            let syntax = transfer_syntax_of(bytes, at);
            if syntax.as_deref() == Some(DEFLATED) {
                return check_element_lengths(path, &inflate(path, &bytes[at..])?, false);
            }
            encoding = match syntax.as_deref() {
                Some("1.2.840.10008.1.2") => (false, false),
                Some("1.2.840.10008.1.2.2") => (true, true),
                _ => EXPLICIT_LE,
            };
        }
        let (explicit, big) = encoding;
        let (group, element) = (u16_at(at, big), u16_at(at + 2, big));
        let (header, length) = if group == 0xFFFE || !explicit {
            (8, u32_at(at + 4, big))
        } else {
            let vr = [bytes[at + 4], bytes[at + 5]];
            let long = matches!(
                &vr,
                b"OB"
                    | b"OD"
                    | b"OF"
                    | b"OL"
                    | b"OV"
                    | b"OW"
                    | b"SQ"
                    | b"SV"
                    | b"UC"
                    | b"UN"
                    | b"UR"
                    | b"UT"
                    | b"UV"
            );
            if long {
                if at + 12 > bytes.len() {
                    break;
                }
                (12, u32_at(at + 8, big))
            } else {
                (8, u32::from(u16_at(at + 6, big)))
            }
        };
        at += header;
        let undefined = length == u32::MAX;
        if (group, element) == (0x7FE0, 0x0010) && undefined {
            return Ok(()); // encapsulated pixel data: fragments, not elements
        }
        // Items and sequences (and undefined lengths) are entered: their contents are elements.
        let entered = group == 0xFFFE || undefined || is_sequence(bytes, at, header, explicit);
        if entered {
            continue;
        }
        let length = length as usize;
        if length > bytes.len() - at {
            return Err(grid_error(
                path,
                GridProblem::SizeMismatch {
                    what: format!("element ({group:04X},{element:04X})'s value"),
                    expected_bytes: length as u64,
                    actual_bytes: (bytes.len() - at) as u64,
                },
            ));
        }
        at += length;
    }
    Ok(())
}

/// The deflated explicit VR little endian transfer syntax.
const DEFLATED: &str = "1.2.840.10008.1.2.1.99";

/// A deflated data set (raw deflate, PS3.5 A.5), inflated: real bytes, refused past the memory
/// limit (a deflate stream expands at most ~1032 times, `DEFLATE_MAX_RATIO`).
fn inflate(path: &Path, deflated: &[u8]) -> Result<Vec<u8>, SceneError> {
    use std::io::Read;
    let limit = crate::limits::memory_limit();
    let mut inflated = Vec::new();
    flate2::read::DeflateDecoder::new(deflated)
        .take(limit.saturating_add(1))
        .read_to_end(&mut inflated)
        .map_err(|e| decode_error(path, "the deflated data set", e))?;
    crate::limits::check_memory(path, "the inflated data set", Some(inflated.len() as u64))?;
    Ok(inflated)
}

/// Whether the explicit-VR element whose value starts at `at` is a sequence (`SQ`).
fn is_sequence(bytes: &[u8], at: usize, header: usize, explicit: bool) -> bool {
    explicit && header == 12 && &bytes[at - 8..at - 6] == b"SQ"
}

/// The file meta group's transfer syntax UID (0002,0010), from the meta bytes before `end`.
fn transfer_syntax_of(bytes: &[u8], end: usize) -> Option<String> {
    let mut at = 0;
    while at + 8 <= end {
        let tag = [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]];
        let vr = [bytes[at + 4], bytes[at + 5]];
        let (header, length) = if matches!(&vr, b"OB" | b"OW" | b"UN" | b"SQ" | b"UT") {
            let b = bytes.get(at + 8..at + 12)?;
            (12, u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        } else {
            (
                8,
                usize::from(u16::from_le_bytes([bytes[at + 6], bytes[at + 7]])),
            )
        };
        let value = bytes.get(at + header..(at + header).checked_add(length)?)?;
        if tag == [0x02, 0x00, 0x10, 0x00] {
            let text = String::from_utf8_lossy(value);
            return Some(text.trim_end_matches(['\0', ' ']).to_string());
        }
        at += header + length;
    }
    None
}

fn decode_error(path: &Path, what: &str, e: impl std::fmt::Display) -> SceneError {
    grid_error(
        path,
        GridProblem::Decode {
            what: what.into(),
            message: e.to_string(),
        },
    )
}

fn read_slice_header(path: &Path) -> Result<Option<Slice>, SceneError> {
    let Some(bytes) = open_dicom(path)? else {
        return Ok(None);
    };
    let obj = OpenFileOptions::new()
        .read_preamble(ReadPreamble::Never)
        .read_until(PIXEL_DATA)
        .from_reader(bytes.as_slice())
        .map_err(|e| decode_error(path, "the DICOM header", e))?;
    check_syntax(path, &obj)?;
    let f = Fields { path, obj: &obj };
    let samples = f.uint_or(SAMPLES_PER_PIXEL, "SamplesPerPixel", 1)?;
    if samples != 1 {
        return Err(f.bad("SamplesPerPixel", "1 (greyscale)", samples.to_string()));
    }
    let frames = f.uint_or(NUMBER_OF_FRAMES, "NumberOfFrames", 1)?;
    if frames != 1 {
        return Err(grid_error(
            path,
            GridProblem::Unsupported {
                what: format!("NumberOfFrames {frames}"),
                reason: "volpt reads series of single-frame slices (a multi-frame object \
                         is one file per volume)"
                    .into(),
            },
        ));
    }
    let rows = f.uint(ROWS, "Rows")?;
    let columns = f.uint(COLUMNS, "Columns")?;
    if rows == 0 || columns == 0 {
        return Err(f.bad(
            "Rows x Columns",
            "at least 1 x 1",
            format!("{rows} x {columns}"),
        ));
    }
    let bits_allocated = f.uint(BITS_ALLOCATED, "BitsAllocated")?;
    if ![8, 16, 32].contains(&bits_allocated) {
        return Err(f.bad("BitsAllocated", "8, 16 or 32", bits_allocated.to_string()));
    }
    let bits_stored = f.uint_or(BITS_STORED, "BitsStored", bits_allocated)?;
    if bits_stored == 0 || bits_stored > bits_allocated {
        return Err(f.bad(
            "BitsStored",
            &format!("1 to BitsAllocated ({bits_allocated})"),
            bits_stored.to_string(),
        ));
    }
    let signed = match f.uint_or(PIXEL_REPRESENTATION, "PixelRepresentation", 0)? {
        0 => false,
        1 => true,
        other => return Err(f.bad("PixelRepresentation", "0 or 1", other.to_string())),
    };
    let pixel_spacing = f.floats::<2>(PIXEL_SPACING, "PixelSpacing")?;
    if pixel_spacing.iter().any(|&s| s <= 0.0) {
        return Err(f.bad(
            "PixelSpacing",
            "two positive numbers (mm)",
            format!("{pixel_spacing:?}"),
        ));
    }
    let orientation = f.floats::<6>(ORIENTATION, "ImageOrientationPatient")?;
    let unit = |v: [f64; 3]| {
        let len = dot(v, v).sqrt();
        (len > 0.5 && len < 1.5).then(|| v.map(|c| c / len))
    };
    let row = unit([orientation[0], orientation[1], orientation[2]]);
    let column = unit([orientation[3], orientation[4], orientation[5]]);
    let (Some(row), Some(column)) = (row, column) else {
        return Err(f.bad(
            "ImageOrientationPatient",
            "two unit direction vectors",
            format!("{orientation:?}"),
        ));
    };
    let position = f.floats::<3>(POSITION, "ImagePositionPatient")?;
    let optional_positive = |tag, name| -> Result<Option<f64>, SceneError> {
        Ok(match obj.element_opt(tag).ok().flatten() {
            None => None,
            Some(_) => Some(f.floats::<1>(tag, name)?[0]).filter(|s| *s > 0.0),
        })
    };
    let single_spacing = optional_positive(SPACING_BETWEEN_SLICES, "SpacingBetweenSlices")?
        .or(optional_positive(SLICE_THICKNESS, "SliceThickness")?)
        .unwrap_or(pixel_spacing[1]);
    let slope = match obj.element_opt(RESCALE_SLOPE).ok().flatten() {
        Some(_) => f.floats::<1>(RESCALE_SLOPE, "RescaleSlope")?[0],
        None => 1.0,
    };
    let intercept = match obj.element_opt(RESCALE_INTERCEPT).ok().flatten() {
        Some(_) => f.floats::<1>(RESCALE_INTERCEPT, "RescaleIntercept")?[0],
        None => 0.0,
    };
    Ok(Some(Slice {
        path: path.to_path_buf(),
        series: f.text(SERIES_UID),
        ct: f.text(MODALITY).eq_ignore_ascii_case("CT"),
        rows,
        columns,
        pixel_spacing,
        row,
        column,
        position,
        single_spacing,
        bits_allocated,
        bits_stored,
        signed,
        slope,
        intercept,
    }))
}

/// Refuses a transfer syntax whose pixels are compressed, by name.
fn check_syntax(path: &Path, obj: &DefaultDicomObject) -> Result<(), SceneError> {
    let uid = obj.meta().transfer_syntax();
    if NATIVE_SYNTAXES.contains(&uid) {
        return Ok(());
    }
    let name = match uid {
        "1.2.840.10008.1.2.5" => "RLE Lossless",
        "1.2.840.10008.1.2.4.50" => "JPEG Baseline (Process 1)",
        "1.2.840.10008.1.2.4.51" => "JPEG Extended (Process 2 & 4)",
        "1.2.840.10008.1.2.4.57" => "JPEG Lossless, Non-Hierarchical (Process 14)",
        "1.2.840.10008.1.2.4.70" => "JPEG Lossless, First-Order Prediction (Process 14 [SV1])",
        "1.2.840.10008.1.2.4.80" => "JPEG-LS Lossless",
        "1.2.840.10008.1.2.4.81" => "JPEG-LS Lossy (Near-Lossless)",
        "1.2.840.10008.1.2.4.90" => "JPEG 2000 (Lossless Only)",
        "1.2.840.10008.1.2.4.91" => "JPEG 2000",
        "1.2.840.10008.1.2.4.201" => "High-Throughput JPEG 2000 (Lossless Only)",
        "1.2.840.10008.1.2.4.203" => "High-Throughput JPEG 2000",
        _ => "an unknown transfer syntax",
    };
    Err(grid_error(
        path,
        GridProblem::Unsupported {
            what: format!("transfer syntax {uid} ({name})"),
            reason: "volpt decodes uncompressed DICOM (implicit or explicit VR, little or big \
                     endian, deflated); decompress the series first, e.g. `gdcmconv --raw` or \
                     `dcmdjpeg`"
                .into(),
        },
    ))
}

impl Slice {
    /// Refuses a slice that does not belong with `first` in one grid.
    fn check_like(&self, first: &Slice) -> Result<(), SceneError> {
        let differ = |field: &str, mine: String, theirs: String| {
            grid_error(
                &self.path,
                GridProblem::BadField {
                    line: None,
                    field: field.into(),
                    expected: format!(
                        "{theirs}, as in {} (one series per folder)",
                        first.path.display()
                    ),
                    found: mine,
                },
            )
        };
        if self.series != first.series {
            return Err(differ(
                "SeriesInstanceUID",
                self.series.clone(),
                first.series.clone(),
            ));
        }
        if [self.rows, self.columns] != [first.rows, first.columns] {
            return Err(differ(
                "Rows x Columns",
                format!("{} x {}", self.rows, self.columns),
                format!("{} x {}", first.rows, first.columns),
            ));
        }
        let near = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-4);
        if !near(&self.pixel_spacing, &first.pixel_spacing) {
            return Err(differ(
                "PixelSpacing",
                format!("{:?}", self.pixel_spacing),
                format!("{:?}", first.pixel_spacing),
            ));
        }
        if !near(&self.row, &first.row) || !near(&self.column, &first.column) {
            return Err(differ(
                "ImageOrientationPatient",
                format!("{:?} {:?}", self.row, self.column),
                format!("{:?} {:?}", first.row, first.column),
            ));
        }
        let format = |s: &Slice| format!("{}/{}/{}", s.bits_allocated, s.bits_stored, s.signed);
        if format(self) != format(first) || self.ct != first.ct {
            return Err(differ(
                "BitsAllocated/BitsStored/PixelRepresentation signed, Modality",
                format!("{}, CT {}", format(self), self.ct),
                format!("{}, CT {}", format(first), first.ct),
            ));
        }
        Ok(())
    }

    /// Appends the slice's values as slice `k` of `layout` (module docs: rescaled, CT offset).
    fn read_pixels(
        &self,
        layout: &RawLayout,
        k: usize,
        out: &mut Vec<f32>,
    ) -> Result<(), SceneError> {
        let path = &self.path;
        let Some(bytes) = open_dicom(path)? else {
            return Err(decode_error(
                path,
                "the DICOM file",
                "its DICM magic is gone",
            ));
        };
        let obj = OpenFileOptions::new()
            .read_preamble(ReadPreamble::Never)
            .from_reader(bytes.as_slice())
            .map_err(|e| decode_error(path, "the DICOM file", e))?;
        let element = obj
            .element_opt(PIXEL_DATA)
            .ok()
            .flatten()
            .ok_or_else(|| missing(path, "PixelData (7FE0,0010)", "the slice's pixels"))?;
        let Some(value) = element.value().primitive() else {
            return Err(decode_error(
                path,
                "PixelData",
                "encapsulated (compressed) pixel data under a native transfer syntax",
            ));
        };
        use dicom_core::value::PrimitiveValue as P;
        let bytes: Vec<u8> = match value {
            P::U8(v) => v.to_vec(),
            P::U16(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            P::I16(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            P::U32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            P::I32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            other => {
                return Err(decode_error(
                    path,
                    "PixelData",
                    format!("{other:?}, not pixel values"),
                ))
            }
        };
        let size = (self.bits_allocated / 8) as usize;
        let pixels = self.rows as usize * self.columns as usize;
        // A trailing pad byte keeps an odd length even.
        if bytes.len() < pixels * size || bytes.len() > pixels * size + 1 {
            return Err(grid_error(
                path,
                GridProblem::SizeMismatch {
                    what: format!(
                        "PixelData of {} x {} pixels x {size} bytes",
                        self.columns, self.rows
                    ),
                    expected_bytes: (pixels * size) as u64,
                    actual_bytes: bytes.len() as u64,
                },
            ));
        }
        let shift = 32 - self.bits_stored;
        let start = k * pixels;
        for (i, b) in bytes.chunks_exact(size).take(pixels).enumerate() {
            let mut word = [0u8; 4];
            word[..size].copy_from_slice(b);
            // The stored bits, in the high end of an i32/u32 and back, sign-extended if signed.
            let bits = u32::from_le_bytes(word) << shift;
            let stored = if self.signed {
                f64::from((bits as i32) >> shift)
            } else {
                f64::from(bits >> shift)
            };
            let rescaled = stored * self.slope + self.intercept;
            let value = if self.ct {
                (rescaled - AIR_HU).max(0.0)
            } else {
                rescaled
            };
            out.push(checked_value(path, layout, start + i, value)?);
        }
        Ok(())
    }
}

/// Reads header fields of one file, with errors naming it and the field.
struct Fields<'a> {
    path: &'a Path,
    obj: &'a DefaultDicomObject,
}

impl Fields<'_> {
    fn bad(&self, field: &str, expected: &str, found: String) -> SceneError {
        grid_error(
            self.path,
            GridProblem::BadField {
                line: None,
                field: field.into(),
                expected: expected.into(),
                found,
            },
        )
    }

    fn uint(&self, tag: Tag, name: &'static str) -> Result<u32, SceneError> {
        let element = self
            .obj
            .element_opt(tag)
            .ok()
            .flatten()
            .ok_or_else(|| missing(self.path, name, "a non-negative integer"))?;
        element
            .to_int::<u32>()
            .map_err(|e| self.bad(name, "a non-negative integer", e.to_string()))
    }

    fn uint_or(&self, tag: Tag, name: &'static str, default: u32) -> Result<u32, SceneError> {
        match self.obj.element_opt(tag).ok().flatten() {
            None => Ok(default),
            Some(_) => self.uint(tag, name),
        }
    }

    fn floats<const N: usize>(&self, tag: Tag, name: &'static str) -> Result<[f64; N], SceneError> {
        let expected = match N {
            1 => "a number",
            2 => "two numbers",
            3 => "three numbers",
            _ => "six numbers",
        };
        let element = self
            .obj
            .element_opt(tag)
            .ok()
            .flatten()
            .ok_or_else(|| missing(self.path, name, expected))?;
        let values = element
            .to_multi_float64()
            .map_err(|e| self.bad(name, expected, e.to_string()))?;
        <[f64; N]>::try_from(values.clone())
            .ok()
            .filter(|v| v.iter().all(|x| x.is_finite()))
            .ok_or_else(|| self.bad(name, expected, format!("{values:?}")))
    }

    /// A text field, trimmed; empty when absent.
    fn text(&self, tag: Tag) -> String {
        self.obj
            .element_opt(tag)
            .ok()
            .flatten()
            .and_then(|e| e.to_str().ok())
            .map(|s| s.trim_end_matches(['\0', ' ']).trim().to_string())
            .unwrap_or_default()
    }
}

fn missing(path: &Path, field: &'static str, expected: &'static str) -> SceneError {
    grid_error(path, GridProblem::MissingField { field, expected })
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
