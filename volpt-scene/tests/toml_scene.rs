//! volpt TOML scene files: what they load to, and one clear error per kind of mistake.

mod common;

use std::path::{Path, PathBuf};

use common::assert_lookat_frame;
use volpt_scene::{
    builder_for, AlbedoDesc, BsdfDesc, Config, DensityDesc, PhaseDesc, SceneAssembler, SceneError,
};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write fixture");
    path
}

/// A 2x2x2 `u8` raw grid and a scene around it; `extra` is appended to the scene text.
fn scene(extra: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("g.raw"),
        [0u8, 50, 100, 150, 200, 250, 255, 0],
    )
    .unwrap();
    let text = format!(
        "[volume]\nfile = \"g.raw\"\nformat = \"raw\"\nresolution = [2, 2, 2]\ntype = \"u8\"\n\
         bounds = [[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]\n{extra}"
    );
    let path = write(dir.path(), "scene.toml", &text);
    (dir, path)
}

fn load(path: &Path, config: Config) -> Result<volpt_scene::SceneDescription, SceneError> {
    SceneAssembler::new(config).assemble(builder_for(path)?.as_ref())
}

fn error(extra: &str) -> String {
    let (_dir, path) = scene(extra);
    load(&path, Config::default()).unwrap_err().to_string()
}

#[test]
fn defaults_are_the_thesis_setup() {
    let (_dir, path) = scene("");
    let desc = load(&path, Config::default()).unwrap();
    let DensityDesc::Grid(grid) = &desc.medium.density else {
        panic!("grid density expected")
    };
    assert_eq!(
        grid.data,
        vec![0.0, 50.0, 100.0, 150.0, 200.0, 250.0, 255.0, 0.0]
    );
    assert_eq!(desc.boundary.bounds.max, [1.0, 2.0, 3.0]);
    assert_eq!(
        desc.boundary.bsdf,
        BsdfDesc::RoughDielectric {
            alpha: 0.1,
            int_ior: 1.05,
            ext_ior: 1.01
        }
    );
    assert_eq!(desc.medium.albedo, AlbedoDesc::Constant([0.9; 3]));
    assert_eq!(desc.medium.phase, PhaseDesc::Isotropic);
    assert_eq!(
        (desc.film.width, desc.film.height, desc.spp),
        (400, 400, 100)
    );
    assert_eq!(desc.integrator.max_depth, None);
    assert_eq!(desc.camera.to_world[2][3], 100.0);
}

#[test]
fn config_overrides_and_parameters_apply() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("data");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(sub.join("g.raw"), [10u8; 8]).unwrap();
    let path = write(
        dir.path(),
        "scene.toml",
        "[defaults]\nwhere = \"nowhere\"\n[volume]\nfile = \"$where/g.raw\"\nformat = \"raw\"\n\
         resolution = [2, 2, 2]\ntype = \"u8\"\nbounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n\
         normalise = 4.0\n",
    );
    let config = Config {
        params: vec![("where".into(), "data".into())],
        spp: Some(3),
        resolution: Some((7, 5)),
        max_depth: Some(Some(9)),
        rr_depth: Some(None),
    };
    let desc = load(&path, config).unwrap();
    let DensityDesc::Grid(grid) = &desc.medium.density else {
        panic!()
    };
    assert_eq!(grid.max_value(), 4.0);
    assert_eq!((desc.film.width, desc.film.height, desc.spp), (7, 5, 3));
    assert_eq!(desc.integrator.max_depth, Some(9));
    // Without the parameter the default names a directory that does not exist.
    let err = load(&path, Config::default()).unwrap_err().to_string();
    assert!(err.contains("nowhere/g.raw"), "{err}");
}

#[test]
fn malformed_toml_names_the_line() {
    let err = error("[phase\ng = 0.5\n");
    assert!(err.contains("scene.toml:7"), "{err}");
}

#[test]
fn unknown_key_is_an_error() {
    let err = error("[camera]\nfov_degrees = 3.0\n");
    assert!(err.contains("unknown field `fov_degrees`"), "{err}");
}

#[test]
fn raw_without_bounds_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("g.raw"), [0u8; 8]).unwrap();
    let path = write(
        dir.path(),
        "scene.toml",
        "[volume]\nfile = \"g.raw\"\nformat = \"raw\"\nresolution = [2, 2, 2]\ntype = \"u8\"\n",
    );
    let err = load(&path, Config::default()).unwrap_err().to_string();
    assert!(err.contains("missing bounds"), "{err}");
}

#[test]
fn out_of_range_values_name_field_and_line() {
    let err = error("[phase]\ng = 1.0\n");
    assert!(
        err.contains("scene.toml:8: phase.g") && err.contains("(-1, 1)"),
        "{err}"
    );
    let err = error("[boundary]\nbsdf = \"plastic\"\n");
    assert!(
        err.contains("boundary.bsdf") && err.contains("plastic"),
        "{err}"
    );
    let err = error("[boundary]\nint_ior = \"unobtainium\"\n");
    assert!(err.contains("boundary.int_ior"), "{err}");
    let err = error("[albedo]\nvalue = 1.5\n");
    assert!(err.contains("albedo.value"), "{err}");
    let err = error("[camera]\norigin = [0.0, 0.0, 0.0]\n");
    assert!(err.contains("camera"), "{err}");
    let err = error("[integrator]\nmax_depth = -7\n");
    assert!(err.contains("integrator.max_depth"), "{err}");
}

