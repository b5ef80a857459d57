//! The library facade on the CPU: renders in chunks, cancelled and resumed, and split into ranges
//! and merged equal one whole render; parameters equal a reload of the changed scene file; the
//! fingerprint sees every part of a render and nothing else.

mod common;

use common::CancelAfter;

use std::path::{Path, PathBuf};

use volpt::{
    merge, Backend, Error, Film, GridLookup, ParamValue, Part, Quiet, RenderRequest,
    RenderSettings, Scene,
};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml")
}

fn small() -> RenderSettings {
    RenderSettings {
        resolution: Some((12, 10)),
        spp: Some(6),
        seed: 3,
        ..RenderSettings::default()
    }
}

fn render(scene: &Scene, samples: std::ops::Range<u32>) -> Film {
    let mut film = scene.film();
    Backend::cpu()
        .render(scene, &mut film, samples, &Quiet)
        .unwrap();
    film
}

#[test]
fn a_cancelled_render_resumed_is_the_whole_render_bit_for_bit() {
    let scene = Scene::load(example(), &small()).unwrap();
    let whole = render(&scene, 0..6);
    let mut film = scene.film();
    let stop = CancelAfter::new(2);
    let backend = Backend::cpu();
    let first = backend.render(&scene, &mut film, 0..6, &stop).unwrap();
    assert!(first.cancelled(&(0..6)), "{:?}", first.samples);
    assert_eq!(
        first.samples,
        0..2,
        "chunks of one sample, cancelled at the second look"
    );
    let rest = backend
        .render(&scene, &mut film, first.samples.end..6, &Quiet)
        .unwrap();
    assert_eq!(rest.samples, 2..6);
    assert_eq!(film.sums, whole.sums);
}

#[test]
fn ranges_merged_equal_the_whole_render_and_the_same_partition_gives_the_same_bits() {
    let scene = Scene::load(example(), &small()).unwrap();
    let whole = render(&scene, 0..6);
    let part = |r: std::ops::Range<u32>| Part {
        fingerprint: scene.fingerprint(),
        seed: scene.seed(),
        film: render(&scene, r.clone()),
        samples: r,
    };
    let parts = vec![part(4..6), part(0..1), part(1..4)];
    let merged = merge(parts.clone()).unwrap();
    assert_eq!(merged.samples, 0..6);
    for (m, w) in merged.film.sums.iter().zip(&whole.sums) {
        for c in 0..3 {
            // Three partial sums added instead of six samples one by one: f64 rounding only.
            assert!(
                (m[c] - w[c]).abs() <= 1e-12 * w[c].abs().max(1.0),
                "{m:?} {w:?}"
            );
        }
    }
    let mut reversed = parts.clone();
    reversed.reverse();
    assert_eq!(merge(reversed).unwrap().film.sums, merged.film.sums);

    let refused = |parts: Vec<Part>, needle: &str| match merge(parts) {
        Err(e @ Error::Films(_)) => assert!(e.to_string().contains(needle), "{e}"),
        other => panic!("expected a refusal naming {needle:?}, got {other:?}"),
    };
    refused(vec![part(0..3), part(2..6)], "both hold samples 2..3");
    refused(vec![part(0..2), part(4..6)], "samples 2..4 are in no film");
    let mut other_seed = part(2..6);
    other_seed.seed += 1;
    refused(vec![part(0..2), other_seed], "seed");
    let mut other_scene = part(2..6);
    other_scene.fingerprint ^= 1;
    refused(vec![part(0..2), other_scene], "fingerprint");
    refused(vec![], "no films");
}

