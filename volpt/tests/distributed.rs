//! Renders split across processes and devices, on the CPU: film files of sample ranges merged
//! equal the whole render (within f64 rounding) and repeat bit for bit; films that cannot add up
//! are refused by name; and the multi-device scheduler (`--gpus`, here with the CPU as devices)
//! equals one device, repeats bit for bit, and cancels, checkpoints and resumes as one device does.

// Lists of sample ranges, some of one range.
#![allow(clippy::single_range_in_vec_init)]

mod common;

use common::CancelAfter;

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Duration;

use volpt::{
    merge_films, read_film, Backend, Checkpointing, Error, Film, FilmFile, MergeError, Quiet,
    RenderSettings, Scene,
};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml")
}

fn scene(spp: u32) -> Scene {
    Scene::load(
        example(),
        &RenderSettings {
            resolution: Some((12, 10)),
            spp: Some(spp),
            seed: 5,
            ..RenderSettings::default()
        },
    )
    .unwrap()
}

fn render(backend: &Backend, scene: &Scene, samples: Range<u32>) -> Film {
    let mut film = scene.film();
    let rendered = backend
        .render(scene, &mut film, samples.clone(), &Quiet)
        .unwrap();
    assert_eq!(rendered.samples, samples);
    film
}

/// Samples `samples` rendered and written to `dir/NAME.vfilm`, as `volpt render --film` does.
fn part(dir: &Path, scene: &Scene, samples: Range<u32>) -> PathBuf {
    let path = dir.join(format!("{}-{}.vfilm", samples.start, samples.end));
    FilmFile {
        fingerprint: scene.fingerprint(),
        seed: scene.seed(),
        ranges: vec![samples.clone()],
        film: render(&Backend::cpu(), scene, samples),
    }
    .write(&path)
    .unwrap();
    path
}

fn named(paths: &[&PathBuf]) -> Vec<(String, FilmFile)> {
    paths
        .iter()
        .map(|p| (p.display().to_string(), read_film(p).unwrap()))
        .collect()
}

/// Within f64 rounding: partial sums added instead of every sample one by one.
fn assert_close(a: &Film, b: &Film) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut differing = 0;
    for (x, y) in a.sums.iter().zip(&b.sums) {
        for c in 0..3 {
            assert!(
                (x[c] - y[c]).abs() <= 1e-12 * y[c].abs().max(1.0),
                "{x:?} against {y:?}"
            );
            differing += usize::from(x[c] != y[c]);
        }
    }
    // Not a proof of anything by itself, but it shows the tolerance is used.
    eprintln!(
        "{differing} of {} sums differ in their last bits",
        3 * a.sums.len()
    );
}

#[test]
fn partial_films_from_files_merge_to_the_whole_render_and_to_the_same_bits_in_any_order() {
    let scene = scene(8);
    let dir = tempfile::tempdir().unwrap();
    let whole = render(&Backend::cpu(), &scene, 0..8);
    let (a, b, c) = (
        part(dir.path(), &scene, 0..3),
        part(dir.path(), &scene, 3..4),
        part(dir.path(), &scene, 4..8),
    );
    let merged = merge_films(named(&[&c, &a, &b]), Some(8)).unwrap();
    assert!(merged.missing.is_empty());
    let film = merged.complete().unwrap();
    assert_eq!(film.ranges, vec![0..8]);
    assert_eq!(film.samples(), 8);
    assert_eq!((film.fingerprint, film.seed), (scene.fingerprint(), 5));
    assert_close(&film.film, &whole);
    // The same partition, named in every order: the same bits.
    for order in [[&a, &b, &c], [&b, &c, &a], [&c, &b, &a]] {
        let again = merge_films(named(&order), Some(8)).unwrap();
        assert_eq!(again.film.film.sums, film.film.sums, "{order:?}");
    }
    // The image averages the merged samples as the whole render's does.
    assert_eq!(film.image().pixels.len(), whole.image(8).pixels.len());
}

