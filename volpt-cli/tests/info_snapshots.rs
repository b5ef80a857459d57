//! Snapshots of `volpt info`: what every included scene and every scene-source fixture assembles
//! to (sizes, bounds, density range, majorant, boundary, phase, light, and the render variant).
//! A loader change that alters any loaded value shows up here as a diff to review.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `volpt info` run from `cwd` on the relative `scene`, so that snapshots hold no absolute paths.
fn info(cwd: &Path, scene: &str, params: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_volpt"))
        .current_dir(cwd)
        .arg("info")
        .arg(scene)
        .args(params)
        .env("RUST_LOG", "error")
        .output()
        .expect("run volpt");
    assert!(
        out.status.success(),
        "volpt info {scene} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// The folder holding Mitsuba's own `smoke.vol` where the project's data sits beside the checkout
/// (`../shared/data`; not redistributable, so not in the repository); `None`, saying so, elsewhere.
fn mitsuba_smoke_data() -> Option<PathBuf> {
    let data = root().join("../shared/data");
    if data.join("smoke.vol").is_file() {
        return Some(data);
    }
    // Straight to stderr, past the test harness's capture of `eprintln!`, so that a passing run
    // shows the skip too.
    let _ = writeln!(
        std::io::stderr(),
        "skipped: the smoke snapshot on Mitsuba's smoke.vol: {} is absent (put Mitsuba's hetvol \
         smoke.vol there to run it; the generated stand-in's snapshot ran instead)",
        data.join("smoke.vol").display()
    );
    None
}

#[test]
fn included_scenes() {
    let root = root();
    insta::assert_snapshot!("example", info(&root, "scenes/example/cube.xml", &[]));
    insta::assert_snapshot!(
        "homogeneous-cube",
        info(&root, "scenes/homogeneous-cube/scene.xml", &[])
    );
    insta::assert_snapshot!(
        "homogeneous-cube-null",
        info(
            &root,
            "scenes/homogeneous-cube/scene.xml",
            &["-Dboundary=null"]
        )
    );
    insta::assert_snapshot!("bucky", info(&root, "scenes/bucky/scene.toml", &[]));
    insta::assert_snapshot!("bucky-vdb", info(&root, "scenes/vdb/bucky.toml", &[]));
    insta::assert_snapshot!(
        "sparse-cloud-vdb",
        info(&root, "scenes/vdb/fixtures/sparse-cloud.vdb", &[])
    );
}

/// cgg-logo and ad read generated grids, envmap-cube a generated sky, smoke a generated stand-in
/// grid: generate them into a copy of their directories.
#[test]
fn generated_thesis_scenes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scenes = dir.path().join("scenes");
    for name in ["cgg-logo", "ad", "envmap-cube", "smoke"] {
        std::fs::create_dir_all(scenes.join(name)).expect("mkdir");
        std::fs::copy(
            root().join("scenes").join(name).join("scene.xml"),
            scenes.join(name).join("scene.xml"),
        )
        .expect("copy scene");
    }
    volpt::scene_files::generate::generate_scene_inputs(&scenes).expect("generate grids");
    insta::assert_snapshot!(
        "cgg-logo",
        info(dir.path(), "scenes/cgg-logo/scene.xml", &[])
    );
    insta::assert_snapshot!("ad", info(dir.path(), "scenes/ad/scene.xml", &[]));
    insta::assert_snapshot!(
        "envmap-cube",
        info(dir.path(), "scenes/envmap-cube/scene.xml", &[])
    );
    insta::assert_snapshot!(
        "smoke-stand-in",
        info(dir.path(), "scenes/smoke/scene.xml", &[])
    );
}

/// Smoke on Mitsuba's own grid, the thesis's, where it is beside the checkout.
#[test]
fn smoke_on_mitsuba_data() {
    let Some(data) = mitsuba_smoke_data() else {
        return;
    };
    let data = format!("-Ddata={}", data.display());
    insta::assert_snapshot!("smoke", info(&root(), "scenes/smoke/scene.xml", &[&data]));
}

/// The scene-loader fixtures that need no generated files (the Mitsuba 0.6 and 3 fixtures with
/// grids are covered by volpt-scene's own tests, which write their grids).
#[test]
fn source_fixtures() {
    let fixtures = root().join("volpt-scene/tests/fixtures");
    for scene in [
        "cube/scene.xml",
        "params/scene.xml",
        "include/scene.xml",
        "metaimage/tiny.mhd",
        "metaimage/msb.mha",
        "vtk/tiny_ascii.vtk",
    ] {
        let name = scene.replace(['/', '.'], "-");
        insta::assert_snapshot!(name, info(&fixtures, scene, &[]));
    }
    let toml = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/toml");
    insta::assert_snapshot!("toml-raw-transfer", info(&toml, "raw-transfer.toml", &[]));
    insta::assert_snapshot!("toml-minimal", info(&toml, "minimal.toml", &[]));
    insta::assert_snapshot!(
        "cli-overrides",
        info(
            &toml,
            "raw-transfer.toml",
            &[
                "--spp",
                "3",
                "--resolution",
                "20x10",
                "--max-depth",
                "-1",
                "--rr-depth",
                "7"
            ]
        )
    );
}
