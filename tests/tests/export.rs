//! `write_mitsuba3`: a description written as a Mitsuba 3 scene and loaded back by volpt's own
//! Mitsuba loader is the same scene. Cell-centred grids and every other setting come back exactly;
//! a vertex-centred (Mitsuba 0.6) grid comes back on a grown box whose trilinear field is the same
//! at every point of the medium.

use std::path::Path;

use volpt_core::{Medium, Vec3};
use volpt_render::SceneVisitor;
use volpt_scene::description::*;
use volpt_scene::mitsuba::{write_mitsuba3, NO_ROULETTE_DEPTH};
use volpt_scene::{load_mitsuba, SceneError};
use volpt_tests::{cube_scene, homogeneous, with_core_scene};

/// A small deterministic generator, so that grids and probe points are varied but reproducible.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn grid(
    resolution: [u32; 3],
    channels: u32,
    bounds: Bounds,
    convention: GridConvention,
) -> GridDesc {
    let mut rng = Lcg(resolution.iter().map(|&r| r as u64).product::<u64>() + channels as u64);
    let n = (resolution.iter().product::<u32>() * channels) as usize;
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution,
        channels,
        bounds,
        convention,
        data: (0..n).map(|_| rng.next()).collect(),
    }
}

fn export_and_load(desc: &SceneDescription, dir: &Path) -> SceneDescription {
    let written = write_mitsuba3(desc, dir, "exported").expect("export");
    assert_eq!(written[0], dir.join("exported.xml"));
    load_mitsuba(&written[0]).expect("load the exported scene")
}

/// What the written scene changes on purpose: "no roulette" is spelled as a huge depth.
fn as_written(desc: &SceneDescription) -> SceneDescription {
    let mut d = desc.clone();
    d.integrator.rr_depth = Some(d.integrator.rr_depth.unwrap_or(NO_ROULETTE_DEPTH));
    d
}

fn assert_matrix_close(a: &Matrix4, b: &Matrix4) {
    for (ra, rb) in a.iter().zip(b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() <= 1e-6 * (1.0 + x.abs()), "{a:?} != {b:?}");
        }
    }
}

#[test]
fn cell_centred_grids_and_settings_come_back_exactly() {
    let bounds = Bounds {
        min: [-0.5, -0.25, -1.0],
        max: [0.5, 0.25, 1.0],
    };
    let mut desc = cube_scene(
        32,
        24,
        MediumDesc {
            density: DensityDesc::Grid(grid([5, 4, 3], 1, bounds, GridConvention::Cell)),
            scale: 40.0,
            albedo: AlbedoDesc::Grid(grid([3, 4, 5], 3, bounds, GridConvention::Cell)),
            phase: PhaseDesc::HenyeyGreenstein { g: -0.3 },
            lookup: Default::default(),
            storage: Default::default(),
        },
        BsdfDesc::RoughDielectric {
            alpha: 0.1,
            int_ior: 1.05,
            ext_ior: 1.01,
        },
        1.0,
    );
    desc.boundary.bounds = bounds;
    desc.camera.fov_axis = FovAxis::Smaller;
    desc.spp = 300;
    let dir = tempfile::tempdir().expect("temp dir");
    let loaded = export_and_load(&desc, dir.path());
    let expected = as_written(&desc);
    assert_matrix_close(&loaded.camera.to_world, &expected.camera.to_world);
    assert_eq!(loaded.camera.fov_degrees, expected.camera.fov_degrees);
    assert_eq!(loaded.camera.fov_axis, expected.camera.fov_axis);
    assert_eq!(loaded.film, expected.film);
    assert_eq!(loaded.spp, expected.spp);
    assert_eq!(loaded.integrator, expected.integrator);
    assert_eq!(loaded.boundary, expected.boundary);
    assert_eq!(loaded.medium, expected.medium);
    assert_eq!(loaded.environment, expected.environment);
}

