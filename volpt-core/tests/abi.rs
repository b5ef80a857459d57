//! The device ABI's host side with a closure as the uploader, as the CUDA backend uses it (a copy to
//! device memory returning its address): the parameters carry the addresses the closure returned,
//! in the order the parts were uploaded, and the lengths of what it was given. The whole-renderer
//! round trip (`tests/tests/device_abi.rs`) uses an uploader type of its own, so it never calls the
//! blanket implementation for closures or the default dense `Uploader::grid`.

use volpt_core::abi::{GridParams, SettingsParams, Uploader};
use volpt_core::{
    Aabb, Component, ConstantEnvironment, Estimator, Grid, GridAlbedo, GridLayout, GridLookup,
    GridMapping, GridMedium, GridPlacement, HenyeyGreenstein, HomogeneousMedium, Isotropic,
    LatLongEnvironment, LatLongRows, NullBoundary, PathSettings, PerspectiveCamera,
    RoughDielectric, Roulette, SceneAbi, SmoothDielectric, Vec2, Vec3, VolumeScene,
};

/// A closure uploader that hands out made-up device addresses and records what it was given.
fn recording(calls: &mut Vec<Vec<f32>>) -> impl FnMut(&[f32]) -> u64 + '_ {
    move |values: &[f32]| {
        calls.push(values.to_vec());
        0x1000 * calls.len() as u64 + 8
    }
}

#[test]
fn a_closure_uploads_a_dense_grid_and_its_address_is_kept() {
    let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5).collect();
    let res = [2, 3, 4];
    let bounds = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5));
    let grid: Grid<'_, 1> = Grid::new(&data, res, GridMapping::vertex_centred(bounds, res));
    let mut calls = Vec::new();
    let params = {
        let mut upload = recording(&mut calls);
        assert_eq!(Uploader::values(&mut upload, &[1.0, 2.0]), 0x1008);
        GridParams::new(&grid, &mut upload, GridPlacement::Dense)
    };
    assert_eq!(calls, vec![vec![1.0, 2.0], data.clone()]);
    assert_eq!(params.data, 0x2008, "the address the closure returned");
    assert_eq!(params.len, 24);
    assert_eq!(params.layout, GridLayout::Dense.to_u32());
    assert_eq!(params.res, res);
    assert_eq!(params.channels, 1);
}

#[test]
fn a_closure_uploads_a_lat_long_map_and_its_distribution() {
    let (width, height) = (3, 2);
    let rgb: Vec<f32> = (0..3 * width * height).map(|i| 0.1 + i as f32).collect();
    let rotation = [Vec3::X, Vec3::Y, Vec3::Z];
    let map = LatLongEnvironment::new(&rgb, width, height, LatLongRows::PoleToPole, rotation, 2.0);
    let mut distribution = vec![0.0; LatLongEnvironment::distribution_len(width, height)];
    map.fill_distribution(&mut distribution);
    let map = LatLongEnvironment {
        distribution: &distribution,
        ..map
    };
    let mut calls = Vec::new();
    let params = map.to_params(&mut recording(&mut calls));
    assert_eq!(calls, vec![rgb.clone(), distribution.clone()]);
    assert_eq!((params.texels, params.len), (0x1008, rgb.len() as u64));
    assert_eq!(
        (params.distribution, params.distribution_len),
        (0x2008, distribution.len() as u64)
    );
    assert_eq!((params.width, params.height, params.scale), (3, 2, 2.0));
}

#[test]
fn a_constant_environment_travels_as_its_radiance() {
    let env = ConstantEnvironment(Vec3::new(0.25, 1.5, 3.0));
    let mut calls = Vec::new();
    let params = env.to_params(&mut recording(&mut calls));
    assert!(calls.is_empty(), "a constant uploads nothing");
    assert_eq!(params.radiance, [0.25, 1.5, 3.0]);
    // SAFETY: a constant's parameters hold no address.
    let decoded = unsafe { ConstantEnvironment::from_params(&params) };
    assert_eq!(decoded.0, env.0);
}

/// Two settings that differ in every field, so that a field decoded into another's place, or a
/// code of the estimator or roulette read back wrongly, shows.
fn settings() -> [PathSettings; 2] {
    [
        PathSettings {
            max_depth: 7,
            rr_depth: 3,
            max_segments: 1000,
            max_tracking_steps: 5000,
            majorant_resolution: 16,
            estimator: Estimator::NextEvent,
            roulette: Roulette::Throughput,
        },
        PathSettings {
            max_depth: PathSettings::UNLIMITED,
            rr_depth: 5,
            max_segments: 1 << 22,
            max_tracking_steps: 1 << 26,
            majorant_resolution: 0,
            estimator: Estimator::PathTracing,
            roulette: Roulette::Mitsuba,
        },
    ]
}

