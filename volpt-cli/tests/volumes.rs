//! `--volume-memory`, `--device-memory-budget`, `--bricked`: clean errors where they do not
//! apply; with a GPU, every placement renders the device-resident image bit for bit.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_clean_error, example_arg, skipped_without_kernels, stderr, volpt};

#[test]
fn volume_flags_on_the_cpu_are_a_clear_error() {
    for flags in [
        &["--volume-memory", "zerocopy"][..],
        &["--device-memory-budget", "2GiB"],
        &["--bricked"],
    ] {
        let mut args = vec![
            "render",
            "--spp",
            "1",
            "--resolution",
            "4x4",
            "-o",
            "/dev/null",
        ];
        let scene = example_arg();
        args.push(&scene);
        args.extend(flags);
        assert_clean_error(
            &volpt(&args),
            &["place grids for the GPU", "CPU backend", "--backend cuda"],
        );
    }
}

#[test]
fn unknown_volume_memory_and_bad_budgets_are_refused() {
    let scene = example_arg();
    let out = volpt(&["render", &scene, "--volume-memory", "pinned"]);
    assert_clean_error(&out, &["device, zerocopy, managed, auto", "\"pinned\""]);
    let out = volpt(&["render", &scene, "--device-memory-budget", "2GB"]);
    assert_clean_error(&out, &["--device-memory-budget", "2GB"]);
    let out = volpt(&["render", &scene, "--device-memory-budget", "0"]);
    assert_clean_error(&out, &["positive number of bytes"]);
}

/// A small TOML scene around a raw `f32` grid with structure (not a constant), so that every
/// corner of a lookup matters.
fn grid_scene(dir: &Path) -> PathBuf {
    let res = [21u32, 13, 9];
    let mut bytes = Vec::new();
    for z in 0..res[2] {
        for y in 0..res[1] {
            for x in 0..res[0] {
                let v = ((x * 7 + y * 13 + z * 29) % 17) as f32 / 17.0;
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("grid.raw"), bytes).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "[volume]\nfile = \"grid.raw\"\nformat = \"raw\"\nresolution = {res:?}\ntype = \"f32\"\n\
             bounds = [[-0.5, -0.3, -0.2], [0.5, 0.3, 0.2]]\nscale = 20.0\n\
             [boundary]\nbsdf = \"null\"\n\
             [camera]\norigin = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
             fov = 20.0\n[film]\nwidth = 8\nheight = 8\n[sampler]\nspp = 2\n"
        ),
    )
    .unwrap();
    scene
}

/// Without a GPU (as in CI) the flags reach the CUDA backend and fail there cleanly; with one,
/// zero-copy, managed (whole and partly prefetched) and bricked grids give the device-resident
/// image bit for bit (naive-sk: the same summation order).
#[test]
fn every_placement_renders_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = grid_scene(dir.path());
    let scene = scene.to_str().unwrap();
    let render = |name: &str, flags: &[&str]| {
        let file = dir.path().join(name);
        let mut args = vec![
            "render",
            scene,
            "--seed",
            "3",
            "--backend",
            "cuda",
            "--strategy",
            "naive-sk",
            "-o",
            file.to_str().unwrap(),
        ];
        args.extend(flags);
        (volpt(&args), file)
    };
    let (out, reference) = render("device.exr", &["--volume-memory", "device"]);
    if !out.status.success() {
        let err = stderr(&out);
        assert!(!err.contains("panicked"), "panicked: {err}");
        if skipped_without_kernels("every_placement_renders_the_same_image", &err) {
            return;
        }
        assert!(
            err.contains("no CUDA driver found"),
            "unexpected error: {err}"
        );
        return;
    }
    let placements: [&[&str]; 6] = [
        &["--volume-memory", "zerocopy"],
        &["--volume-memory", "managed"],
        &["--volume-memory", "managed", "--device-memory-budget", "1K"],
        &["--volume-memory", "auto", "--device-memory-budget", "1K"],
        &["--volume-memory", "zerocopy", "--bricked"],
        &["--volume-memory", "device", "--bricked"],
    ];
    for (i, flags) in placements.iter().enumerate() {
        let (out, file) = render(&format!("{i}.exr"), flags);
        assert!(out.status.success(), "{flags:?}: {}", stderr(&out));
        let compare = volpt(&[
            "compare",
            reference.to_str().unwrap(),
            file.to_str().unwrap(),
            "--identical",
        ]);
        assert!(compare.status.success(), "{flags:?}: {}", stderr(&compare));
    }
    let (out, _) = render(
        "over.exr",
        &["--volume-memory", "device", "--device-memory-budget", "1K"],
    );
    assert_clean_error(&out, &["does not fit the device memory budget"]);
}
