//! Running the `volpt` binary in the CLI tests, and what every such test asserts of its output.
// Each test file uses its own part of these helpers.
#![allow(dead_code)]

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
