//! `volpt print compensate` as a user runs it: a process, real PNG and TOML files in, the record
//! out; bad input refused with a message naming the file before anything renders; Ctrl-C keeps
//! the iterations finished.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn volpt() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_volpt"));
    command.env("RUST_LOG", "warn");
    command
}

fn materials() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/print/materials.toml")
}

/// A `w` x `h` target: red and blue bars one to two pixels wide over the left half, a grey ramp
/// on the right.
fn write_target(path: &Path, [w, h]: [u32; 2]) {
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let rgb = if x < w / 2 {
                if (x / (1 + x % 2)) % 2 == 0 {
                    [200, 40, 40]
                } else {
                    [40, 60, 200]
                }
            } else {
                let v = (60 + 150 * y / h.max(2)) as u8;
                [v, v, v]
            };
            pixels.extend(rgb);
        }
    }
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&pixels).unwrap();
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A small compensation's flags: 8 layers, 4 of them colour, the CPU.
const SMALL: &[&str] = &["--layers", "8", "--colour-layers", "4", "--quiet"];

fn run(args: &[&str]) -> Output {
    volpt().args(args).output().unwrap()
}

#[test]
fn a_compensation_writes_its_whole_record_and_the_same_arguments_write_the_same_one() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("target.png");
    write_target(&target, [12, 10]);
    let record = |name: &str| {
        let out = dir.path().join(name);
        let output = run(&[
            &[
                "print",
                "compensate",
                s(&target),
                "--materials",
                s(&materials()),
            ],
            SMALL,
            &["--spp", "8", "--iterations", "3", "-o", s(&out)],
        ]
        .concat());
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        assert!(
            output.status.success(),
            "{stdout}{}",
            String::from_utf8_lossy(&output.stderr)
        );
        (out, stdout)
    };
    let (out, stdout) = record("a");
    assert!(stdout.starts_with("12 x 10 texels: "), "{stdout}");
    let csv = std::fs::read_to_string(out.join("iterations.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(
        rows[0],
        "iteration,mean_delta_e,p95_delta_e,noise_delta_e,spp,best"
    );
    let iterations = rows.len() - 1;
    assert!((1..=3).contains(&iterations), "{csv}");
    assert_eq!(
        rows.iter().filter(|r| r.ends_with(",1")).count(),
        1,
        "{csv}"
    );
    for k in 0..iterations {
        for file in ["prediction.png", "delta_e.png"] {
            let path = out.join(format!("iteration_{k:02}")).join(file);
            assert!(path.is_file(), "{}", path.display());
        }
    }
    for file in [
        "target.png",
        "prediction.png",
        "comparison.png",
        "delta_e.svg",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    // The target comes back as it was given.
    assert_eq!(
        decode(&out.join("target.png")),
        decode(&target),
        "target.png"
    );
    // The slice stack: 8 slices of 12 x 10 palette pixels, and its materials.toml, which is a
    // material table `--materials` takes again.
    let slices = out.join("slices");
    for z in 0..8 {
        let slice = slices.join(format!("slice_{z:04}.png"));
        assert_eq!(decode(&slice).len(), 12 * 10 * 3, "{}", slice.display());
    }
    assert!(!slices.join("slice_0008.png").exists());
    let toml = std::fs::read_to_string(slices.join("materials.toml")).unwrap();
    assert!(
        toml.contains("layers = 8") && toml.contains("name = \"cyan\""),
        "{toml}"
    );
    // The same arguments give the same record (fixed seeds): the CSV and every picture.
    let (again, _) = record("b");
    assert_eq!(
        std::fs::read_to_string(again.join("iterations.csv")).unwrap(),
        csv
    );
    for file in [
        "prediction.png",
        "slices/slice_0007.png",
        "iteration_00/delta_e.png",
    ] {
        assert_eq!(decode(&out.join(file)), decode(&again.join(file)), "{file}");
    }
    // A stack's materials.toml is a material table.
    let reuse = run(&[
        &[
            "print",
            "compensate",
            s(&target),
            "--materials",
            s(&slices.join("materials.toml")),
        ],
        SMALL,
        &[
            "--spp",
            "4",
            "--iterations",
            "1",
            "-o",
            s(&dir.path().join("c")),
        ],
    ]
    .concat());
    assert!(
        reuse.status.success(),
        "{}",
        String::from_utf8_lossy(&reuse.stderr)
    );
}

fn decode(path: &Path) -> Vec<u8> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buffer).unwrap();
    buffer.truncate(frame.buffer_size());
    buffer
}

