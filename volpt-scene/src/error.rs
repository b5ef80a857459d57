//! Errors from loading a scene.
//!
//! Every message names the file it is about and, for XML, the line; value errors also name the
//! field and say what was expected and what was found, so that a user can fix the scene without
//! reading volpt's source. Each variant's message is complete on its own (it includes any
//! underlying cause), so callers can print it with `{}` alone; the cause is also its `source()`,
//! for callers that walk the chain.

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;

#[derive(Debug, Error)]
pub enum SceneError {
    /// A file could not be read or written.
    #[error("{}: {error}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        error: std::io::Error,
    },

    /// The file is not well-formed XML (or not UTF-8).
    #[error("{}:{line}: malformed XML: {}", path.display(), excerpt(message))]
    Xml {
        path: PathBuf,
        line: usize,
        message: String,
    },

    /// Valid Mitsuba that volpt does not render (an unknown element, plugin or combination).
    #[error("{}:{line}: {} is not supported: {}", path.display(), excerpt(what), excerpt(reason))]
    Unsupported {
        path: PathBuf,
        line: usize,
        what: String,
        reason: String,
    },

    /// A value that cannot be parsed or is out of range.
    #[error("{}:{line}: {}: expected {expected}, found {}", path.display(), excerpt(field), excerpt(found))]
    InvalidValue {
        path: PathBuf,
        line: usize,
        field: String,
        expected: String,
        found: String,
    },

    /// Something required is absent; `element` is the element that should contain it.
    #[error("{}:{line}: {element}: missing {}", path.display(), excerpt(what))]
    Missing {
        path: PathBuf,
        line: usize,
        element: String,
        what: String,
    },

    /// A volpt TOML scene file is malformed: bad TOML, an unknown key, or a value of the wrong type.
    #[error("{}:{line}: {}", path.display(), excerpt(message))]
    Toml {
        path: PathBuf,
        line: usize,
        message: String,
    },

    /// A `.vol` grid file is malformed or holds values volpt cannot use.
    #[error("{}: {problem}", path.display())]
    Vol { path: PathBuf, problem: VolProblem },

    /// A volume grid file (MetaImage, VTK, raw) is malformed or holds values volpt cannot use.
    #[error("{}: {problem}", path.display())]
    Grid { path: PathBuf, problem: GridProblem },

    /// A triangle-mesh file is malformed, or its mesh is not a closed, consistently oriented
    /// surface.
    #[error("{}: {problem}", path.display())]
    Mesh {
        path: PathBuf,
        problem: crate::mesh::MeshProblem,
    },

    /// An environment map image is unreadable or holds values volpt cannot use.
    #[error("{}: {problem}", path.display())]
    Envmap {
        path: PathBuf,
        problem: EnvmapProblem,
    },

    /// A scene that cannot be written in the requested format without changing it.
    #[error("{}: cannot write this scene: {reason}", path.display())]
    Export { path: PathBuf, reason: String },

    /// A path that is not a regular file (a FIFO, a device, a directory): reading one could block
    /// or never end, so loaders refuse it before opening it.
    #[error("{}: expected a regular file, found {kind}", path.display())]
    NotAFile { path: PathBuf, kind: &'static str },

    /// Data whose declared size would take more memory than volpt's limit
    /// ([`crate::limits::memory_limit`]); nothing was allocated for it.
    #[error(
        "{}: {what} would take {}, over the memory limit of {limit} bytes \
         (--memory-limit raises it)",
        path.display(),
        bytes.map_or("more than 2^64 bytes".to_owned(), |b| format!("{b} bytes"))
    )]
    OverMemoryLimit {
        path: PathBuf,
        what: String,
        /// `None` when the size overflows 64 bits.
        bytes: Option<u64>,
        limit: u64,
    },

    /// An assembled scene that no renderer can use (checked for every source, see
    /// [`crate::validate`]); `source` names the scene file or builder.
    #[error("{source_name}: {field}: expected {expected}, found {found}")]
    InvalidScene {
        source_name: String,
        field: String,
        expected: String,
        found: String,
    },

    /// An error in a file that a scene file refers to (a grid, a mesh): says which element
    /// referred to it, then the error itself (which names the referred-to file).
    #[error("{}:{line}: {element}: {error}", path.display())]
    Referenced {
        path: PathBuf,
        line: usize,
        element: String,
        #[source]
        error: Box<SceneError>,
    },

    /// A material-indexed volume that cannot be rendered ([`crate::material`]): `path` is its
    /// index grid's file, slice folder or scene.
    #[error("{}: {problem}", path.display())]
    Material {
        path: PathBuf,
        problem: MaterialProblem,
    },
}

