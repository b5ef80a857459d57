//! Running the `volpt` binary in the CLI tests, and what every such test asserts of its output.
// Each test file uses its own part of these helpers.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn volpt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_volpt"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run volpt")
}

/// The example scene (`scenes/example/cube.xml`).
pub fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml")
}

/// The example scene, as a command-line argument.
pub fn example_arg() -> String {
    example().to_str().expect("a UTF-8 path").to_owned()
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Fails with a message that contains every one of `needles`, and does not panic.
pub fn assert_clean_error(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert!(!out.status.success(), "expected failure, stderr: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    for n in needles {
        assert!(err.contains(n), "error lacks {n:?}: {err}");
    }
}

pub fn assert_success(out: &Output) {
    assert!(out.status.success(), "stderr: {}", stderr(out));
}

/// Whether a failed `--backend cuda` run failed because this `volpt` carries no GPU kernels
/// (`cargo xtask ptx` did not run before the build), which stops it before the driver. The error
/// must then say how to build them; the caller skips what needs the kernels, and this says so.
/// With `VOLPT_REQUIRE_PTX=1` (as `.ci/run` sets) a build without kernels fails instead.
pub fn skipped_without_kernels(test: &str, err: &str) -> bool {
    if !err.contains("was built without the GPU's") {
        return false;
    }
    assert!(
        err.contains("cargo xtask ptx"),
        "the missing kernels' error does not say how to build them: {err}"
    );
    assert!(
        std::env::var_os("VOLPT_REQUIRE_PTX").is_none(),
        "{test}: VOLPT_REQUIRE_PTX is set but this volpt has no GPU kernels: run `cargo xtask ptx` \
         before building: {err}"
    );
    // Straight to stderr, past the test harness's capture of `eprintln!`, so that a passing run
    // shows the skip too.
    let _ = writeln!(
        std::io::stderr(),
        "skipped: {test} past the kernels' check: this volpt was built without GPU kernels; run \
         `cargo xtask ptx`, then the test again"
    );
    true
}
