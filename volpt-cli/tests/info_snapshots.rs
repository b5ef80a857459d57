//! Snapshots of `volpt info`: what every included scene and every scene-source fixture assembles
//! to (sizes, bounds, density range, majorant, boundary, phase, light, and the render variant).
//! A loader change that alters any loaded value shows up here as a diff to review.

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

/// Set to `1` to skip the snapshots of the scenes that read `../shared/data` where it is not
/// beside the checkout (`.ci/run` does, and says so); without it, missing data is a failure.
const SKIP_SHARED_DATA: &str = "VOLPT_SKIP_SHARED_DATA";

fn shared_data() -> Option<PathBuf> {
    let data = root().join("../shared/data");
    if ["smoke.vol", "Bucky.raw"]
        .iter()
        .all(|f| data.join(f).is_file())
    {
        return Some(data);
    }
    assert_eq!(
        std::env::var(SKIP_SHARED_DATA).as_deref(),
        Ok("1"),
        "{} lacks smoke.vol or Bucky.raw: put the shared data beside the checkout, or set \
         {SKIP_SHARED_DATA}=1 to skip the smoke and bucky snapshots explicitly",
        data.display()
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
}

/// cgg-logo and ad read generated grids, envmap-cube a generated sky: generate them into a copy of
/// their directories.
#[test]
fn generated_thesis_scenes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scenes = dir.path().join("scenes");
    for name in ["cgg-logo", "ad", "envmap-cube"] {
        std::fs::create_dir_all(scenes.join(name)).expect("mkdir");
        std::fs::copy(
            root().join("scenes").join(name).join("scene.xml"),
            scenes.join(name).join("scene.xml"),
        )
        .expect("copy scene");
    }
    volpt_scene::generate::generate_scene_inputs(&scenes).expect("generate grids");
    insta::assert_snapshot!(
        "cgg-logo",
        info(dir.path(), "scenes/cgg-logo/scene.xml", &[])
    );
    insta::assert_snapshot!("ad", info(dir.path(), "scenes/ad/scene.xml", &[]));
    insta::assert_snapshot!(
        "envmap-cube",
        info(dir.path(), "scenes/envmap-cube/scene.xml", &[])
    );
}

#[test]
fn scenes_from_shared_data() {
    let Some(data) = shared_data() else {
        eprintln!(
            "skipped on request ({SKIP_SHARED_DATA}=1): no ../shared/data beside the checkout"
        );
        return;
    };
    let data = format!("-Ddata={}", data.display());
    let root = root();
    insta::assert_snapshot!("smoke", info(&root, "scenes/smoke/scene.xml", &[&data]));
    insta::assert_snapshot!("bucky", info(&root, "scenes/bucky/scene.toml", &[&data]));
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
