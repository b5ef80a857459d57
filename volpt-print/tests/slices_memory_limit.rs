//! A slice stack over the memory limit is refused before a slice is read. Its own test binary:
//! the limit is process-wide.

mod common;

use volpt_print::slices::{read_slices, write_slices, MATERIALS_FILE};
use volpt_print::{PrintError, VoxelPrint};
use volpt_scene::SceneError;

#[test]
fn a_stack_over_the_memory_limit_is_refused_before_reading_slices() {
    let dir = tempfile::tempdir().unwrap();
    let print = VoxelPrint::new(common::inks(), [0.1; 3], [8, 8, 4], vec![4; 256]).unwrap();
    write_slices(&print, dir.path()).unwrap();
    // A header claiming 100k x 100k x 1000 voxels, with no slice of that size anywhere: refused
    // on the claim alone (no slice is opened: the numbering would fail otherwise).
    let toml = dir.path().join(MATERIALS_FILE);
    let text = std::fs::read_to_string(&toml).unwrap();
    let huge = text
        .replace("width = 8", "width = 100000")
        .replace("height = 8", "height = 100000")
        .replace("layers = 4", "layers = 1000");
    std::fs::write(&toml, huge).unwrap();
    let e = read_slices(dir.path()).unwrap_err();
    assert!(
        matches!(&e, PrintError::Scene(SceneError::OverMemoryLimit { .. })),
        "{e:?}"
    );
    assert!(e.to_string().contains("100000 x 100000 x 1000"), "{e}");
    std::fs::write(&toml, text).unwrap();
    assert_eq!(read_slices(dir.path()).unwrap(), print);
    // A real stack over a lowered limit is refused too.
    volpt_scene::limits::set_memory_limit(255);
    let e = read_slices(dir.path()).unwrap_err();
    assert!(
        matches!(&e, PrintError::Scene(SceneError::OverMemoryLimit { .. })),
        "{e:?}"
    );
}