/// A copy of the example scene file with `edits` (text replacements) applied.
fn edited_example(dir: &Path, edits: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(example()).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    let path = dir.join("cube.xml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn parameters_render_as_the_changed_scene_file_does() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = Scene::load(example(), &small()).unwrap();
    scene.set("medium.scale", ParamValue::Float(2.0)).unwrap();
    scene.set("phase.g", ParamValue::Float(0.3)).unwrap();
    scene
        .set("medium.albedo", ParamValue::Rgb([0.5, 0.6, 0.7]))
        .unwrap();
    scene.set("max_depth", ParamValue::Int(7)).unwrap();
    let changed = edited_example(
        dir.path(),
        &[
            (r#"name="scale" value="1""#, r#"name="scale" value="2""#),
            (r#"name="g" value="0.6""#, r#"name="g" value="0.3""#),
            ("0.98, 0.8, 0.45", "0.5, 0.6, 0.7"),
            (
                r#"name="maxDepth" value="-1""#,
                r#"name="maxDepth" value="7""#,
            ),
        ],
    );
    let reloaded = Scene::load(&changed, &small()).unwrap();
    assert_eq!(scene.fingerprint(), reloaded.fingerprint());
    assert_eq!(render(&scene, 0..6).sums, render(&reloaded, 0..6).sums);
}

#[test]
fn the_camera_moves_as_a_lookat_in_the_scene_file_does() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = Scene::load(example(), &small()).unwrap();
    scene
        .set("camera.up", ParamValue::Vec3([0.0, 1.0, 0.0]))
        .unwrap();
    scene
        .set("camera.target", ParamValue::Vec3([0.1, 0.0, 0.0]))
        .unwrap();
    scene
        .set("camera.origin", ParamValue::Vec3([2.0, 3.0, 3.0]))
        .unwrap();
    scene.set("camera.fov", ParamValue::Float(25.0)).unwrap();
    // Moving the origin kept the direction: the target moved with it.
    let reloaded = Scene::load(
        edited_example(
            dir.path(),
            &[
                (
                    r#"origin="3.2, 2.4, 4" target="0, -0.1, 0""#,
                    r#"origin="2, 3, 3" target="-1.1, 0.6, -1""#,
                ),
                (r#"name="fov" value="30""#, r#"name="fov" value="25""#),
            ],
        ),
        &small(),
    )
    .unwrap();
    let (a, b) = (scene.description().camera, reloaded.description().camera);
    assert_eq!(a.fov_degrees, b.fov_degrees);
    for (ra, rb) in a.to_world.iter().zip(&b.to_world) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-6, "{:?} vs {:?}", a.to_world, b.to_world);
        }
    }
}

/// The example's sensor made orthographic (its film 1.4 units wide), at `origin` looking at
/// `target`.
fn orthographic_example(dir: &Path, origin: &str, target: &str) -> PathBuf {
    edited_example(
        dir,
        &[
            (
                r#"<sensor type="perspective">"#,
                r#"<sensor type="orthographic">"#,
            ),
            (r#"<float name="fov" value="30"/>"#, ""),
            (
                r#"<lookat origin="3.2, 2.4, 4" target="0, -0.1, 0" up="0, 1, 0"/>"#,
                &format!(
                    r#"<scale value="0.7"/><lookat origin="{origin}" target="{target}" up="0, 1, 0"/>"#
                ),
            ),
        ],
    )
}

#[test]
fn an_orthographic_camera_moved_keeps_its_extent_and_takes_no_field_of_view() {
    let dir = tempfile::tempdir().unwrap();
    let example = orthographic_example(dir.path(), "3.2, 2.4, 4", "0, -0.1, 0");
    let mut scene = Scene::load(example, &small()).unwrap();
    scene
        .set("camera.origin", ParamValue::Vec3([2.0, 3.0, 3.0]))
        .unwrap();
    let e = scene
        .set("camera.fov", ParamValue::Float(25.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("orthographic"), "{e}");
    // Moving the origin kept the direction (the target moved with it) and the film's scale.
    let moved = tempfile::tempdir().unwrap();
    let reloaded = Scene::load(
        orthographic_example(moved.path(), "2, 3, 3", "-1.2, 0.5, -1"),
        &small(),
    )
    .unwrap();
    let (a, b) = (scene.description().camera, reloaded.description().camera);
    for (ra, rb) in a.to_world.iter().zip(&b.to_world) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-5, "{:?} vs {:?}", a.to_world, b.to_world);
        }
    }
}

