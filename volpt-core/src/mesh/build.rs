//! Building a [`TriangleMesh`](super::TriangleMesh)'s BVH on the host: binned SAH (Wald 2007,
//! "On fast construction of SAH-based bounding volume hierarchies"; pbrt-v4 7.3.2), 16 bins along
//! the axis of widest centroid spread, leaves of up to 4 triangles unless splitting costs more.
//!
//! Our own, not a crate's: the node and triangle layout is what the GPU kernels read
//! ([`BvhNode`], [`MeshTriangle`], `Pod`), the depth must be bounded by the traversal's stack, and
//! the per-triangle planes are rounded from f64 here. The `bvh` crate (nalgebra, its own flat node
//! type) would still need all of that converted.

use alloc::vec::Vec;
use core::fmt;

use super::{BvhNode, MeshTriangle, MAX_BVH_DEPTH};
use crate::geometry::Aabb;
use crate::Vec3;

/// A mesh's BVH and triangles in BVH order, owned: borrow them as a
/// [`TriangleMesh`](super::TriangleMesh) with [`MeshBuffers::mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct MeshBuffers {
    pub nodes: Vec<BvhNode>,
    pub triangles: Vec<MeshTriangle>,
    /// Each triangle's vertex normals, in `triangles`' order; empty: face normals
    /// ([`super::TriangleMesh::normals`], [`MeshBuffers::with_vertex_normals`]).
    pub normals: Vec<super::CornerNormals>,
    /// `order[i]`: the input index of triangle `i`.
    pub order: Vec<u32>,
    pub bounds: Aabb,
    /// The distance grid's values ([`super::SurfaceDistance`]), empty until
    /// [`MeshBuffers::with_distances`], and its resolution.
    pub distances: Vec<f32>,
    pub distance_res: [u32; 3],
}

impl MeshBuffers {
    pub fn mesh(&self) -> super::TriangleMesh<'_> {
        let distance = if self.distances.is_empty() {
            super::SurfaceDistance::NONE
        } else {
            super::SurfaceDistance {
                values: &self.distances,
                ..super::distance::layout(self.bounds, self.distance_res)
            }
        };
        super::TriangleMesh {
            nodes: &self.nodes,
            triangles: &self.triangles,
            normals: &self.normals,
            bounds: self.bounds,
            distance,
        }
    }

    /// These buffers with a distance grid of `res` cells over the mesh's box, computed here one
    /// slab after another (a host with threads may refine the slabs,
    /// [`super::distance::refine_slab`], in parallel and set `distances` itself).
    pub fn with_distances(mut self, res: [u32; 3]) -> Self {
        let mut values = super::distance::surface_bound(&self.mesh(), res);
        let slab = (res[0] * res[1]) as usize;
        for (z, out) in values.chunks_mut(slab).enumerate() {
            super::distance::refine_slab(&self.mesh(), res, z as u32, out);
        }
        self.distances = values;
        self.distance_res = res;
        self
    }

    /// These buffers shaded with vertex normals: `corners[t]`, the normals at the corners of
    /// input triangle `t` (as its indices list them), each normalised here in f64 and put in BVH
    /// order. A normal that is not finite or has no length is refused: it has no direction.
    pub fn with_vertex_normals(
        mut self,
        corners: &[super::CornerNormals],
    ) -> Result<Self, BuildError> {
        if corners.len() != self.order.len() {
            return Err(BuildError::NormalCount {
                normals: corners.len(),
                triangles: self.order.len(),
            });
        }
        let mut normals = Vec::with_capacity(corners.len());
        for &input in &self.order {
            let triangle = input as usize;
            let mut unit = [[0.0f32; 3]; 3];
            for (corner, (out, n)) in unit.iter_mut().zip(corners[triangle]).enumerate() {
                let length =
                    libm::sqrt(n.iter().map(|&c| f64::from(c) * f64::from(c)).sum::<f64>());
                if !(length.is_finite() && length > 0.0) {
                    return Err(BuildError::BadNormal {
                        triangle,
                        corner,
                        normal: n,
                    });
                }
                *out = n.map(|c| (f64::from(c) / length) as f32);
            }
            normals.push(unit);
        }
        self.normals = normals;
        Ok(self)
    }
}

