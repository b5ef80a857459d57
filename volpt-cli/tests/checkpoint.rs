//! Long renders lose nothing: a render saved by `--checkpoint` (at its end, or on Ctrl-C) and
//! continued with `--resume` gives the uninterrupted render's image bit for bit; a damaged or
//! foreign checkpoint is a clear error.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{assert_success, example_arg as example, volpt};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `volpt compare --identical` of two renders.
fn assert_identical(a: &Path, b: &Path) {
    let out = volpt(&["compare", s(a), s(b), "--identical"]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

const SMALL: [&str; 4] = ["--resolution", "24x16", "--seed", "9"];

fn render(spp: u32, extra: &[&str], out: &Path) -> Output {
    let (spp, example) = (spp.to_string(), example());
    let mut args = vec!["render", &example, "--spp", &spp, "-o", s(out)];
    args.extend(SMALL);
    args.extend(extra);
    volpt(&args)
}

#[test]
fn a_resumed_render_equals_the_uninterrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| -> PathBuf { dir.path().join(name) };
    assert_success(&render(9, &[], &p("whole.exr")));
    assert_success(&render(
        4,
        &["--checkpoint", s(&p("c.ckpt"))],
        &p("part.exr"),
    ));
    // The resumed render adds samples 4..9 to the saved sums of 0..4.
    assert_success(&render(
        9,
        &["--resume", s(&p("c.ckpt"))],
        &p("resumed.exr"),
    ));
    assert_identical(&p("whole.exr"), &p("resumed.exr"));
}

#[test]
fn ctrl_c_saves_the_finished_samples() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| -> PathBuf { dir.path().join(name) };
    let ckpt = p("c.ckpt");
    let example = example();
    // Many samples, a checkpoint after every chunk: Ctrl-C arrives long before the end.
    let child = Command::new(env!("CARGO_BIN_EXE_volpt"))
        .args([
            "render",
            &example,
            "--spp",
            "100000",
            "-o",
            s(&p("never.exr")),
        ])
        .args(SMALL)
        .args(["--checkpoint", s(&ckpt), "--checkpoint-interval", "0.05"])
        .env("RUST_LOG", "warn")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !ckpt.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no checkpoint written"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(130), "{stdout}");
    // "interrupted after N of 100000 samples per pixel: saved to ..."
    let samples: u32 = stdout
        .split_once("interrupted after ")
        .and_then(|(_, rest)| rest.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(samples > 0 && samples < 100_000, "{stdout}");
    assert!(!p("never.exr").exists());
    // Resumed to two more samples, it is the render of that many samples from scratch.
    let total = samples + 2;
    assert_success(&render(total, &["--resume", s(&ckpt)], &p("resumed.exr")));
    assert_success(&render(total, &[], &p("whole.exr")));
    assert_identical(&p("whole.exr"), &p("resumed.exr"));
}

#[test]
fn damaged_or_foreign_checkpoints_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| -> PathBuf { dir.path().join(name) };
    let ckpt = p("c.ckpt");
    assert_success(&render(2, &["--checkpoint", s(&ckpt)], &p("a.exr")));
    let good = std::fs::read(&ckpt).unwrap();

    let err = |out: Output| {
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    // Another seed: the same scene, but not the same paths.
    let out = volpt(&[
        "render",
        &example(),
        "--spp",
        "4",
        "-o",
        s(&p("b.exr")),
        "--resolution",
        "24x16",
        "--seed",
        "10",
        "--resume",
        s(&ckpt),
    ]);
    let e = err(out);
    assert!(
        e.contains("c.ckpt") && e.contains("seed") && e.contains("10"),
        "{e}"
    );
    // Other integrator settings: not the same estimator.
    let e = err(render(
        4,
        &["--resume", s(&ckpt), "--max-depth", "3"],
        &p("b.exr"),
    ));
    assert!(e.contains("c.ckpt") && e.contains("another render"), "{e}");
    // Another grid lookup: not the same medium.
    let e = err(render(
        4,
        &["--resume", s(&ckpt), "--lookup", "nearest"],
        &p("b.exr"),
    ));
    assert!(e.contains("c.ckpt") && e.contains("another render"), "{e}");
    // Another film size.
    let mut args = vec!["render".to_owned(), example(), "--spp".into(), "4".into()];
    args.extend(["-o", s(&p("b.exr")), "--resolution", "8x8", "--seed", "9"].map(String::from));
    args.extend(["--resume".to_owned(), s(&ckpt).to_owned()]);
    let e = err(volpt(&args.iter().map(String::as_str).collect::<Vec<_>>()));
    assert!(e.contains("c.ckpt") && e.contains("8x8"), "{e}");
    // One flipped byte in the sums.
    let mut bad = good.clone();
    let i = bad.len() / 2;
    bad[i] ^= 0x10;
    std::fs::write(&ckpt, &bad).unwrap();
    let e = err(render(4, &["--resume", s(&ckpt)], &p("b.exr")));
    assert!(e.contains("c.ckpt") && e.contains("checksum"), "{e}");
    // Cut short.
    std::fs::write(&ckpt, &good[..good.len() - 100]).unwrap();
    let e = err(render(4, &["--resume", s(&ckpt)], &p("b.exr")));
    assert!(e.contains("c.ckpt") && e.contains("bytes"), "{e}");
    // More samples saved than asked for.
    std::fs::write(&ckpt, &good).unwrap();
    let e = err(render(1, &["--resume", s(&ckpt)], &p("b.exr")));
    assert!(e.contains("more than the 1"), "{e}");
}
