//! Triangle-mesh files for a mesh boundary: Wavefront OBJ, PLY (ASCII and binary, either byte
//! order) and STL (ASCII and binary), read into shared vertices and triangles, then checked
//! (finite vertices, indices in range, no degenerate triangle, closed, manifold and consistently
//! oriented) and built into the core's BVH ([`volpt_core::mesh::build`]).
//!
//! Hostile files get a [`MeshProblem`] naming what is wrong, never a panic: counts a header
//! claims are checked against the bytes the file holds before anything is allocated for them.
//! STL stores every triangle's corners separately; corners at the same position (bit for bit,
//! `-0` as `0`) are welded into one vertex, so that the mesh's edges are shared.

use std::collections::HashMap;
use std::fmt;
use std::path::Path;
use std::sync::Arc;

use serde::{Serialize, Serializer};

use volpt_core::mesh::build::{build_with, BuildError, Fork, MeshBuffers};
use volpt_core::mesh::CornerNormals;

use crate::error::SceneError;

/// Vertices and triangles (indices into the vertices, counter-clockwise seen from outside), and
/// the vertex normals the file gives at each triangle's corners.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleSoup {
    pub vertices: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// One entry per triangle, its corners' normals in its indices' order (not yet unit
    /// vectors); empty where the file has none for every corner.
    pub normals: Vec<CornerNormals>,
}

impl TriangleSoup {
    /// These triangles with no vertex normals.
    pub fn new(vertices: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            vertices,
            triangles,
            normals: Vec::new(),
        }
    }

    /// Smooth vertex normals computed from the triangles, as Mitsuba 3 computes them for a mesh
    /// file without normals (`Mesh::recompute_vertex_normals`): at each vertex, the sum of its
    /// triangles' unit normals, each weighted by the triangle's angle at that vertex (Thürmer and
    /// Wüthrich 1998, "Computing vertex normals from polygonal facets", JGT 3(1)), in f64.
    /// Indices out of range and degenerate triangles add nothing (the build refuses them).
    pub fn smooth_normals(&self) -> Vec<CornerNormals> {
        use glam::DVec3;
        let mut sums = vec![DVec3::ZERO; self.vertices.len()];
        let p = |i: u32| {
            self.vertices
                .get(i as usize)
                .map(|v| DVec3::from(v.map(f64::from)))
        };
        for t in &self.triangles {
            let (Some(a), Some(b), Some(c)) = (p(t[0]), p(t[1]), p(t[2])) else {
                continue;
            };
            let corners = [a, b, c];
            let n = (b - a).cross(c - a);
            let length = n.length();
            if length.is_nan() || length <= 0.0 {
                continue;
            }
            for k in 0..3 {
                let e0 = corners[(k + 1) % 3] - corners[k];
                let e1 = corners[(k + 2) % 3] - corners[k];
                let cos = e0.dot(e1) / (e0.length_squared() * e1.length_squared()).sqrt();
                let angle = cos.clamp(-1.0, 1.0).acos();
                sums[t[k] as usize] += n / length * angle;
            }
        }
        self.triangles
            .iter()
            .map(|t| {
                t.map(|i| {
                    sums.get(i as usize)
                        .map_or([0.0; 3], |s| s.as_vec3().to_array())
                })
            })
            .collect()
    }
}

/// What is wrong with a mesh file.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshProblem {
    /// The extension is none of `.obj`, `.ply`, `.stl`.
    Format { extension: String },
    /// A line or field that does not parse; `line` for text formats.
    Parse {
        line: Option<usize>,
        field: String,
        expected: String,
        found: String,
    },
    /// The header claims more elements than the file's bytes can hold.
    Truncated {
        what: String,
        claimed: u64,
        needed_bytes: u64,
        available_bytes: u64,
    },
    /// The mesh is not a closed, consistently oriented surface, or a triangle or vertex is bad.
    Geometry(BuildError),
}

