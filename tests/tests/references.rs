//! The renderer against references that share none of its code (`volpt_tests::reference`: own `f64`
//! camera, box, trilinear grid, environment map and single-scattering integral, built from the scene
//! description). Every window is the renderer's own standard error (5 sigma per pixel) plus the
//! reference's quadrature error, estimated as the difference between two quadrature orders.

use glam::DVec3;
use volpt_scene::description::*;
use volpt_tests::compare::{
    absorber_expectation, assert_matches, coverage, per_pixel, relative_bias, Coverage, Expected,
    Moments,
};
use volpt_tests::reference::{
    single_scattered_radiance, Orders, RefCamera, RefEnvironment, RefMedium,
};
use volpt_tests::{look_at, pixel_statistics, render_cpu};

/// A lat-long map (Mitsuba 3 rows) that is bright towards +y and dim below the horizon, and brighter
/// towards -z than +z, with a different profile per channel.
fn sky() -> LatLongDesc {
    let (width, height) = (16u32, 17u32);
    let mut rgb = Vec::new();
    for j in 0..height {
        let up = (std::f32::consts::PI * j as f32 / (height - 1) as f32).cos();
        for i in 0..width {
            let azimuth = (std::f32::consts::TAU * (i as f32 + 0.5) / width as f32).cos();
            let bright = up.max(0.0).powi(2) * (1.0 + 0.5 * azimuth);
            rgb.extend([0.05 + 4.0 * bright, 0.05 + 2.5 * bright, 0.1 + bright]);
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

fn unit_cube() -> Bounds {
    Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    }
}

fn scene(
    camera_at: [f32; 3],
    fov: f32,
    (width, height): (u32, u32),
    medium: MediumDesc,
    environment: EnvironmentDesc,
) -> SceneDescription {
    SceneDescription {
        lights: Default::default(),
        camera: CameraDesc {
            to_world: look_at(camera_at),
            fov_degrees: fov,
            fov_axis: FovAxis::X,
            projection: Projection::Perspective,
        },
        film: FilmDesc { width, height },
        spp: 1,
        integrator: IntegratorDesc {
            max_depth: None,
            rr_depth: None,
        },
        boundary: BoundaryDesc {
            bounds: unit_cube(),
            bsdf: BsdfDesc::Null,
            mesh: None,
        },
        medium,
        environment,
    }
}

/// Single scattering (`max_depth = 2`) of a thin Henyey-Greenstein medium under a sky that is
/// bright above: forward (g = 0.7) and backward (g = -0.7) scattering send the camera light from
/// opposite sides of the sky, so sampling the phase function about the wrong direction, a wrong
/// albedo or channel, or a wrong transmittance fails many pixels. The camera looks down at the
/// cube, which fills the frame (no silhouette, so the pixel integrals are smooth). A third case has
/// grid extinction with a constant albedo (the other medium variant that scatters).
#[test]
fn single_scattering_matches_numerical_integration() {
    let cases = [
        (0.7f32, 21, DensityDesc::Constant(1.6)),
        (-0.7, 22, DensityDesc::Constant(1.6)),
        (0.7, 23, DensityDesc::Grid(smooth_grid())),
    ];
    for (g, seed, density) in cases {
        let grid = matches!(density, DensityDesc::Grid(_));
        let medium = MediumDesc {
            density,
            scale: 0.5,
            albedo: AlbedoDesc::Constant([0.9, 0.7, 0.5]),
            phase: PhaseDesc::HenyeyGreenstein { g },
            lookup: Default::default(),
            storage: Default::default(),
        };
        let mut desc = scene(
            [0.5, 1.3, 1.9],
            16.0,
            (20, 14),
            medium,
            EnvironmentDesc::LatLong(sky()),
        );
        desc.integrator.max_depth = Some(2);
        let reference_medium = RefMedium::new(&desc);
        let env = RefEnvironment::new(&desc.environment);
        let camera = RefCamera::new(&desc.camera, &desc.film);
        assert!(
            coverage(&camera, &reference_medium.bounds)
                .iter()
                .all(|&c| c == Coverage::Medium),
            "the cube must fill the frame"
        );
        let reference = per_pixel(&camera, (3, 2), |d, fine| {
            // Grid media need optical depths by steps along every direction: fewer of them.
            let orders = match (fine, grid) {
                (true, false) => Orders {
                    along: 8,
                    cosine: 16,
                    azimuth: 24,
                    steps: 1,
                },
                (false, false) => Orders {
                    along: 4,
                    cosine: 8,
                    azimuth: 12,
                    steps: 1,
                },
                (true, true) => Orders {
                    along: 6,
                    cosine: 12,
                    azimuth: 16,
                    steps: 24,
                },
                (false, true) => Orders {
                    along: 3,
                    cosine: 6,
                    azimuth: 8,
                    steps: 12,
                },
            };
            Moments {
                first: single_scattered_radiance(&reference_medium, &env, camera.origin, d, orders),
                second: DVec3::ZERO,
            }
        });
        const SPP: u32 = 1024;
        let (image, _) = render_cpu(&desc, SPP, seed);
        let stats = pixel_statistics(&desc, SPP, seed);
        let expected: Vec<Expected> = reference
            .iter()
            .zip(&stats)
            .map(|((fine, coarse), s)| Expected {
                mean: fine.first,
                variance: DVec3::from_array(s.map(|(_, var)| var)),
                quadrature: (fine.first - coarse.first).abs(),
            })
            .collect();
        let what = format!("g = {g}, {}", if grid { "grid" } else { "homogeneous" });
        let z = assert_matches(&what, &image, &expected, |_| true);
        eprintln!("single scattering {what}: image-wide z per channel {z:.2?}");
    }
}

/// A smoothly varying 4^3 density grid (grid extinction with a constant albedo).
fn smooth_grid() -> GridDesc {
    let n = 4u32;
    let mut data = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                data.push(0.8 + 0.2 * ((x + 2 * y + 3 * z) % 4) as f32);
            }
        }
    }
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [n; 3],
        channels: 1,
        bounds: unit_cube(),
        convention: GridConvention::Vertex,
        data,
    }
}

