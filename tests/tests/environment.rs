//! Lat-long environment maps (Mitsuba's `envmap`) through the whole renderer: Beer-Lambert against
//! the map seen along each camera ray, white furnaces in a map of constant radiance, and which
//! direction sees which texel (Mitsuba's uv convention, both row conventions).

use volpt_core::Component;
use volpt_core::{Environment, LatLongEnvironment, Vec3};
use volpt_render::factory::EnvironmentKind;
use volpt_render::{Image, Variant};
use volpt_scene::description::*;
use volpt_tests::compare::{absorber_expectation, assert_matches, coverage, Coverage};
use volpt_tests::reference::{RefCamera, RefMedium};
use volpt_tests::{cube_scene, homogeneous, render_cpu};

/// A `width` x `height` map whose texel `(x, y)` is `f(x, y)`.
fn map(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> LatLongDesc {
    let mut rgb = Vec::new();
    for y in 0..height {
        for x in 0..width {
            rgb.extend(f(x, y));
        }
    }
    LatLongDesc {
        width,
        height,
        rgb,
        to_world: IDENTITY,
        scale: 1.0,
        rows: LatLongRows::PoleToPole,
    }
}

/// Rotation by `degrees` about +y, counter-clockwise seen from +y (Mitsuba's `<rotate y="1">`).
fn rotate_y(degrees: f32) -> Matrix4 {
    let (s, c) = degrees.to_radians().sin_cos();
    [
        [c, 0.0, s, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [-s, 0.0, c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// A smoothly varying, strictly positive map with different content per channel.
fn wavy_map() -> LatLongDesc {
    map(64, 32, |x, y| {
        let (u, v) = (x as f32 / 64.0, y as f32 / 32.0);
        [
            1.0 + (std::f32::consts::TAU * u).sin() * 0.5,
            0.3 + v,
            0.2 + ((x * 7 + y * 3) % 5) as f32 * 0.2,
        ]
    })
}

#[test]
fn variant_names_the_environment() {
    let mut desc = cube_scene(
        4,
        4,
        homogeneous(1.0, 0.5, PhaseDesc::HenyeyGreenstein { g: 0.3 }),
        BsdfDesc::RoughDielectric {
            alpha: 0.1,
            int_ior: 1.5,
            ext_ior: 1.0,
        },
        1.0,
    );
    assert_eq!(
        Variant::of(&desc).to_string(),
        "homogeneous/rough_dielectric/henyey_greenstein/constant"
    );
    desc.environment = EnvironmentDesc::LatLong(wavy_map());
    let variant = Variant::of(&desc);
    assert_eq!(variant.environment, EnvironmentKind::LatLong);
    assert_eq!(
        variant.to_string(),
        "homogeneous/rough_dielectric/henyey_greenstein/lat_long"
    );
}

/// A pure absorber behind an index-matched boundary in a varying, rotated and scaled map: every
/// pixel channel that sees only the medium or only the map within 5 standard errors (plus the
/// quadrature error) of the independent reference `mean(L_env(dir) exp(-tau))` over the pixel
/// (own camera, box and lat-long lookup in f64), and each channel's sum within 5 standard errors.
/// Looking the map up along any other direction than the escaping ray's (or mixing up channels,
/// rows or the rotation) fails by far.
#[test]
fn absorber_in_an_envmap_transmits_beer_lambert() {
    const SPP: u32 = 256;
    let mut desc = cube_scene(
        24,
        24,
        homogeneous(1.5, 0.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    let mut env = wavy_map();
    env.to_world = rotate_y(30.0);
    env.scale = 0.8;
    desc.environment = EnvironmentDesc::LatLong(env);
    let (image, _) = render_cpu(&desc, SPP, 5);
    let camera = RefCamera::new(&desc.camera, &desc.film);
    let cover = coverage(&camera, &RefMedium::new(&desc).bounds);
    let expected = absorber_expectation(&desc, SPP, 1);
    assert_matches("absorber in a map", &image, &expected, |i| {
        cover[i] != Coverage::Silhouette
    });
}

fn constant_map(value: f32) -> LatLongDesc {
    let mut env = map(16, 8, |_, _| [value, 0.5 * value, 2.0 * value]);
    env.to_world = rotate_y(-70.0);
    env.scale = 1.25;
    env
}

fn assert_furnace(image: &Image, radiance: [f32; 3], tolerance: f32) {
    for (i, px) in image.pixels.iter().enumerate() {
        for (c, r) in px.iter().zip(radiance) {
            assert!(
                (c - r).abs() <= tolerance * r,
                "pixel {i}: {px:?} in a furnace of radiance {radiance:?}"
            );
        }
    }
}

/// Albedo 1 in a map of constant radiance: every path-traced path carries exactly that radiance
/// (times the map's scale), through index-matched and smooth dielectric boundaries. (NEE of a map
/// is compared with path tracing on envmap-cube in heterogeneous.rs.)
#[test]
fn white_furnace_in_a_constant_envmap() {
    let expected = [1.25 * 0.8, 1.25 * 0.4, 1.25 * 1.6];
    for bsdf in [
        BsdfDesc::Null,
        BsdfDesc::Dielectric {
            int_ior: 1.5,
            ext_ior: 1.0,
        },
    ] {
        let mut desc = cube_scene(
            16,
            16,
            homogeneous(10.0, 1.0, PhaseDesc::HenyeyGreenstein { g: 0.5 }),
            bsdf,
            1.0,
        );
        desc.environment = EnvironmentDesc::LatLong(constant_map(0.8));
        let settings = volpt_core::PathSettings {
            estimator: volpt_core::Estimator::PathTracing,
            ..volpt_render::path_settings(&desc)
        };
        let (image, stats) = volpt_tests::render_with(&desc, 16, 3, settings);
        assert_eq!(stats.counters.truncated, 0);
        assert_furnace(&image, expected, 1e-4);
    }
}

/// Through a GGX boundary with alpha -> 0 the furnace holds two-sided on the image mean (see
/// `white_furnace_rough_dielectric` in analytic.rs for why only there).
#[test]
fn white_furnace_in_a_constant_envmap_rough_dielectric() {
    let mut desc = cube_scene(
        32,
        32,
        homogeneous(10.0, 1.0, PhaseDesc::Isotropic),
        BsdfDesc::RoughDielectric {
            alpha: 1e-3,
            int_ior: 1.05,
            ext_ior: 1.01,
        },
        1.0,
    );
    desc.environment = EnvironmentDesc::LatLong(constant_map(0.8));
    let (image, stats) = render_cpu(&desc, 64, 5);
    assert_eq!(stats.counters.truncated, 0);
    let expected = [1.25 * 0.8, 1.25 * 0.4, 1.25 * 1.6];
    for (c, r) in expected.into_iter().enumerate() {
        let values: Vec<f64> = image.pixels.iter().map(|p| p[c] as f64).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let se = (var / n).sqrt();
        assert!(
            (mean - r).abs() <= 4.0 * se + 1e-4 * r,
            "channel {c}: {mean} +- {se}, expected {r}"
        );
    }
}

/// A camera at the origin looking along `dir` (with `up` not parallel to it) through one pixel of a
/// 1-degree field of view, far from the medium, so that it sees the environment only.
fn looking(dir: [f32; 3], up: [f32; 3], env: &LatLongDesc) -> [f32; 3] {
    let mut desc = cube_scene(
        1,
        1,
        homogeneous(1.0, 0.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    desc.boundary.bounds = Bounds {
        min: [50.0; 3],
        max: [51.0; 3],
    };
    let d = Vec3::from_array(dir);
    let left = Vec3::from_array(up).cross(d).normalize();
    let up = d.cross(left);
    desc.camera.to_world = [
        [left.x, up.x, d.x, 0.0],
        [left.y, up.y, d.y, 0.0],
        [left.z, up.z, d.z, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    desc.camera.fov_degrees = 1.0;
    desc.environment = EnvironmentDesc::LatLong(env.clone());
    render_cpu(&desc, 4, 1).0.pixels[0]
}

/// Mitsuba's convention: `u = atan2(d.x, -d.z) / 2 pi`, `v = acos(d.y) / pi`, the top row at +y.
/// On an 8 x 6 map, +x is `u = 1/4` (between columns 1 and 2) and the equator is between rows 2 and
/// 3 in both row conventions; -z is the seam `u = 0`, +z is `u = 1/2`, -x is `u = 3/4`. Red marks
/// columns 1-2 of rows 2-3, green the top two rows (the pole and its neighbour, which a ray half a
/// degree off the pole also reads in Mitsuba 3's convention): +x must see red only, +y green only, every other
/// axis neither. Rotating the map by 90 degrees about +y takes its +x to world -z.
#[test]
fn directions_see_the_texels_of_mitsubas_uv_convention() {
    let mut env = map(8, 6, |x, y| {
        let red = if (1..=2).contains(&x) && (2..=3).contains(&y) {
            5.0
        } else {
            0.0
        };
        let green = if y <= 1 { 3.0 } else { 0.0 };
        [red, green, 0.0]
    });
    let axes: [([f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, -1.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
    ];
    for rows in [LatLongRows::PoleToPole, LatLongRows::CellCentred] {
        env.rows = rows;
        for (to_world, red_at) in [
            (IDENTITY, [1.0, 0.0, 0.0]),
            (rotate_y(90.0), [0.0, 0.0, -1.0]),
        ] {
            env.to_world = to_world;
            for (dir, up) in axes {
                let seen = looking(dir, up, &env);
                let red = if dir == red_at { 5.0 } else { 0.0 };
                let green = if dir == [0.0, 1.0, 0.0] { 3.0 } else { 0.0 };
                for (s, e) in seen.iter().zip([red, green, 0.0]) {
                    assert!(
                        (s - e).abs() < 1e-3,
                        "{rows:?}, to_world {to_world:?}: looking along {dir:?} saw {seen:?}, \
                         expected {:?}",
                        [red, green, 0.0]
                    );
                }
            }
        }
    }
}

/// The row conventions differ between the poles: rows valued 0, 1, 2, 3 seen 45 degrees below +y
/// (`v = 1/4`) read 0.5 where rows sit at cell centres (Mitsuba 0.6: row `4 v - 0.5`) and 0.75 where
/// the outer rows lie on the poles (Mitsuba 3: row `3 v`).
#[test]
fn row_conventions_place_rows_as_mitsuba_does() {
    let rgb: Vec<f32> = (0..4)
        .flat_map(|y| std::iter::repeat_n([y as f32; 3], 8).flatten())
        .collect();
    let identity = [Vec3::X, Vec3::Y, Vec3::Z];
    let dir = Vec3::new(1.0, 1.0, 0.0).normalize();
    for (rows, expected) in [
        (volpt_core::LatLongRows::CellCentred, 0.5),
        (volpt_core::LatLongRows::PoleToPole, 0.75),
    ] {
        let env = LatLongEnvironment::new(&rgb, 8, 4, rows, identity, 1.0);
        let seen = env.radiance(dir);
        assert!((seen.x - expected).abs() < 1e-5, "{rows:?}: {seen}");
    }
}

/// What a GPU kernel rebuilds from launch parameters is the host's map, field for field: here the
/// "device address" is the host slice itself.
#[test]
fn launch_parameters_carry_the_map() {
    let rgb: Vec<f32> = (0..8 * 4 * 3).map(|i| i as f32 * 0.25).collect();
    let to_map = [Vec3::new(0.0, 0.0, 1.0), Vec3::Y, Vec3::new(-1.0, 0.0, 0.0)];
    let env = LatLongEnvironment::new(
        &rgb,
        8,
        4,
        volpt_core::LatLongRows::CellCentred,
        to_map,
        1.5,
    );
    let mut uploads = 0;
    let params = env.to_params(&mut |values: &[f32]| {
        uploads += 1;
        values.as_ptr() as u64
    });
    assert_eq!(uploads, 1);
    // SAFETY: the address is `rgb`'s, alive for the whole test.
    let back = unsafe { LatLongEnvironment::from_params(&params) };
    assert_eq!(back.rgb, &rgb[..]);
    assert_eq!(
        (back.width, back.height, back.world_to_map, back.scale),
        (8, 4, to_map, 1.5)
    );
    assert_eq!(
        (back.row_scale, back.row_offset),
        (env.row_scale, env.row_offset)
    );
    for dir in [Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize(), -Vec3::Z] {
        assert_eq!(back.radiance(dir), env.radiance(dir));
    }
}
