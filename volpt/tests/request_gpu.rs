//! Render requests on a GPU (skipped without one; `VOLPT_REQUIRE_GPU=1` fails instead, as
//! bench/device/facade-request.sh sets): a scene the backend reads otherwise than loaded (its
//! bricked storage, its default lookup) renders from a copy of its description the image of the
//! scene adopted by the backend, bit for bit; threads sharing one scene and one GPU render the
//! images of the same requests rendered one after another.

use std::path::Path;

use volpt::{
    Backend, BackendOptions, Film, GpuOptions, GridLookup, Quiet, RenderRequest, RenderSettings,
    Scene,
};

fn bucky() -> Scene {
    let settings = RenderSettings {
        resolution: Some((48, 40)),
        spp: Some(8),
        seed: 5,
        ..RenderSettings::default()
    };
    Scene::load(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/bucky/scene.toml"),
        &settings,
    )
    .unwrap()
}

/// The GPU backend of `gpu`, or `None` (noted) where this machine or build has none.
fn gpu(gpu: GpuOptions) -> Option<Backend> {
    match Backend::open(&BackendOptions::cuda(gpu)) {
        Ok(backend) => Some(backend),
        Err(error) => {
            assert!(
                std::env::var_os("VOLPT_REQUIRE_GPU").is_none(),
                "VOLPT_REQUIRE_GPU is set but no GPU backend opens: {error}"
            );
            eprintln!("skipped: no GPU backend ({error})");
            None
        }
    }
}

fn render(backend: &Backend, scene: &Scene, request: &RenderRequest) -> Film {
    let mut film = scene.film();
    backend.render(scene, &mut film, request, &Quiet).unwrap();
    film
}

#[test]
fn on_a_gpu_a_scene_read_otherwise_renders_as_the_scene_adopted() {
    for options in [
        GpuOptions::default(),
        GpuOptions {
            bricked: true,
            ..GpuOptions::default()
        },
    ] {
        let Some(backend) = gpu(options) else { return };
        let scene = bucky();
        let mut adopted = bucky();
        backend.adopt(&mut adopted);
        for request in [
            RenderRequest::samples(0..8),
            RenderRequest::samples(2..6).with_seed(9),
            RenderRequest::samples(0..4).with_lookup(GridLookup::Trilinear),
        ] {
            assert_eq!(
                render(&backend, &scene, &request).sums,
                render(&backend, &adopted, &request).sums,
                "{options:?} {request:?}"
            );
            assert_eq!(
                backend.fingerprint(&scene, &request).unwrap(),
                backend.fingerprint(&adopted, &request).unwrap()
            );
        }
    }
}

#[test]
fn on_a_gpu_concurrent_renders_of_one_shared_scene_equal_serial_ones() {
    let Some(backend) = gpu(GpuOptions::default()) else {
        return;
    };
    let scene = bucky();
    let requests = [
        RenderRequest::samples(0..8),
        RenderRequest::samples(0..8).with_seed(3),
        RenderRequest::samples(0..4).with_lookup(GridLookup::Trilinear),
        RenderRequest::samples(0..4).with_lookup(GridLookup::Nearest),
    ];
    let serial: Vec<Film> = requests
        .iter()
        .map(|r| render(&backend, &scene.clone(), r))
        .collect();
    let concurrent: Vec<Film> = std::thread::scope(|threads| {
        let renders: Vec<_> = requests
            .iter()
            .map(|request| {
                let (scene, backend) = (&scene, &backend);
                threads.spawn(move || render(backend, scene, request))
            })
            .collect();
        renders.into_iter().map(|r| r.join().unwrap()).collect()
    });
    for ((film, serial), request) in concurrent.iter().zip(&serial).zip(&requests) {
        assert_eq!(film.sums, serial.sums, "{request:?}");
    }
}