#[test]
fn a_merge_with_gaps_lists_them_and_its_film_completes_later_to_the_whole_render() {
    let scene = scene(8);
    let dir = tempfile::tempdir().unwrap();
    let whole = render(&Backend::cpu(), &scene, 0..8);
    let (a, c) = (
        part(dir.path(), &scene, 0..2),
        part(dir.path(), &scene, 5..7),
    );
    let merged = merge_films(named(&[&a, &c]), Some(8)).unwrap();
    assert_eq!(merged.missing, vec![2..5, 7..8]);
    assert_eq!(merged.film.ranges, vec![0..2, 5..7]);
    let err = merged.clone().complete().unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("samples 2..5, 7..8 are in no film") && text.contains("0..2, 5..7"),
        "{text}"
    );
    // Without --spp only the holes between films count: 7..8 is not known to be missing.
    let unbounded = merge_films(named(&[&a, &c]), None).unwrap();
    assert_eq!(unbounded.missing, vec![2..5]);

    // The film with gaps, written and read back (two ranges), plus the missing parts.
    let gappy = dir.path().join("gappy.vfilm");
    merged.film.write(&gappy).unwrap();
    assert_eq!(read_film(&gappy).unwrap().ranges, vec![0..2, 5..7]);
    let (b, d) = (
        part(dir.path(), &scene, 2..5),
        part(dir.path(), &scene, 7..8),
    );
    let full = merge_films(named(&[&d, &gappy, &b]), Some(8))
        .unwrap()
        .complete()
        .unwrap();
    assert_eq!(full.ranges, vec![0..8]);
    assert_close(&full.film, &whole);
}

#[test]
fn films_that_do_not_add_up_to_one_render_are_refused_naming_both_files() {
    let scene = scene(6);
    let dir = tempfile::tempdir().unwrap();
    let a = part(dir.path(), &scene, 0..3);
    let overlapping = part(dir.path(), &scene, 2..6);
    match merge_films(named(&[&overlapping, &a]), None) {
        Err(MergeError::Overlap {
            first,
            second,
            overlap,
        }) => {
            assert_eq!(overlap, 2..3);
            assert!(first.ends_with("0-3.vfilm") && second.ends_with("2-6.vfilm"));
        }
        other => panic!("expected an overlap, got {other:?}"),
    }

    let b = part(dir.path(), &scene, 3..6);
    let mismatch = |edit: &dyn Fn(&mut FilmFile), field: &str| {
        let mut films = named(&[&a, &b]);
        edit(&mut films[1].1);
        match merge_films(films, None) {
            Err(e @ MergeError::Mismatch { .. }) => {
                let text = e.to_string();
                assert!(text.contains(field), "{text}");
                assert!(
                    text.contains("3-6.vfilm") && text.contains("0-3.vfilm"),
                    "{text}"
                );
            }
            other => panic!("expected a mismatch of {field}, got {other:?}"),
        }
    };
    mismatch(&|f| f.fingerprint ^= 1, "scene fingerprint");
    mismatch(&|f| f.seed += 1, "seed is 6");
    mismatch(
        &|f| {
            f.film = Film::new(10, 12);
        },
        "film size is 10x12",
    );
    // Another scene setting: another fingerprint, from the real scene loader.
    let other = Scene::load(
        example(),
        &RenderSettings {
            resolution: Some((12, 10)),
            max_depth: Some(Some(3)),
            seed: 5,
            ..RenderSettings::default()
        },
    )
    .unwrap();
    let foreign = dir.path().join("foreign.vfilm");
    FilmFile {
        fingerprint: other.fingerprint(),
        seed: 5,
        ranges: vec![3..6],
        film: render(&Backend::cpu(), &other, 3..6),
    }
    .write(&foreign)
    .unwrap();
    assert!(matches!(
        merge_films(named(&[&a, &foreign]), None),
        Err(MergeError::Mismatch {
            field: "scene fingerprint (the scene and every setting that changes its image)",
            ..
        })
    ));

    assert!(matches!(
        merge_films(named(&[&a, &b]), Some(5)),
        Err(MergeError::Beyond { spp: 5, .. })
    ));
    assert_eq!(merge_films(vec![], None), Err(MergeError::Empty));
}

#[test]
fn a_damaged_film_file_is_refused_through_the_facade_naming_the_file_and_field() {
    let scene = scene(2);
    let dir = tempfile::tempdir().unwrap();
    let path = part(dir.path(), &scene, 0..2);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes.truncate(bytes.len() - 3);
    std::fs::write(&path, &bytes).unwrap();
    match read_film(&path) {
        Err(e @ Error::FilmFile(_)) => {
            let text = e.to_string();
            assert!(
                text.contains("0-2.vfilm") && text.contains("length"),
                "{text}"
            );
        }
        other => panic!("expected a film-file error, got {other:?}"),
    }
}