#[test]
fn bad_parameters_are_refused_by_name_and_change_nothing() {
    let mut scene = Scene::load(example(), &small()).unwrap();
    let before = scene.fingerprint();
    for (key, value, needle) in [
        ("medium.density", ParamValue::Float(1.0), "one of spp, seed"),
        ("phase.g", ParamValue::Float(1.0), "(-1, 1)"),
        ("medium.scale", ParamValue::Float(f32::NAN), "finite"),
        ("medium.scale", ParamValue::Float(-1.0), ">= 0"),
        ("medium.albedo", ParamValue::Rgb([0.5, 1.5, 0.5]), "[0, 1]"),
        (
            "camera.up",
            ParamValue::Vec3([0.0, 0.0, 0.0]),
            "not parallel",
        ),
        ("camera.fov", ParamValue::Float(180.0), "(0, 180)"),
        ("spp", ParamValue::Int(0), "from 1"),
        ("max_depth", ParamValue::Int(-2), "from -1"),
    ] {
        let err = scene.set(key, value).unwrap_err();
        let text = err.to_string();
        assert!(text.contains(key) && text.contains(needle), "{text}");
        assert_eq!(scene.fingerprint(), before, "{key} changed the scene");
    }
    // A scale that makes the medium too dense for f32 positions is refused by the loader's
    // check, as a bad value of the parameter that was set.
    let err = scene
        .set("medium.scale", ParamValue::Float(1e12))
        .unwrap_err();
    assert!(
        matches!(&err, Error::Param { key, .. } if key == "medium.scale"),
        "{err}"
    );
    assert!(err.to_string().contains("mean free path"), "{err}");
    assert_eq!(scene.fingerprint(), before);
}

#[test]
fn the_fingerprint_sees_the_render_and_not_the_sample_count_or_seed() {
    let scene = Scene::load(example(), &small()).unwrap();
    let fp = |settings: RenderSettings| Scene::load(example(), &settings).unwrap().fingerprint();
    let base = scene.fingerprint();
    assert_eq!(
        fp(RenderSettings {
            spp: Some(99),
            seed: 8,
            ..small()
        }),
        base
    );
    for changed in [
        RenderSettings {
            resolution: Some((12, 11)),
            ..small()
        },
        RenderSettings {
            max_depth: Some(Some(3)),
            ..small()
        },
        RenderSettings {
            roulette: Some(volpt::Roulette::Throughput),
            ..small()
        },
        RenderSettings {
            effects: volpt::Effects::General,
            ..small()
        },
        RenderSettings {
            params: vec![("resolution".into(), "12".into())],
            resolution: None,
            ..small()
        },
    ] {
        assert_ne!(fp(changed.clone()), base, "{changed:?}");
    }
    // A render's own: its lookup and path settings are part of it, its seed and samples not.
    let cpu = Backend::cpu();
    let request = |r: RenderRequest| cpu.fingerprint(&scene, &r).unwrap();
    assert_eq!(request(RenderRequest::samples(0..6)), base);
    assert_eq!(request(RenderRequest::samples(2..9).with_seed(11)), base);
    let nearest = RenderRequest::samples(0..6).with_lookup(GridLookup::Nearest);
    assert_ne!(request(nearest), base, "the request's lookup");
    let mut path = scene.path_settings();
    path.max_depth = 2;
    assert_ne!(request(RenderRequest::samples(0..6).with_path(path)), base);
}

#[test]
fn a_film_of_another_size_is_refused() {
    let scene = Scene::load(example(), &small()).unwrap();
    let err = Backend::cpu()
        .render(&scene, &mut Film::new(3, 3), 0..1, &Quiet)
        .unwrap_err();
    assert!(
        err.to_string().contains("3x3") && err.to_string().contains("12x10"),
        "{err}"
    );
}

#[test]
fn a_set_resolution_renders_as_a_load_at_it_and_a_refused_one_changes_nothing() {
    let mut scene = Scene::load(example(), &small()).unwrap();
    scene.set_resolution(6, 5).unwrap();
    let loaded = Scene::load(
        example(),
        &RenderSettings {
            resolution: Some((6, 5)),
            ..small()
        },
    )
    .unwrap();
    assert_eq!(render(&scene, 0..2).sums, render(&loaded, 0..2).sums);
    assert!(scene.set_resolution(0, 5).is_err());
    assert_eq!(scene.resolution(), (6, 5));
}

