//! The `volpt` binary end to end: a real scene file in, real EXR and PNG out, and clear errors
//! (never a panic) for bad input.

use std::path::{Path, PathBuf};

mod common;
use common::{assert_clean_error, assert_success, example, skipped_without_kernels, stderr, volpt};

use volpt::scene_files::vol::{write_vol, VolGrid};
use volpt::scene_files::Bounds;

#[test]
fn renders_the_example_to_exr_and_png() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("cube.exr");
    let out = volpt(&[
        "render",
        example().to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--spp",
        "2",
        "-D",
        "resolution=24",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("24x24 at 2 spp"), "{stdout}");
    assert!(stdout.contains("M paths/s"), "{stdout}");
    let pixels = read_rgb(&exr, 24);
    assert_eq!(pixels.len(), 24 * 24);
    // The corner sees the white environment; the centre sees the amber cube, darker in blue.
    assert_eq!(pixels[0], [1.0, 1.0, 1.0]);
    let centre = pixels[12 * 24 + 12];
    assert!(centre[2] < centre[0], "centre {centre:?}");
    let png = std::fs::read(dir.path().join("cube.png")).expect("PNG preview");
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn info_names_the_variant() {
    let out = volpt(&["info", example().to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("homogeneous/rough_dielectric/henyey_greenstein/constant"),
        "{stdout}"
    );
}

#[test]
fn missing_scene_file_is_a_clear_error() {
    let out = volpt(&["render", "no/such/scene.xml"]);
    assert_clean_error(&out, &["no/such/scene.xml"]);
}

#[test]
fn malformed_xml_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("broken.xml");
    std::fs::write(
        &scene,
        "<scene version=\"0.6.0\">\n  <sensor type=\"perspective\">\n</scene>\n",
    )
    .unwrap();
    let out = volpt(&["info", scene.to_str().unwrap()]);
    assert_clean_error(&out, &["broken.xml", ":3"]);
}

fn grid_scene(dir: &Path, vol_name: &str) -> PathBuf {
    grid_scene_with(dir, vol_name, "", "")
}

/// `grid_scene` with more of the grid's and the medium's parameters (XML, each on its own line).
fn grid_scene_with(dir: &Path, vol_name: &str, volume: &str, medium: &str) -> PathBuf {
    let scene = dir.join("grid.xml");
    let xml = format!(
        r#"<scene version="0.6.0">
  <sensor type="perspective">
    <float name="fov" value="30"/>
    <transform name="toWorld"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
  </sensor>
  <emitter type="constant"/>
  <medium type="heterogeneous" id="m">
    <volume name="density" type="gridvolume"><string name="filename" value="{vol_name}"/>{volume}</volume>
    <volume name="albedo" type="constvolume"><spectrum name="value" value="0.9"/></volume>{medium}
  </medium>
  <shape type="cube"><bsdf type="null"/><ref name="interior" id="m"/></shape>
</scene>"#
    );
    std::fs::write(&scene, xml).unwrap();
    scene
}

fn grid(values: Vec<f32>) -> VolGrid {
    VolGrid {
        resolution: [2, 2, 2],
        channels: 1,
        bbox: Bounds {
            min: [-1.0; 3],
            max: [1.0; 3],
        },
        data: values,
    }
}

#[test]
fn truncated_vol_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let vol = dir.path().join("d.vol");
    write_vol(&vol, &grid(vec![1.0; 8])).unwrap();
    let bytes = std::fs::read(&vol).unwrap();
    std::fs::write(&vol, &bytes[..bytes.len() - 5]).unwrap();
    let scene = grid_scene(dir.path(), "d.vol");
    let out = volpt(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        dir.path().join("o.exr").to_str().unwrap(),
    ]);
    assert_clean_error(&out, &["d.vol"]);
}

#[test]
fn nan_and_negative_densities_are_clear_errors() {
    for (i, bad) in [f32::NAN, -1.0].into_iter().enumerate() {
        let dir = tempfile::tempdir().unwrap();
        let mut values = vec![1.0; 8];
        values[5] = bad;
        let name = format!("bad{i}.vol");
        write_vol(&dir.path().join(&name), &grid(values)).unwrap();
        let scene = grid_scene(dir.path(), &name);
        let out = volpt(&["info", scene.to_str().unwrap()]);
        assert_clean_error(&out, &[name.as_str()]);
    }
}