#[test]
fn homogeneous_media_boundaries_and_depths_come_back() {
    for (bsdf, phase, max_depth, rr_depth) in [
        (BsdfDesc::Null, PhaseDesc::Isotropic, None, None),
        (
            BsdfDesc::Dielectric {
                int_ior: 1.5,
                ext_ior: 1.0,
            },
            PhaseDesc::HenyeyGreenstein { g: 0.9 },
            Some(7),
            Some(3),
        ),
    ] {
        let mut desc = cube_scene(8, 8, homogeneous(12.5, 0.75, phase), bsdf, 0.5);
        desc.medium.albedo = AlbedoDesc::Constant([0.98, 0.8, 0.45]);
        desc.integrator = IntegratorDesc {
            max_depth,
            rr_depth,
        };
        desc.environment = EnvironmentDesc::Constant([0.25, 0.5, 2.0]);
        let dir = tempfile::tempdir().expect("temp dir");
        let loaded = export_and_load(&desc, dir.path());
        let expected = as_written(&desc);
        assert_eq!(loaded.integrator, expected.integrator);
        assert_eq!(loaded.boundary, expected.boundary);
        assert_eq!(loaded.medium, expected.medium);
        assert_eq!(loaded.environment, expected.environment);
    }
}

/// `sigma_t` and albedo at `points`, through the scene the renderer builds.
struct Probe(Vec<Vec3>);

impl SceneVisitor for Probe {
    type Output = Vec<(f32, [f32; 3])>;
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        self.0
            .iter()
            .map(|&p| {
                (
                    scene.medium().sigma_t(p),
                    scene.medium().albedo(p).to_array(),
                )
            })
            .collect()
    }
}

/// A Mitsuba 0.6 grid (samples on the faces of its box) is written cell-centred on a grown box:
/// the renderer sees the same extinction and albedo everywhere inside the medium's box, the faces,
/// edges and corners included. Writing it on the original box instead would move every sample
/// and fail by far.
#[test]
fn vertex_centred_grids_keep_their_field() {
    let bounds = Bounds {
        min: [-0.5, -0.5, -0.1953125],
        max: [0.5, 0.5, 0.1953125],
    };
    let mut desc = cube_scene(
        8,
        8,
        MediumDesc {
            density: DensityDesc::Grid(grid([7, 5, 4], 1, bounds, GridConvention::Vertex)),
            scale: 800.0,
            albedo: AlbedoDesc::Grid(grid([4, 6, 3], 3, bounds, GridConvention::Vertex)),
            phase: PhaseDesc::Isotropic,
            lookup: Default::default(),
            storage: Default::default(),
        },
        BsdfDesc::Null,
        1.0,
    );
    desc.boundary.bounds = bounds;
    let dir = tempfile::tempdir().expect("temp dir");
    let loaded = export_and_load(&desc, dir.path());
    let DensityDesc::Grid(g) = &loaded.medium.density else {
        panic!("density is not a grid: {:?}", loaded.medium.density);
    };
    assert_eq!(g.convention, GridConvention::Cell);

    let mut rng = Lcg(7);
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let mut points: Vec<Vec3> = (0..2000)
        .map(|_| {
            Vec3::new(
                lerp(bounds.min[0], bounds.max[0], rng.next()),
                lerp(bounds.min[1], bounds.max[1], rng.next()),
                lerp(bounds.min[2], bounds.max[2], rng.next()),
            )
        })
        .collect();
    for corner in 0..8 {
        let pick = |axis: usize| {
            if corner >> axis & 1 == 0 {
                bounds.min[axis]
            } else {
                bounds.max[axis]
            }
        };
        points.push(Vec3::new(pick(0), pick(1), pick(2)));
    }
    let original = with_core_scene(&desc, Probe(points.clone()));
    let exported = with_core_scene(&loaded, Probe(points.clone()));
    for ((p, a), b) in points.iter().zip(&original).zip(&exported) {
        assert!(
            (a.0 - b.0).abs() <= 1e-4 * a.0.max(1.0),
            "sigma_t at {p}: {} vs {}",
            a.0,
            b.0
        );
        for c in 0..3 {
            assert!(
                (a.1[c] - b.1[c]).abs() <= 1e-5,
                "albedo at {p}: {:?} vs {:?}",
                a.1,
                b.1
            );
        }
    }
}