/// Why a mesh cannot be built (the loaders check closedness and orientation before this).
#[derive(Clone, Debug, PartialEq)]
pub enum BuildError {
    NoTriangles,
    /// Vertex `vertex` has a coordinate that is not finite.
    NonFiniteVertex {
        vertex: usize,
        position: [f32; 3],
    },
    /// Triangle `triangle` names vertex `index`, of `vertices`.
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertices: usize,
    },
    /// Triangle `triangle` has no area (its normal is undefined).
    Degenerate {
        triangle: usize,
    },
    /// The edge from vertex `from` to vertex `to` of triangle `triangle` borders no other
    /// triangle: the mesh has a hole.
    OpenEdge {
        triangle: usize,
        from: u32,
        to: u32,
    },
    /// Triangles `first` and `second` both run along the edge from vertex `from` to vertex `to`:
    /// they face opposite ways.
    InconsistentOrientation {
        first: usize,
        second: usize,
        from: u32,
        to: u32,
    },
    /// The edge between vertices `from` and `to` borders `triangles` triangles (a closed
    /// manifold surface has two at every edge).
    NonManifoldEdge {
        from: u32,
        to: u32,
        triangles: usize,
    },
    /// Every triangle faces inwards: the signed volume the mesh encloses, `volume`, is not
    /// positive (a closed mesh that faces outwards encloses a positive one, cavities included).
    InsideOut {
        volume: f64,
    },
    /// Corner `corner` of triangle `triangle` has a vertex normal `normal` that is not finite or
    /// has no length.
    BadNormal {
        triangle: usize,
        corner: usize,
        normal: [f32; 3],
    },
    /// `normals` triangles' vertex normals for a mesh of `triangles` triangles.
    NormalCount {
        normals: usize,
        triangles: usize,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoTriangles => write!(f, "the mesh has no triangles"),
            Self::NonFiniteVertex { vertex, position } => {
                write!(f, "vertex {vertex} is {position:?}: expected finite coordinates")
            }
            Self::IndexOutOfRange { triangle, index, vertices } => write!(
                f,
                "triangle {triangle} names vertex {index}, but the mesh has {vertices} vertices"
            ),
            Self::Degenerate { triangle } => {
                write!(f, "triangle {triangle} is degenerate (zero area): no normal")
            }
            Self::OpenEdge { triangle, from, to } => write!(
                f,
                "the mesh is not closed: edge {from}-{to} of triangle {triangle} borders no other triangle"
            ),
            Self::InconsistentOrientation { first, second, from, to } => write!(
                f,
                "the mesh is not consistently oriented: triangles {first} and {second} both run \
                 from vertex {from} to vertex {to} (one of them faces inwards)"
            ),
            Self::NonManifoldEdge { from, to, triangles } => write!(
                f,
                "the mesh is not manifold: edge {from}-{to} borders {triangles} triangles, expected 2"
            ),
            Self::InsideOut { volume } => write!(
                f,
                "the mesh faces inwards: it encloses a signed volume of {volume:e}, expected a \
                 positive one (each triangle's vertices counter-clockwise seen from outside); \
                 reverse every triangle"
            ),
            Self::BadNormal { triangle, corner, normal } => write!(
                f,
                "the vertex normal at corner {corner} of triangle {triangle} is {normal:?}: \
                 expected a finite, non-zero vector"
            ),
            Self::NormalCount { normals, triangles } => write!(
                f,
                "vertex normals for {normals} triangles, but the mesh has {triangles} triangles"
            ),
        }
    }
}

const BINS: usize = 16;
const LEAF_SIZE: usize = 4;
/// The cost of visiting a node relative to one triangle test: both are one load and a few dozen
/// flops.
const TRAVERSAL_COST: f32 = 1.0;

struct Prim {
    bounds: Aabb,
    centroid: Vec3,
    index: u32,
}

/// Runs two parts of the BVH build, on two threads where the host has them; [`Serial`] runs
/// them one after the other. The BVH is the same either way.
pub trait Fork: Sync {
    fn join<A: Send, B: Send>(
        &self,
        a: impl FnOnce() -> A + Send,
        b: impl FnOnce() -> B + Send,
    ) -> (A, B);
}

/// Builds on the calling thread.
pub struct Serial;