#[test]
fn settings_survive_the_device_encoding() {
    for s in settings() {
        let params = SettingsParams::from(&s);
        assert_eq!(PathSettings::from(&params), s);
        // The codes the parameters document.
        let estimator = (s.estimator == Estimator::NextEvent) as u32;
        let roulette = (s.roulette == Roulette::Throughput) as u32;
        assert_eq!((params.estimator, params.roulette), (estimator, roulette));
        assert_eq!(params.max_depth, s.max_depth);
    }
}

#[test]
fn grid_lookups_travel_as_their_documented_codes() {
    assert_eq!(GridLookup::Trilinear.code(), 0);
    assert_eq!(GridLookup::Nearest.code(), 1);
    assert_eq!(GridLookup::Stochastic.code(), 2);
    for lookup in [
        GridLookup::Trilinear,
        GridLookup::Nearest,
        GridLookup::Stochastic,
    ] {
        assert_eq!(GridLookup::from_code(lookup.code()), lookup);
    }
}

type Furnace = VolumeScene<HomogeneousMedium, NullBoundary, HenyeyGreenstein, ConstantEnvironment>;

/// A scene that differs from its neighbours in every number: a camera with distinct axes, an
/// off-centre box and the first settings above.
fn scene() -> Furnace {
    VolumeScene {
        camera: PerspectiveCamera {
            origin: Vec3::new(0.5, -1.0, -4.0),
            axis_x: Vec3::new(-1.0, 0.1, 0.0),
            axis_y: Vec3::new(0.05, 1.0, 0.2),
            axis_z: Vec3::new(0.0, -0.2, 1.0),
            tan_half_fov: Vec2::new(0.3, 0.225),
            width: 8,
            height: 6,
            // Not the default: the flag must survive the encoding too.
            orthographic: true,
        },
        bounds: Aabb::new(Vec3::new(-1.0, -0.5, 0.0), Vec3::new(2.0, 1.5, 3.0)),
        medium: HomogeneousMedium {
            sigma_t: 1.5,
            albedo: Vec3::new(0.9, 0.8, 0.7),
        },
        boundary: NullBoundary,
        phase: HenyeyGreenstein { g: 0.6 },
        environment: ConstantEnvironment(Vec3::new(0.25, 1.5, 3.0)),
        lights: volpt_core::Lights {
            sun: volpt_core::DirectionalLight::new(
                Vec3::new(0.3, -1.0, 0.2),
                0.1,
                Vec3::new(2.0, 1.5, 1.0),
            ),
            spot: volpt_core::SpotLight::spot(
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::new(0.0, -1.0, 0.1),
                Vec3::splat(5.0),
                0.5,
                0.3,
            ),
        },
        settings: settings()[0],
    }
}

/// Both dielectric boundaries through their device parameters: the relative index (and the rough
/// one's roughness) decoded again. The scene above has an index-matched boundary, which has none.
#[test]
fn dielectric_boundaries_survive_the_device_encoding() {
    let mut calls = Vec::new();
    let smooth = SmoothDielectric { eta: 1.33 };
    // SAFETY: the parameters hold no address.
    let decoded =
        unsafe { SmoothDielectric::from_params(&smooth.to_params(&mut recording(&mut calls))) };
    assert_eq!(decoded.eta, smooth.eta);
    let rough = RoughDielectric {
        eta: 1.05,
        distribution: volpt_core::microfacet::Ggx { alpha: 0.1 },
    };
    // SAFETY: as above.
    let decoded =
        unsafe { RoughDielectric::from_params(&rough.to_params(&mut recording(&mut calls))) };
    assert_eq!((decoded.eta, decoded.distribution.alpha), (1.05, 0.1));
    assert!(calls.is_empty(), "a boundary lives in its parameters alone");
}

