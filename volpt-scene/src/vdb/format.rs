//! The OpenVDB file format (`.vdb`, file versions 222 to 224: OpenVDB 3.0 to 12), read from bytes
//! in memory with every length checked against the bytes that are there. Only what a volume
//! renderer needs: the grid descriptors, a float or vec3 float tree (`Tree_float_5_4_3`,
//! `Tree_vec3s_5_4_3`, either saved as half), its background, its index-to-world transform, its
//! tiles and its leaves. Layout as OpenVDB's `io/Archive.cc`, `io/Compression.h`,
//! `tree/RootNode.h`, `tree/InternalNode.h` and `tree/LeafNode.h` write it.

use super::blosc;

/// The first file version this reader takes: per-grid compression and node-mask compression
/// (OpenVDB 3.0, 2014), which every OpenVDB since writes.
pub const MIN_VERSION: u32 = 222;
pub const MAX_VERSION: u32 = 224;
const VERSION_GRID_INSTANCING: u32 = 216;

const COMPRESS_ZIP: u32 = 0x1;
const COMPRESS_ACTIVE_MASK: u32 = 0x2;
const COMPRESS_BLOSC: u32 = 0x4;

/// `log2` of the edge of a tree level's nodes, leaves first: 8^3 leaves, 16^3 and 32^3 internal
/// nodes (the `5_4_3` of the type name).
const LOG2: [u32; 3] = [3, 4, 5];

/// A format error: what is wrong, for the caller to put after the file name.
pub type Problem = String;

/// A little-endian cursor over the file's bytes.
pub struct Cursor<'a> {
    bytes: &'a [u8],
    pub at: usize,
}

impl<'a> Cursor<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], Problem> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(format!(
                "truncated: {what} needs {n} bytes at offset {}, the file has {}",
                self.at,
                self.bytes.len()
            ));
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], Problem> {
        Ok(self.take(N, what)?.try_into().unwrap())
    }

    pub fn u8(&mut self, what: &str) -> Result<u8, Problem> {
        Ok(self.array::<1>(what)?[0])
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, Problem> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }

    pub fn i32(&mut self, what: &str) -> Result<i32, Problem> {
        Ok(i32::from_le_bytes(self.array(what)?))
    }

    pub fn i64(&mut self, what: &str) -> Result<i64, Problem> {
        Ok(i64::from_le_bytes(self.array(what)?))
    }

    pub fn f32(&mut self, what: &str) -> Result<f32, Problem> {
        Ok(f32::from_le_bytes(self.array(what)?))
    }

    pub fn f64(&mut self, what: &str) -> Result<f64, Problem> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }

    /// A `u32`-length-prefixed string (names are ASCII in practice; other bytes are kept lossily).
    pub fn string(&mut self, what: &str) -> Result<String, Problem> {
        let n = self.u32(what)? as usize;
        Ok(String::from_utf8_lossy(self.take(n, what)?).into_owned())
    }

    pub fn seek(&mut self, to: i64, what: &str) -> Result<(), Problem> {
        match usize::try_from(to) {
            Ok(to) if to <= self.bytes.len() => {
                self.at = to;
                Ok(())
            }
            _ => Err(format!(
                "{what} is at offset {to}, outside the file's {} bytes",
                self.bytes.len()
            )),
        }
    }

    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }
}

/// One grid of the file, as its descriptor says.
#[derive(Clone, Debug)]
pub struct Descriptor {
    /// The grid's name (without OpenVDB's suffix that makes duplicate names unique).
    pub name: String,
    /// The tree type without `_HalfFloat`.
    pub type_name: String,
    pub half: bool,
    /// An instance shares another grid's tree: its name.
    pub instance_of: String,
    pub grid_pos: i64,
}

pub struct Header {
    pub version: u32,
    pub library: (u32, u32),
    pub grids: Vec<Descriptor>,
}