impl Fork for Serial {
    fn join<A: Send, B: Send>(
        &self,
        a: impl FnOnce() -> A + Send,
        b: impl FnOnce() -> B + Send,
    ) -> (A, B) {
        (a(), b())
    }
}

/// Subtrees of fewer triangles are built serially: forking them costs more than it saves.
const FORK_MIN: usize = 1 << 15;

/// Builds the BVH of the triangles `indices` over `vertices`, each triangle counter-clockwise
/// seen from outside.
pub fn build(vertices: &[[f32; 3]], indices: &[[u32; 3]]) -> Result<MeshBuffers, BuildError> {
    build_with(vertices, indices, &Serial)
}

/// [`build`], its subtrees built in parallel by `fork`.
pub fn build_with(
    vertices: &[[f32; 3]],
    indices: &[[u32; 3]],
    fork: &impl Fork,
) -> Result<MeshBuffers, BuildError> {
    if indices.is_empty() {
        return Err(BuildError::NoTriangles);
    }
    if let Some((vertex, position)) = vertices
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
    {
        return Err(BuildError::NonFiniteVertex {
            vertex,
            position: *position,
        });
    }
    let mut triangles = Vec::with_capacity(indices.len());
    check_indices(vertices.len(), indices)?;
    check_closed(indices)?;
    for (triangle, tri) in indices.iter().enumerate() {
        let mut v = [[0.0f32; 3]; 3];
        for (slot, &index) in v.iter_mut().zip(tri) {
            *slot = vertices[index as usize];
        }
        let (normal, offset) = plane(&v).ok_or(BuildError::Degenerate { triangle })?;
        triangles.push(MeshTriangle { v, normal, offset });
    }
    check_outward(vertices, indices)?;
    let mut prims: Vec<Prim> = triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let [a, b, c] = t.v.map(Vec3::from);
            let bounds = Aabb::new(a.min(b).min(c), a.max(b).max(c));
            Prim {
                bounds,
                centroid: (bounds.min + bounds.max) * 0.5,
                index: i as u32,
            }
        })
        .collect();
    let mut nodes = build_tree(&mut prims, 1, fork);
    offset_leaves(&mut nodes);
    let order: Vec<u32> = prims.iter().map(|p| p.index).collect();
    let bounds = Aabb::new(nodes[0].min.into(), nodes[0].max.into());
    Ok(MeshBuffers {
        nodes,
        triangles: order.iter().map(|&i| triangles[i as usize]).collect(),
        normals: Vec::new(),
        order,
        bounds,
        distances: Vec::new(),
        distance_res: [0; 3],
    })
}

/// The divergence theorem: a closed mesh whose triangles face outwards encloses the positive
/// volume `sum(a . (b x c)) / 6`, in f64 (relative to the first vertex, so that a mesh far from
/// the origin keeps its digits). Inside-out meshes (an STL exported with inverted normals) are
/// closed and consistent, so only this catches them.
fn check_outward(vertices: &[[f32; 3]], indices: &[[u32; 3]]) -> Result<(), BuildError> {
    let origin = vertices[indices[0][0] as usize].map(f64::from);
    let at = |i: u32| {
        let v = vertices[i as usize];
        [0, 1, 2].map(|k| f64::from(v[k]) - origin[k])
    };
    let volume: f64 = indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(at);
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        })
        .sum::<f64>()
        / 6.0;
    if volume > 0.0 {
        Ok(())
    } else {
        Err(BuildError::InsideOut { volume })
    }
}

fn check_indices(vertices: usize, indices: &[[u32; 3]]) -> Result<(), BuildError> {
    for (triangle, tri) in indices.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertices) {
            return Err(BuildError::IndexOutOfRange {
                triangle,
                index,
                vertices,
            });
        }
    }
    Ok(())
}