impl fmt::Display for MeshProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Format { extension } => write!(
                f,
                "expected a mesh file .obj, .ply or .stl, found extension \"{extension}\""
            ),
            Self::Parse {
                line,
                field,
                expected,
                found,
            } => {
                if let Some(line) = line {
                    write!(f, "line {line}: ")?;
                }
                write!(f, "{field}: expected {expected}, found {found}")
            }
            Self::Truncated {
                what,
                claimed,
                needed_bytes,
                available_bytes,
            } => write!(
                f,
                "the header claims {claimed} {what}, which need {needed_bytes} bytes, but the file \
                 holds {available_bytes} after the header"
            ),
            Self::Geometry(e) => write!(f, "{e}"),
        }
    }
}

fn problem(path: &Path, problem: MeshProblem) -> SceneError {
    SceneError::Mesh {
        path: path.to_path_buf(),
        problem,
    }
}

fn parse_error(line: Option<usize>, field: &str, expected: &str, found: &str) -> MeshProblem {
    let found: String = found.chars().take(60).collect();
    MeshProblem::Parse {
        line,
        field: field.into(),
        expected: expected.into(),
        found: format!("\"{found}\""),
    }
}

/// A closed triangle mesh that bounds the medium, placed in world space, with its BVH. The
/// boundary's box ([`crate::BoundaryDesc::bounds`]) is then the mesh's bounding box.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshDesc {
    /// What it was made from (a file, or Mitsuba's `sphere`), for `volpt info`.
    pub source: String,
    pub buffers: MeshBuffers,
    /// FNV-1a of the triangles' and their vertex normals' bytes: what a scene's fingerprint
    /// takes in for them.
    pub content: u64,
}

impl MeshDesc {
    /// Checks `soup`, places it by `to_world` (a row-major affine transform, applied in f64, each
    /// coordinate then rounded once to f32) and builds its BVH; `source` names it in errors and
    /// in `volpt info`. A mirroring transform reverses every triangle, so that they still face
    /// outwards. The soup's vertex normals, if it has any, shade the mesh: transformed by the
    /// inverse transpose (normals stay perpendicular to the placed surface) and normalised.
    pub fn placed(
        source: &Path,
        soup: &TriangleSoup,
        to_world: &[[f64; 4]; 4],
    ) -> Result<Arc<Self>, SceneError> {
        let m = to_world;
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        let vertices: Vec<[f32; 3]> = soup
            .vertices
            .iter()
            .map(|v| {
                let p = v.map(f64::from);
                core::array::from_fn(|r| {
                    (m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]) as f32
                })
            })
            .collect();
        let mirrored = det < 0.0;
        let triangles: Vec<[u32; 3]> = if mirrored {
            soup.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
        } else {
            soup.triangles.clone()
        };
        // The cofactor matrix is the inverse transpose times the determinant, whose sign the
        // normal must not take.
        let cofactor = |r: usize, c: usize| {
            let (r0, r1) = ((r + 1) % 3, (r + 2) % 3);
            let (c0, c1) = ((c + 1) % 3, (c + 2) % 3);
            (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) * det.signum()
        };
        let normal_matrix: [[f64; 3]; 3] =
            core::array::from_fn(|r| core::array::from_fn(|c| cofactor(r, c)));
        let place_normal = |n: [f32; 3]| -> [f32; 3] {
            let n = n.map(f64::from);
            core::array::from_fn(|r| {
                (normal_matrix[r][0] * n[0]
                    + normal_matrix[r][1] * n[1]
                    + normal_matrix[r][2] * n[2]) as f32
            })
        };
        let normals: Vec<CornerNormals> = soup
            .normals
            .iter()
            .map(|&[a, b, c]| {
                let corners = if mirrored { [a, c, b] } else { [a, b, c] };
                corners.map(place_normal)
            })
            .collect();
        let placed = TriangleSoup {
            vertices,
            triangles,
            normals,
        };
        let mut buffers = build_mesh(source, &placed)?;
        if !placed.normals.is_empty() {
            buffers = buffers
                .with_vertex_normals(&placed.normals)
                .map_err(|e| problem(source, MeshProblem::Geometry(e)))?;
        }
        let buffers = with_distances(buffers);
        let mut hash = FNV_OFFSET;
        let triangle_bytes = buffers.triangles.iter().map(bytemuck::bytes_of);
        let normal_bytes = buffers.normals.iter().map(bytemuck::bytes_of);
        for bytes in triangle_bytes.chain(normal_bytes) {
            for byte in bytes {
                hash = (hash ^ u64::from(*byte)).wrapping_mul(FNV_PRIME);
            }
        }
        Ok(Arc::new(Self {
            source: source.display().to_string(),
            buffers,
            content: hash,
        }))
    }

    pub fn triangle_count(&self) -> usize {
        self.buffers.triangles.len()
    }
}