/// The file header and every grid descriptor.
pub fn header(c: &mut Cursor<'_>) -> Result<Header, Problem> {
    let magic = c.array::<8>("the magic number")?;
    if magic != [0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0] {
        return Err(format!(
            "not an OpenVDB file: expected the magic number 20 42 44 56 00 00 00 00, found {}",
            magic.map(|b| format!("{b:02x}")).join(" ")
        ));
    }
    let version = c.u32("the file version")?;
    if !(MIN_VERSION..=MAX_VERSION).contains(&version) {
        return Err(format!(
            "file format version {version} is not supported: expected {MIN_VERSION} to \
             {MAX_VERSION} (OpenVDB 3.0 to 12)"
        ));
    }
    let library = (c.u32("the library version")?, c.u32("the library version")?);
    let has_offsets = c.u8("the grid offsets flag")? != 0;
    if !has_offsets {
        return Err(
            "the file was streamed without grid offsets, which this reader does not support".into(),
        );
    }
    c.take(36, "the file's UUID")?;
    skip_metadata(c, "the file's metadata")?;
    let count = c.i32("the grid count")?;
    // Each descriptor takes at least 3 strings and 3 offsets.
    if count < 0 || count as usize > c.remaining() / 36 {
        return Err(format!("the grid count {count} does not fit the file"));
    }
    let mut grids = Vec::with_capacity(count as usize);
    for _ in 0..count {
        let unique = c.string("a grid name")?;
        // OpenVDB makes duplicate names unique with a record separator and a number.
        let name = unique.split('\u{1e}').next().unwrap_or_default().to_owned();
        let mut type_name = c.string("a grid type")?;
        let half = type_name.ends_with("_HalfFloat");
        if half {
            type_name.truncate(type_name.len() - "_HalfFloat".len());
        }
        let instance_of = if version >= VERSION_GRID_INSTANCING {
            c.string("a grid's instance parent")?
        } else {
            String::new()
        };
        let grid_pos = c.i64("a grid's offset")?;
        let _block_pos = c.i64("a grid's block offset")?;
        let end_pos = c.i64("a grid's end offset")?;
        grids.push(Descriptor {
            name,
            type_name,
            half,
            instance_of,
            grid_pos,
        });
        // The next descriptor follows this grid's data.
        if end_pos <= c.at as i64 {
            return Err(format!(
                "grid {:?} ends before it starts",
                grids.last().unwrap().name
            ));
        }
        c.seek(end_pos, "the next grid descriptor")?;
    }
    Ok(Header {
        version,
        library,
        grids,
    })
}

/// Skips a metadata map: a count, then (name, type name, `u32` size, value bytes) each.
fn skip_metadata(c: &mut Cursor<'_>, what: &str) -> Result<(), Problem> {
    let count = c.i32(what)?;
    if count < 0 || count as usize > c.remaining() / 12 {
        return Err(format!(
            "{what}: the entry count {count} does not fit the file"
        ));
    }
    for _ in 0..count {
        c.string(what)?;
        c.string(what)?;
        let n = c.u32(what)? as usize;
        c.take(n, what)?;
    }
    Ok(())
}

/// A grid's index-to-world map: `world = index * scale + translation`. OpenVDB's axis-aligned maps
/// only; volpt's grids are axis-aligned boxes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub scale: [f64; 3],
    pub translation: [f64; 3],
}

fn vec3d(c: &mut Cursor<'_>, what: &str) -> Result<[f64; 3], Problem> {
    Ok([c.f64(what)?, c.f64(what)?, c.f64(what)?])
}

fn transform(c: &mut Cursor<'_>) -> Result<Transform, Problem> {
    let name = c.string("the transform's map type")?;
    let what = "the transform";
    let t = match name.as_str() {
        "ScaleMap" | "UniformScaleMap" => {
            let scale = vec3d(c, what)?;
            for _ in 0..4 {
                vec3d(c, what)?;
            }
            Transform {
                scale,
                translation: [0.0; 3],
            }
        }
        "ScaleTranslateMap" | "UniformScaleTranslateMap" => {
            let translation = vec3d(c, what)?;
            let scale = vec3d(c, what)?;
            for _ in 0..4 {
                vec3d(c, what)?;
            }
            Transform { scale, translation }
        }
        "TranslationMap" => Transform {
            scale: [1.0; 3],
            translation: vec3d(c, what)?,
        },
        "AffineMap" => {
            // A 4x4 matrix for row vectors: world = [i j k 1] * m.
            let mut m = [[0.0; 4]; 4];
            for row in &mut m {
                for v in row.iter_mut() {
                    *v = c.f64(what)?;
                }
            }
            let off_diagonal = (0..3).any(|r| (0..3).any(|k| r != k && m[r][k] != 0.0));
            if off_diagonal || m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 {
                return Err(
                    "an AffineMap that rotates, shears or projects is not supported: \
                     volpt's grids are axis-aligned boxes"
                        .into(),
                );
            }
            Transform {
                scale: [m[0][0], m[1][1], m[2][2]],
                translation: [m[3][0], m[3][1], m[3][2]],
            }
        }
        other => {
            return Err(format!(
                "transform map {other:?} is not supported: expected an axis-aligned scale and \
                 translation (ScaleMap, ScaleTranslateMap, their uniform forms, TranslationMap, \
                 or a diagonal AffineMap)"
            ))
        }
    };
    if t.scale.iter().any(|s| !(s.is_finite() && *s > 0.0))
        || t.translation.iter().any(|v| !v.is_finite())
    {
        return Err(format!(
            "the transform's voxel size must be positive and finite and its translation \
             finite, found scale {:?}, translation {:?}",
            t.scale, t.translation
        ));
    }
    Ok(t)
}