/// Checks that every edge borders exactly two triangles that run along it in opposite directions:
/// the mesh is closed, manifold and consistently oriented. Sorting the directed edges by their
/// undirected key keeps this `O(n log n)` without a hash map.
pub fn check_closed(indices: &[[u32; 3]]) -> Result<(), BuildError> {
    // One integer per directed edge, so that the sort compares single words: from the top, the
    // low vertex, the high vertex, whether it runs from low to high, the triangle.
    let mut edges: Vec<u128> = Vec::with_capacity(3 * indices.len());
    for (triangle, t) in indices.iter().enumerate() {
        for k in 0..3 {
            let (from, to) = (t[k], t[(k + 1) % 3]);
            let key = u128::from(from.min(to)) << 96 | u128::from(from.max(to)) << 64;
            edges.push(key | u128::from(from < to) << 63 | triangle as u128);
        }
    }
    edges.sort_unstable();
    let unpack = |e: u128| {
        (
            (e >> 96) as u32,
            (e >> 64) as u32,
            e >> 63 & 1 == 1,
            (e & (u128::from(u64::MAX) >> 1)) as usize,
        )
    };
    for group in edges.chunk_by(|a, b| a >> 64 == b >> 64) {
        let (lo, hi, up, triangle) = unpack(group[0]);
        let (from, to) = if up { (lo, hi) } else { (hi, lo) };
        match group {
            [_] => return Err(BuildError::OpenEdge { triangle, from, to }),
            [a, b] if unpack(*a).2 == unpack(*b).2 => {
                return Err(BuildError::InconsistentOrientation {
                    first: unpack(*a).3,
                    second: unpack(*b).3,
                    from,
                    to,
                })
            }
            [_, _] => {}
            _ => {
                return Err(BuildError::NonManifoldEdge {
                    from: lo,
                    to: hi,
                    triangles: group.len(),
                })
            }
        }
    }
    Ok(())
}

/// The unit normal of the counter-clockwise triangle `v` and its plane's offset, in f64 and
/// rounded once (a face in an axis plane gets an exact axis normal and offset); `None` if the
/// triangle has no area.
fn plane(v: &[[f32; 3]; 3]) -> Option<([f32; 3], f32)> {
    let p = v.map(|p| p.map(f64::from));
    let e1 = [0, 1, 2].map(|i| p[1][i] - p[0][i]);
    let e2 = [0, 1, 2].map(|i| p[2][i] - p[0][i]);
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let len = libm::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if !len.is_finite() || len == 0.0 {
        return None;
    }
    // `+ 0.0` turns a -0 component into +0, as the box's normals are.
    let n = n.map(|c| c / len + 0.0);
    let offset = n[0] * p[0][0] + n[1] * p[0][1] + n[2] * p[0][2];
    Some((n.map(|c| c as f32), offset as f32))
}

fn union(a: Aabb, b: Aabb) -> Aabb {
    Aabb::new(a.min.min(b.min), a.max.max(b.max))
}