/// `buffers` with their distance grid ([`volpt_core::mesh::distance`]), its slabs refined on
/// every core.
fn with_distances(mut buffers: MeshBuffers) -> MeshBuffers {
    use volpt_core::mesh::distance::{
        refine_slab, resolution_for, surface_bound, DISTANCE_RESOLUTION,
    };
    let res = resolution_for(buffers.bounds, DISTANCE_RESOLUTION);
    let mesh = buffers.mesh();
    let mut values = surface_bound(&mesh, res);
    let slab = (res[0] * res[1]) as usize;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    // Interleaved slabs: the surface's cells, the costly ones, are spread over all threads.
    let mut slabs: Vec<(usize, &mut [f32])> = values.chunks_mut(slab).enumerate().collect();
    let mut shares: Vec<Vec<(usize, &mut [f32])>> = (0..threads).map(|_| Vec::new()).collect();
    for (i, s) in slabs.drain(..).enumerate() {
        shares[i % threads].push(s);
    }
    std::thread::scope(|scope| {
        for share in shares {
            let mesh = &mesh;
            scope.spawn(move || {
                for (z, out) in share {
                    refine_slab(mesh, res, z as u32, out);
                }
            });
        }
    });
    buffers.distances = values;
    buffers.distance_res = res;
    buffers
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// The source, the triangle count and the triangles' hash: not the triangles themselves, which
/// may be millions (a fingerprint serialises the description at every render).
impl Serialize for MeshDesc {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        (&self.source, self.triangle_count() as u64, self.content).serialize(serializer)
    }
}

/// Reads a mesh file (by its extension) and builds its BVH.
pub fn load_mesh(path: &Path) -> Result<MeshBuffers, SceneError> {
    let soup = read_mesh(path)?;
    build_mesh(path, &soup)
}

/// Checks `soup` and builds its BVH, on every core; `path` names it in errors.
pub fn build_mesh(path: &Path, soup: &TriangleSoup) -> Result<MeshBuffers, SceneError> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    build_with(&soup.vertices, &soup.triangles, &Threads::new(threads))
        .map_err(|e| problem(path, MeshProblem::Geometry(e)))
}

/// Forks the BVH build onto scoped threads while any are left of the budget it was given
/// (the host's cores), then builds on the calling thread.
pub struct Threads {
    spare: std::sync::atomic::AtomicUsize,
}

impl Threads {
    /// A fork for `threads` threads in all, the calling one included.
    pub fn new(threads: usize) -> Self {
        Self {
            spare: threads.saturating_sub(1).into(),
        }
    }
}

impl Fork for Threads {
    fn join<A: Send, B: Send>(
        &self,
        a: impl FnOnce() -> A + Send,
        b: impl FnOnce() -> B + Send,
    ) -> (A, B) {
        use std::sync::atomic::Ordering;
        let taken = self
            .spare
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| n.checked_sub(1))
            .is_ok();
        if !taken {
            return (a(), b());
        }
        let joined = std::thread::scope(|scope| {
            let b = scope.spawn(b);
            let a = a();
            (a, b.join())
        });
        self.spare.fetch_add(1, Ordering::AcqRel);
        match joined {
            (a, Ok(b)) => (a, b),
            (_, Err(panic)) => std::panic::resume_unwind(panic),
        }
    }
}

