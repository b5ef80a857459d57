//! A sparse VDB whose dense box would not fit the memory limit loads within a small stated bound.
//! Its own test binary: the memory limit is one setting for the whole process.

use std::path::Path;

use volpt_scene::description::SampleLayout;
use volpt_scene::limits::set_memory_limit;
use volpt_scene::vdb::{read_vdb, Sparsity, VdbOptions};
use volpt_scene::SceneError;

/// `scenes/vdb/fixtures/sparse-cloud.vdb` (OpenVDB): two balls of radius 10 voxels at opposite
/// corners of a 512^3 index box, about 4,300 active voxels: the dense box is over 30,000 times
/// its active voxels.
#[test]
fn a_sparse_cloud_loads_within_its_bound_where_the_dense_box_would_be_refused() {
    const LIMIT: u64 = 64 << 20;
    // Stored: 2 x 27 leaves at most (a ball of diameter 21 spans 3 to 4 leaves per axis: 64 x
    // 2 KiB each) plus the background brick, and a table of 64^3 bricks x 4 bytes (1 MiB).
    const BOUND: u64 = (2 * 64 + 1) * 2048 + (64 * 64 * 64) * 4;
    set_memory_limit(LIMIT);
    // The committed fixture, or the one CI has just written with OpenVDB.
    let path = match std::env::var_os("VOLPT_VDB_FIXTURES") {
        Some(dir) => Path::new(&dir).join("sparse-cloud.vdb"),
        None => {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/vdb/fixtures/sparse-cloud.vdb")
        }
    };
    let options = |sparsity| VdbOptions {
        sparsity,
        ..Default::default()
    };
    let grid = read_vdb(&path, &options(Sparsity::Auto)).unwrap();
    assert_eq!(grid.layout, SampleLayout::Sparse);
    assert_eq!(grid.resolution, [512; 3]);
    let dense = grid.dense_bytes().unwrap();
    assert_eq!(dense, 512 * 512 * 512 * 4);
    assert!(dense > LIMIT, "the dense box must exceed the limit");
    assert!(
        grid.stored_bytes() <= BOUND,
        "{} bytes stored, bound {BOUND}",
        grid.stored_bytes()
    );
    let active = grid.samples().iter().filter(|&&v| v > 0.0).count() as u64;
    assert!(
        512 * 512 * 512 >= 100 * active,
        "{active} active voxels: not 100x sparse"
    );
    // The dense path is refused by the same limit.
    let error = read_vdb(&path, &options(Sparsity::Never)).unwrap_err();
    assert!(
        matches!(error, SceneError::OverMemoryLimit { .. }),
        "{error}"
    );
}