fn half_area(b: Aabb) -> f32 {
    let e = (b.max - b.min).max(Vec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

const EMPTY: Aabb = Aabb {
    min: Vec3::splat(f32::INFINITY),
    max: Vec3::splat(f32::NEG_INFINITY),
};

/// The nodes of the subtree of `prims` (reordering them into leaf order) at `depth`, its root
/// first and its children's indices relative to it: large subtrees are split and their halves
/// built by `fork`, then concatenated (the second child's index moved past the first's nodes).
/// Leaves are at most [`MAX_BVH_DEPTH`] deep, so the traversal's stack suffices.
fn build_tree(prims: &mut [Prim], depth: usize, fork: &impl Fork) -> Vec<BvhNode> {
    if prims.len() < FORK_MIN {
        let mut nodes = Vec::with_capacity(2 * prims.len() / LEAF_SIZE + 1);
        build_node(prims, depth, &mut nodes);
        return nodes;
    }
    let bounds = prims.iter().fold(EMPTY, |b, p| union(b, p.bounds));
    let mut root = BvhNode {
        min: bounds.min.into(),
        max: bounds.max.into(),
        ..BvhNode::default()
    };
    let split = if depth >= MAX_BVH_DEPTH {
        None
    } else {
        sah_split(prims, bounds)
    };
    let Some(mid) = split else {
        root.count = prims.len() as u32;
        return alloc::vec![root];
    };
    let (left, right) = prims.split_at_mut(mid);
    let (left, right) = fork.join(
        || build_tree(left, depth + 1, fork),
        || build_tree(right, depth + 1, fork),
    );
    root.first = 1 + left.len() as u32;
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(root);
    let moved = |offset: u32| {
        move |mut n: BvhNode| {
            if n.count == 0 {
                n.first += offset;
            }
            n
        }
    };
    nodes.extend(left.into_iter().map(moved(1)));
    nodes.extend(right.into_iter().map(moved(root.first)));
    nodes
}

/// Builds the subtree of `prims` (reordering them into leaf order) at `depth` into `nodes`,
/// children's indices relative to `nodes`' start, and returns its node's index.
fn build_node(prims: &mut [Prim], depth: usize, nodes: &mut Vec<BvhNode>) -> u32 {
    let first = nodes.len() as u32;
    let bounds = prims.iter().fold(EMPTY, |b, p| union(b, p.bounds));
    nodes.push(BvhNode {
        min: bounds.min.into(),
        max: bounds.max.into(),
        ..BvhNode::default()
    });
    let split = if prims.len() <= LEAF_SIZE || depth >= MAX_BVH_DEPTH {
        None
    } else {
        sah_split(prims, bounds)
    };
    match split {
        Some(mid) => {
            let (left, right) = prims.split_at_mut(mid);
            build_node(left, depth + 1, nodes);
            let second = build_node(right, depth + 1, nodes);
            nodes[first as usize].first = second;
        }
        None => {
            // `first` is set by `offset_leaves` once every leaf is known.
            nodes[first as usize].count = prims.len() as u32;
        }
    }
    first
}

/// Numbers each leaf's triangles: leaves come in depth-first order, which is the prims' order.
fn offset_leaves(nodes: &mut [BvhNode]) {
    let mut next = 0u32;
    for node in nodes.iter_mut().filter(|n| n.count > 0) {
        node.first = next;
        next += node.count;
    }
}

/// Partitions `prims` at the binned SAH's best split and returns the split's position, or
/// `None` if a leaf is cheaper (or the centroids cannot be separated).
fn sah_split(prims: &mut [Prim], bounds: Aabb) -> Option<usize> {
    let centroids = prims
        .iter()
        .fold(EMPTY, |b, p| union(b, Aabb::new(p.centroid, p.centroid)));
    let extent = centroids.max - centroids.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    if extent[axis] <= 0.0 || extent[axis].is_nan() {
        return median_split(prims, axis);
    }
    let bin_of = |p: &Prim| {
        let u = (p.centroid[axis] - centroids.min[axis]) / extent[axis];
        ((u * BINS as f32) as usize).min(BINS - 1)
    };
    let mut counts = [0usize; BINS];
    let mut boxes = [EMPTY; BINS];
    for p in prims.iter() {
        let b = bin_of(p);
        counts[b] += 1;
        boxes[b] = union(boxes[b], p.bounds);
    }
    // Sweep from the right, then from the left.
    let mut right_area = [0.0f32; BINS];
    let mut right_count = [0usize; BINS];
    let (mut acc, mut n) = (EMPTY, 0);
    for b in (1..BINS).rev() {
        acc = union(acc, boxes[b]);
        n += counts[b];
        right_area[b] = half_area(acc);
        right_count[b] = n;
    }
    let (mut acc, mut n) = (EMPTY, 0);
    let mut best = (f32::INFINITY, 0);
    for b in 1..BINS {
        acc = union(acc, boxes[b - 1]);
        n += counts[b - 1];
        if n == 0 || right_count[b] == 0 {
            continue;
        }
        let cost = half_area(acc) * n as f32 + right_area[b] * right_count[b] as f32;
        if cost < best.0 {
            best = (cost, b);
        }
    }
    let parent = half_area(bounds);
    let leaf_cost = prims.len() as f32;
    let split_cost = TRAVERSAL_COST + best.0 / parent;
    if best.0.is_infinite() {
        return median_split(prims, axis);
    }
    if split_cost >= leaf_cost && prims.len() <= 4 * LEAF_SIZE {
        return None;
    }
    let mut mid = 0;
    for i in 0..prims.len() {
        if bin_of(&prims[i]) < best.1 {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    Some(mid)
}

/// Halves `prims` by their centroids along `axis`.
fn median_split(prims: &mut [Prim], axis: usize) -> Option<usize> {
    if prims.len() < 2 {
        return None;
    }
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    Some(mid)
}