/// Reads a mesh file's vertices and triangles (by its extension), unchecked.
pub fn read_mesh(path: &Path) -> Result<TriangleSoup, SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let parse = match extension.as_str() {
        "obj" => parse_obj,
        "ply" => parse_ply,
        "stl" => parse_stl,
        _ => return Err(problem(path, MeshProblem::Format { extension })),
    };
    let bytes = crate::limits::read_file(path)?;
    parse(&bytes).map_err(|p| problem(path, p))
}

fn parse_f32(word: &str) -> Option<f32> {
    word.parse::<f32>().ok()
}

/// Wavefront OBJ: `v x y z [w]`, `vn x y z` and `f` with 1-based (or negative, relative) indices
/// in any of the `i`, `i/t`, `i//n`, `i/t/n` forms; polygons are fanned into triangles. The
/// normals are kept if every face's every corner names one. Everything else (texture
/// coordinates, groups, materials) is ignored.
pub fn parse_obj(bytes: &[u8]) -> Result<TriangleSoup, MeshProblem> {
    let text = String::from_utf8_lossy(bytes);
    let mut soup = TriangleSoup::default();
    let mut normals: Vec<[f32; 3]> = Vec::new();
    // Every corner so far named a normal.
    let mut all_normals = true;
    for (i, line) in text.lines().enumerate() {
        let line_no = Some(i + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Option<Vec<f32>> = words.map(parse_f32).collect();
                match coords.as_deref() {
                    Some(&[x, y, z]) | Some(&[x, y, z, _]) => soup.vertices.push([x, y, z]),
                    _ => return Err(parse_error(line_no, "vertex (v)", "\"v x y z\"", line)),
                }
            }
            Some("vn") => {
                let coords: Option<Vec<f32>> = words.map(parse_f32).collect();
                match coords.as_deref() {
                    Some(&[x, y, z]) => normals.push([x, y, z]),
                    _ => return Err(parse_error(line_no, "normal (vn)", "\"vn x y z\"", line)),
                }
            }
            Some("f") => {
                let mut face = Vec::new();
                let mut face_normals = Vec::new();
                for word in words {
                    let mut parts = word.split('/');
                    let index = obj_index(parts.next(), soup.vertices.len()).ok_or_else(|| {
                        let n = soup.vertices.len();
                        parse_error(
                            line_no,
                            "face (f)",
                            &format!(
                                "vertex indices 1..={n} (or -1..=-{n}) of the vertices so far"
                            ),
                            word,
                        )
                    })?;
                    face.push(index);
                    match parts.nth(1).filter(|w| !w.is_empty()) {
                        Some(w) => face_normals.push(
                            obj_index(Some(w), normals.len())
                                .map(|n| normals[n as usize])
                                .ok_or_else(|| {
                                    let n = normals.len();
                                    parse_error(
                                        line_no,
                                        "face (f)",
                                        &format!(
                                            "normal indices 1..={n} (or -1..=-{n}) of the normals so far"
                                        ),
                                        word,
                                    )
                                })?,
                        ),
                        None => all_normals = false,
                    }
                }
                if face.len() < 3 {
                    return Err(parse_error(
                        line_no,
                        "face (f)",
                        "at least 3 vertices",
                        line,
                    ));
                }
                for k in 1..face.len() - 1 {
                    soup.triangles.push([face[0], face[k], face[k + 1]]);
                    if all_normals {
                        let n = &face_normals;
                        soup.normals.push([n[0], n[k], n[k + 1]]);
                    }
                }
            }
            _ => {}
        }
    }
    if !all_normals {
        soup.normals.clear();
    }
    Ok(soup)
}

/// An OBJ index (1-based, or negative: relative to the end) into a list of `len` so far, as a
/// 0-based index.
fn obj_index(word: Option<&str>, len: usize) -> Option<u32> {
    let i = word?.parse::<i64>().ok()?;
    let n = len as i64;
    match i {
        i if i > 0 && i <= n => Some((i - 1) as u32),
        i if i < 0 && -i <= n => Some((n + i) as u32),
        _ => None,
    }
}

