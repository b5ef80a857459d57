//! VDB tiles are uniform regions, not dense boxes: OpenVDB's own `fill()` of a 1024^3 box (512
//! tiles of 128^3, 8.8 KB), of a 4096^3 box (one tile, a 594-byte file) and of a 16384^3 box (64
//! root tiles) load, assemble into a scene and get their majorant grid in time and memory
//! proportional to the stored nodes and the 128^3 blocks of the box, not to its voxels or bricks.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use volpt_core::grid::{Grid, GridMapping};
use volpt_core::majorant::{build_majorants, MajorantGrid};
use volpt_core::{Aabb, Vec3};
use volpt_scene::description::SampleLayout;
use volpt_scene::vdb::{read_vdb, VdbOptions};
use volpt_scene::{builder_for, Config, SceneAssembler};

fn fixture(name: &str) -> PathBuf {
    match std::env::var_os("VOLPT_VDB_FIXTURES") {
        Some(dir) => Path::new(&dir).join(name),
        None => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/vdb/fixtures")
            .join(name),
    }
}

/// `fill4096.vdb` with its one root tile replaced by `n`^3 root tiles of 0.5 (a box of
/// `4096 n` voxels per axis, `17 n^3` bytes of tiles): what OpenVDB's `fill()` writes for that box.
fn root_tiles(n: i32, dir: &Path) -> PathBuf {
    let bytes = std::fs::read(fixture("fill4096.vdb")).unwrap();
    // The file ends with the root's tile count, child count and its one tile (origin, value,
    // active state).
    let tail = 4 + 4 + 12 + 4 + 1;
    let (head, old) = bytes.split_at(bytes.len() - tail);
    assert_eq!(&old[..8], [1, 0, 0, 0, 0, 0, 0, 0], "one tile, no children");
    let mut out = head.to_vec();
    out.extend((n * n * n).to_le_bytes());
    out.extend(0u32.to_le_bytes());
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                for o in [x, y, z] {
                    out.extend((o * 4096).to_le_bytes());
                }
                out.extend(0.5f32.to_le_bytes());
                out.push(1);
            }
        }
    }
    // The grid descriptor's end offset is the file's length.
    let end = (bytes.len() as i64).to_le_bytes();
    let at = (0..head.len() - 8)
        .find(|&i| head[i..i + 8] == end)
        .expect("the grid's end offset");
    let len = out.len() as i64;
    out[at..at + 8].copy_from_slice(&len.to_le_bytes());
    let path = dir.join(format!("fill{}.vdb", 4096 * n));
    std::fs::write(&path, out).unwrap();
    path
}

/// Loads `path`, assembles it as `volpt render` does and builds a 64^3 majorant grid over it, in
/// another thread: `Err` if that takes longer than `limit` (the old code did not return). Returns
/// the time and the bytes the grid takes.
fn load_and_bound(path: PathBuf, limit: Duration) -> Result<(Duration, u64), String> {
    // An unoptimised build reads the brick table about ten times slower.
    let limit = if cfg!(debug_assertions) {
        limit * 10
    } else {
        limit
    };
    let name = path.display().to_string();
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        let started = Instant::now();
        let grid = read_vdb(&path, &VdbOptions::default()).unwrap();
        assert_eq!(grid.layout, SampleLayout::Sparse);
        let n = grid.resolution[0];
        assert_eq!(grid.resolution, [n; 3]);
        assert!(grid.samples().iter().all(|&v| v == 0.5 || v == 0.0));
        let bounds = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0));
        let density = Grid::<1>::sparse(
            &grid.data,
            grid.resolution,
            GridMapping::cell_centred(bounds, grid.resolution),
        );
        // Inside: one tile's value everywhere, and a lookup reads it.
        assert_eq!(density.lookup(Vec3::new(0.3, 0.9, 0.01)), [0.5]);
        let res = MajorantGrid::resolution_for(bounds, 64);
        let mut majorants = vec![0.0; res.iter().map(|&r| r as usize).product()];
        build_majorants(&density, 2.0, bounds, res, &mut majorants);
        assert!(
            majorants.iter().all(|&m| m == 1.0),
            "every cell bounds 2 x 0.5"
        );
        let bytes = grid.stored_bytes();
        drop(grid);
        let builder = builder_for(&path).unwrap();
        SceneAssembler::new(Config::default())
            .assemble(builder.as_ref())
            .unwrap();
        let _ = send.send((started.elapsed(), bytes));
    });
    receive
        .recv_timeout(limit)
        .map_err(|_| format!("{name} did not load within {limit:?}"))
}

/// 0.04 s on the 2-core dev machine (release); 0.5 s when every brick of the box had a table
/// entry, 7.4 s before tiles' bricks were read once.
#[test]
fn a_filled_1024_box_of_tiles_loads_without_visiting_its_voxels() {
    let (took, bytes) = load_and_bound(fixture("fill1024.vdb"), Duration::from_secs(1)).unwrap();
    println!("fill1024.vdb: {took:?}, {bytes} bytes");
    assert!(bytes < 64 << 10, "{bytes} bytes");
}

/// 0.1 s and 136 KB (two bricks and one table entry per 128^3 block) on the 2-core dev machine
/// (release); 8 s and 512 MiB with a table entry per brick of the box, minutes before that.
#[test]
fn a_594_byte_vdb_of_one_4096_tile_loads_without_visiting_its_voxels() {
    let (took, bytes) = load_and_bound(fixture("fill4096.vdb"), Duration::from_secs(1)).unwrap();
    println!("fill4096.vdb: {took:?}, {bytes} bytes");
    assert!(bytes < 256 << 10, "{bytes} bytes");
}

/// A box of 16384^3 voxels in 64 root tiles: 8 MiB of table (4 bytes per 128^3 block), where a
/// table entry per brick (32 GiB) was refused under the memory limit.
#[test]
fn a_16384_box_of_root_tiles_loads_in_the_memory_of_its_blocks() {
    let dir = tempfile::tempdir().unwrap();
    let path = root_tiles(4, dir.path());
    let (took, bytes) = load_and_bound(path, Duration::from_secs(2)).unwrap();
    println!("fill16384.vdb: {took:?}, {bytes} bytes");
    assert!(bytes < 9 << 20, "{bytes} bytes");
}
