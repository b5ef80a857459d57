//! How long a large mesh boundary takes to load, phase by phase: a generated closed sphere of
//! about N triangles written as a binary STL, then read (parse), checked and built (closedness,
//! BVH), and given its distance grid, as `MeshDesc::placed` does for a scene file.
//!
//! ```sh
//! cargo run --release -p volpt-scene --example mesh_load -- [triangles, default 1000000]
//! ```

use std::path::Path;
use std::time::Instant;

use volpt_core::mesh::primitives::sphere;
use volpt_scene::mesh::{build_mesh, read_mesh, MeshDesc};

fn main() {
    let wanted: u32 = std::env::args()
        .nth(1)
        .map_or(1_000_000, |a| a.parse().expect("a triangle count"));
    // A latitude-longitude sphere of r rings and 2r segments has about 4 r^2 triangles.
    let rings = ((f64::from(wanted) / 4.0).sqrt().ceil() as u32).max(3);
    let (vertices, triangles) = sphere([0.0; 3], 1.0, rings, 2 * rings);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("sphere.stl");
    write_stl(&path, &vertices, &triangles);
    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
    println!(
        "{} triangles, binary STL of {:.1} MB, {} threads",
        triangles.len(),
        bytes as f64 / 1e6,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );

    let start = Instant::now();
    let soup = read_mesh(&path).expect("the STL reads");
    let read = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let buffers = build_mesh(&path, &soup).expect("the sphere is closed");
    let built = start.elapsed().as_secs_f64();
    println!(
        "read {read:.3} s, check and BVH {built:.3} s ({} nodes)",
        buffers.nodes.len()
    );
    drop(buffers);
    let identity = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let start = Instant::now();
    let mesh = MeshDesc::placed(&path, &soup, &identity).expect("the sphere places");
    let placed = start.elapsed().as_secs_f64();
    println!(
        "placed (transform, check, BVH, distance grid {:?}): {placed:.3} s; distance grid alone about {:.3} s",
        mesh.buffers.distance_res,
        placed - built
    );
    println!("total from the file: {:.3} s", read + placed);
}

/// A binary STL of the mesh: an 80-byte header, the count, and per triangle its normal (zero:
/// readers recompute it), three vertices and a 2-byte attribute.
fn write_stl(path: &Path, vertices: &[[f32; 3]], triangles: &[[u32; 3]]) {
    let mut out = vec![0u8; 80];
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        out.extend([0u8; 12]);
        for &v in t {
            for c in vertices[v as usize] {
                out.extend(c.to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    std::fs::write(path, out).expect("the STL writes");
}
