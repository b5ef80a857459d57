//! `volpt converge` end to end: progressive renders of a white furnace (whose reference is
//! analytic), the CSV, the plots and the table; and a rendered, cached reference.

use std::path::{Path, PathBuf};

mod common;
use common::volpt;

fn stability_cube() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/stability/cube.xml")
}

fn column(csv: &str, setting: &str, name: &str) -> Vec<f64> {
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == name).unwrap();
    csv.lines()
        .skip(1)
        .filter(|l| l.starts_with(&format!("{setting},")))
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// In a white furnace every complete path-traced path returns exactly the light: unlimited depth has no error
/// at all, and max_depth 2 (paths that scatter more than once are cut) a bias that more samples
/// do not remove, which the halves tell apart from noise.
#[test]
fn furnace_errors_separate_bias_from_noise() {
    let dir = tempfile::tempdir().unwrap();
    let scene = stability_cube();
    let out = volpt(&[
        "converge",
        scene.to_str().unwrap(),
        "--resolution",
        "8x8",
        "--setting",
        "estimator=pt",
        "--setting",
        "max_depth=2,-1",
        "--max-spp",
        "64",
        "--time",
        "100",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("converge.csv")).unwrap();
    let unlimited = column(&csv, "estimator=pt max_depth=-1", "rmse");
    assert_eq!(unlimited.len(), 6, "rounds of 2, 6, ..., 126 spp: {csv}");
    assert!(unlimited.iter().all(|&e| e == 0.0), "{unlimited:?}");
    let bias = column(&csv, "estimator=pt max_depth=2", "bias");
    let variance = column(&csv, "estimator=pt max_depth=2", "variance");
    let last = bias.len() - 1;
    assert!(bias[last] > 0.1, "bias {bias:?}");
    assert!(variance[last] < variance[0] / 10.0, "variance {variance:?}");
    for plot in ["rmse.svg", "rel-mse.svg"] {
        let svg = std::fs::read_to_string(dir.path().join(plot)).unwrap();
        assert!(
            svg.contains("<polyline") && svg.contains("max_depth=2"),
            "{plot}"
        );
    }
    let table = std::fs::read_to_string(dir.path().join("table.md")).unwrap();
    assert!(
        table.contains("| estimator=pt max_depth=2 |")
            && table.contains("| estimator=pt max_depth=-1 |")
    );
}

/// A scene without an analytic value gets a rendered reference, which a second run reuses.
#[test]
fn rendered_reference_is_cached() {
    let dir = tempfile::tempdir().unwrap();
    let scene = stability_cube();
    let run = || {
        volpt(&[
            "converge",
            scene.to_str().unwrap(),
            "-Dalbedo=0.8",
            "--resolution",
            "4x4",
            "--reference-spp",
            "64",
            "--setting",
            "roulette=on,off",
            "--max-spp",
            "8",
            "-o",
            dir.path().to_str().unwrap(),
        ])
    };
    let first = run();
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let references = || {
        let mut r: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with("reference-"))
            .collect();
        r.sort();
        r
    };
    let before = references();
    assert_eq!(before.len(), 2, "two halves: {before:?}");
    let modified = std::fs::metadata(dir.path().join(&before[0]))
        .unwrap()
        .modified()
        .unwrap();
    assert!(run().status.success());
    assert_eq!(references(), before);
    let again = std::fs::metadata(dir.path().join(&before[0]))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(modified, again, "the reference was rendered again");
}

#[test]
fn unknown_setting_is_a_clear_error() {
    let scene = stability_cube();
    let out = volpt(&[
        "converge",
        scene.to_str().unwrap(),
        "--setting",
        "fast_math=on",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("unknown setting"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
}

/// The film-precision and lookup knobs run end to end (in a furnace every sample is exactly the
/// light, so an f32 film is exact too, and the homogeneous medium has no grid to look up), and
/// both plots come as PNG beside the SVG.
#[test]
fn accumulation_and_lookup_knobs_run_and_plot_as_png() {
    let dir = tempfile::tempdir().unwrap();
    let scene = stability_cube();
    let out = volpt(&[
        "converge",
        scene.to_str().unwrap(),
        "--resolution",
        "4x4",
        "--setting",
        "accumulation=f64,f32",
        "--setting",
        "lookup=trilinear,nearest",
        "--max-spp",
        "8",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("converge.csv")).unwrap();
    for setting in [
        "accumulation=f64 lookup=trilinear",
        "accumulation=f32 lookup=nearest",
    ] {
        let rmse = column(&csv, setting, "rmse");
        assert!(
            !rmse.is_empty() && rmse.iter().all(|&e| e == 0.0),
            "{setting}: {csv}"
        );
    }
    for plot in ["rmse.png", "rel-mse.png"] {
        let bytes = std::fs::read(dir.path().join(plot)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{plot}");
    }
}

/// The GPU film sums in f64 only: asking for an f32 film there is refused before anything renders.
#[test]
fn f32_accumulation_on_the_gpu_is_a_clear_error() {
    let scene = stability_cube();
    let out = volpt(&[
        "converge",
        scene.to_str().unwrap(),
        "--backend",
        "cuda",
        "--setting",
        "accumulation=f32",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("the GPU film sums in f64 only"),
        "{err}"
    );
}