/// A constant region of the tree: a tile of `dim`^3 voxels at `origin` (index space) whose value
/// differs from the background.
#[derive(Clone, Debug, PartialEq)]
pub struct Tile {
    pub origin: [i32; 3],
    pub dim: u32,
    pub value: Vec<f32>,
}

/// A grid's tree without its leaf values: what the sparse storage is sized from.
pub struct Topology {
    pub channels: usize,
    pub half: bool,
    pub compression: u32,
    pub version: u32,
    pub background: Vec<f32>,
    pub transform: Transform,
    pub tiles: Vec<Tile>,
    /// Leaf origins, in the order their values follow in the file.
    pub leaves: Vec<[i32; 3]>,
}

/// The channels of a tree type this reader takes.
pub fn channels_of(type_name: &str) -> Option<usize> {
    match type_name {
        "Tree_float_5_4_3" => Some(1),
        "Tree_vec3s_5_4_3" => Some(3),
        _ => None,
    }
}

/// Reads a grid's compression, metadata, transform and topology, leaving `c` at its buffers.
pub fn topology(c: &mut Cursor<'_>, d: &Descriptor, version: u32) -> Result<Topology, Problem> {
    let channels = channels_of(&d.type_name).ok_or_else(|| {
        format!(
            "grid {:?} is a {}: expected a float or vec3s grid (Tree_float_5_4_3, \
             Tree_vec3s_5_4_3)",
            d.name, d.type_name
        )
    })?;
    c.seek(d.grid_pos, "the grid")?;
    let compression = c.u32("the grid's compression flags")?;
    if compression & !(COMPRESS_ZIP | COMPRESS_ACTIVE_MASK | COMPRESS_BLOSC) != 0 {
        return Err(format!("unknown compression flags {compression:#x}"));
    }
    skip_metadata(c, "the grid's metadata")?;
    let transform = transform(c)?;
    let mut t = Topology {
        channels,
        half: d.half,
        compression,
        version,
        background: Vec::new(),
        transform,
        tiles: Vec::new(),
        leaves: Vec::new(),
    };
    let buffer_count = c.i32("the tree's buffer count")?;
    if buffer_count != 1 {
        return Err(format!("the tree has {buffer_count} buffers: expected 1"));
    }
    t.background = values(c, channels, "the background")?;
    let tiles = c.u32("the root's tile count")? as usize;
    let children = c.u32("the root's child count")? as usize;
    let tile_bytes = 12 + 4 * channels + 1;
    if tiles > c.remaining() / tile_bytes || children > c.remaining() / 12 {
        return Err(format!(
            "the root's {tiles} tiles and {children} children do not fit the file"
        ));
    }
    let root_dim = 1u32 << (LOG2[0] + LOG2[1] + LOG2[2]);
    for _ in 0..tiles {
        let origin = coord(c, "a root tile")?;
        if origin.iter().any(|&o| o % root_dim as i32 != 0) {
            return Err(format!(
                "a root tile at {origin:?} is not aligned to {root_dim}"
            ));
        }
        let value = values(c, channels, "a root tile")?;
        c.u8("a root tile's state")?;
        if value != t.background {
            t.tiles.push(Tile {
                origin,
                dim: root_dim,
                value,
            });
        }
    }
    // Buffers follow in the order of the root's map, sorted by origin, whatever the order here.
    let mut subtrees = Vec::with_capacity(children);
    for _ in 0..children {
        let origin = coord(c, "a root child")?;
        if origin.iter().any(|&o| o % root_dim as i32 != 0) {
            return Err(format!(
                "a root child at {origin:?} is not aligned to {root_dim}"
            ));
        }
        let mut leaves = Vec::new();
        internal(c, &mut t, 2, origin, &mut leaves)?;
        subtrees.push((origin, leaves));
    }
    subtrees.sort_by_key(|(origin, _)| *origin);
    if subtrees.windows(2).any(|w| w[0].0 == w[1].0) {
        return Err("two root children at the same origin".into());
    }
    t.leaves = subtrees.into_iter().flat_map(|(_, l)| l).collect();
    Ok(t)
}