/// The example cube with a density grid of `values` (n x n x n, x fastest) over its box.
struct GridCube(Vec<f32>);

impl volpt::scene_files::SceneBuilder for GridCube {
    fn source(&self) -> String {
        "grid cube".into()
    }

    fn build(
        &self,
        _: &[(String, String)],
    ) -> Result<volpt::SceneDescription, volpt::scene_files::SceneError> {
        use volpt::scene_files::{DensityDesc, GridConvention, GridDesc};
        let mut desc = Scene::load(example(), &small())
            .unwrap()
            .description()
            .clone();
        let n = (self.0.len() as f64).cbrt().round() as u32;
        desc.medium.density = DensityDesc::Grid(GridDesc {
            resolution: [n; 3],
            channels: 1,
            bounds: desc.boundary.bounds,
            convention: GridConvention::Cell,
            data: self.0.clone(),
            layout: Default::default(),
        });
        Ok(desc)
    }
}

#[test]
fn the_fingerprint_sees_every_grid_value_and_a_clone_renders_as_its_scene() {
    let values = vec![0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0];
    let scene = Scene::build(&GridCube(values.clone()), &small()).unwrap();
    let base = scene.fingerprint();
    assert_eq!(base, scene.fingerprint(), "computed once, the same");
    for i in 0..values.len() {
        let mut changed = values.clone();
        changed[i] = f32::from_bits(changed[i].to_bits() + 1);
        let other = Scene::build(&GridCube(changed), &small()).unwrap();
        assert_ne!(other.fingerprint(), base, "voxel {i} changed by one ulp");
    }
    // A clone has its own copy of the grids; it renders and fingerprints as its scene, also
    // after the scene it was cloned from has rendered (and cached its factory's scans).
    let whole = render(&scene, 0..6);
    let clone = scene.clone();
    assert_eq!(clone.fingerprint(), base);
    assert_eq!(render(&clone, 0..6).sums, whole.sums);
    drop(scene);
    assert_eq!(render(&clone, 0..6).sums, whole.sums);
}

#[test]
fn a_scene_rendered_again_after_its_scale_changes_renders_as_one_loaded_at_that_scale() {
    // The factory keeps the majorant grid between renders of a scene: a new scale must not find
    // the old one.
    // Denser along x: the majorant grid's cells differ, so the factory tracks with it.
    let values: Vec<f32> = (0..512).map(|i| (i % 8) as f32 / 4.0).collect();
    let settings = RenderSettings {
        majorant_resolution: Some(4),
        ..small()
    };
    let mut scene = Scene::build(&GridCube(values.clone()), &settings).unwrap();
    let _ = render(&scene, 0..6);
    let scale = match scene.get("medium.scale").unwrap() {
        ParamValue::Float(s) => s,
        other => panic!("{other:?}"),
    };
    scene
        .set("medium.scale", ParamValue::Float(scale * 3.0))
        .unwrap();
    let mut fresh = Scene::build(&GridCube(values), &settings).unwrap();
    fresh
        .set("medium.scale", ParamValue::Float(scale * 3.0))
        .unwrap();
    assert_eq!(render(&scene, 0..6).sums, render(&fresh, 0..6).sums);
}