/// Welds STL's per-triangle corners into shared vertices.
#[derive(Default)]
struct Welder {
    soup: TriangleSoup,
    index: HashMap<[u32; 3], u32>,
}

impl Welder {
    fn vertex(&mut self, p: [f32; 3]) -> u32 {
        // `+ 0.0`: -0 and 0 are one position.
        let key = p.map(|c| (c + 0.0).to_bits());
        let next = self.soup.vertices.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.soup.vertices.push(p);
            next
        })
    }

    fn triangle(&mut self, corners: [[f32; 3]; 3]) {
        let t = corners.map(|p| self.vertex(p));
        self.soup.triangles.push(t);
    }
}

/// STL: binary when the file's length is exactly what its triangle count says (80-byte header,
/// count, 50 bytes a triangle), else ASCII if it starts with `solid` and reads as text.
pub fn parse_stl(bytes: &[u8]) -> Result<TriangleSoup, MeshProblem> {
    let binary_count = bytes
        .get(80..84)
        .map(|b| u32::from_le_bytes(b.try_into().unwrap()) as u64);
    // Binary exporters may also start the header with "solid": the length, or bytes that are
    // not text, say binary.
    let text = bytes[..bytes.len().min(1024)]
        .iter()
        .all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace());
    let ascii = bytes.trim_ascii_start().starts_with(b"solid")
        && text
        && binary_count.is_none_or(|n| 84 + 50 * n != bytes.len() as u64);
    if ascii {
        return parse_stl_ascii(bytes);
    }
    let Some(count) = binary_count else {
        return Err(MeshProblem::Truncated {
            what: "bytes of binary STL header".into(),
            claimed: 84,
            needed_bytes: 84,
            available_bytes: bytes.len() as u64,
        });
    };
    let body = &bytes[84..];
    let needed = 50 * count;
    if (body.len() as u64) < needed {
        return Err(MeshProblem::Truncated {
            what: "triangles".into(),
            claimed: count,
            needed_bytes: needed,
            available_bytes: body.len() as u64,
        });
    }
    let mut welder = Welder::default();
    for record in body.chunks_exact(50).take(count as usize) {
        let f = |k: usize| f32::from_le_bytes(record[4 * k..4 * k + 4].try_into().unwrap());
        // Floats 0-2 are the facet normal, which the vertices' order already gives.
        welder.triangle([[f(3), f(4), f(5)], [f(6), f(7), f(8)], [f(9), f(10), f(11)]]);
    }
    Ok(welder.soup)
}

