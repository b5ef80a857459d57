//! Scenes that load: every field of the resulting description is checked.

mod common;

use common::*;
use volpt_scene::{
    load_mitsuba, load_mitsuba_with, AlbedoDesc, Bounds, BsdfDesc, DensityDesc, EnvironmentDesc,
    FilmDesc, FovAxis, GridConvention, GridDesc, IntegratorDesc, PhaseDesc, SceneDescription,
    SceneError,
};

const BOX: Bounds = Bounds {
    min: [-0.5, -0.5, -0.2],
    max: [0.5, 0.5, 0.2],
};

/// Camera at (0, 0, 4) looking at the origin with +y up: Mitsuba's camera +x (left) is world -x.
const LOOKAT_0_0_4: [[f32; 4]; 4] = [
    [-1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, -1.0, 4.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn assert_bounds(a: Bounds, b: Bounds) {
    assert_close3(a.min, b.min);
    assert_close3(a.max, b.max);
}

/// The fields both versions of the smoke-in-glass fixture share.
fn assert_smoke_scene(
    scene: &SceneDescription,
    grid: &volpt_scene::VolGrid,
    convention: GridConvention,
) {
    assert_matrix(&scene.camera.to_world, &LOOKAT_0_0_4);
    assert_eq!(scene.camera.fov_degrees, 30.0);
    assert_eq!(scene.camera.fov_axis, FovAxis::Y);
    assert_eq!(
        scene.film,
        FilmDesc {
            width: 320,
            height: 240
        }
    );
    assert_eq!(scene.spp, 64);
    assert_eq!(
        scene.integrator,
        IntegratorDesc {
            max_depth: None,
            rr_depth: Some(10)
        }
    );
    assert_bounds(scene.boundary.bounds, BOX);
    match scene.boundary.bsdf {
        BsdfDesc::RoughDielectric {
            alpha,
            int_ior,
            ext_ior,
        } => {
            assert_close(alpha, 0.2);
            assert_close(int_ior, 1.333);
            assert_close(ext_ior, 1.000277);
        }
        other => panic!("expected a rough dielectric, found {other:?}"),
    }
    assert_eq!(scene.medium.scale, 20.0);
    match &scene.medium.albedo {
        AlbedoDesc::Constant(albedo) => assert_close3(*albedo, [0.9, 0.8, 0.7]),
        other => panic!("expected a constant albedo, found {other:?}"),
    }
    assert_eq!(scene.medium.phase, PhaseDesc::HenyeyGreenstein { g: 0.3 });
    match &scene.medium.density {
        DensityDesc::Grid(GridDesc {
            layout: volpt_scene::SampleLayout::Dense,
            resolution,
            channels,
            bounds,
            convention: c,
            data,
        }) => {
            assert_eq!(*resolution, grid.resolution);
            assert_eq!(*channels, 1);
            assert_bounds(*bounds, BOX);
            assert_eq!(*c, convention);
            assert_eq!(data, &grid.data);
        }
        other => panic!("expected a density grid, found {other:?}"),
    }
    assert_eq!(scene.environment, EnvironmentDesc::Constant([0.5; 3]));
}

#[test]
fn mitsuba06_scene_loads_every_field() {
    let dir = stage("mitsuba06");
    // Mitsuba 0.6 takes the grid's extent from the file's bounding box.
    let grid = density_grid([4, 3, 2], BOX);
    write_grid(dir.path(), "density.vol", &grid);
    let scene = load_mitsuba(&dir.path().join("scene.xml")).expect("scene loads");
    assert_smoke_scene(&scene, &grid, GridConvention::Vertex);
}

#[test]
fn mitsuba3_scene_loads_every_field() {
    let dir = stage("mitsuba3");
    // Mitsuba 3 ignores the file's box: the grid spans [0, 1]^3 mapped by to_world.
    let grid = density_grid(
        [4, 3, 2],
        Bounds {
            min: [7.0; 3],
            max: [9.0; 3],
        },
    );
    write_grid(dir.path(), "density.vol", &grid);
    let scene = load_mitsuba(&dir.path().join("scene.xml")).expect("scene loads");
    assert_smoke_scene(&scene, &grid, GridConvention::Cell);
}

#[test]
fn mitsuba3_grid_can_use_the_files_bbox() {
    let (dir, path) = scene_file(&medium_scene(
        r#"<medium type="heterogeneous" name="interior">
            <volume name="sigma_t" type="gridvolume">
                <string name="filename" value="d.vol"/>
                <boolean name="use_grid_bbox" value="true"/>
                <transform name="to_world"><translate x="1"/></transform>
            </volume>
            <volume name="albedo" type="gridvolume"><string name="filename" value="a.vol"/></volume>
        </medium>"#,
    ));
    write_grid(dir.path(), "d.vol", &density_grid([2, 2, 2], BOX));
    // A grey albedo grid is expanded to RGB.
    let albedo = volpt_scene::VolGrid {
        data: vec![0.25; 8],
        ..density_grid([2, 2, 2], BOX)
    };
    write_grid(dir.path(), "a.vol", &albedo);
    let scene = load_mitsuba(&path).expect("scene loads");
    let DensityDesc::Grid(density) = &scene.medium.density else {
        panic!("expected a grid")
    };
    assert_bounds(
        density.bounds,
        Bounds {
            min: [0.5, -0.5, -0.2],
            max: [1.5, 0.5, 0.2],
        },
    );
    let AlbedoDesc::Grid(albedo) = &scene.medium.albedo else {
        panic!("expected a grid")
    };
    assert_eq!(albedo.channels, 3);
    assert_eq!(albedo.data, vec![0.25; 24]);
    assert_bounds(
        albedo.bounds,
        Bounds {
            min: [0.0; 3],
            max: [1.0; 3],
        },
    );
    assert_eq!(albedo.convention, GridConvention::Cell);
    // Mitsuba 3's defaults where the scene says nothing.
    assert_eq!(
        scene.film,
        FilmDesc {
            width: 768,
            height: 576
        }
    );
    assert_eq!(scene.spp, 4);
    assert_eq!(
        scene.integrator,
        IntegratorDesc {
            max_depth: None,
            rr_depth: Some(5)
        }
    );
    assert_eq!(scene.environment, EnvironmentDesc::Constant([0.0; 3]));
    assert_eq!(scene.medium.phase, PhaseDesc::Isotropic);
    assert_eq!(scene.medium.scale, 1.0);
}

#[test]
fn cube_is_scaled_then_translated() {
    let dir = stage("cube");
    let scene = load_mitsuba(&dir.path().join("scene.xml")).expect("scene loads");
    // [-1, 1]^3 scaled by (2, 0.5, 1), then moved by (1, 2, 3).
    assert_bounds(
        scene.boundary.bounds,
        Bounds {
            min: [-1.0, 1.5, 2.0],
            max: [3.0, 2.5, 4.0],
        },
    );
    assert_eq!(
        scene.boundary.bsdf,
        BsdfDesc::Dielectric {
            int_ior: 2.419,
            ext_ior: 1.000277
        }
    );
    assert_eq!(scene.medium.density, DensityDesc::Constant(2.0));
    assert_eq!(scene.medium.albedo, AlbedoDesc::Constant([0.5, 0.25, 1.0]));
    // A 35 mm focal length sets the diagonal field of view: 2 atan(43.27 / 70) = 63.44 degrees.
    assert_eq!(scene.camera.fov_axis, FovAxis::Diagonal);
    assert_close(scene.camera.fov_degrees, 63.4398);
    assert_matrix(&scene.camera.to_world, &volpt_scene::IDENTITY);
}

#[test]
fn default_focal_length_is_50mm() {
    let (_dir, path) = scene_file(
        &bsdf_scene(r#"<bsdf type="null"/>"#).replace(r#"<float name="fov" value="40"/>"#, ""),
    );
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(scene.camera.fov_axis, FovAxis::Diagonal);
    assert_close(scene.camera.fov_degrees, 46.7930);
}

#[test]
fn cube_rotated_by_90_degrees_is_still_a_box() {
    let (_dir, path) = scene_file(&bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        r#"<shape type="cube">"#,
        r#"<shape type="cube"><transform name="to_world"><scale x="2"/><rotate z="1" angle="90"/></transform>"#,
    ));
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_bounds(
        scene.boundary.bounds,
        Bounds {
            min: [-1.0, -2.0, -1.0],
            max: [1.0, 2.0, 1.0],
        },
    );
}

/// `<rotate>` about an arbitrary (unnormalised) axis is the rotation by Rodrigues' formula,
/// `R = cos(a) I + sin(a) [k]x + (1 - cos(a)) k k^T`, computed here in f64 for the sensor's
/// `to_world` (axis-aligned rotations, elsewhere, leave the off-diagonal terms at zero).
#[test]
fn rotate_about_any_axis_is_rodrigues_rotation() {
    for (axis, angle) in [
        ([0.3, -0.5, 0.8], 37.0),
        ([-2.0, 1.0, 0.5], -120.0),
        ([1.0, 1.0, 1.0], 200.0),
    ] {
        let rotate = format!(
            r#"<transform name="to_world"><rotate x="{}" y="{}" z="{}" angle="{angle}"/></transform>"#,
            axis[0], axis[1], axis[2]
        );
        let text = cube_scene("        <bsdf type=\"null\"/>\n        <medium type=\"homogeneous\" name=\"interior\"/>")
            .replace(
                r#"<float name="fov" value="40"/>"#,
                &format!(r#"<float name="fov" value="40"/>{rotate}"#),
            );
        let (_dir, path) = scene_file(&text);
        let scene = load_mitsuba(&path).expect("scene loads");
        let axis: [f64; 3] = axis;
        let norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let k = axis.map(|v| v / norm);
        let (s, c) = f64::to_radians(angle).sin_cos();
        let cross = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
        let mut expected = volpt_scene::IDENTITY;
        for i in 0..3 {
            for j in 0..3 {
                let identity = if i == j { 1.0 } else { 0.0 };
                expected[i][j] = (c * identity + s * cross[i][j] + (1.0 - c) * k[i] * k[j]) as f32;
            }
        }
        assert_matrix(&scene.camera.to_world, &expected);
    }
}

/// `<lookat>` for an oblique view is Mitsuba's frame (+z towards the target, +y up, +x to the
/// image's left), against the frame built in f64 (`assert_lookat_frame`; the other scenes look
/// along a coordinate axis, where one component of each cross product vanishes).
#[test]
fn oblique_lookat_is_mitsubas_frame() {
    let (origin, target, up) = ([3.0, 4.0, 12.0], [1.0, -1.0, 0.5], [0.2, 1.0, 0.1]);
    let lookat = format!(
        r#"<transform name="to_world"><lookat origin="{}, {}, {}" target="{}, {}, {}" up="{}, {}, {}"/></transform>"#,
        origin[0], origin[1], origin[2], target[0], target[1], target[2], up[0], up[1], up[2]
    );
    let text = bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        r#"<float name="fov" value="40"/>"#,
        &format!(r#"<float name="fov" value="40"/>{lookat}"#),
    );
    let (_dir, path) = scene_file(&text);
    let to_world = load_mitsuba(&path).expect("scene loads").camera.to_world;
    assert_lookat_frame(&to_world, origin, target, up);
}

#[test]
fn matrix_transform_is_row_major() {
    let (_dir, path) = scene_file(&bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        r#"<shape type="cube">"#,
        r#"<shape type="cube"><transform name="to_world"><matrix value="0.5 0 0 10  0 1 0 0  0 0 1 0  0 0 0 1"/></transform>"#,
    ));
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_bounds(
        scene.boundary.bounds,
        Bounds {
            min: [9.5, -1.0, -1.0],
            max: [10.5, 1.0, 1.0],
        },
    );
}

#[test]
fn params_override_defaults() {
    let path = fixtures().join("params/scene.xml");
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(scene.spp, 16);
    assert_eq!(scene.medium.phase, PhaseDesc::HenyeyGreenstein { g: 0.5 });

    let params = [
        ("spp".to_string(), "256".to_string()),
        ("g".to_string(), "-0.25".to_string()),
    ];
    let scene = load_mitsuba_with(&path, &params).expect("scene loads");
    assert_eq!(scene.spp, 256);
    assert_eq!(scene.medium.phase, PhaseDesc::HenyeyGreenstein { g: -0.25 });
}

#[test]
fn undefined_param_is_an_error_naming_it() {
    let (_dir, path) = scene_file(&bsdf_scene(
        r#"<bsdf type="dielectric"><float name="int_ior" value="$eta"/></bsdf>"#,
    ));
    let err = load_mitsuba(&path).unwrap_err();
    message_of(&err, &["scene.xml:", "$eta", "-D eta="]);
}

#[test]
fn includes_are_relative_to_the_including_file() {
    let path = fixtures().join("include/scene.xml");
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(scene.camera.fov_degrees, 45.0);
    assert_eq!(scene.camera.fov_axis, FovAxis::X);
    assert_eq!(scene.boundary.bsdf, BsdfDesc::Null);
    // sigmaA 0.5 + sigmaS 1.5: extinction 2, albedo 0.75; scale from the including file's default.
    assert_eq!(scene.medium.density, DensityDesc::Constant(2.0));
    assert_eq!(scene.medium.albedo, AlbedoDesc::Constant([0.75; 3]));
    assert_eq!(scene.medium.scale, 2.0);
    let scene = load_mitsuba_with(&path, &[("fov".into(), "20".into())]).expect("scene loads");
    assert_eq!(scene.camera.fov_degrees, 20.0);
}

#[test]
fn include_cycle_is_an_error() {
    let (dir, path) =
        scene_file(r#"<scene version="3.0.0"><include filename="other.xml"/></scene>"#);
    std::fs::write(
        dir.path().join("other.xml"),
        r#"<scene version="3.0.0"><include filename="scene.xml"/></scene>"#,
    )
    .unwrap();
    let err = load_mitsuba(&path).unwrap_err();
    message_of(&err, &["other.xml:1", "includes itself"]);
}

#[test]
fn refs_resolve_bsdfs_media_and_phases() {
    let (_dir, path) = scene_file(
        r#"<scene version="3.0.0">
    <sensor type="perspective"/>
    <phase type="hg" id="forward"><float name="g" value="0.9"/></phase>
    <bsdf type="dielectric" id="glass"><float name="int_ior" value="1.4"/><float name="ext_ior" value="1.1"/></bsdf>
    <medium type="homogeneous" id="fog">
        <float name="sigma_t" value="3"/>
        <ref id="forward"/>
    </medium>
    <shape type="cube">
        <ref id="glass"/>
        <ref name="interior" id="fog"/>
    </shape>
</scene>"#,
    );
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(
        scene.boundary.bsdf,
        BsdfDesc::Dielectric {
            int_ior: 1.4,
            ext_ior: 1.1
        }
    );
    assert_eq!(scene.medium.density, DensityDesc::Constant(3.0));
    assert_eq!(scene.medium.albedo, AlbedoDesc::Constant([0.75; 3]));
    assert_eq!(scene.medium.phase, PhaseDesc::HenyeyGreenstein { g: 0.9 });
}

#[test]
fn named_iors_match_mitsuba() {
    for (name, ior) in [
        ("vacuum", 1.0),
        ("water", 1.333),
        ("Fused Quartz", 1.458),
        ("bk7", 1.5046),
        ("pet", 1.575),
    ] {
        assert_eq!(volpt_scene::mitsuba::named_ior(name), Some(ior), "{name}");
    }
    assert_eq!(volpt_scene::mitsuba::named_ior("unobtainium"), None);

    let (_dir, path) = scene_file(&bsdf_scene(
        r#"<bsdf type="dielectric"><string name="intIOR" value="acrylic glass"/><string name="extIOR" value="water"/></bsdf>"#,
    ));
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(
        scene.boundary.bsdf,
        BsdfDesc::Dielectric {
            int_ior: 1.49,
            ext_ior: 1.333
        }
    );
}

#[test]
fn dielectric_defaults_are_bk7_in_air() {
    let (_dir, path) = scene_file(&bsdf_scene(r#"<bsdf type="dielectric"/>"#));
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(
        scene.boundary.bsdf,
        BsdfDesc::Dielectric {
            int_ior: 1.5046,
            ext_ior: 1.000277
        }
    );
}

#[test]
fn roughdielectric_with_equal_alpha_u_and_v() {
    let (_dir, path) = scene_file(&bsdf_scene(
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
           <float name="alphaU" value="0.3"/><float name="alphaV" value="0.3"/></bsdf>"#,
    ));
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(
        scene.boundary.bsdf,
        BsdfDesc::RoughDielectric {
            alpha: 0.3,
            int_ior: 1.5046,
            ext_ior: 1.000277
        }
    );
}

#[test]
fn homogeneous_spellings_and_srgb() {
    let (_dir, path) = scene_file(&medium_scene(
        r##"<medium type="homogeneous" name="interior">
            <volume name="sigma_t" type="constvolume"><float name="value" value="4"/></volume>
            <srgb name="albedo" value="#ffffff"/>
            <float name="scale" value="0.5"/>
            <phase type="isotropic"/>
        </medium>"##,
    ));
    let scene = load_mitsuba(&path).expect("scene loads");
    assert_eq!(scene.medium.density, DensityDesc::Constant(4.0));
    assert_eq!(scene.medium.albedo, AlbedoDesc::Constant([1.0; 3]));
    assert_eq!(scene.medium.scale, 0.5);
    assert_eq!(scene.medium.phase, PhaseDesc::Isotropic);
}

#[test]
fn integrator_depths() {
    let with = |body: &str| -> Result<IntegratorDesc, SceneError> {
        let (_dir, path) = scene_file(&bsdf_scene(r#"<bsdf type="null"/>"#).replace(
            "<shape",
            &format!("<integrator type=\"volpath\">{body}</integrator>\n<shape"),
        ));
        load_mitsuba(&path).map(|s| s.integrator)
    };
    assert_eq!(
        with(r#"<integer name="max_depth" value="8"/>"#)
            .unwrap()
            .max_depth,
        Some(8)
    );
    assert_eq!(
        with(r#"<integer name="rrDepth" value="-1"/>"#)
            .unwrap()
            .rr_depth,
        None
    );
    let err = with(r#"<integer name="max_depth" value="-2"/>"#).unwrap_err();
    message_of(&err, &["scene.xml:", "max_depth", "-1 (unlimited)", "-2"]);
}