/// What is wrong with a material-indexed volume.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialProblem {
    /// A table of no material, or of more than 256 (indices are bytes).
    TableSize { found: usize },
    /// A voxel names a material the table does not have.
    IndexOutOfTable {
        voxel: [u32; 3],
        index: u32,
        materials: usize,
    },
    /// A voxel value that is not a material index (not an integer in 0..=255).
    NotAnIndex { voxel: [u32; 3], value: f32 },
    /// An index grid of another size than the volume's.
    GridSize {
        resolution: [u32; 3],
        expected: u64,
        found: u64,
    },
    /// The grid file holds something else than one channel of dense samples.
    NotAnIndexGrid { what: String },
    /// A slice of another size than the expected one (`source` says whose: the first slice's,
    /// or the scene's resolution).
    SliceSize {
        slice: String,
        expected: [u32; 2],
        found: [u32; 2],
        source: String,
    },
    /// A slice whose pixel's colour names no material of the palette (`#rrggbb name, ...`).
    PaletteColour {
        slice: String,
        pixel: [u32; 2],
        colour: [u8; 3],
        palette: String,
    },
    /// A slice count other than the expected one (`source` says what expects it).
    SliceCount {
        expected: u32,
        found: u32,
        source: String,
    },
    /// A slice volpt cannot decode (not an 8-bit RGB or RGBA PNG, or corrupt).
    Slice { slice: String, message: String },
}

impl fmt::Display for MaterialProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TableSize { found } => write!(
                f,
                "materials: expected 1 to 65536 materials (indices are at most 16 bits), found {found}"
            ),
            Self::IndexOutOfTable {
                voxel,
                index,
                materials,
            } => write!(
                f,
                "voxel {voxel:?}: expected a material index below {materials} (the table's \
                 length), found {index}"
            ),
            Self::NotAnIndex { voxel, value } => write!(
                f,
                "voxel {voxel:?}: expected a material index (an integer 0..=255), found {value}"
            ),
            Self::GridSize {
                resolution,
                expected,
                found,
            } => write!(
                f,
                "index grid: expected {expected} indices ({resolution:?} voxels), found {found}"
            ),
            Self::NotAnIndexGrid { what } => write!(f, "index grid: {what}"),
            Self::SliceSize {
                slice,
                expected,
                found,
                source,
            } => write!(
                f,
                "slice {slice}: expected {}x{} pixels ({source}), found {}x{}",
                expected[0], expected[1], found[0], found[1]
            ),
            Self::PaletteColour {
                slice,
                pixel,
                colour,
                palette,
            } => write!(
                f,
                "slice {slice}, pixel {pixel:?}: expected a palette colour of the materials \
                 ({palette}), found #{:02x}{:02x}{:02x}",
                colour[0], colour[1], colour[2]
            ),
            Self::SliceCount {
                expected,
                found,
                source,
            } => write!(f, "slices: expected {expected} ({source}), found {found}"),
            Self::Slice { slice, message } => write!(f, "slice {slice}: {message}"),
        }
    }
}

