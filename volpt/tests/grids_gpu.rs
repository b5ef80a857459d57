//! Replaceable grids on a GPU (skipped without one; `VOLPT_REQUIRE_GPU=1` fails instead, as
//! bench/device/facade-grids.sh sets): a GPU keeps a scene's grids between renders, and a scene
//! whose grid was replaced renders, bit for bit, the image of the scene loaded fresh with the new
//! values, dense and bricked, default and trilinear lookups: a kept grid is never stale. Values
//! equal to the grid's own leave the image as it was.

mod grid_scene;

use grid_scene::{albedo, density, scene_file};
use volpt::{
    Backend, BackendOptions, Film, GpuOptions, GridLookup, Quiet, RenderRequest, RenderSettings,
    Scene,
};

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
fn on_a_gpu_a_replaced_grid_renders_as_the_scene_loaded_with_it() {
    for options in [
        GpuOptions::default(),
        GpuOptions {
            bricked: true,
            ..GpuOptions::default()
        },
    ] {
        let Some(backend) = gpu(options) else { return };
        for request in [
            RenderRequest::samples(0..8),
            RenderRequest::samples(0..8).with_lookup(GridLookup::Trilinear),
        ] {
            let dir = tempfile::tempdir().unwrap();
            let load = |density: &[f32], albedo: &[f32]| {
                let path = scene_file(dir.path(), density, albedo);
                Scene::load(path, &RenderSettings::default()).unwrap()
            };
            let what = format!("{options:?} {request:?}");
            let mut scene = load(&density(4.0), &albedo(1.0));
            // The first render leaves the scene's grids on the GPU.
            let first = render(&backend, &scene, &request);
            scene.set_grid("density", density(9.0)).unwrap();
            let replaced = render(&backend, &scene, &request);
            assert_ne!(
                replaced.sums, first.sums,
                "{what}: the old density was kept"
            );
            scene.set_grid("albedo", albedo(0.2)).unwrap();
            let both = render(&backend, &scene, &request);
            scene.set_grid("density", density(9.0)).unwrap();
            let again = render(&backend, &scene, &request);
            assert_eq!(
                again.sums, both.sums,
                "{what}: equal values changed the image"
            );

            let fresh = load(&density(9.0), &albedo(0.2));
            assert_eq!(
                render(&backend, &fresh, &request).sums,
                both.sums,
                "{what}: not the image of the scene loaded with the new grids"
            );
            let original = load(&density(4.0), &albedo(1.0));
            assert_eq!(render(&backend, &original, &request).sums, first.sums);
        }
    }
}
