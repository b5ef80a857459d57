//! How long a large mesh boundary takes to load, phase by phase: a mesh file, or a generated
//! closed sphere of about N triangles written as a binary STL, then read (parse), checked and built (closedness,
//! BVH), and given its distance grid, each phase on its own, then all of it as
//! `MeshDesc::placed` does for a scene file (the total: read + placed).
//!
//! ```sh
//! cargo run --release -p volpt-scene --example mesh_load -- [triangles, default 1000000 | FILE]
//! ```

use std::path::Path;
use std::time::Instant;

use volpt_core::mesh::build::{build, check_closed};
use volpt_core::mesh::distance::{refine_slab, resolution_for, surface_bound, DISTANCE_RESOLUTION};
use volpt_core::mesh::primitives::sphere;
use volpt_scene::mesh::{build_mesh, read_mesh, MeshDesc};

fn main() {
    let arg = std::env::args().nth(1);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = match arg.as_deref().map(|a| (a, a.parse::<u32>())) {
        Some((file, Err(_))) => Path::new(file).to_path_buf(),
        wanted => {
            let wanted = wanted.map_or(1_000_000, |(_, n)| n.expect("a count"));
            // A latitude-longitude sphere of r rings and 2r segments has about 4 r^2 triangles.
            let rings = ((f64::from(wanted) / 4.0).sqrt().ceil() as u32).max(3);
            let (vertices, triangles) = sphere([0.0; 3], 1.0, rings, 2 * rings);
            let path = dir.path().join("sphere.stl");
            write_stl(&path, &vertices, &triangles);
            path
        }
    };
    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
    println!(
        "{}: {:.1} MB, {} threads",
        path.display(),
        bytes as f64 / 1e6,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );

    let start = Instant::now();
    let soup = read_mesh(&path).expect("the STL reads");
    let read = start.elapsed().as_secs_f64();
    println!(
        "read (parse, weld): {read:.3} s, {} triangles",
        soup.triangles.len()
    );

    // The phases of `MeshDesc::placed`, each on its own (the BVH build does the checks too).
    let time = |what: &str, f: &mut dyn FnMut()| {
        let start = Instant::now();
        f();
        println!("  {what}: {:.3} s", start.elapsed().as_secs_f64());
    };
    time("closedness check (sort of the edges)", &mut || {
        check_closed(&soup.triangles).expect("closed");
    });
    time("checks and BVH, one thread", &mut || {
        build(&soup.vertices, &soup.triangles).expect("the sphere is closed");
    });
    let mut buffers = None;
    time("checks and BVH, every core", &mut || {
        buffers = Some(build_mesh(&path, &soup).expect("the sphere is closed"));
    });
    let buffers = buffers.expect("built");
    let res = resolution_for(buffers.bounds, DISTANCE_RESOLUTION);
    let mut values = Vec::new();
    time("distance grid: surface cells' bound", &mut || {
        values = surface_bound(&buffers.mesh(), res);
    });
    time(
        "distance grid: refined near the surface, one thread",
        &mut || {
            let slab = (res[0] * res[1]) as usize;
            for (z, out) in values.chunks_mut(slab).enumerate() {
                refine_slab(&buffers.mesh(), res, z as u32, out);
            }
        },
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
        "placed (transform, checks, BVH, distance grid {:?}; every core): {placed:.3} s ({} nodes)",
        mesh.buffers.distance_res,
        mesh.buffers.nodes.len()
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