/// A material-indexed print of two materials: a 3x2x2 `u8` index grid and its table, written as
/// a TOML scene with `white_sigma_a` as the white material's absorption.
fn print_scene(dir: &Path, white_sigma_a: &str) -> PathBuf {
    std::fs::write(
        dir.join("print.raw"),
        [0u8, 1, 1, 0, 0, 1, 1, 1, 0, 0, 0, 1],
    )
    .unwrap();
    let text = format!(
        "[volume]\nfile = \"print.raw\"\nformat = \"raw\"\nresolution = [3, 2, 2]\ntype = \"u8\"\n\
         bounds = [[-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]]\n\
         [[materials]]\nname = \"cyan\"\nsigma_s = [4.0, 6.0, 7.0]\nsigma_a = [6.0, 0.8, 0.2]\ng = 0.3\n\
         [[materials]]\nname = \"white\"\nsigma_s = [9.0, 9.0, 9.0]\nsigma_a = {white_sigma_a}\n"
    );
    let path = dir.join("print.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A TOML scene of a 3 x 2 x 2 print of two materials with `indices` (one byte per voxel).
fn indexed_scene(dir: &Path, indices: &[u8]) -> PathBuf {
    std::fs::write(dir.join("print.raw"), indices).unwrap();
    let text = r##"[volume]
file = "print.raw"
format = "raw"
resolution = [3, 2, 2]
type = "u8"
bounds = [[0.0, 0.0, 0.0], [3.0, 2.0, 2.0]]
[boundary]
bsdf = "dielectric"
[[materials]]
name = "cyan"
sigma_s = [4.0, 6.0, 7.0]
sigma_a = [6.0, 0.8, 0.2]
g = 0.3
[[materials]]
name = "white"
sigma_t = 12.0
albedo = [0.99, 0.98, 0.97]
"##;
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A material's coefficients set as parameters render as the scene file with those
/// coefficients, bit for bit; the scene lists them; a refused value leaves the scene as it was.
#[test]
fn material_parameters_render_as_the_changed_scene_file_does() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = Scene::load(print_scene(dir.path(), "[0.1, 0.2, 0.3]"), &small()).unwrap();
    let keys: Vec<String> = scene.params().into_iter().map(|(k, _)| k).collect();
    assert!(
        keys.iter().any(|k| k == "materials.white.sigma_a"),
        "{keys:?}"
    );
    let before = render(&scene, 0..6);
    assert!(scene
        .set("materials.white.sigma_a", ParamValue::Rgb([-1.0, 0.0, 0.0]))
        .is_err());
    assert_eq!(render(&scene, 0..6).sums, before.sums);
    scene
        .set("materials.white.sigma_a", ParamValue::Rgb([2.0, 1.0, 0.5]))
        .unwrap();
    assert_eq!(
        scene.get("materials.1.sigma_a").unwrap(),
        ParamValue::Rgb([2.0, 1.0, 0.5])
    );
    let other = tempfile::tempdir().unwrap();
    let changed = Scene::load(print_scene(other.path(), "[2.0, 1.0, 0.5]"), &small()).unwrap();
    let (a, b) = (render(&scene, 0..6), render(&changed, 0..6));
    assert_ne!(a.sums, before.sums);
    assert_eq!(a.sums, b.sums);
}

#[test]
fn new_indices_render_as_the_scene_loaded_with_them_and_refused_ones_change_nothing() {
    let (before, after) = (
        [0, 1, 1, 0, 0, 1, 1, 1, 0, 0, 0, 1],
        [1, 1, 0, 0, 1, 0, 0, 1, 1, 0, 1, 1],
    );
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let mut scene = Scene::load(indexed_scene(a.path(), &before), &small()).unwrap();
    let reloaded = Scene::load(indexed_scene(b.path(), &after), &small()).unwrap();
    let original = scene.fingerprint();
    assert_ne!(original, reloaded.fingerprint());
    // Refusals: the wrong count, an index past the table; the scene stays as it was.
    let e = scene.set_indices(&after[..11]).unwrap_err().to_string();
    assert!(e.contains("12") && e.contains("11"), "{e}");
    let mut past = after;
    past[4] = 2;
    let e = scene.set_indices(&past).unwrap_err().to_string();
    assert!(e.contains('2'), "{e}");
    assert_eq!(scene.fingerprint(), original);
    // The same indices change nothing; new ones render as the scene loaded with them.
    scene.set_indices(&before).unwrap();
    assert_eq!(scene.fingerprint(), original);
    scene.set_indices(&after).unwrap();
    assert_eq!(scene.fingerprint(), reloaded.fingerprint());
    assert_eq!(render(&scene, 0..6).sums, render(&reloaded, 0..6).sums);
    // A medium without indices has none to replace.
    let mut cube = Scene::load(example(), &small()).unwrap();
    let e = cube.set_indices(&after).unwrap_err().to_string();
    assert!(e.contains("material-indexed"), "{e}");
}