/// An 8^3 density grid whose inner 6^3 samples sit at the maximum (so that rays cross a plateau of
/// extinction equal to the majorant over most of their length in the medium) and whose outer
/// samples lie between 0.05 and 0.25 of it.
fn plateau_grid(convention: GridConvention) -> GridDesc {
    let n = 8u32;
    let mut data = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let core = [x, y, z].iter().all(|&i| (1..=6).contains(&i));
                data.push(if core {
                    1.0
                } else {
                    0.05 + 0.05 * ((x * 3 + y * 5 + z * 7) % 5) as f32
                });
            }
        }
    }
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [n; 3],
        channels: 1,
        bounds: unit_cube(),
        convention,
        data,
    }
}

/// Beer-Lambert through a pure absorber whose grid has a plateau at its maximum density, seen from
/// an oblique camera, restricted to the pixels that see the medium all over (the background would
/// dilute a bias): each pixel's expectation is `L * mean(exp(-tau))` over the pixel, its variance
/// `L^2 T (1 - T) / spp` (a path escapes unscattered or is absorbed). A majorant below the plateau's
/// extinction lets too much light through exactly there: 10% too low, it moves the sum of the
/// plateau's pixels by many standard errors (the plateau's optical depth, about 2, maximises the
/// signal-to-noise ratio of `T (exp(0.1 tau) - 1) / sqrt(T (1 - T))`).
#[test]
fn grid_absorber_matches_independent_beer_lambert() {
    const SPP: u32 = 1024;
    for (convention, seed) in [(GridConvention::Vertex, 31), (GridConvention::Cell, 32)] {
        let medium = MediumDesc {
            density: DensityDesc::Grid(plateau_grid(convention)),
            scale: 2.5,
            albedo: AlbedoDesc::Constant([0.0; 3]),
            phase: PhaseDesc::Isotropic,
            lookup: Default::default(),
            storage: Default::default(),
        };
        let desc = scene(
            [2.0, 1.5, 2.5],
            28.0,
            (28, 24),
            medium,
            EnvironmentDesc::Constant([1.5; 3]),
        );
        let camera = RefCamera::new(&desc.camera, &desc.film);
        let cover = coverage(&camera, &RefMedium::new(&desc).bounds);
        let seen = cover.iter().filter(|&&c| c == Coverage::Medium).count();
        assert!(seen > 200, "{seen} pixels see the medium");
        let expected = absorber_expectation(&desc, SPP, 800);
        let (image, _) = render_cpu(&desc, SPP, seed);
        let what = format!("{convention:?} grid");
        let in_medium = |i: usize| cover[i] == Coverage::Medium;
        let z = assert_matches(&what, &image, &expected, in_medium);
        let bias = relative_bias(&image, &expected, in_medium);
        assert!(
            bias.abs() < 0.01,
            "{what}: relative bias {bias} over the medium"
        );
        eprintln!(
            "Beer-Lambert {what}: z = {:.2}, relative bias {bias:.4}",
            z[0]
        );
    }
}

/// An opaque box in the upper left of the view (world +y is up, and the camera looks along -z, so
/// world -x is to the left): pixels that see it are black, pixels that miss it show the
/// environment, wherever the reference camera says they are. A flipped or mirrored image fails.
#[test]
fn image_orientation_matches_the_reference_camera() {
    let mut desc = scene(
        [0.0, 0.0, 4.0],
        60.0,
        (24, 16),
        MediumDesc {
            density: DensityDesc::Constant(200.0),
            scale: 1.0,
            albedo: AlbedoDesc::Constant([0.0; 3]),
            phase: PhaseDesc::Isotropic,
            lookup: Default::default(),
            storage: Default::default(),
        },
        EnvironmentDesc::Constant([1.0; 3]),
    );
    desc.boundary.bounds = Bounds {
        min: [-1.6, 0.3, -0.5],
        max: [-0.4, 1.4, 0.5],
    };
    let camera = RefCamera::new(&desc.camera, &desc.film);
    let cover = coverage(&camera, &RefMedium::new(&desc).bounds);
    let (image, _) = render_cpu(&desc, 16, 3);
    let (mut dark, mut bright) = (0, 0);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let value = image.pixel(x, y)[0];
            match cover[(y * camera.width + x) as usize] {
                Coverage::Medium => {
                    assert!(
                        value < 1e-3,
                        "pixel ({x}, {y}) sees the opaque box: {value}"
                    );
                    assert!(x < camera.width / 2 && y < camera.height / 2);
                    dark += 1;
                }
                Coverage::Background => {
                    assert_eq!(value, 1.0, "pixel ({x}, {y}) misses the box");
                    bright += 1;
                }
                Coverage::Silhouette => {}
            }
        }
    }
    assert!(dark >= 10 && bright >= 200, "{dark} dark, {bright} bright");
}
