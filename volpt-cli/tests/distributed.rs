//! A render split into sample ranges (`volpt render --samples A..B --film FILE`) and merged
//! (`volpt merge`) gives the whole render's image, the same bits whatever order the films are
//! named in; films that cannot add up are refused with the files named; gaps are listed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{assert_clean_error, assert_success, example_arg as example, stderr, volpt};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `volpt render` of the example, small, seed 4 unless `extra` names one, with `extra`; in `dir`
/// (where a default `out.exr` would land).
fn render(dir: &Path, extra: &[&str]) -> Output {
    let seed: &[&str] = if extra.contains(&"--seed") {
        &[]
    } else {
        &["--seed", "4"]
    };
    Command::new(env!("CARGO_BIN_EXE_volpt"))
        .current_dir(dir)
        .args(["render", &example(), "--resolution", "16x12"])
        .args(seed)
        .args(extra)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run volpt")
}

fn part(dir: &Path, a: u32, b: u32) -> PathBuf {
    let film = dir.join(format!("{a}-{b}.vfilm"));
    let range = format!("{a}..{b}");
    assert_success(&render(dir, &["--samples", &range, "--film", s(&film)]));
    film
}

fn compare(a: &Path, b: &Path, how: &[&str]) -> Output {
    let mut args = vec!["compare", s(a), s(b)];
    args.extend(how);
    volpt(&args)
}

#[test]
fn parts_merged_give_the_whole_render_and_the_same_bits_in_any_order() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let (a, b, c) = (
        part(dir.path(), 0, 2),
        part(dir.path(), 2, 3),
        part(dir.path(), 3, 6),
    );
    // A part written with --film and without -o writes no image.
    assert!(!p("out.exr").exists(), "a film-only render wrote out.exr");
    assert_success(&render(
        dir.path(),
        &["--spp", "6", "-o", s(&p("whole.exr"))],
    ));

    let merged = volpt(&[
        "merge",
        s(&c),
        s(&a),
        s(&b),
        "--spp",
        "6",
        "-o",
        s(&p("merged.exr")),
        "--film",
        s(&p("merged.vfilm")),
    ]);
    assert_success(&merged);
    let stdout = String::from_utf8_lossy(&merged.stdout);
    assert!(
        stdout.contains("merged 3 films") && stdout.contains("samples 0..6"),
        "{stdout}"
    );
    assert!(p("merged.png").is_file());
    // Partial sums added: the whole render's image up to f64 rounding, then rounded to f32.
    assert_success(&compare(
        &p("whole.exr"),
        &p("merged.exr"),
        &["--max-relative", "1e-6"],
    ));

    // Another order, and the merged film merged on its own: the same bits.
    assert_success(&volpt(&[
        "merge",
        s(&b),
        s(&c),
        s(&a),
        "-o",
        s(&p("again.exr")),
    ]));
    assert_success(&compare(
        &p("merged.exr"),
        &p("again.exr"),
        &["--identical"],
    ));
    assert_success(&volpt(&[
        "merge",
        s(&p("merged.vfilm")),
        "-o",
        s(&p("from-film.exr")),
    ]));
    assert_success(&compare(
        &p("merged.exr"),
        &p("from-film.exr"),
        &["--identical"],
    ));
}

#[test]
fn overlaps_gaps_other_renders_and_damaged_films_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let (a, b) = (part(dir.path(), 0, 2), part(dir.path(), 1, 3));
    let out = s(&p("m.exr")).to_owned();

    assert_clean_error(
        &volpt(&["merge", s(&a), s(&b), "-o", &out]),
        &["0-2.vfilm and ", "1-3.vfilm both hold samples 1..2"],
    );

    let c = part(dir.path(), 4, 6);
    assert_clean_error(
        &volpt(&["merge", s(&a), s(&c), "--spp", "8", "-o", &out]),
        &["samples 2..4, 6..8 are in no film", "--allow-gaps"],
    );
    assert!(!p("m.exr").exists(), "a refused merge wrote its image");
    let gappy = volpt(&[
        "merge",
        s(&a),
        s(&c),
        "--allow-gaps",
        "-o",
        &out,
        "--film",
        s(&p("gappy.vfilm")),
    ]);
    assert_success(&gappy);
    assert!(
        stderr(&gappy).contains("warning: samples 2..4 are in no film"),
        "{}",
        stderr(&gappy)
    );
    assert!(p("m.exr").is_file());

    // Another seed is another render.
    let other = p("seed.vfilm");
    assert_success(&render(
        dir.path(),
        &["--samples", "2..4", "--seed", "5", "--film", s(&other)],
    ));
    assert_clean_error(
        &volpt(&["merge", s(&a), s(&other), "-o", &out]),
        &[
            "seed.vfilm is a film of another render",
            "its seed is 5",
            "is 4",
        ],
    );
    // Another setting is another scene fingerprint.
    let depth = p("depth.vfilm");
    assert_success(&render(
        dir.path(),
        &["--samples", "2..4", "--max-depth", "2", "--film", s(&depth)],
    ));
    assert_clean_error(
        &volpt(&["merge", s(&a), s(&depth), "-o", &out]),
        &["depth.vfilm", "scene fingerprint"],
    );

    let mut bytes = std::fs::read(&a).unwrap();
    let last = bytes.len() - 20;
    bytes[last] ^= 0x40;
    std::fs::write(p("damaged.vfilm"), &bytes).unwrap();
    assert_clean_error(
        &volpt(&["merge", s(&p("damaged.vfilm")), s(&c), "-o", &out]),
        &["damaged.vfilm", "checksum"],
    );
    std::fs::write(p("short.vfilm"), &bytes[..bytes.len() / 2]).unwrap();
    assert_clean_error(
        &volpt(&["merge", s(&p("short.vfilm")), "-o", &out]),
        &["short.vfilm", "truncated"],
    );
    assert_clean_error(&volpt(&["merge", s(&a)]), &["nothing to write"]);
}

#[test]
fn a_checkpoint_merges_with_the_parts_after_it() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let ckpt = p("first.ckpt");
    assert_success(&render(
        dir.path(),
        &[
            "--spp",
            "3",
            "--checkpoint",
            s(&ckpt),
            "-o",
            s(&p("first.exr")),
        ],
    ));
    let rest = part(dir.path(), 3, 5);
    assert_success(&render(
        dir.path(),
        &["--spp", "5", "-o", s(&p("whole.exr"))],
    ));
    assert_success(&volpt(&[
        "merge",
        s(&rest),
        s(&ckpt),
        "--spp",
        "5",
        "-o",
        s(&p("merged.exr")),
    ]));
    assert_success(&compare(
        &p("whole.exr"),
        &p("merged.exr"),
        &["--max-relative", "1e-6"],
    ));
}

#[test]
fn bad_ranges_and_gpus_on_the_cpu_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    assert_clean_error(
        &render(dir.path(), &["--samples", "4..4", "--film", "x.vfilm"]),
        &["4..4, which holds none"],
    );
    assert_clean_error(
        &render(dir.path(), &["--samples", "0-4", "--film", "x.vfilm"]),
        &["expected A..B"],
    );
    assert_clean_error(
        &render(dir.path(), &["--samples", "0..4", "--checkpoint", "c.ckpt"]),
        &["--checkpoint"],
    );
    assert_clean_error(
        &render(dir.path(), &["--gpus", "all"]),
        &["--gpus all", "--backend cuda"],
    );
    assert_clean_error(&render(dir.path(), &["--gpus", "0,0"]), &["named twice"]);
}