#[test]
fn several_devices_equal_one_and_repeat_bit_for_bit() {
    let scene = scene(13);
    let whole = render(&Backend::cpu(), &scene, 0..13);
    for devices in [2, 3] {
        let backend = Backend::cpu_as_devices(devices);
        assert_eq!(backend.devices(), devices);
        let first = render(&backend, &scene, 0..13);
        assert_close(&first, &whole);
        let second = render(&backend, &scene, 0..13);
        assert_eq!(first.sums, second.sums, "{devices} devices, run twice");
    }
    // A range that continues a film (a resumed render): the film's samples come first.
    let backend = Backend::cpu_as_devices(2);
    let mut film = render(&Backend::cpu(), &scene, 0..4);
    backend.render(&scene, &mut film, 4..13, &Quiet).unwrap();
    assert_close(&film, &whole);
}

#[test]
fn several_devices_cancelled_hold_a_prefix_of_samples_and_resume_to_the_whole_render() {
    let scene = scene(12);
    let whole = render(&Backend::cpu(), &scene, 0..12);
    let backend = Backend::cpu_as_devices(2);
    let mut film = scene.film();
    let stop = CancelAfter::new(3);
    let first = backend.render(&scene, &mut film, 0..12, &stop).unwrap();
    assert!(first.cancelled(&(0..12)), "{:?}", first.samples);
    assert_eq!(first.samples.start, 0);
    // The film holds exactly its samples: it equals a render of that prefix.
    let prefix = render(&Backend::cpu(), &scene, first.samples.clone());
    assert_close(&film, &prefix);
    let rest = backend
        .render(&scene, &mut film, first.samples.end..12, &Quiet)
        .unwrap();
    assert_eq!(rest.samples, first.samples.end..12);
    assert_close(&film, &whole);
}

#[test]
fn several_devices_write_checkpoints_that_resume_on_one_device() {
    let scene = scene(10);
    let whole = render(&Backend::cpu(), &scene, 0..10);
    let dir = tempfile::tempdir().unwrap();
    let save = dir.path().join("render.ckpt");
    let checkpointing = Checkpointing {
        save: save.clone(),
        resume: None,
        interval: Duration::from_millis(1),
    };
    let stop = CancelAfter::new(2);
    let (_, rendered) =
        volpt::render_checkpointed(&Backend::cpu_as_devices(2), &scene, &checkpointing, &stop)
            .unwrap();
    let held = rendered.samples.end;
    assert!(held < 10, "cancelled early: {:?}", rendered.samples);
    // The checkpoint is a film of samples 0..held, readable by merge as well.
    assert_eq!(read_film(&save).unwrap().ranges, vec![0..held]);
    let resume = Checkpointing {
        resume: Some(save.clone()),
        ..checkpointing
    };
    let (film, rendered) =
        volpt::render_checkpointed(&Backend::cpu(), &scene, &resume, &Quiet).unwrap();
    assert_eq!(rendered.samples, held..10);
    assert_close(&film, &whole);
}

#[test]
fn gpus_are_refused_on_the_cpu_and_named_as_given() {
    let gpus: volpt::Gpus = "0,2".parse().unwrap();
    assert_eq!(gpus, volpt::Gpus::List(0b101));
    assert_eq!(gpus.to_string(), "0,2");
    assert_eq!("all".parse::<volpt::Gpus>().unwrap(), volpt::Gpus::All);
    for bad in ["", "0,0", "x", "64", "1,,2"] {
        assert!(bad.parse::<volpt::Gpus>().is_err(), "{bad:?}");
    }
    assert_eq!(gpus.ordinals(3).unwrap(), vec![0, 2]);
    let err = gpus.ordinals(2).unwrap_err().to_string();
    assert!(
        err.contains("found GPU 2") && err.contains("sees 2 GPUs"),
        "{err}"
    );
    let options = volpt::BackendOptions {
        kind: volpt::BackendKind::Cpu,
        gpu: volpt::GpuOptions {
            gpus: volpt::Gpus::All,
            ..Default::default()
        },
    };
    let err = Backend::open(&options).err().unwrap();
    assert!(
        matches!(
            &err,
            volpt::Error::Conflict { key: "gpus", value, with: "backend", with_value, .. }
                if value == "all" && with_value == "cpu"
        ),
        "{err}"
    );
    // Each front end spells the keys its own way.
    let flags = err.spelled(&|key, value| format!("--{key} {}", value.unwrap_or_default()));
    assert!(
        flags.starts_with("--gpus all with --backend cpu: "),
        "{flags}"
    );
}