#[test]
fn bad_input_is_refused_naming_the_file_before_anything_renders() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let target = p("target.png");
    write_target(&target, [6, 4]);
    let no_black = p("no-black.toml");
    let table = std::fs::read_to_string(materials()).unwrap();
    std::fs::write(&no_black, table.replace("\"black\"", "\"soot\"")).unwrap();
    let negative = p("negative.toml");
    std::fs::write(
        &negative,
        table.replacen("[6.0, 0.4, 0.1]", "[6.0, -0.4, 0.1]", 1),
    )
    .unwrap();
    let not_png = p("not.png");
    std::fs::write(&not_png, "not a PNG").unwrap();
    // A folder holding a record's slices already.
    let done = p("done");
    std::fs::create_dir_all(done.join("slices")).unwrap();
    std::fs::write(done.join("slices/materials.toml"), "").unwrap();
    let m = materials();
    let missing = p("missing.png");
    let cases: Vec<(Vec<&str>, Vec<String>)> = vec![
        (
            vec![s(&target), "--materials", s(&no_black)],
            vec![s(&no_black).into(), "no material named black".into()],
        ),
        (
            vec![s(&target), "--materials", s(&negative)],
            vec![s(&negative).into(), "materials[0].sigma_a".into()],
        ),
        (
            vec![s(&not_png), "--materials", s(&m)],
            vec![s(&not_png).into(), "PNG".into()],
        ),
        (
            vec![s(&missing), "--materials", s(&m)],
            vec![s(&missing).into()],
        ),
        (
            vec![s(&target), "--materials", s(&m), "-o", s(&done)],
            vec![s(&done).into(), "slices".into()],
        ),
        (
            vec![s(&target), "--materials", s(&m), "--colour-layers", "9"],
            vec!["colour".into(), "9 colour".into()],
        ),
        (
            vec![s(&target), "--materials", s(&m), "--step", "1.5"],
            vec!["step".into()],
        ),
    ];
    for (args, expected) in cases {
        let out = p("out");
        let default_out = ["-o", s(&out)];
        let given = |flag: &str| args.contains(&flag);
        let output = run(&[
            &["print", "compensate"][..],
            &args,
            &["--layers", "8", "--spp", "1", "--iterations", "1"],
            if given("--colour-layers") {
                &[]
            } else {
                &["--colour-layers", "4"]
            },
            if given("-o") { &[] } else { &default_out },
        ]
        .concat());
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} was accepted");
        for text in &expected {
            assert!(
                stderr.contains(text.as_str()),
                "{args:?}: {text:?} not in {stderr}"
            );
        }
        assert!(!stderr.contains("panicked"), "{stderr}");
        // Nothing rendered: no record begun.
        assert!(!out.join("iterations.csv").exists(), "{args:?}");
    }
}

#[test]
fn ctrl_c_ends_the_loop_and_keeps_the_iterations_finished() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("target.png");
    write_target(&target, [48, 48]);
    let out = dir.path().join("out");
    // Each prediction takes a while (48 x 48 texels, 60 layers, 64 samples, no noise control):
    // Ctrl-C after the first iteration's line, long before the 50th.
    let mut child = volpt()
        .args([
            "print",
            "compensate",
            s(&target),
            "--materials",
            s(&materials()),
        ])
        .args([
            "--layers",
            "60",
            "--colour-layers",
            "20",
            "--spp",
            "64",
            "--noise-ratio",
            "0",
        ])
        .args(["--iterations", "50", "-o", s(&out)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (lines, seen) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            let _ = lines.send(line);
        }
    });
    let start = Instant::now();
    let mut log = String::new();
    loop {
        let line = seen
            .recv_timeout(Duration::from_secs(120).saturating_sub(start.elapsed()))
            .unwrap_or_else(|_| panic!("no iteration finished: {log}"));
        log.push_str(&line);
        log.push('\n');
        if line.contains("iteration 0:") {
            break;
        }
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let output = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(130), "{stdout}{log}");
    assert!(stdout.contains("(interrupted)"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("iterations.csv")).unwrap();
    let iterations = csv.lines().count() - 1;
    assert!((1..50).contains(&iterations), "{csv}");
    assert!(out.join("slices/materials.toml").is_file());
    assert!(out.join("delta_e.svg").is_file());
}

#[test]
fn without_backend_the_gpu_is_chosen_where_usable_else_the_cpu_and_the_choice_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("target.png");
    write_target(&target, [4, 3]);
    let compensate = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let output = run(&[
            &[
                "print",
                "compensate",
                s(&target),
                "--materials",
                s(&materials()),
            ],
            &["--layers", "4", "--colour-layers", "2", "--spp", "2"][..],
            &["--iterations", "1", "-o", s(&out)],
            extra,
        ]
        .concat());
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        assert!(output.status.success(), "{stderr}");
        stderr
    };
    let chosen = compensate("default", &[]);
    let probe = volpt::GpuProbe::now();
    match probe {
        volpt::GpuProbe::Gpus(n) if n > 0 => assert!(
            chosen.contains("(no --backend: a GPU is present"),
            "{chosen}"
        ),
        _ => {
            let (_, why) = volpt::preferred_kind(&probe, &volpt::GpuOptions::default());
            assert!(
                chosen.contains(" on CPU, ") && chosen.contains(&format!("(no --backend: {why};")),
                "{chosen}"
            );
        }
    }
    let named = compensate("named", &["--backend", "cpu"]);
    assert!(
        named.contains(" on CPU, ") && named.contains("(--backend;"),
        "{named}"
    );
}
