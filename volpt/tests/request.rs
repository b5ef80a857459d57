//! Render requests on the CPU: a request's seed, path settings and lookup render as a scene
//! changed to them does, without changing the scene; threads sharing one scene render at once,
//! each its own request, the images of the same requests rendered one after another.

use std::path::{Path, PathBuf};

use volpt::{
    Backend, Estimator, Film, GridLookup, Quiet, RenderRequest, RenderSettings, Roulette, Scene,
};

/// A scene with a density grid, so that lookups differ.
fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/bucky/scene.toml")
}

fn small() -> RenderSettings {
    RenderSettings {
        resolution: Some((12, 10)),
        spp: Some(4),
        seed: 3,
        ..RenderSettings::default()
    }
}

fn render(scene: &Scene, request: &RenderRequest) -> Film {
    let mut film = scene.film();
    Backend::cpu()
        .render(scene, &mut film, request, &Quiet)
        .unwrap();
    film
}

/// Requests that differ in every choice a request makes.
fn requests(scene: &Scene) -> Vec<RenderRequest> {
    let mut shallow = scene.path_settings();
    shallow.max_depth = 3;
    shallow.roulette = Roulette::Throughput;
    shallow.estimator = Estimator::PathTracing;
    vec![
        RenderRequest::samples(0..4),
        RenderRequest::samples(0..4).with_seed(9),
        RenderRequest::samples(1..3).with_seed(10),
        RenderRequest::samples(0..4).with_path(shallow),
        RenderRequest::samples(0..4).with_lookup(GridLookup::Nearest),
        RenderRequest::samples(0..4).with_lookup(GridLookup::Stochastic),
        RenderRequest::samples(0..2)
            .with_lookup(GridLookup::Nearest)
            .with_seed(4)
            .with_effects(volpt::Effects::General),
    ]
}

#[test]
fn a_request_renders_as_the_scene_changed_to_its_choices_and_leaves_the_scene_as_it_was() {
    let scene = Scene::load(example(), &small()).unwrap();
    let before = (scene.fingerprint(), scene.seed(), scene.path_settings());
    let cpu = Backend::cpu();
    for request in requests(&scene) {
        let mut changed = scene.clone();
        if let Some(seed) = request.seed {
            changed.set_seed(seed);
        }
        if let Some(path) = request.path {
            changed.set_path_settings(path);
        }
        if let Some(lookup) = request.lookup {
            changed.set_lookup(lookup).unwrap();
        }
        if let Some(effects) = request.effects {
            changed.set_effects(effects);
        }
        let samples = RenderRequest::samples(request.samples.clone());
        assert_eq!(
            render(&scene, &request).sums,
            render(&changed, &samples).sums,
            "{request:?}"
        );
        assert_eq!(
            cpu.fingerprint(&scene, &request).unwrap(),
            changed.fingerprint(),
            "{request:?}"
        );
    }
    let after = (scene.fingerprint(), scene.seed(), scene.path_settings());
    assert_eq!(after, before, "renders do not change the scene");
}

#[test]
fn concurrent_renders_of_one_shared_scene_equal_serial_ones() {
    let scene = Scene::load(example(), &small()).unwrap();
    let requests = requests(&scene);
    // Each alone, on a scene of its own.
    let serial: Vec<Film> = requests.iter().map(|r| render(&scene.clone(), r)).collect();
    // Every request at once, twice over, all sharing the one scene (and one backend).
    let backend = Backend::cpu();
    let concurrent: Vec<Film> = std::thread::scope(|threads| {
        let renders: Vec<_> = requests
            .iter()
            .chain(&requests)
            .map(|request| {
                let (scene, backend) = (&scene, &backend);
                threads.spawn(move || {
                    let mut film = scene.film();
                    backend.render(scene, &mut film, request, &Quiet).unwrap();
                    film
                })
            })
            .collect();
        renders.into_iter().map(|r| r.join().unwrap()).collect()
    });
    for (k, film) in concurrent.iter().enumerate() {
        let n = k % requests.len();
        assert_eq!(film.sums, serial[n].sums, "{:?}", requests[n]);
    }
}