fn sky(rows: LatLongRows) -> LatLongDesc {
    let (width, height) = (8, 5);
    let mut rng = Lcg(3);
    let (s, c) = 30f32.to_radians().sin_cos();
    LatLongDesc {
        width,
        height,
        rgb: (0..3 * width * height).map(|_| 4.0 * rng.next()).collect(),
        to_world: [
            [c, 0.0, s, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [-s, 0.0, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
        scale: 0.8,
        rows,
    }
}

#[test]
fn mitsuba3_environment_maps_come_back() {
    let mut desc = cube_scene(
        8,
        8,
        homogeneous(1.0, 0.5, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    let map = sky(LatLongRows::PoleToPole);
    desc.environment = EnvironmentDesc::LatLong(map.clone());
    let dir = tempfile::tempdir().expect("temp dir");
    let loaded = export_and_load(&desc, dir.path());
    let EnvironmentDesc::LatLong(back) = &loaded.environment else {
        panic!("not a map: {:?}", loaded.environment);
    };
    assert_eq!((back.width, back.height), (map.width, map.height));
    assert_eq!(back.rgb, map.rgb);
    assert_eq!(back.scale, map.scale);
    assert_eq!(back.rows, map.rows);
    assert_matrix_close(&back.to_world, &map.to_world);
}

#[test]
fn mitsuba06_environment_maps_are_refused_not_moved() {
    let mut desc = cube_scene(
        8,
        8,
        homogeneous(1.0, 0.5, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    desc.environment = EnvironmentDesc::LatLong(sky(LatLongRows::CellCentred));
    let dir = tempfile::tempdir().expect("temp dir");
    let err = write_mitsuba3(&desc, dir.path(), "exported").expect_err("a 0.6 map must be refused");
    assert!(matches!(err, SceneError::Export { .. }), "{err:?}");
    let message = err.to_string();
    assert!(message.contains("exported.xml"), "{message}");
    assert!(message.contains("cell-centred rows"), "{message}");
}

/// A chromatic extinction travels as Mitsuba 3 spells it (an RGB in [0, 1] times `scale`) under
/// `volpathmis`, and comes back as the same extinction per channel.
#[test]
fn chromatic_extinction_comes_back_under_volpathmis() {
    let mut medium = homogeneous(1.0, 0.8, PhaseDesc::Isotropic);
    medium.density = DensityDesc::Rgb([2.0, 5.0, 10.0]);
    medium.scale = 3.0;
    let desc = cube_scene(8, 8, medium, BsdfDesc::Null, 1.0);
    let dir = tempfile::tempdir().expect("temp dir");
    let loaded = export_and_load(&desc, dir.path());
    let xml = std::fs::read_to_string(dir.path().join("exported.xml")).unwrap();
    assert!(xml.contains("<integrator type=\"volpathmis\">"), "{xml}");
    let DensityDesc::Rgb(rgb) = loaded.medium.density else {
        panic!("{:?}", loaded.medium.density)
    };
    for (c, expected) in [6.0f32, 15.0, 30.0].into_iter().enumerate() {
        let got = loaded.medium.scale * rgb[c];
        assert!(
            (got - expected).abs() <= 1e-5 * expected,
            "{got} != {expected}"
        );
    }
    assert_eq!(loaded.medium.albedo, desc.medium.albedo);
}

/// A density per channel (a three-channel `sigma_t` grid) comes back exactly, under
/// `volpathmis`, and with nearest lookups its grids are written and read back `nearest`.
#[test]
fn a_density_per_channel_comes_back_with_its_filter() {
    let bounds = Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    let mut medium = homogeneous(1.0, 0.8, PhaseDesc::Isotropic);
    medium.density = DensityDesc::Grid(grid([4, 3, 5], 3, bounds, GridConvention::Cell));
    medium.scale = 7.0;
    let desc = cube_scene(8, 8, medium, BsdfDesc::Null, 1.0);
    for lookup in [GridLookup::Trilinear, GridLookup::Nearest] {
        let mut desc = desc.clone();
        desc.medium.lookup = lookup;
        let dir = tempfile::tempdir().expect("temp dir");
        let loaded = export_and_load(&desc, dir.path());
        let xml = std::fs::read_to_string(dir.path().join("exported.xml")).unwrap();
        assert!(xml.contains("<integrator type=\"volpathmis\">"), "{xml}");
        assert_eq!(loaded.medium, as_written(&desc).medium, "{lookup:?}");
    }
}

/// A material-indexed volume, which Mitsuba 3 cannot read as a table, is written as its table
/// expanded per voxel: RGB `gridvolume`s of the extinction (times `scale`) and the albedo, read
/// `nearest`, cell-centred over the volume's box, under `volpathmis`; each voxel's values are its
/// material's. A table whose materials' `g` differ (one phase per Mitsuba 3 medium) is refused.
#[test]
fn an_indexed_volume_is_written_as_rgb_grids_of_its_materials() {
    use volpt_scene::material::{IndexedDesc, MaterialDesc};
    let material = |name: &str, sigma_s: [f32; 3], sigma_a: [f32; 3], g: f32| MaterialDesc {
        name: name.into(),
        sigma_s,
        sigma_a,
        g,
        colour: None,
    };
    let materials = vec![
        material("cyan", [4.0, 6.0, 7.0], [6.0, 0.8, 0.2], 0.3),
        material("white", [12.0, 12.0, 12.0], [0.02, 0.03, 0.05], 0.3),
    ];
    let bounds = Bounds {
        min: [-1.0, -0.5, -0.25],
        max: [1.0, 0.5, 0.25],
    };
    let indices = [0u8, 1, 1, 0, 1, 0, 0, 0, 1, 1, 0, 1];
    let indexed = IndexedDesc::new(
        Path::new("print.raw"),
        materials.clone(),
        [3, 2, 2],
        bounds,
        &indices,
    )
    .unwrap();
    let mut medium = homogeneous(1.0, 0.8, indexed.phase());
    medium.density = DensityDesc::Indexed(indexed);
    medium.scale = 2.0;
    let desc = cube_scene(8, 8, medium, BsdfDesc::Null, 1.0);
    let dir = tempfile::tempdir().expect("temp dir");
    write_mitsuba3(&desc, dir.path(), "exported").expect("export");
    let xml = std::fs::read_to_string(dir.path().join("exported.xml")).unwrap();
    assert!(xml.contains("<integrator type=\"volpathmis\">"), "{xml}");
    assert!(xml.contains("<medium type=\"heterogeneous\""), "{xml}");
    assert!(xml.contains("<float name=\"scale\" value=\"2\"/>"), "{xml}");
    assert_eq!(xml.matches("value=\"nearest\"").count(), 2, "{xml}");
    for (file, field) in [("exported-sigma_t.vol", 0), ("exported-albedo.vol", 1)] {
        let vol = volpt_scene::vol::read_vol(&dir.path().join(file)).unwrap();
        assert_eq!((vol.resolution, vol.channels), ([3, 2, 2], 3));
        for (i, &k) in indices.iter().enumerate() {
            let m = materials[k as usize].material();
            let expected = if field == 0 { m.sigma_t } else { m.albedo };
            assert_eq!(
                vol.data[3 * i..3 * i + 3],
                expected.to_array(),
                "{file} voxel {i}"
            );
        }
    }
    // One material of another g: refused, naming why.
    let mut other = materials;
    other[1].g = -0.2;
    let indexed =
        IndexedDesc::new(Path::new("print.raw"), other, [3, 2, 2], bounds, &indices).unwrap();
    let mut desc = desc;
    desc.medium.density = DensityDesc::Indexed(indexed);
    let err = write_mitsuba3(&desc, dir.path(), "refused").expect_err("g differ");
    assert!(err.to_string().contains("one phase function"), "{err}");
}

#[test]
fn an_orthographic_camera_comes_back_with_its_extent() {
    let mut desc = cube_scene(
        16,
        12,
        homogeneous(2.0, 0.5, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    desc.camera.projection = Projection::Orthographic;
    // The frame scaled by 1.5: the film spans 3 x 2.25 units, and the scale must come back.
    for row in desc.camera.to_world.iter_mut().take(3) {
        row[0] *= 1.5;
        row[1] *= 1.5;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let text = {
        let loaded = export_and_load(&desc, dir.path());
        assert_eq!(loaded.camera.projection, Projection::Orthographic);
        assert_matrix_close(&loaded.camera.to_world, &desc.camera.to_world);
        assert_eq!(loaded.film, desc.film);
        std::fs::read_to_string(dir.path().join("exported.xml")).unwrap()
    };
    assert!(text.contains(r#"<sensor type="orthographic">"#), "{text}");
    assert!(!text.contains(r#"name="fov""#), "{text}");
}
