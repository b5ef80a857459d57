//! No guard of an estimator lives only in a test that CI skips.
//!
//! CI (`.ci/run`) runs on a clone with nothing beside it and sets `VOLPT_SKIP_SHARED_DATA=1`: every
//! test that reads `../shared/data` returns early there. This test reads the workspace's Rust
//! sources and finds the tests that can be skipped that way (a test whose body, or a function of
//! the same file that it calls, mentions `shared/data` or `SKIP_SHARED_DATA`) and the tests that
//! guard an estimator (whose body, or a function it calls, renders or tracks: `pixel_statistics`,
//! `render_cpu`, `with_scene`, `trace`, `ratio_tracking`, ... or runs `volpt render`). A test that
//! is both must be listed in [`TWINS`] with tests on generated data that guard the same estimators,
//! and each twin must exist, guard an estimator and not be skippable. An entry whose test no longer
//! exists or can no longer be skipped fails too, so the list cannot go stale.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Each test that CI skips and that guards an estimator, the tests that guard the same estimators
/// on generated data, and what the skipped test compares.
const TWINS: &[(&str, &[&str], &str)] = &[(
    "tests/tests/heterogeneous.rs::grid_and_nee_match_global_pt_on_smoke_and_bucky",
    &[
        "tests/tests/estimators.rs::next_event_estimation_matches_path_tracing_on_a_generated_medium",
        "tests/tests/estimators.rs::global_majorant_matches_the_majorant_grid_on_a_generated_medium",
    ],
    "majorant grid against global and NEE against path tracing on smoke (a heterogeneous grid \
     with empty space) and bucky",
)];

/// What makes a function skippable in CI: it reads the data CI lacks.
const SKIP_MARKERS: &[&str] = &["shared/data", "SKIP_SHARED_DATA"];

/// What makes a function a guard of an estimator: it renders, traces paths or tracks.
const ESTIMATOR_MARKERS: &[&str] = &[
    "pixel_statistics",
    "ImageMean::render(",
    "render_cpu(",
    "render_with(",
    "volpt_render::render(",
    "with_scene(",
    "with_scene_as(",
    "with_core_scene(",
    "trace(",
    "sample_pixel(",
    "delta_tracking(",
    "ratio_tracking(",
    "walk_majorants(",
    "\"render\"",
];

/// A function of a source file: its name, whether it is a `#[test]`, its body (comments removed).
#[derive(Debug)]
struct Function {
    name: String,
    test: bool,
    body: String,
}

/// `src` without `//` and `/* */` comments (string and char literals kept as they are).
fn strip_comments(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            i += 2;
            while i < b.len() && !b[i..].starts_with(b"*/") {
                i += 1;
            }
            i += 2;
        } else if b[i] == b'"' {
            let end = string_end(b, i);
            out.push_str(&src[i..end]);
            i = end;
        } else {
            let c = src[i..].chars().next().expect("char boundary");
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// The index just past the string literal that opens at `b[start] == '"'`.
fn string_end(b: &[u8], start: usize) -> usize {
    let mut i = start + 1;
    while i < b.len() && b[i] != b'"' {
        i += if b[i] == b'\\' { 2 } else { 1 };
    }
    (i + 1).min(b.len())
}

/// The index just past the block that opens at `b[open] == '{'`, ignoring braces in string and
/// char literals.
fn block_end(b: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    let mut i = open;
    while i < b.len() {
        match b[i] {
            b'"' => {
                i = string_end(b, i);
                continue;
            }
            // '{' and '}' as char literals; lifetimes ('a) never close with a quote two on.
            b'\'' if i + 2 < b.len() && b[i + 2] == b'\'' => i += 2,
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return i + 1;
                }
            }
            _ => {}
        }
        i += 1;
    }
    b.len()
}

/// Every function with a body in `src`, nested ones included.
fn functions(src: &str) -> Vec<Function> {
    let src = strip_comments(src);
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(at) = src[from..].find("fn ").map(|k| k + from) {
        from = at + 3;
        if at > 0 && (b[at - 1].is_ascii_alphanumeric() || b[at - 1] == b'_') {
            continue;
        }
        let name: String = src[at + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if name.is_empty() {
            continue;
        }
        let (Some(open), semi) = (src[at..].find('{'), src[at..].find(';')) else {
            continue;
        };
        if semi.is_some_and(|s| s < open) {
            continue; // a declaration without a body
        }
        let open = at + open;
        let end = block_end(b, open);
        // The attributes between the previous item and this one.
        let before = &src[..at];
        let item_start = before.rfind(['}', ';']).map_or(0, |k| k + 1);
        out.push(Function {
            name,
            test: before[item_start..].contains("#[test]"),
            body: src[open..end].to_owned(),
        });
    }
    out
}

/// Per function name of one file: whether it (or a function of the file it calls) matches
/// `markers`.
fn reaches(functions: &[Function], markers: &[&str]) -> BTreeMap<String, bool> {
    let mut hit: BTreeMap<String, bool> =
        functions.iter().map(|f| (f.name.clone(), false)).collect();
    for f in functions {
        if markers.iter().any(|m| f.body.contains(m)) {
            hit.insert(f.name.clone(), true);
        }
    }
    loop {
        let mut changed = false;
        for f in functions {
            if hit[&f.name] {
                continue;
            }
            let calls = |g: &Function| {
                f.body.match_indices(&format!("{}(", g.name)).any(|(k, _)| {
                    k == 0 || {
                        let c = f.body.as_bytes()[k - 1];
                        !(c.is_ascii_alphanumeric() || c == b'_')
                    }
                })
            };
            if functions.iter().any(|g| hit[&g.name] && calls(g)) {
                hit.insert(f.name.clone(), true);
                changed = true;
            }
        }
        if !changed {
            return hit;
        }
    }
}

/// What the scan found about one test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Test {
    skippable: bool,
    estimator: bool,
}