/// What is wrong with a `.vol` file.
#[derive(Clone, Debug, PartialEq)]
pub enum VolProblem {
    /// The file is shorter than the fixed-size header.
    TruncatedHeader {
        expected_bytes: u64,
        actual_bytes: u64,
    },
    BadMagic {
        found: [u8; 3],
    },
    UnsupportedVersion {
        found: u8,
    },
    UnsupportedEncoding {
        found: i32,
    },
    BadResolution {
        found: [i32; 3],
    },
    BadChannels {
        found: i32,
    },
    /// The declared size overflows or cannot be held in this machine's memory.
    TooLarge {
        resolution: [i32; 3],
        channels: i32,
    },
    /// The data after the header is not exactly the size the header declares.
    SizeMismatch {
        resolution: [u32; 3],
        channels: u32,
        expected_bytes: u64,
        actual_bytes: u64,
    },
    BadBounds {
        min: [f32; 3],
        max: [f32; 3],
    },
    /// A voxel value outside what the grid's role allows (non-finite, negative, above 1).
    BadValue {
        voxel: [u32; 3],
        channel: u32,
        value: f32,
        expected: &'static str,
    },
    /// The grid has a channel count its role does not allow.
    WrongChannels {
        role: &'static str,
        expected: &'static str,
        found: u32,
    },
    /// An in-memory grid whose data length disagrees with its resolution (when writing).
    DataLength {
        expected: usize,
        found: usize,
    },
}

impl fmt::Display for VolProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TruncatedHeader {
                expected_bytes,
                actual_bytes,
            } => write!(
                f,
                "truncated .vol header: expected {expected_bytes} bytes, found {actual_bytes}"
            ),
            Self::BadMagic { found } => write!(
                f,
                "not a Mitsuba .vol file: expected the bytes \"VOL\", found {:?}",
                String::from_utf8_lossy(found)
            ),
            Self::UnsupportedVersion { found } => {
                write!(f, "expected .vol format version 3, found version {found}")
            }
            Self::UnsupportedEncoding { found } => write!(
                f,
                "unsupported .vol encoding: expected 1 (float32), 2 (float16) or 3 (uint8), \
                 found {found}"
            ),
            Self::BadResolution { found: [x, y, z] } => write!(
                f,
                "expected a positive resolution on every axis, found {x} x {y} x {z}"
            ),
            Self::BadChannels { found } => {
                write!(f, "expected 1 or 3 channels, found {found}")
            }
            Self::TooLarge {
                resolution: [x, y, z],
                channels,
            } => write!(
                f,
                "header declares {x} x {y} x {z} voxels x {channels} channels, \
                 more than this machine can address"
            ),
            Self::SizeMismatch {
                resolution: [x, y, z],
                channels,
                expected_bytes,
                actual_bytes,
            } => {
                write!(
                    f,
                    "header declares {x} x {y} x {z} voxels x {channels} channels = \
                     {expected_bytes} data bytes, but the file holds {actual_bytes} bytes \
                     after the header"
                )
            }
            Self::BadBounds { min, max } => write!(
                f,
                "bounding box: expected finite numbers, found min {min:?} max {max:?}"
            ),
            Self::BadValue {
                voxel: [x, y, z],
                channel,
                value,
                expected,
            } => write!(
                f,
                "voxel (x={x}, y={y}, z={z}) channel {channel}: expected {expected}, found {value}"
            ),
            Self::WrongChannels {
                role,
                expected,
                found,
            } => {
                write!(
                    f,
                    "{role} grid: expected {expected}, found {found} channels"
                )
            }
            Self::DataLength { expected, found } => write!(
                f,
                "grid data: expected {expected} values (resolution x channels), found {found}"
            ),
        }
    }
}

/// What is wrong with a volume grid file (MetaImage, VTK, raw).
#[derive(Clone, Debug, PartialEq)]
pub enum GridProblem {
    /// A required header field is absent.
    MissingField {
        field: &'static str,
        expected: &'static str,
    },
    /// A header field (or a caller-supplied layout value) that cannot be parsed or is out of
    /// range; `line` is the header line, where there is one.
    BadField {
        line: Option<usize>,
        field: String,
        expected: String,
        found: String,
    },
    /// Valid in the format, but not something volpt reads (a rotated grid, compressed VTK XML).
    Unsupported { what: String, reason: String },
    /// The declared size overflows or exceeds the most values volpt reads from one grid.
    TooLarge {
        resolution: [u32; 3],
        channels: u32,
        limit: u64,
    },
    /// The data holds fewer bytes than the header declares.
    SizeMismatch {
        what: String,
        expected_bytes: u64,
        actual_bytes: u64,
    },
    /// The data holds more bytes than the header declares.
    ExcessData { what: String, expected_bytes: u64 },
    /// The data cannot be decoded (a corrupt zlib stream, a VTK file vtkio rejects).
    Decode { what: String, message: String },
    /// A voxel value volpt cannot use (non-finite or negative).
    BadValue {
        voxel: [u32; 3],
        channel: u32,
        value: f64,
        expected: &'static str,
    },
    /// An in-memory grid whose data length disagrees with its resolution (when writing).
    DataLength { expected: usize, found: usize },
}

