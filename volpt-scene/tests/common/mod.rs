//! Shared test helpers: staging fixtures in a temporary directory next to generated `.vol` files.

#![allow(dead_code)] // each test binary uses a different subset

use std::path::{Path, PathBuf};

use tempfile::TempDir;
use volpt_scene::{write_vol, Bounds, SceneError, VolGrid};

pub fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// Copies `tests/fixtures/<name>` (recursively) into a fresh temporary directory.
pub fn stage(name: &str) -> TempDir {
    let dir = TempDir::new().expect("temporary directory");
    copy_dir(&fixtures().join(name), dir.path());
    dir
}

fn copy_dir(from: &Path, to: &Path) {
    for entry in std::fs::read_dir(from).expect("fixture directory") {
        let entry = entry.expect("fixture entry");
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            std::fs::create_dir_all(&target).expect("create directory");
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).expect("copy fixture");
        }
    }
}

/// A small density grid with distinct, non-negative values: value = index / 10.
pub fn density_grid(resolution: [u32; 3], bbox: Bounds) -> VolGrid {
    let n = (resolution[0] * resolution[1] * resolution[2]) as usize;
    VolGrid {
        resolution,
        channels: 1,
        bbox,
        data: (0..n).map(|i| i as f32 / 10.0).collect(),
    }
}

pub fn unit_bounds() -> Bounds {
    Bounds {
        min: [0.0; 3],
        max: [1.0; 3],
    }
}

pub fn write_grid(dir: &Path, name: &str, grid: &VolGrid) -> PathBuf {
    let path = dir.join(name);
    write_vol(&path, grid).expect("write .vol");
    path
}

/// Writes `text` as `scene.xml` in a fresh directory.
pub fn scene_file(text: &str) -> (TempDir, PathBuf) {
    let dir = TempDir::new().expect("temporary directory");
    let path = dir.path().join("scene.xml");
    std::fs::write(&path, text).expect("write scene");
    (dir, path)
}

/// A Mitsuba 3 scene with a camera and a cube holding `shape_body` (bsdf and medium).
pub fn cube_scene(shape_body: &str) -> String {
    format!(
        "<scene version=\"3.0.0\">\n\
         \x20   <sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n\
         \x20   <shape type=\"cube\">\n{shape_body}\n    </shape>\n\
         </scene>\n"
    )
}

/// A cube scene with a null boundary and the given medium.
pub fn medium_scene(medium: &str) -> String {
    cube_scene(&format!("        <bsdf type=\"null\"/>\n{medium}"))
}

/// A cube scene with the given bsdf and a default homogeneous medium.
pub fn bsdf_scene(bsdf: &str) -> String {
    cube_scene(&format!(
        "{bsdf}\n        <medium type=\"homogeneous\" name=\"interior\"/>"
    ))
}

/// The error message, asserted to mention every one of `parts`.
pub fn message_of(err: &SceneError, parts: &[&str]) -> String {
    let message = err.to_string();
    for part in parts {
        assert!(
            message.contains(part),
            "message {message:?} should mention {part:?}"
        );
    }
    message
}

pub fn assert_close(a: f32, b: f32) {
    assert!((a - b).abs() <= 1e-5 * b.abs().max(1.0), "{a} != {b}");
}

pub fn assert_close3(a: [f32; 3], b: [f32; 3]) {
    for (x, y) in a.iter().zip(&b) {
        assert_close(*x, *y);
    }
}

pub fn assert_matrix(a: &[[f32; 4]; 4], b: &[[f32; 4]; 4]) {
    for (ra, rb) in a.iter().zip(b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-6, "{a:?} != {b:?}");
        }
    }
}

/// `to_world` is Mitsuba's `lookat` frame for `origin`, `target` and `up` (+z towards the target,
/// +y up, +x to the image's left), built here in f64 independently of the loaders' f32 code.
pub fn assert_lookat_frame(
    to_world: &[[f32; 4]; 4],
    origin: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
) {
    let normalize = |v: [f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / n)
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let forward = normalize([0, 1, 2].map(|i| target[i] - origin[i]));
    let left = normalize(cross(up, forward));
    let new_up = cross(forward, left);
    for i in 0..3 {
        for (j, want) in [left[i], new_up[i], forward[i], origin[i]]
            .into_iter()
            .enumerate()
        {
            assert!(
                (to_world[i][j] as f64 - want).abs() < 1e-5,
                "row {i} column {j}: {to_world:?}"
            );
        }
    }
}