/// Every `#[test]` of `src`, by name.
fn classify(src: &str) -> BTreeMap<String, Test> {
    let fns = functions(src);
    let skippable = reaches(&fns, SKIP_MARKERS);
    let estimator = reaches(&fns, ESTIMATOR_MARKERS);
    fns.iter()
        .filter(|f| f.test)
        .map(|f| {
            let test = Test {
                skippable: skippable[&f.name],
                estimator: estimator[&f.name],
            };
            (f.name.clone(), test)
        })
        .collect()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read dir") {
        let path = entry.expect("dir entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() {
            if !name.starts_with('.') && name != "target" {
                rust_files(&path, out);
            }
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}

/// Every test of the workspace, as `path::name` (path relative to the workspace root).
fn workspace_tests() -> BTreeMap<String, Test> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut tests = BTreeMap::new();
    for file in files {
        // This file's own made-up sources (below) are no tests of the workspace.
        if file.ends_with("tests/tests/ci_guards.rs") {
            continue;
        }
        let src = std::fs::read_to_string(&file).expect("read source");
        let rel = file.strip_prefix(&root).expect("inside the root");
        for (name, test) in classify(&src) {
            tests.insert(format!("{}::{name}", rel.display()), test);
        }
    }
    tests
}

/// The problems of `tests` against `twins`: skipped guards without twins, bad twins, stale entries.
fn problems(tests: &BTreeMap<String, Test>, twins: &[(&str, &[&str], &str)]) -> Vec<String> {
    let mut problems = Vec::new();
    let listed: BTreeSet<&str> = twins.iter().map(|t| t.0).collect();
    for (name, test) in tests {
        if test.skippable && test.estimator && !listed.contains(name.as_str()) {
            problems.push(format!(
                "{name} guards an estimator but CI skips it (no ../shared/data): give it a twin \
                 on generated data and list both in TWINS"
            ));
        }
    }
    for (skipped, twins, _) in twins {
        match tests.get(*skipped) {
            Some(t) if t.skippable && t.estimator => {}
            _ => problems.push(format!(
                "{skipped} is listed in TWINS but is no skippable estimator guard (any more)"
            )),
        }
        if twins.is_empty() {
            problems.push(format!("{skipped} has no twin"));
        }
        for twin in *twins {
            match tests.get(*twin) {
                Some(t) if t.estimator && !t.skippable => {}
                Some(t) => problems.push(format!(
                    "{twin}, twin of {skipped}, must guard an estimator and run in CI: {t:?}"
                )),
                None => problems.push(format!("{twin}, twin of {skipped}, does not exist")),
            }
        }
    }
    problems
}

#[test]
fn no_estimator_guard_is_skipped_in_ci_without_a_twin_on_generated_data() {
    let tests = workspace_tests();
    // The scan sees the suite: many tests, the known skippable ones among them.
    assert!(tests.len() > 300, "only {} tests found", tests.len());
    let skippable: Vec<&String> = tests
        .iter()
        .filter(|(_, t)| t.skippable)
        .map(|(n, _)| n)
        .collect();
    eprintln!("tests CI skips: {skippable:#?}");
    assert!(
        skippable.len() >= 3,
        "the scan found too few skippable tests"
    );
    let problems = problems(&tests, TWINS);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The check can fail: on a made-up file, a skippable rendering test without a twin is reported,
/// through a helper it calls, and one with a twin that is itself skippable too.
#[test]
fn the_scan_reports_a_skipped_estimator_guard() {
    let src = r#"
        fn data() -> Option<PathBuf> { root().join("../shared/data").is_dir().then(..) }
        fn compare(desc: &Scene) { let s = pixel_statistics_with(desc, 4, 1, settings); }
        /// Calls both through helpers.
        #[test]
        fn on_shared_data() {
            let Some(d) = data() else { eprintln!("skipped {}", '}'); return; };
            compare(&load(d));
        }
        #[test]
        fn on_generated_data() { compare(&generated()); }
        #[test]
        fn loader_only() { let d = data(); }
    "#;
    let tests: BTreeMap<String, Test> = classify(src)
        .into_iter()
        .map(|(n, t)| (format!("x.rs::{n}"), t))
        .collect();
    let test = |skippable, estimator| Test {
        skippable,
        estimator,
    };
    assert_eq!(tests["x.rs::on_shared_data"], test(true, true));
    assert_eq!(tests["x.rs::on_generated_data"], test(false, true));
    assert_eq!(tests["x.rs::loader_only"], test(true, false));
    assert_eq!(problems(&tests, &[]).len(), 1);
    let twins: &[(&str, &[&str], &str)] =
        &[("x.rs::on_shared_data", &["x.rs::on_generated_data"], "")];
    assert!(problems(&tests, twins).is_empty());
    let bad: &[(&str, &[&str], &str)] = &[("x.rs::on_shared_data", &["x.rs::loader_only"], "")];
    assert_eq!(problems(&tests, bad).len(), 1);
}