#[test]
fn both_albedo_sources_is_an_error() {
    let err = error("[albedo]\nvalue = 0.5\ntransfer_function = \"t.tf\"\n");
    assert!(err.contains("either transfer_function or value"), "{err}");
}

#[test]
fn unknown_extension_is_an_error() {
    let err = builder_for(Path::new("scene.blend"))
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains(".toml"), "{err}");
}

/// Values just inside each limit load, the limits themselves do not: `g` in (-1, 1), a positive
/// roughness, a field of view in (0, 180), a depth >= 0.
#[test]
fn values_inside_the_limits_load_and_the_limits_do_not() {
    let (_dir, path) = scene("[phase]\ng = -0.5\n[integrator]\nmax_depth = 5\n");
    let desc = load(&path, Config::default()).unwrap();
    assert_eq!(desc.medium.phase, PhaseDesc::HenyeyGreenstein { g: -0.5 });
    assert_eq!(desc.integrator.max_depth, Some(5));
    assert!(error("[phase]\ng = -1.0\n").contains("phase.g"));
    for alpha in ["0.0", "-0.1"] {
        let err = error(&format!("[boundary]\nalpha = {alpha}\n"));
        assert!(err.contains("boundary.alpha"), "alpha {alpha}: {err}");
    }
    let err = error("[camera]\nfov = 0.0\n");
    assert!(err.contains("camera.fov"), "{err}");
}

/// The camera: the thesis's field of view by default, and Mitsuba's `lookat` frame (+z towards
/// the target, +y up, +x to the image's left) for an oblique view, against the frame built in
/// f64 (`assert_lookat_frame`).
#[test]
fn camera_frame_is_mitsubas_lookat() {
    let (_dir, path) = scene("");
    assert_eq!(
        load(&path, Config::default()).unwrap().camera.fov_degrees,
        0.7
    );
    let (origin, target, up) = ([3.0, 4.0, 12.0], [1.0, -1.0, 0.5], [0.2, 1.0, 0.1]);
    let (_dir, path) = scene(&format!(
        "[camera]\norigin = {origin:?}\ntarget = {target:?}\nup = {up:?}\n"
    ));
    let to_world = load(&path, Config::default()).unwrap().camera.to_world;
    assert_lookat_frame(&to_world, origin, target, up);
}

/// An orthographic TOML camera is Mitsuba 3's `orthographic` sensor whose frame is the lookat
/// scaled by half the extent (x) and by half the extent's height times the film's aspect (y):
/// the same frame as the Mitsuba XML spelling it so, for both spellings of `extent`.
#[test]
fn an_orthographic_camera_is_mitsubas_sensor_scaled_to_its_extent() {
    let camera = |extent: &str| {
        format!(
            "[camera]\nprojection = \"orthographic\"\norigin = [0.5, 1.0, 9.0]\n\
             target = [0.5, 1.0, 0.0]\nup = [0.0, 1.0, 0.0]\nextent = {extent}\n\
             [film]\nwidth = 40\nheight = 20\n"
        )
    };
    let dir = tempfile::tempdir().unwrap();
    // Film 40 x 20 (aspect 2): extent [3, 1.2] scales x by 1.5 and y by 0.6 x 2 = 1.2; extent 3
    // alone has height 1.5, y scaled by 1.5.
    for (extent, [sx, sy]) in [("[3.0, 1.2]", [1.5, 1.2]), ("3.0", [1.5, 1.5])] {
        let (_d, path) = scene(&camera(extent));
        let toml = load(&path, Config::default()).unwrap();
        assert_eq!(
            toml.camera.projection,
            volpt_scene::Projection::Orthographic
        );
        let xml = write(
            dir.path(),
            "ortho.xml",
            &format!(
                r#"<scene version="3.0.0"><sensor type="orthographic">
                <transform name="to_world"><scale x="{sx}" y="{sy}"/>
                <lookat origin="0.5, 1, 9" target="0.5, 1, 0" up="0, 1, 0"/></transform>
                <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="20"/></film>
                </sensor><shape type="cube"><bsdf type="null"/><medium type="homogeneous" name="interior"/></shape></scene>"#
            ),
        );
        let mitsuba = volpt_scene::load_mitsuba(&xml).unwrap();
        for (r, (a, b)) in toml
            .camera
            .to_world
            .iter()
            .zip(&mitsuba.camera.to_world)
            .enumerate()
        {
            for k in 0..4 {
                assert!(
                    (a[k] - b[k]).abs() < 1e-6,
                    "extent {extent}: row {r}: TOML {a:?}, Mitsuba {b:?}"
                );
            }
        }
    }
}

#[test]
fn an_orthographic_camera_needs_an_extent_and_takes_no_field_of_view() {
    let ortho = "[camera]\nprojection = \"orthographic\"\n";
    for (extra, expected) in [
        (ortho.to_string(), "camera.extent: expected the film's size"),
        (
            format!("{ortho}extent = 2.0\nfov = 30.0\n"),
            "camera.fov: expected no field of view on an orthographic camera",
        ),
        (
            format!("{ortho}extent = [2.0, -1.0]\n"),
            "camera.extent: expected a width and height above 0",
        ),
        (
            "[camera]\nextent = 2.0\n".to_owned(),
            "camera.extent: expected no extent on a perspective camera",
        ),
        (
            "[camera]\nprojection = \"fisheye\"\n".to_owned(),
            "projection",
        ),
    ] {
        let e = error(&extra);
        assert!(e.contains(expected), "{extra:?}: {e}");
    }
}
