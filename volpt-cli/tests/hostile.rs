//! The `volpt` binary given hostile arguments (issue 12): output paths, thread and trial counts,
//! film sizes, images holding NaN, the memory limit, `--max-depth 0`. Each is a clear error (or a
//! sensible result), never a panic, a hang or an abort.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{assert_clean_error, assert_success, example_arg as example, volpt};

/// A quick render of the example to `output`, with `extra` arguments.
fn render(output: &Path, extra: &[&str]) -> Output {
    let scene = example();
    let mut args = vec![
        "render",
        &scene,
        "--resolution",
        "8x8",
        "--spp",
        "1",
        "-o",
        output.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    volpt(&args)
}

#[test]
fn an_output_not_named_exr_is_refused_so_the_preview_cannot_overwrite_it() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let out = render(&png, &[]);
    assert_clean_error(&out, &["x.png", ".exr"]);
    assert!(!png.exists(), "nothing is written");
    assert_success(&render(&dir.path().join("y.EXR"), &[]));
    assert!(dir.path().join("y.png").exists());
}

#[cfg(unix)]
#[test]
fn an_output_that_is_not_a_file_gets_the_image_and_no_preview() {
    // A `/dev/null.png` left by an older volpt must not make this pass or fail: nothing may write it.
    let preview = Path::new("/dev/null.png");
    let before = std::fs::metadata(preview).and_then(|m| m.modified()).ok();
    let out = render(Path::new("/dev/null"), &[]);
    assert_success(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("no preview"));
    let after = std::fs::metadata(preview).and_then(|m| m.modified()).ok();
    assert_eq!(before, after, "{} was written", preview.display());
}

#[test]
fn export_names_cannot_leave_the_output_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("a/b");
    for name in ["../../x", "/tmp/x", "..", "c/d"] {
        let out = volpt(&[
            "scene",
            "export",
            &example(),
            "-o",
            out_dir.to_str().unwrap(),
            "--name",
            name,
        ]);
        assert_clean_error(&out, &["plain file name"]);
    }
    assert!(!dir.path().join("x.xml").exists());
}

#[test]
fn thread_and_trial_counts_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(&dir.path().join("t.exr"), &["--threads", "100000"]);
    assert_clean_error(&out, &["--threads", "100000"]);
    let out = volpt(&["bench", &example(), "--trials", "4294967295"]);
    assert_clean_error(&out, &["--trials"]);
}

#[test]
fn films_over_the_memory_limit_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let scene = example();
    let output = dir.path().join("big.exr");
    let out = volpt(&[
        "render",
        &scene,
        "--resolution",
        "100000x100000",
        "-o",
        output.to_str().unwrap(),
    ]);
    assert_clean_error(&out, &["cube.xml", "film", "100000 x 100000"]);
    let out = volpt(&[
        "info",
        &scene,
        "--resolution",
        "1000x1000",
        "--memory-limit",
        "64K",
    ]);
    assert_clean_error(&out, &["film", "memory limit of 65536 bytes"]);
    let out = volpt(&["info", &scene, "--memory-limit", "lots"]);
    assert_clean_error(&out, &["--memory-limit"]);
}

fn write_exr(path: &Path, value: f32) {
    exr::prelude::write_rgb_file(path, 2, 2, |x, y| {
        if (x, y) == (1, 0) {
            (value, 0.5f32, 0.5f32)
        } else {
            (0.5f32, 0.5f32, 0.5f32)
        }
    })
    .unwrap();
}

#[test]
fn compare_fails_on_non_finite_pixels_and_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| -> PathBuf { dir.path().join(name) };
    write_exr(&path("good.exr"), 0.5);
    write_exr(&path("nan.exr"), f32::NAN);
    write_exr(&path("inf.exr"), f32::INFINITY);
    let arg = |name: &str| path(name).to_str().unwrap().to_owned();
    assert_success(&volpt(&["compare", &arg("good.exr"), &arg("good.exr")]));
    for bad in ["nan.exr", "inf.exr"] {
        let out = volpt(&["compare", &arg(bad), &arg(bad)]);
        assert_clean_error(&out, &[bad, "x=1, y=0", "finite"]);
        let out = volpt(&[
            "compare",
            &arg("good.exr"),
            &arg(bad),
            "--max-relative",
            "1",
        ]);
        assert_clean_error(&out, &[bad]);
    }
    for bound in ["nan", "inf", "-1"] {
        let out = volpt(&[
            "compare",
            &arg("good.exr"),
            &arg("good.exr"),
            &format!("--max-relative={bound}"),
        ]);
        assert_clean_error(&out, &["--max-relative", "finite"]);
    }
}

#[test]
fn max_depth_zero_renders_black_as_in_mitsuba() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("black.exr");
    assert_success(&render(&output, &["--max-depth", "0"]));
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &output,
        |size, _| vec![0.0f32; size.width() * size.height() * 3],
        |pixels: &mut Vec<f32>, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (position.y() * 8 + position.x());
            pixels[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .unwrap();
    let pixels = image.layer_data.channel_data.pixels;
    assert!(pixels.iter().all(|&v| v == 0.0), "{pixels:?}");
}

#[test]
fn a_file_the_vtk_parser_panics_on_is_a_clean_error() {
    // Found by fuzzing: vtkio indexes an empty array; the panic is caught, and its message must
    // not reach the user either.
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../volpt-scene/tests/fixtures/hostile/vtkio-panics.vti");
    let out = volpt(&["info", file.to_str().unwrap()]);
    assert_clean_error(&out, &["vtkio-panics.vti", "malformed"]);
}