/// Mitsuba's settings that volpt has no choice of (the medium's tracking method, the grid's
/// filter and wrap mode) load with a warning that names the place, the value and what volpt
/// does instead; the values volpt uses load silently, in any case and with spaces around them.
#[test]
fn settings_volpt_has_no_choice_of_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    write_vol(&dir.path().join("d.vol"), &grid(vec![1.0; 8])).unwrap();
    let setting =
        |name: &str, value: &str| format!("\n      <string name=\"{name}\" value=\"{value}\"/>");
    // `volpt info`'s warnings for a grid's filter and wrap mode and a medium's method.
    let warnings = |filter: &str, wrap: &str, method: &str| {
        let grid = setting("filter_type", filter) + &setting("wrap_mode", wrap);
        let scene = grid_scene_with(dir.path(), "d.vol", &grid, &setting("method", method));
        let out = volpt(&["info", scene.to_str().unwrap()]);
        assert_success(&out);
        stderr(&out)
    };
    let err = warnings("cubic", "repeat", "ratio");
    for warning in [
        "grid.xml:10: <string name=\"filter_type\"> value \"cubic\": volpt uses trilinear (or nearest)",
        "grid.xml:11: <string name=\"wrap_mode\"> value \"repeat\": volpt uses clamp",
        "grid.xml:13: <string name=\"method\"> value \"ratio\": volpt uses delta (Woodcock) \
         tracking, which is unbiased",
    ] {
        assert!(err.contains(warning), "no warning {warning:?}: {err}");
    }
    let err = warnings(" Trilinear", "CLAMP", "woodcock ");
    assert!(!err.contains("volpt uses"), "{err}");
    // Nearest is read as such (Mitsuba 3's other filter): no warning.
    let err = warnings("nearest", "clamp", "woodcock");
    assert!(!err.contains("volpt uses"), "{err}");
}

/// Half-precision texels end at 65504: `--lookup texture-f16` refuses a grid beyond that, naming
/// the largest value and the alternative; `--lookup texture` (f32 texels) takes it.
#[test]
fn half_texels_refuse_a_grid_beyond_their_range() {
    let dir = tempfile::tempdir().unwrap();
    let mut values = vec![1.0; 8];
    values[3] = 1e5;
    write_vol(&dir.path().join("big.vol"), &grid(values)).unwrap();
    let scene = grid_scene(dir.path(), "big.vol");
    let scene = scene.to_str().unwrap();
    let out = volpt(&["info", scene, "--lookup", "texture-f16"]);
    assert_clean_error(
        &out,
        &[
            "texture-f16",
            "100000",
            "65504",
            "--lookup: expected",
            "texture (f32 texels)",
        ],
    );
    let out = volpt(&["info", scene, "--lookup", "texture"]);
    assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("grid_density__grid_albedo__texture_trilinear/"),
        "{stdout}"
    );
}

#[test]
fn the_majorant_grid_bound_is_the_librarys_in_the_flags_spelling() {
    let e = example();
    let e = e.to_str().unwrap();
    for cells in ["0", "1025"] {
        let out = volpt(&["info", e, "--majorant-resolution", cells]);
        let words = format!("--majorant-resolution: expected 1 to 1024 cells, found {cells}");
        assert_clean_error(&out, &[&words]);
        let setting = format!("majorant_resolution={cells}");
        let out = volpt(&["converge", e, "--setting", &setting]);
        let words = format!("majorant_resolution: expected 1 to 1024 cells, found {cells}");
        assert_clean_error(&out, &[&words]);
    }
}

#[test]
fn the_gpu_knobs_bounds_are_the_librarys_on_every_backend() {
    let e = example();
    let e = e.to_str().unwrap();
    for (flag, value, words) in [
        (
            "--max-registers",
            "8",
            "--max-registers: expected 16 to 255, found 8",
        ),
        (
            "--max-registers",
            "256",
            "--max-registers: expected 16 to 255, found 256",
        ),
        ("--refill-at", "0", "--refill-at: expected 1 to 32, found 0"),
        (
            "--refill-at",
            "33",
            "--refill-at: expected 1 to 32, found 33",
        ),
    ] {
        for backend in ["cpu", "cuda"] {
            let out = volpt(&["render", e, "--backend", backend, flag, value]);
            assert_clean_error(&out, &[words]);
        }
    }
}

#[test]
fn zero_threads_and_zero_trials_are_refused() {
    let e = example();
    let out = volpt(&["render", e.to_str().unwrap(), "--threads", "0"]);
    assert_clean_error(&out, &["--threads"]);
    let out = volpt(&["bench", e.to_str().unwrap(), "--trials", "0"]);
    assert_clean_error(&out, &["--trials"]);
}

fn read_rgb(path: &Path, width: usize) -> Vec<[f32; 3]> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| vec![[0.0f32; 3]; res.width() * res.height()],
        move |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * width + pos.x()] = [r, g, b];
        },
    )
    .expect("a readable EXR");
    image.layer_data.channel_data.pixels
}