fn coord(c: &mut Cursor<'_>, what: &str) -> Result<[i32; 3], Problem> {
    Ok([c.i32(what)?, c.i32(what)?, c.i32(what)?])
}

/// `channels` plain `f32` values (backgrounds and root tiles are never stored as half).
fn values(c: &mut Cursor<'_>, channels: usize, what: &str) -> Result<Vec<f32>, Problem> {
    (0..channels).map(|_| c.f32(what)).collect()
}

/// A bit mask of `2^(3 log2)` bits, as `u64` words.
fn mask(c: &mut Cursor<'_>, log2: u32, what: &str) -> Result<Vec<u64>, Problem> {
    let words = (1usize << (3 * log2)) / 64;
    let bytes = c.take(8 * words, what)?;
    Ok(bytes
        .chunks_exact(8)
        .map(|w| u64::from_le_bytes(w.try_into().unwrap()))
        .collect())
}

fn bit(mask: &[u64], i: usize) -> bool {
    mask[i / 64] >> (i % 64) & 1 != 0
}

/// The local coordinate of entry `n` of a node of edge `2^log2`: z fastest, as OpenVDB orders it.
fn local(n: usize, log2: u32) -> [i32; 3] {
    let m = (1usize << log2) - 1;
    [
        (n >> (2 * log2)) as i32,
        ((n >> log2) & m) as i32,
        (n & m) as i32,
    ]
}

/// An internal node of `level` (2: 32^3 children of 128^3 voxels; 1: 16^3 leaves), its tiles
/// and, depth first, its children.
fn internal(
    c: &mut Cursor<'_>,
    t: &mut Topology,
    level: usize,
    origin: [i32; 3],
    leaves: &mut Vec<[i32; 3]>,
) -> Result<(), Problem> {
    let log2 = LOG2[level];
    let child_log2: u32 = LOG2[..level].iter().sum();
    let child_dim = 1i32 << child_log2;
    let child_mask = mask(c, log2, "an internal node's child mask")?;
    let value_mask = mask(c, log2, "an internal node's value mask")?;
    let n = 1usize << (3 * log2);
    let tiles = compressed_values(c, t, n, &value_mask, log2, "an internal node's tiles")?;
    for i in 0..n {
        if !bit(&child_mask, i) {
            let value = &tiles[i * t.channels..(i + 1) * t.channels];
            if value != t.background.as_slice() {
                let l = local(i, log2);
                t.tiles.push(Tile {
                    origin: [0, 1, 2].map(|a| origin[a] + l[a] * child_dim),
                    dim: child_dim as u32,
                    value: value.to_vec(),
                });
            }
        }
    }
    for i in (0..n).filter(|&i| bit(&child_mask, i)) {
        let l = local(i, log2);
        let child = [0, 1, 2].map(|a| origin[a] + l[a] * child_dim);
        if level == 1 {
            // A leaf's topology is its value mask; its values come with the buffers.
            c.take(64, "a leaf's value mask")?;
            leaves.push(child);
        } else {
            internal(c, t, level - 1, child, leaves)?;
        }
    }
    Ok(())
}

/// Reads every leaf's values, in [`Topology::leaves`] order, handing each to `leaf` as
/// `512 * channels` values, z fastest (OpenVDB's order).
pub fn leaf_buffers(
    c: &mut Cursor<'_>,
    t: &Topology,
    mut leaf: impl FnMut(usize, &[f32]),
) -> Result<(), Problem> {
    for i in 0..t.leaves.len() {
        let value_mask = mask(c, LOG2[0], "a leaf's value mask")?;
        let values = compressed_values(c, t, 512, &value_mask, LOG2[0], "a leaf's values")?;
        leaf(i, &values);
    }
    Ok(())
}

