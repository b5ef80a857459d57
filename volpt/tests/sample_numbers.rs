//! Sample numbers at the top of `u32`: a range that ends at `u32::MAX` renders its samples and
//! returns (a pass end computed in `u32` once wrapped to a small number, and the pass loop never
//! finished), on one device and on several, and its film file merges with its neighbour's.

// Lists of sample ranges of one range.
#![allow(clippy::single_range_in_vec_init)]

use std::ops::Range;
use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use volpt::{merge_films, Backend, FilmFile, Quiet, RenderSettings, Scene};

fn scene() -> Scene {
    Scene::load(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml"),
        &RenderSettings {
            resolution: Some((6, 5)),
            spp: Some(4),
            seed: 5,
            ..RenderSettings::default()
        },
    )
    .unwrap()
}

/// Renders `samples` on `backend` in another thread, failing unless all of them are rendered
/// within a minute (a wrapped pass end loops for ever).
fn render_within_a_minute(backend: Backend, samples: Range<u32>) -> volpt::Film {
    let (send, receive) = mpsc::channel();
    let end = samples.end;
    std::thread::spawn(move || {
        let scene = scene();
        let mut film = scene.film();
        let rendered = backend
            .render(&scene, &mut film, samples.clone(), &Quiet)
            .map(|r| r.samples);
        let _ = send.send((rendered, film));
    });
    let (rendered, film) = receive
        .recv_timeout(Duration::from_secs(60))
        .expect("a render of samples ending at u32::MAX returns");
    assert_eq!(rendered.unwrap().end, end);
    film
}

#[test]
fn a_range_ending_at_u32_max_renders_on_one_device_and_several() {
    let top = u32::MAX - 5..u32::MAX;
    let one = render_within_a_minute(Backend::cpu(), top.clone());
    assert!(one.holds_samples());
    let several = render_within_a_minute(Backend::cpu_as_devices(2), top);
    assert_eq!(one.sums, several.sums);
}

#[test]
fn films_of_the_last_sample_numbers_merge() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let mut parts = Vec::new();
    for samples in [u32::MAX - 9..u32::MAX - 4, u32::MAX - 4..u32::MAX] {
        let film = render_within_a_minute(Backend::cpu(), samples.clone());
        let path = dir.path().join(format!("{}.vfilm", samples.start));
        FilmFile {
            fingerprint: scene.fingerprint(),
            seed: scene.seed(),
            ranges: vec![samples],
            film,
        }
        .write(&path)
        .unwrap();
        parts.push((path.display().to_string(), volpt::read_film(&path).unwrap()));
    }
    let merged = merge_films(parts, None).unwrap();
    assert_eq!(merged.film.ranges, [u32::MAX - 9..u32::MAX]);
    assert_eq!(merged.film.samples(), 9);
}