impl fmt::Display for GridProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingField { field, expected } => {
                write!(f, "missing header field {field}: expected {expected}")
            }
            Self::BadField {
                line,
                field,
                expected,
                found,
            } => {
                if let Some(line) = line {
                    write!(f, "line {line}: ")?;
                }
                write!(
                    f,
                    "{}: expected {expected}, found {:?}",
                    excerpt(field),
                    excerpt(found)
                )
            }
            Self::Unsupported { what, reason } => {
                write!(f, "{} is not supported: {reason}", excerpt(what))
            }
            Self::TooLarge {
                resolution: [x, y, z],
                channels,
                limit,
            } => write!(
                f,
                "header declares {x} x {y} x {z} voxels x {channels} channels, \
                 more than the {limit} values volpt reads from one grid"
            ),
            Self::SizeMismatch {
                what,
                expected_bytes,
                actual_bytes,
            } => write!(
                f,
                "{what}: expected {expected_bytes} bytes, found only {actual_bytes}"
            ),
            Self::ExcessData {
                what,
                expected_bytes,
            } => write!(f, "{what}: expected {expected_bytes} bytes, found more"),
            Self::Decode { what, message } => write!(f, "{what}: {}", excerpt(message)),
            Self::BadValue {
                voxel: [x, y, z],
                channel,
                value,
                expected,
            } => write!(
                f,
                "voxel (x={x}, y={y}, z={z}) channel {channel}: expected {expected}, found {value}"
            ),
            Self::DataLength { expected, found } => write!(
                f,
                "grid data: expected {expected} values (resolution x channels), found {found}"
            ),
        }
    }
}

/// What is wrong with an environment map image.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvmapProblem {
    /// Not an image format volpt reads (only OpenEXR).
    Format { extension: String },
    /// The file is not a readable OpenEXR image.
    Decode { message: String },
    /// Neither R, G and B channels nor a single luminance (Y) channel.
    Channels { found: Vec<String> },
    /// Fewer pixels than the lookup needs.
    TooSmall {
        width: usize,
        height: usize,
        min_width: usize,
        min_height: usize,
    },
    /// A pixel value that is not a radiance (non-finite or negative).
    BadTexel {
        x: usize,
        y: usize,
        channel: String,
        value: f32,
    },
}

impl fmt::Display for EnvmapProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Format { extension } => write!(
                f,
                ".{extension} environment maps are not supported: volpt reads OpenEXR only, \
                 so convert it to .exr (linear RGB, half or float)"
            ),
            Self::Decode { message } => {
                write!(f, "not a readable OpenEXR image: {}", excerpt(message))
            }
            Self::Channels { found } => write!(
                f,
                "expected R, G and B channels (or one Y channel), found {}",
                if found.is_empty() {
                    "none".to_owned()
                } else {
                    found.join(", ")
                }
            ),
            Self::TooSmall {
                width,
                height,
                min_width,
                min_height,
            } => write!(
                f,
                "expected at least {min_width} x {min_height} pixels, found {width} x {height}"
            ),
            Self::BadTexel {
                x,
                y,
                channel,
                value,
            } => write!(
                f,
                "pixel (x={x}, y={y}) channel {channel}: expected a finite radiance >= 0, \
                 found {value}"
            ),
        }
    }
}

/// The longest piece of input text an error message quotes, in bytes.
pub const MAX_QUOTED_BYTES: usize = 200;

/// `text`, or its beginning and its length when it is longer than [`MAX_QUOTED_BYTES`]: a
/// message quotes input so that the user can find it, and a 10 MB line helps nobody.
pub fn excerpt(text: &str) -> std::borrow::Cow<'_, str> {
    if text.len() <= MAX_QUOTED_BYTES {
        return text.into();
    }
    let mut end = MAX_QUOTED_BYTES;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}... ({} bytes in all)", &text[..end], text.len()).into()
}