/// OpenVDB's `readCompressedValues`: `n` values of a node whose value mask is `value_mask`,
/// possibly only the active ones stored (the inactive ones then one or two values, chosen by a
/// selection mask), possibly half, zip or blosc compressed.
fn compressed_values(
    c: &mut Cursor<'_>,
    t: &Topology,
    n: usize,
    value_mask: &[u64],
    log2: u32,
    what: &str,
) -> Result<Vec<f32>, Problem> {
    const NO_MASK_OR_INACTIVE_VALS: u8 = 0;
    const NO_MASK_AND_ONE_INACTIVE_VAL: u8 = 2;
    const MASK_AND_NO_INACTIVE_VALS: u8 = 3;
    const MASK_AND_ONE_INACTIVE_VAL: u8 = 4;
    const MASK_AND_TWO_INACTIVE_VALS: u8 = 5;
    const NO_MASK_AND_ALL_VALS: u8 = 6;
    let ch = t.channels;
    let meta = c.u8(what)?;
    if meta > NO_MASK_AND_ALL_VALS {
        return Err(format!("{what}: unknown value compression {meta}"));
    }
    let background = t.background.clone();
    let minus: Vec<f32> = background.iter().map(|v| -v).collect();
    let mut inactive0 = if meta == NO_MASK_OR_INACTIVE_VALS {
        background.clone()
    } else {
        minus
    };
    let mut inactive1 = background;
    if matches!(
        meta,
        NO_MASK_AND_ONE_INACTIVE_VAL | MASK_AND_ONE_INACTIVE_VAL | MASK_AND_TWO_INACTIVE_VALS
    ) {
        inactive0 = values(c, ch, what)?;
        if meta == MASK_AND_TWO_INACTIVE_VALS {
            inactive1 = values(c, ch, what)?;
        }
    }
    let selection = if matches!(
        meta,
        MASK_AND_NO_INACTIVE_VALS | MASK_AND_ONE_INACTIVE_VAL | MASK_AND_TWO_INACTIVE_VALS
    ) {
        Some(mask(c, log2, what)?)
    } else {
        None
    };
    let active_only = t.compression & COMPRESS_ACTIVE_MASK != 0 && meta != NO_MASK_AND_ALL_VALS;
    let stored = if active_only {
        value_mask.iter().map(|w| w.count_ones() as usize).sum()
    } else {
        n
    };
    let scalar = if t.half { 2 } else { 4 };
    let bytes = stored * ch * scalar;
    // OpenVDB's HalfReader reads nothing at all for no values (its readData would read a length).
    let raw = if t.half && stored == 0 {
        Vec::new()
    } else {
        data(c, t.compression, bytes, what)?
    };
    let read: Vec<f32> = if t.half {
        raw.chunks_exact(2)
            .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
            .collect()
    } else {
        raw.chunks_exact(4)
            .map(|w| f32::from_le_bytes(w.try_into().unwrap()))
            .collect()
    };
    if stored == n {
        return Ok(read);
    }
    let mut out = Vec::with_capacity(n * ch);
    let mut next = read.chunks_exact(ch);
    for i in 0..n {
        if bit(value_mask, i) {
            out.extend_from_slice(next.next().expect("counted above"));
        } else if selection.as_ref().is_some_and(|s| bit(s, i)) {
            out.extend_from_slice(&inactive1);
        } else {
            out.extend_from_slice(&inactive0);
        }
    }
    Ok(out)
}

/// OpenVDB's `readData`: `bytes` bytes, stored as they are or zip or blosc compressed (an `i64`
/// length first; a negative length means stored uncompressed).
fn data(
    c: &mut Cursor<'_>,
    compression: u32,
    bytes: usize,
    what: &str,
) -> Result<Vec<u8>, Problem> {
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
        return Ok(c.take(bytes, what)?.to_vec());
    }
    let n = c.i64(what)?;
    if n <= 0 {
        let stored = n.unsigned_abs() as usize;
        if stored != bytes {
            return Err(format!(
                "{what}: {stored} uncompressed bytes where {bytes} were expected"
            ));
        }
        return Ok(c.take(bytes, what)?.to_vec());
    }
    let chunk = c.take(n as usize, what)?;
    if compression & COMPRESS_BLOSC != 0 {
        blosc::decompress(chunk, bytes).map_err(|e| format!("{what}: {e}"))
    } else {
        use std::io::Read;
        let mut out = Vec::with_capacity(bytes);
        flate2::read::ZlibDecoder::new(chunk)
            .take(bytes as u64 + 1)
            .read_to_end(&mut out)
            .map_err(|e| format!("{what}: the zlib stream does not decode: {e}"))?;
        if out.len() != bytes {
            return Err(format!(
                "{what}: the zlib stream holds {} bytes where {bytes} were expected",
                out.len()
            ));
        }
        Ok(out)
    }
}
