//! VDB tiles are uniform regions, not dense boxes: OpenVDB's own `fill()` of a 1024^3 box (512
//! tiles of 128^3, 8.8 KB) and of a 4096^3 box (one tile, a 594-byte file) load, assemble into
//! a scene and get their majorant grid in time proportional to the stored nodes and the brick
//! table, not to the box's voxels (before: 5 s for 1024^3, minutes for 4096^3, in the majorant
//! grid's per-brick reads of the tile's one stored brick).

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

/// Loads `name`, assembles it as `volpt render` does and builds a 64^3 majorant grid over it, in
/// another thread: `Err` if that takes longer than `limit` (the old code did not return).
fn load_and_bound(name: &'static str, limit: Duration) -> Result<Duration, String> {
    // An unoptimised build reads the brick table about ten times slower.
    let limit = if cfg!(debug_assertions) {
        limit * 10
    } else {
        limit
    };
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        let started = Instant::now();
        let path = fixture(name);
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
        let res = MajorantGrid::resolution_for(bounds, 64);
        let mut majorants = vec![0.0; res.iter().map(|&r| r as usize).product()];
        build_majorants(&density, 2.0, bounds, res, &mut majorants);
        assert!(
            majorants.iter().all(|&m| m == 1.0),
            "every cell bounds 2 x 0.5"
        );
        drop(grid);
        let builder = builder_for(&path).unwrap();
        SceneAssembler::new(Config::default())
            .assemble(builder.as_ref())
            .unwrap();
        let _ = send.send(started.elapsed());
    });
    receive
        .recv_timeout(limit)
        .map_err(|_| format!("{name} did not load within {limit:?}"))
}

/// 0.5 s on the 2-core dev machine (release), 7.4 s before tiles' bricks were read once.
#[test]
fn a_filled_1024_box_of_tiles_loads_without_visiting_its_voxels() {
    let took = load_and_bound("fill1024.vdb", Duration::from_secs(4)).unwrap();
    println!("fill1024.vdb: {took:?}");
}

/// 8 s on the 2-core dev machine (release; most of it the 512 MiB brick table, built twice),
/// more than ten minutes before.
#[test]
fn a_594_byte_vdb_of_one_4096_tile_loads_without_visiting_its_voxels() {
    let took = load_and_bound("fill4096.vdb", Duration::from_secs(60)).unwrap();
    println!("fill4096.vdb: {took:?}");
}
