//! Replaceable grids on the CPU ([`Scene::set_grid`]): a scene whose grid's values are replaced
//! renders, bit for bit and with the same fingerprint, the image of the scene loaded from files
//! holding the new values, however often and whichever grid is replaced; values equal to the
//! grid's own change nothing; values of the wrong size, out of range, for a grid the scene lacks
//! are refused with a typed error that leaves the scene as it was.

mod grid_scene;

use std::path::Path;

use grid_scene::{albedo, density, scene_file};
use volpt::{Backend, Error, Film, GridLookup, Quiet, RenderRequest, RenderSettings, Scene};

fn load(path: &Path) -> Scene {
    Scene::load(path, &RenderSettings::default()).unwrap()
}

fn render(scene: &Scene) -> Film {
    render_as(scene, &RenderRequest::samples(0..4))
}

fn render_as(scene: &Scene, request: &RenderRequest) -> Film {
    let mut film = scene.film();
    Backend::cpu()
        .render(scene, &mut film, request, &Quiet)
        .unwrap();
    film
}

/// Asserts that `scene` renders as (and has the fingerprint of) the scene loaded from files of
/// `density` and `albedo`.
fn renders_as_loaded(scene: &Scene, density: &[f32], albedo: &[f32], what: &str) {
    let dir = tempfile::tempdir().unwrap();
    let fresh = load(&scene_file(dir.path(), density, albedo));
    assert_eq!(render(scene).sums, render(&fresh).sums, "{what}");
    assert_eq!(scene.fingerprint(), fresh.fingerprint(), "{what}");
    // Read otherwise than loaded: from the copy of the description a request's lookup makes.
    let nearest = RenderRequest::samples(0..2).with_lookup(GridLookup::Nearest);
    assert_eq!(
        render_as(scene, &nearest).sums,
        render_as(&fresh, &nearest).sums,
        "{what}, nearest"
    );
}

#[test]
fn a_replaced_grid_renders_as_the_scene_loaded_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = load(&scene_file(dir.path(), &density(4.0), &albedo(1.0)));
    assert_eq!(scene.grid_names(), ["density", "albedo"]);
    assert_eq!(scene.grid("density").unwrap().data, density(4.0));
    let first = render(&scene);
    let fingerprint = scene.fingerprint();
    // A copy of the description read otherwise, kept by the scene until its data changes.
    render_as(
        &scene,
        &RenderRequest::samples(0..2).with_lookup(GridLookup::Nearest),
    );

    // Each grid, one after the other, rendered in between: nothing of a render before is
    // read again (the factory's majorant grid of the old density, the old values' hash).
    scene.set_grid("density", density(9.0)).unwrap();
    renders_as_loaded(&scene, &density(9.0), &albedo(1.0), "density replaced");
    assert_ne!(
        render(&scene).sums,
        first.sums,
        "new values render otherwise"
    );
    assert_ne!(scene.fingerprint(), fingerprint);

    scene.set_grid("albedo", albedo(0.2)).unwrap();
    renders_as_loaded(&scene, &density(9.0), &albedo(0.2), "albedo replaced");

    // Back to the values it was loaded with: the image and fingerprint it was loaded with.
    scene = scene.with_grid("density", density(4.0)).unwrap();
    scene.set_grid("albedo", albedo(1.0)).unwrap();
    assert_eq!(render(&scene).sums, first.sums);
    assert_eq!(scene.fingerprint(), fingerprint);
}

#[test]
fn a_clone_keeps_its_grids_when_the_original_replaces_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = load(&scene_file(dir.path(), &density(4.0), &albedo(1.0)));
    let before = render(&scene);
    let clone = scene.clone();
    scene.set_grid("density", density(2.0)).unwrap();
    assert_eq!(render(&clone).sums, before.sums);
    assert_ne!(render(&scene).sums, before.sums);
}

#[test]
fn the_same_values_change_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = load(&scene_file(dir.path(), &density(4.0), &albedo(1.0)));
    let before = (render(&scene).sums, scene.fingerprint());
    let address = scene.grid("density").unwrap().data.as_ptr();
    scene.set_grid("density", density(4.0)).unwrap();
    scene.set_grid("albedo", albedo(1.0)).unwrap();
    assert_eq!((render(&scene).sums, scene.fingerprint()), before);
    assert_eq!(
        scene.grid("density").unwrap().data.as_ptr(),
        address,
        "equal values are not taken: the grid the renderers keep stays"
    );
}

#[test]
fn values_a_grid_cannot_take_are_refused_and_leave_the_scene_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = load(&scene_file(dir.path(), &density(4.0), &albedo(1.0)));
    let before = (render(&scene).sums, scene.fingerprint());
    let count = density(1.0).len();
    let mut negative = density(4.0);
    negative[7] = -1.0;
    let mut nan = albedo(1.0);
    nan[2] = f32::NAN;
    let mut bright = albedo(1.0);
    bright[5] = 1.5;
    for (grid, values, expected, found) in [
        (
            "density",
            vec![1.0; count + 1],
            "120 values (6 x 5 x 4 samples x 1 channels)",
            "121 values".to_owned(),
        ),
        (
            "albedo",
            vec![0.5; count],
            "360 values (6 x 5 x 4 samples x 3 channels)",
            "120 values".to_owned(),
        ),
        ("density", negative, "values in [0", "-1".to_owned()),
        ("albedo", nan, "values in [0", "NaN".to_owned()),
        ("albedo", bright, "values in [0", "1.5".to_owned()),
        (
            "temperature",
            density(1.0),
            "one of the medium's grids: density, albedo",
            "no such grid".to_owned(),
        ),
    ] {
        let error = scene.set_grid(grid, values).unwrap_err();
        match &error {
            Error::Grid {
                grid: g,
                expected: e,
                found: f,
            } => {
                assert_eq!(g, grid);
                assert!(e.starts_with(expected), "{error}");
                assert_eq!(f, &found, "{error}");
            }
            _ => panic!("{grid}: not a grid error: {error:?}"),
        }
        assert_eq!(
            (render(&scene).sums, scene.fingerprint()),
            before,
            "{error}"
        );
    }
}

#[test]
fn a_medium_without_grids_has_none_to_replace() {
    let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
    let mut scene = Scene::load(scene_path, &RenderSettings::default()).unwrap();
    assert!(scene.grid_names().is_empty());
    let error = scene.set_grid("density", vec![1.0]).unwrap_err();
    assert!(
        matches!(&error, Error::Grid { expected, .. } if expected.contains("has none")),
        "{error}"
    );
}