/// The whole scene's parameters, decoded again: the very numbers (and, since `to_params` evaluates
/// the layout proof `SceneParams::LAYOUT`, a layout without padding).
#[test]
fn a_scene_survives_the_device_encoding() {
    let scene = scene();
    let mut calls = Vec::new();
    let params = scene.to_params(&mut recording(&mut calls));
    assert!(
        calls.is_empty(),
        "nothing of this scene lives in device memory"
    );
    // SAFETY: the parameters hold no address.
    let decoded = unsafe { Furnace::from_params(&params) };
    let (a, b) = (scene.camera, decoded.camera);
    assert_eq!(
        (a.origin, a.axis_x, a.axis_y, a.axis_z, a.tan_half_fov),
        (b.origin, b.axis_x, b.axis_y, b.axis_z, b.tan_half_fov)
    );
    assert_eq!((a.width, a.height), (b.width, b.height));
    assert_eq!(a.orthographic, b.orthographic);
    assert_eq!(decoded.bounds, scene.bounds);
    assert_eq!(decoded.settings, scene.settings);
    assert_eq!(decoded.medium.sigma_t, scene.medium.sigma_t);
    assert_eq!(decoded.medium.albedo, scene.medium.albedo);
    assert_eq!(decoded.phase.g, scene.phase.g);
    assert_eq!(decoded.environment.0, scene.environment.0);
    assert_eq!(decoded.lights, scene.lights);
}

/// The kernel entry point of a scene type is named by its parts, in registry order (medium,
/// boundary, phase, environment).
#[test]
fn a_scene_type_names_its_parts_in_registry_order() {
    assert_eq!(
        Furnace::names(),
        [
            "homogeneous",
            "index_matched",
            "henyey_greenstein",
            "constant"
        ]
    );
    type Other<'a> = VolumeScene<
        GridMedium<'a, GridAlbedo<'a>>,
        RoughDielectric,
        Isotropic,
        LatLongEnvironment<'a>,
    >;
    assert_eq!(
        Other::names(),
        [
            "grid_density__grid_albedo__dense_trilinear",
            "rough_dielectric",
            "isotropic",
            "lat_long"
        ]
    );
}

/// A generic part's name is composed from its type parameters' names, so every instantiation has
/// its own: a constant albedo read in any layout is not the grid albedo read so, nor the constant
/// albedo read dense.
#[test]
fn a_generic_part_is_named_by_its_parameters() {
    use volpt_core::{AnyLayout, ConstantAlbedo, DenseTrilinear};
    assert_eq!(
        <GridMedium<'static, ConstantAlbedo, AnyLayout> as Component>::NAME,
        "grid_density__constant_albedo__any_layout"
    );
    assert_eq!(
        <GridMedium<'static, GridAlbedo<'static, AnyLayout>, AnyLayout> as Component>::NAME,
        "grid_density__grid_albedo__any_layout"
    );
    assert_eq!(
        <GridMedium<'static, ConstantAlbedo, DenseTrilinear> as Component>::NAME,
        "grid_density__constant_albedo__dense_trilinear"
    );
}

/// A grid decoded from its parameters (the values left where they are, as a host uploader does)
/// looks up what the original does everywhere, with either lookup: a swapped scale and offset, a
/// lost bound or a lookup code read back wrongly changes the lookups.
#[test]
fn a_grid_survives_the_device_encoding() {
    let data: Vec<f32> = (0..60).map(|i| ((i * 37) % 17) as f32 * 0.25).collect();
    let res = [3, 4, 5];
    let bounds = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5));
    for mapping in [
        GridMapping::vertex_centred(bounds, res),
        GridMapping::cell_centred(bounds, res),
    ] {
        for lookup in [
            GridLookup::Trilinear,
            GridLookup::Nearest,
            GridLookup::Stochastic,
        ] {
            let grid: Grid<'_, 1> = Grid::new(&data, res, mapping).with_lookup(lookup);
            let mut in_place = |values: &[f32]| values.as_ptr() as u64;
            let params = GridParams::new(&grid, &mut in_place, GridPlacement::AnyLayout);
            assert_eq!(params.lookup, lookup.code());
            // SAFETY: `data` outlives `decoded` and holds `params.len` values.
            let decoded: Grid<'_, 1> = unsafe { params.grid() };
            assert_eq!(decoded.lookup, lookup);
            for i in 0..=20 {
                for j in 0..=6 {
                    let p = Vec3::new(
                        -1.5 + 0.25 * i as f32,
                        -0.2 + 0.3 * j as f32,
                        1.9 + 0.13 * (i + j) as f32,
                    );
                    assert_eq!(decoded.lookup(p), grid.lookup(p), "{lookup:?} at {p}");
                }
            }
        }
    }
}
