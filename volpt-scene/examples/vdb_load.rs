//! Times reading one `.vdb` grid and reports what it takes in memory:
//! `cargo run --release -p volpt-scene --example vdb_load -- FILE [GRID]`
//! (the load-time figures of docs/out-of-core.md, "Sparse grids (VDB)").

use std::time::Instant;

use volpt_scene::vdb::{read_vdb, VdbOptions};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: vdb_load FILE [GRID]");
    let options = VdbOptions {
        grid: args.next(),
        ..Default::default()
    };
    volpt_scene::limits::set_memory_limit(u64::MAX);
    let start = Instant::now();
    let grid = read_vdb(path.as_ref(), &options).unwrap_or_else(|e| panic!("{e}"));
    let seconds = start.elapsed().as_secs_f64();
    let mib = |b: u64| b as f64 / f64::from(1 << 20);
    println!(
        "{path}: {:?} x {} channels, {:?}, read in {seconds:.2} s; stored {:.1} MiB, dense {:.1} MiB",
        grid.resolution,
        grid.channels,
        grid.layout,
        mib(grid.stored_bytes()),
        grid.dense_bytes().map_or(f64::INFINITY, mib)
    );
}