/// Without a GPU (as in CI) `--backend cuda` is a clear error naming what is missing and never a
/// panic; with one, its naive-sk image is bit-identical to the CPU's (same seed, same paths).
#[test]
fn cuda_backend_without_a_gpu_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = example();
    let render = |name: &str, backend: &[&str]| {
        let file = dir.path().join(name);
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--spp",
            "2",
            "--resolution",
            "8x8",
            "-o",
            file.to_str().unwrap(),
        ];
        args.extend(backend);
        (volpt(&args), file)
    };
    let (out, gpu_file) = render(
        "gpu.exr",
        &[
            "--backend",
            "cuda",
            "--math",
            "exact",
            "--strategy",
            "naive-sk",
        ],
    );
    if out.status.success() {
        let (cpu, cpu_file) = render("cpu.exr", &[]);
        assert!(cpu.status.success(), "{}", stderr(&cpu));
        let (gpu, cpu) = (read_rgb(&gpu_file, 8), read_rgb(&cpu_file, 8));
        assert_eq!(gpu.len(), 64);
        assert_eq!(gpu, cpu, "the GPU's naive-sk image differs from the CPU's");
        return;
    }
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "panicked: {err}");
    if skipped_without_kernels("cuda_backend_without_a_gpu_is_a_clear_error", &err) {
        return;
    }
    assert!(
        err.contains("no CUDA driver found") || err.contains("CUDA driver call failed"),
        "unclear error: {err}"
    );
}

#[test]
fn strategy_on_the_cpu_is_a_clear_error() {
    let scene = example();
    let out = volpt(&["render", scene.to_str().unwrap(), "--strategy", "naive-sk"]);
    assert_clean_error(
        &out,
        &["--strategy naive-sk", "CPU backend has no strategies"],
    );
}

#[test]
fn refill_threshold_on_the_cpu_is_a_clear_error() {
    let scene = example();
    let out = volpt(&["render", scene.to_str().unwrap(), "--refill-at", "8"]);
    assert_clean_error(&out, &["--refill-at 8", "CPU backend has no strategies"]);
}

#[test]
fn tiles_on_the_cpu_and_malformed_tiles_are_clear_errors() {
    let scene = example();
    let out = volpt(&["render", scene.to_str().unwrap(), "--tiles", "4,4"]);
    assert_clean_error(&out, &["--tiles 4,4", "CPU backend has no launches"]);
    for bad in ["4", "4,x"] {
        let out = volpt(&["render", scene.to_str().unwrap(), "--tiles", bad]);
        assert_clean_error(&out, &["--tiles", "COLUMNS,ROWS"]);
    }
    // The bound is the library's (volpt::TILES), in its words, whichever the backend.
    for (bad, backend) in [("0,3", "cpu"), ("5000,1", "cuda")] {
        let out = volpt(&[
            "render",
            scene.to_str().unwrap(),
            "--backend",
            backend,
            "--tiles",
            bad,
        ]);
        assert_clean_error(
            &out,
            &[&format!(
                "--tiles: expected columns and rows of 1 to 4096 each, found {bad}"
            )],
        );
    }
}

#[test]
fn gpu_math_on_the_cpu_is_a_clear_error() {
    let scene = example();
    let out = volpt(&["render", scene.to_str().unwrap(), "--math", "fast"]);
    assert_clean_error(
        &out,
        &["--math fast", "CPU backend always computes exactly"],
    );
}

/// `volpt scene export` writes the scene as volpt loads it in Mitsuba 3 spelling: the example (a
/// Mitsuba 0.6 file with parameters) exported and rendered again gives the very same image.
#[test]
fn exported_scene_renders_bit_identically() {
    let dir = tempfile::tempdir().unwrap();
    let out = volpt(&[
        "scene",
        "export",
        example().to_str().unwrap(),
        "-D",
        "resolution=20",
        "--spp",
        "2",
        "-o",
        dir.path().to_str().unwrap(),
        "--name",
        "exported",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let exported = dir.path().join("exported.xml");
    let text = std::fs::read_to_string(&exported).unwrap();
    assert!(text.contains("<scene version=\"3.0.0\">"), "{text}");
    assert!(text.contains("name=\"sample_count\" value=\"2\""), "{text}");
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    for (scene, image, params) in [
        (example(), &a, &["-D", "resolution=20", "--spp", "2"][..]),
        (exported, &b, &[][..]),
    ] {
        let mut args = vec!["render", scene.to_str().unwrap(), "--seed", "5"];
        args.extend_from_slice(params);
        args.extend_from_slice(&["-o", image.to_str().unwrap()]);
        let out = volpt(&args);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let out = volpt(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--identical",
    ]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        stderr(&out)
    );
}

#[test]
fn export_into_a_file_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let out = volpt(&[
        "scene",
        "export",
        example().to_str().unwrap(),
        "-o",
        file.to_str().unwrap(),
    ]);
    assert_clean_error(&out, &["not-a-dir"]);
}
