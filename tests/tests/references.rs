//! The renderer against references that share none of its code (`volpt_tests::reference`: own `f64`
//! camera, box, trilinear grid, environment map and single-scattering integral, built from the scene
//! description). Every window is the renderer's own standard error (5 sigma per pixel) plus the
//! reference's quadrature error, estimated as the difference between two quadrature orders.

use glam::DVec3;
use volpt_scene::description::*;
use volpt_tests::reference::{
    gauss_legendre, single_scattered_radiance, Orders, RefCamera, RefEnvironment, RefMedium,
};
use volpt_tests::{look_at, pixel_statistics, render_cpu};

/// Per-pixel windows in standard errors: a false alarm among the ~1000 pixel channels of a test
/// has probability below 1e-3.
const Z_PIXEL: f64 = 5.0;

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
        camera: CameraDesc {
            to_world: look_at(camera_at),
            fov_degrees: fov,
            fov_axis: FovAxis::X,
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
        },
        medium,
        environment,
    }
}

/// The reference for every pixel at two quadrature orders: `(fine, |fine - coarse|)`.
fn reference_image(
    desc: &SceneDescription,
    radiance: impl Fn(DVec3, bool) -> DVec3 + Sync,
    (fine, coarse): (usize, usize),
) -> Vec<(DVec3, DVec3)> {
    let camera = RefCamera::new(&desc.camera, &desc.film);
    let (fine, coarse) = (gauss_legendre(fine), gauss_legendre(coarse));
    let pixels: Vec<(u32, u32)> = (0..camera.height)
        .flat_map(|y| (0..camera.width).map(move |x| (x, y)))
        .collect();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = pixels.len().div_ceil(threads);
    std::thread::scope(|s| {
        let workers: Vec<_> = pixels
            .chunks(chunk)
            .map(|part| {
                let (camera, radiance, fine, coarse) = (&camera, &radiance, &fine, &coarse);
                s.spawn(move || {
                    part.iter()
                        .map(|&(x, y)| {
                            let f = camera.pixel_mean(x, y, fine, |d| radiance(d, true));
                            let c = camera.pixel_mean(x, y, coarse, |d| radiance(d, false));
                            (f, (f - c).abs())
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("reference worker"))
            .collect()
    })
}

/// Whether all of pixel `(x, y)`, corners included, sees the box (the box is convex, so its
/// corners suffice).
fn sees_medium_everywhere(camera: &RefCamera, medium: &RefMedium, x: u32, y: u32) -> bool {
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .iter()
        .all(|&(fx, fy)| {
            let d = camera.direction(x as f64 + fx, y as f64 + fy);
            medium.bounds.interval(camera.origin, d).is_some()
        })
}

/// Per pixel and channel `|image - reference| <= 5 se + quadrature error`, and over all checked
/// pixel channels the summed difference within 5 of its standard errors (plus the summed
/// quadrature errors). Returns the image-wide z for the report.
fn assert_matches(
    what: &str,
    image: &volpt_render::Image,
    stats: &[[(f64, f64); 3]],
    reference: &[(DVec3, DVec3)],
    checked: impl Fn(usize) -> bool,
) -> f64 {
    let (mut sum_diff, mut sum_var, mut sum_quadrature, mut count) = (0.0, 0.0, 0.0, 0);
    for (i, px) in image.pixels.iter().enumerate() {
        if !checked(i) {
            continue;
        }
        let (expected, quadrature) = reference[i];
        for c in 0..3 {
            let diff = px[c] as f64 - expected[c];
            let se = stats[i][c].1.sqrt();
            let bound = Z_PIXEL * se + quadrature[c] + 1e-6 * expected[c];
            assert!(
                diff.abs() <= bound,
                "{what}: pixel {i} channel {c}: {} vs reference {} (se {se}, quadrature {})",
                px[c],
                expected[c],
                quadrature[c]
            );
            sum_diff += diff;
            sum_var += stats[i][c].1;
            sum_quadrature += quadrature[c];
            count += 1;
        }
    }
    assert!(count > 0, "{what}: no pixel checked");
    let z = sum_diff / sum_var.sqrt();
    assert!(
        sum_diff.abs() <= 5.0 * sum_var.sqrt() + sum_quadrature,
        "{what}: summed difference {sum_diff} (z = {z}) over {count} pixel channels"
    );
    z
}

/// Single scattering (`max_depth = 2`) of a thin Henyey-Greenstein medium under a sky that is
/// bright above: forward (g = 0.7) and backward (g = -0.7) scattering send the camera light from
/// opposite sides of the sky, so sampling the phase function about the wrong direction, a wrong
/// albedo or channel, or a wrong transmittance fails many pixels. The camera looks down at the
/// cube, which fills the frame (no silhouette, so the pixel integrals are smooth).
#[test]
fn single_scattering_matches_numerical_integration() {
    for (g, seed) in [(0.7f32, 21), (-0.7, 22)] {
        let medium = MediumDesc {
            density: DensityDesc::Constant(1.6),
            scale: 0.5,
            albedo: AlbedoDesc::Constant([0.9, 0.7, 0.5]),
            phase: PhaseDesc::HenyeyGreenstein { g },
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
        let all_hit = (0..camera.height).all(|y| {
            (0..camera.width).all(|x| sees_medium_everywhere(&camera, &reference_medium, x, y))
        });
        assert!(all_hit, "the cube must fill the frame");
        let reference = reference_image(
            &desc,
            |d, fine| {
                let orders = if fine {
                    Orders {
                        along: 8,
                        cosine: 16,
                        azimuth: 24,
                        steps: 1,
                    }
                } else {
                    Orders {
                        along: 4,
                        cosine: 8,
                        azimuth: 12,
                        steps: 1,
                    }
                };
                single_scattered_radiance(&reference_medium, &env, camera.origin, d, orders)
            },
            (3, 2),
        );
        const SPP: u32 = 1024;
        let (image, _) = render_cpu(&desc, SPP, seed);
        let stats = pixel_statistics(&desc, SPP, seed);
        let z = assert_matches(&format!("g = {g}"), &image, &stats, &reference, |_| true);
        eprintln!("single scattering g = {g}: image-wide z = {z:.2}");
    }
}

/// An 8^3 density grid whose middle 4^3 samples sit at the maximum (so that rays cross a plateau
/// of extinction equal to the majorant) and whose other samples vary between 0.1 and 0.5 of it.
fn plateau_grid(convention: GridConvention) -> GridDesc {
    let n = 8u32;
    let mut data = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let core = [x, y, z].iter().all(|&i| (2..=5).contains(&i));
                data.push(if core {
                    1.0
                } else {
                    0.1 + 0.1 * ((x * 3 + y * 5 + z * 7) % 5) as f32
                });
            }
        }
    }
    GridDesc {
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
/// extinction lets too much light through exactly there.
#[test]
fn grid_absorber_matches_independent_beer_lambert() {
    const SPP: u32 = 256;
    for (convention, seed) in [(GridConvention::Vertex, 31), (GridConvention::Cell, 32)] {
        let medium = MediumDesc {
            density: DensityDesc::Grid(plateau_grid(convention)),
            scale: 4.0,
            albedo: AlbedoDesc::Constant([0.0; 3]),
            phase: PhaseDesc::Isotropic,
        };
        let radiance = 1.5;
        let desc = scene(
            [2.0, 1.5, 2.5],
            28.0,
            (28, 24),
            medium,
            EnvironmentDesc::Constant([radiance; 3]),
        );
        let reference_medium = RefMedium::new(&desc);
        let camera = RefCamera::new(&desc.camera, &desc.film);
        let reference = reference_image(
            &desc,
            |d, fine| {
                let steps = if fine { 800 } else { 400 };
                let t = reference_medium.transmittance_to_exit(camera.origin, d, steps);
                DVec3::splat(radiance as f64 * t)
            },
            (4, 3),
        );
        let in_medium: Vec<bool> = (0..camera.height)
            .flat_map(|y| (0..camera.width).map(move |x| (x, y)))
            .map(|(x, y)| sees_medium_everywhere(&camera, &reference_medium, x, y))
            .collect();
        let seen = in_medium.iter().filter(|&&m| m).count();
        assert!(seen > 200, "{seen} pixels see the medium");
        let (image, _) = render_cpu(&desc, SPP, seed);
        let stats: Vec<[(f64, f64); 3]> = reference
            .iter()
            .map(|(mean, _)| {
                let t = mean.x / radiance as f64;
                let var = (radiance as f64).powi(2) * t * (1.0 - t) / SPP as f64;
                [(mean.x, var); 3]
            })
            .collect();
        let what = format!("{convention:?} grid");
        let z = assert_matches(&what, &image, &stats, &reference, |i| in_medium[i]);
        let (rendered, expected) = in_medium
            .iter()
            .enumerate()
            .filter(|(_, &m)| m)
            .fold((0.0, 0.0), |(r, e), (i, _)| {
                (r + image.pixels[i][0] as f64, e + reference[i].0.x)
            });
        let bias = rendered / expected - 1.0;
        assert!(
            bias.abs() < 0.01,
            "{what}: relative bias {bias} over the medium"
        );
        eprintln!("Beer-Lambert {what}: z = {z:.2}, relative bias {bias:.4}");
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
        },
        EnvironmentDesc::Constant([1.0; 3]),
    );
    desc.boundary.bounds = Bounds {
        min: [-1.6, 0.3, -0.5],
        max: [-0.4, 1.4, 0.5],
    };
    let box_ = RefMedium::new(&desc).bounds;
    let camera = RefCamera::new(&desc.camera, &desc.film);
    let (image, _) = render_cpu(&desc, 16, 3);
    let (mut dark, mut bright) = (0, 0);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let hits = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(fx, fy)| {
                    let d = camera.direction(x as f64 + fx, y as f64 + fy);
                    box_.interval(camera.origin, d).is_some()
                })
                .iter()
                .filter(|&&h| h)
                .count();
            let value = image.pixel(x, y)[0];
            match hits {
                4 => {
                    assert!(
                        value < 1e-3,
                        "pixel ({x}, {y}) sees the opaque box: {value}"
                    );
                    dark += 1;
                    assert!(x < camera.width / 2 && y < camera.height / 2);
                }
                0 => {
                    assert_eq!(value, 1.0, "pixel ({x}, {y}) misses the box");
                    bright += 1;
                }
                _ => {}
            }
        }
    }
    assert!(dark >= 10 && bright >= 200, "{dark} dark, {bright} bright");
}
