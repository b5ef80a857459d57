//! Triangle meshes of simple closed shapes, counter-clockwise seen from outside: Mitsuba's `cube`
//! and `sphere` plugins, and a torus (the non-convex test shape).

use alloc::vec::Vec;
use core::f64::consts::PI;

use crate::geometry::Aabb;

/// Vertices and triangles (vertex indices) of a mesh.
pub type IndexedMesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// The 12 triangles of a box's faces.
pub fn cuboid(b: Aabb) -> IndexedMesh {
    let corner = |i: u32| [0, 1, 2].map(|a| if i >> a & 1 == 1 { b.max[a] } else { b.min[a] });
    let vertices = (0..8).map(corner).collect();
    let mut triangles = Vec::with_capacity(12);
    for a in 0..3 {
        // The face's square in the plane of the next two axes: (b, c) counter-clockwise about
        // +a, since e_b x e_c = e_a; the min face turns the other way.
        let (ab, ac) = (1u32 << ((a + 1) % 3), 1u32 << ((a + 2) % 3));
        for side in [0u32, 1u32 << a] {
            let q = [side, side | ab, side | ab | ac, side | ac];
            let q = if side == 0 {
                [q[0], q[3], q[2], q[1]]
            } else {
                q
            };
            triangles.push([q[0], q[1], q[2]]);
            triangles.push([q[0], q[2], q[3]]);
        }
    }
    (vertices, triangles)
}

/// A latitude-longitude sphere: `rings` bands from pole to pole, `segments` around.
pub fn sphere(center: [f64; 3], radius: f64, rings: u32, segments: u32) -> IndexedMesh {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let at = |theta: f64, phi: f64| {
        [
            center[0] + radius * libm::sin(theta) * libm::cos(phi),
            center[1] + radius * libm::sin(theta) * libm::sin(phi),
            center[2] + radius * libm::cos(theta),
        ]
    };
    let mut vertices = alloc::vec![at(0.0, 0.0), at(PI, 0.0)];
    for r in 1..rings {
        for s in 0..segments {
            vertices.push(at(
                PI * r as f64 / rings as f64,
                2.0 * PI * s as f64 / segments as f64,
            ));
        }
    }
    let ring = |r: u32, s: u32| 2 + (r - 1) * segments + s % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, ring(1, s), ring(1, s + 1)]);
        triangles.push([1, ring(rings - 1, s + 1), ring(rings - 1, s)]);
        for r in 1..rings - 1 {
            let q = [
                ring(r, s),
                ring(r + 1, s),
                ring(r + 1, s + 1),
                ring(r, s + 1),
            ];
            triangles.push([q[0], q[1], q[2]]);
            triangles.push([q[0], q[2], q[3]]);
        }
    }
    outward(vertices, triangles, |_| center)
}

/// A torus about the z axis through `center`: the circle of radius `major` swept by a tube of
/// radius `minor`, `rings` steps around the axis and `sides` around the tube.
pub fn torus(center: [f64; 3], major: f64, minor: f64, rings: u32, sides: u32) -> IndexedMesh {
    let (rings, sides) = (rings.max(3), sides.max(3));
    let mut vertices = Vec::new();
    for i in 0..rings {
        let u = 2.0 * PI * i as f64 / rings as f64;
        for j in 0..sides {
            let v = 2.0 * PI * j as f64 / sides as f64;
            let w = major + minor * libm::cos(v);
            vertices.push([
                center[0] + w * libm::cos(u),
                center[1] + w * libm::sin(u),
                center[2] + minor * libm::sin(v),
            ]);
        }
    }
    let at = |i: u32, j: u32| (i % rings) * sides + j % sides;
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..sides {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            triangles.push([q[0], q[1], q[2]]);
            triangles.push([q[0], q[2], q[3]]);
        }
    }
    // The tube's centre nearest a point: the outward normal points away from it.
    outward(vertices, triangles, |p| {
        let r = libm::hypot(p[0] - center[0], p[1] - center[1]);
        [
            center[0] + major * (p[0] - center[0]) / r,
            center[1] + major * (p[1] - center[1]) / r,
            center[2],
        ]
    })
}

/// Rounds the vertices to f32 and turns every triangle to face away from `inside(centroid)`.
fn outward(
    vertices: Vec<[f64; 3]>,
    mut triangles: Vec<[u32; 3]>,
    inside: impl Fn([f64; 3]) -> [f64; 3],
) -> IndexedMesh {
    for t in &mut triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let e1 = [0, 1, 2].map(|k| b[k] - a[k]);
        let e2 = [0, 1, 2].map(|k| c[k] - a[k]);
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
        let o = inside(centroid);
        if (0..3).map(|k| n[k] * (centroid[k] - o[k])).sum::<f64>() < 0.0 {
            t.swap(1, 2);
        }
    }
    let vertices = vertices.iter().map(|p| p.map(|c| c as f32)).collect();
    (vertices, triangles)
}