fn parse_stl_ascii(bytes: &[u8]) -> Result<TriangleSoup, MeshProblem> {
    let text = String::from_utf8_lossy(bytes);
    let mut welder = Welder::default();
    let mut corners = Vec::with_capacity(3);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("vertex") => {
                let coords: Option<Vec<f32>> = words.map(parse_f32).collect();
                match coords.as_deref() {
                    Some(&[x, y, z]) => corners.push([x, y, z]),
                    _ => return Err(parse_error(Some(i + 1), "vertex", "\"vertex x y z\"", line)),
                }
            }
            Some("endloop") => {
                let Ok(triangle) = <[[f32; 3]; 3]>::try_from(corners.as_slice()) else {
                    return Err(parse_error(
                        Some(i + 1),
                        "facet",
                        "3 vertices per facet",
                        &format!("{} vertices", corners.len()),
                    ));
                };
                welder.triangle(triangle);
                corners.clear();
            }
            _ => {}
        }
    }
    Ok(welder.soup)
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(word: &str) -> Option<Self> {
        Some(match word {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    fn read(self, b: &[u8], big_endian: bool) -> f64 {
        macro_rules! num {
            ($t:ty) => {{
                let a = b[..std::mem::size_of::<$t>()].try_into().unwrap();
                (if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }) as f64
            }};
        }
        match self {
            Self::I8 => num!(i8),
            Self::U8 => num!(u8),
            Self::I16 => num!(i16),
            Self::U16 => num!(u16),
            Self::I32 => num!(i32),
            Self::U32 => num!(u32),
            Self::F32 => num!(f32),
            Self::F64 => num!(f64),
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    scalar: Scalar,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum PlyFormat {
    Ascii,
    Binary { big_endian: bool },
}

/// PLY: `vertex` elements' `x y z` (and `nx ny nz`, the vertex normals, if all three are there)
/// and `face` elements' `vertex_indices` (or `vertex_index`) lists, fanned into triangles; other
/// elements and properties are skipped.
pub fn parse_ply(bytes: &[u8]) -> Result<TriangleSoup, MeshProblem> {
    let header_end = bytes
        .windows(10)
        .position(|w| w == b"end_header")
        .ok_or_else(|| parse_error(None, "header", "a PLY header ending in end_header", "none"))?;
    let header = String::from_utf8_lossy(&bytes[..header_end]);
    let mut body = &bytes[header_end + 10..];
    // The header's last line ends with \n (or \r\n).
    if body.starts_with(b"\r") {
        body = &body[1..];
    }
    if body.starts_with(b"\n") {
        body = &body[1..];
    }
    let mut lines = header.lines().enumerate();
    if lines.next().map(|(_, l)| l.trim()) != Some("ply") {
        return Err(parse_error(
            Some(1),
            "magic",
            "\"ply\"",
            header.lines().next().unwrap_or(""),
        ));
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for (i, line) in lines {
        let bad = |expected: &str| parse_error(Some(i + 1), "header", expected, line);
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", "ascii", _] => format = Some(PlyFormat::Ascii),
            ["format", "binary_little_endian", _] => {
                format = Some(PlyFormat::Binary { big_endian: false })
            }
            ["format", "binary_big_endian", _] => {
                format = Some(PlyFormat::Binary { big_endian: true })
            }
            ["format", ..] => return Err(bad("ascii, binary_little_endian or binary_big_endian")),
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count.parse().map_err(|_| bad("an element count"))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => {
                let element = elements.last_mut().ok_or_else(|| bad("an element first"))?;
                element.properties.push(Property {
                    name: name.to_string(),
                    list: Some(Scalar::parse(count).ok_or_else(|| bad("a PLY scalar type"))?),
                    scalar: Scalar::parse(item).ok_or_else(|| bad("a PLY scalar type"))?,
                });
            }
            ["property", ty, name] => {
                let element = elements.last_mut().ok_or_else(|| bad("an element first"))?;
                element.properties.push(Property {
                    name: name.to_string(),
                    list: None,
                    scalar: Scalar::parse(ty).ok_or_else(|| bad("a PLY scalar type"))?,
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(bad("format, element, property or comment")),
        }
    }
    let format = format.ok_or_else(|| parse_error(None, "header", "a format line", "none"))?;
    let mut reader = match format {
        PlyFormat::Ascii => PlyReader::Ascii {
            words: std::str::from_utf8(body)
                .map_err(|_| parse_error(None, "body", "ASCII numbers", "non-UTF-8 bytes"))?
                .split_ascii_whitespace(),
            remaining: body.len(),
        },
        PlyFormat::Binary { big_endian } => PlyReader::Binary {
            bytes: body,
            big_endian,
        },
    };
    let mut soup = TriangleSoup::default();
    let mut vertex_normals: Vec<[f32; 3]> = Vec::new();
    for element in &elements {
        // Every element takes at least one byte (binary) or two (ASCII: a number and a space)
        // per property: a count beyond that cannot be in the file.
        let min_bytes =
            element.properties.len().max(1) as u64 * if format == PlyFormat::Ascii { 2 } else { 1 };
        let needed = element.count.saturating_mul(min_bytes);
        if needed > reader.remaining() as u64 {
            return Err(MeshProblem::Truncated {
                what: format!("{} elements", element.name),
                claimed: element.count,
                needed_bytes: needed,
                available_bytes: reader.remaining() as u64,
            });
        }
        let is_vertex = element.name == "vertex";
        let is_face = element.name == "face";
        let xyz = ["x", "y", "z"].map(|c| element.properties.iter().position(|p| p.name == c));
        let nxyz = ["nx", "ny", "nz"].map(|c| element.properties.iter().position(|p| p.name == c));
        let has_normals = is_vertex && nxyz.iter().all(|p| p.is_some());
        if is_vertex && xyz.iter().any(|p| p.is_none()) {
            return Err(parse_error(
                None,
                "vertex element",
                "properties x, y and z",
                "others",
            ));
        }
        for _ in 0..element.count {
            let mut position = [0.0f32; 3];
            let mut normal = [0.0f32; 3];
            for (k, property) in element.properties.iter().enumerate() {
                let field = || format!("{} property {}", element.name, property.name);
                match property.list {
                    None => {
                        let value = reader.scalar(property.scalar, &field)?;
                        if let Some(axis) = xyz.iter().position(|&p| p == Some(k)) {
                            position[axis] = value as f32;
                        }
                        if let Some(axis) = nxyz.iter().position(|&p| p == Some(k)) {
                            normal[axis] = value as f32;
                        }
                    }
                    Some(count_type) => {
                        let count = reader.scalar(count_type, &field)?;
                        if !(0.0..=u32::MAX as f64).contains(&count) || count.fract() != 0.0 {
                            return Err(parse_error(
                                None,
                                &field(),
                                "a list length",
                                &count.to_string(),
                            ));
                        }
                        let face_list = is_face
                            && (property.name == "vertex_indices"
                                || property.name == "vertex_index");
                        let mut face = Vec::new();
                        for _ in 0..count as u64 {
                            let index = reader.scalar(property.scalar, &field)?;
                            if face_list {
                                if !(0.0..=u32::MAX as f64).contains(&index) || index.fract() != 0.0
                                {
                                    return Err(parse_error(
                                        None,
                                        &field(),
                                        "a vertex index",
                                        &index.to_string(),
                                    ));
                                }
                                face.push(index as u32);
                            }
                        }
                        if face_list {
                            if face.len() < 3 {
                                return Err(parse_error(
                                    None,
                                    &field(),
                                    "at least 3 vertices",
                                    &face.len().to_string(),
                                ));
                            }
                            for k in 1..face.len() - 1 {
                                soup.triangles.push([face[0], face[k], face[k + 1]]);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                soup.vertices.push(position);
            }
            if has_normals {
                vertex_normals.push(normal);
            }
        }
    }
    if !vertex_normals.is_empty() {
        // An index out of range gets no normal here; the build refuses the triangle.
        let normal = |i: u32| vertex_normals.get(i as usize).copied().unwrap_or([0.0; 3]);
        soup.normals = soup.triangles.iter().map(|t| t.map(normal)).collect();
    }
    Ok(soup)
}

enum PlyReader<'a> {
    Ascii {
        words: std::str::SplitAsciiWhitespace<'a>,
        remaining: usize,
    },
    Binary {
        bytes: &'a [u8],
        big_endian: bool,
    },
}

impl PlyReader<'_> {
    fn remaining(&self) -> usize {
        match self {
            Self::Ascii { remaining, .. } => *remaining,
            Self::Binary { bytes, .. } => bytes.len(),
        }
    }

    fn scalar(&mut self, scalar: Scalar, field: &dyn Fn() -> String) -> Result<f64, MeshProblem> {
        let end = || MeshProblem::Truncated {
            what: field(),
            claimed: 1,
            needed_bytes: scalar.size() as u64,
            available_bytes: 0,
        };
        match self {
            Self::Ascii { words, remaining } => {
                let word = words.next().ok_or_else(end)?;
                *remaining = remaining.saturating_sub(word.len() + 1);
                word.parse::<f64>()
                    .map_err(|_| parse_error(None, &field(), "a number", word))
            }
            Self::Binary { bytes, big_endian } => {
                if bytes.len() < scalar.size() {
                    return Err(end());
                }
                let value = scalar.read(bytes, *big_endian);
                *bytes = &bytes[scalar.size()..];
                Ok(value)
            }
        }
    }
}
