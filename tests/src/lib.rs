//! Shared helpers for the integration tests: small scenes built directly as descriptions, and
//! rendering them through the same factory and CPU backend the CLI uses; [`reference`] holds the
//! independent `f64` references they are compared with, [`compare`] the comparisons.

pub mod agreement;
pub mod compare;
pub mod generated;
pub mod reference;

use volpt_core::path::PathState;
use volpt_core::{Medium, PathSettings, Ray, Scene};
use volpt_render::{render, with_scene, Image, RenderOptions, RenderStats, SceneVisitor};
use volpt_scene::description::*;

/// A camera at `origin` looking at the world origin with `up` = +y, Mitsuba's `lookat`.
pub fn look_at(origin: [f32; 3]) -> Matrix4 {
    let o = glam_vec(origin);
    let dir = (-o).normalize();
    let left = glam::Vec3::Y.cross(dir).normalize();
    let up = dir.cross(left);
    [
        [left.x, up.x, dir.x, o.x],
        [left.y, up.y, dir.y, o.y],
        [left.z, up.z, dir.z, o.z],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

fn glam_vec(v: [f32; 3]) -> glam::Vec3 {
    glam::Vec3::from_array(v)
}

/// A `width` x `height` view of the unit cube [-0.5, 0.5]^3 from an oblique direction, so that
/// rays cross it through faces, edges and corners, with a constant environment of radiance `env`.
pub fn cube_scene(
    width: u32,
    height: u32,
    medium: MediumDesc,
    bsdf: BsdfDesc,
    env: f32,
) -> SceneDescription {
    SceneDescription {
        lights: Default::default(),
        camera: CameraDesc {
            to_world: look_at([2.0, 1.5, 2.5]),
            fov_degrees: 45.0,
            fov_axis: FovAxis::X,
            projection: Projection::Perspective,
        },
        film: FilmDesc { width, height },
        spp: 16,
        integrator: IntegratorDesc {
            max_depth: None,
            rr_depth: None,
        },
        boundary: BoundaryDesc {
            bounds: Bounds {
                min: [-0.5; 3],
                max: [0.5; 3],
            },
            bsdf,
            mesh: None,
        },
        medium,
        environment: EnvironmentDesc::Constant([env; 3]),
    }
}

pub fn homogeneous(sigma_t: f32, albedo: f32, phase: PhaseDesc) -> MediumDesc {
    MediumDesc {
        density: DensityDesc::Constant(sigma_t),
        scale: 1.0,
        albedo: AlbedoDesc::Constant([albedo; 3]),
        phase,
        lookup: Default::default(),
        storage: Default::default(),
    }
}

struct Cpu(RenderOptions);

impl SceneVisitor for Cpu {
    type Output = (Image, RenderStats);
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        render(scene, &self.0, &|_, _| {}).expect("render")
    }
}

/// The plain estimator the estimator tests compare against: path tracing, no roulette, depth
/// unlimited, a majorant grid of 16 cells along the box.
pub fn plain_path_tracing() -> PathSettings {
    PathSettings {
        max_depth: PathSettings::UNLIMITED,
        rr_depth: PathSettings::UNLIMITED,
        majorant_resolution: 16,
        estimator: volpt_core::Estimator::PathTracing,
        ..PathSettings::default()
    }
}

/// Renders `desc` on the CPU with `spp` samples and the scene's integrator settings.
pub fn render_cpu(desc: &SceneDescription, spp: u32, seed: u32) -> (Image, RenderStats) {
    render_with(desc, spp, seed, volpt_render::path_settings(desc))
}

pub fn render_with(
    desc: &SceneDescription,
    spp: u32,
    seed: u32,
    settings: PathSettings,
) -> (Image, RenderStats) {
    let options = RenderOptions {
        spp,
        seed,
        threads: None,
    };
    with_scene(desc, settings, Cpu(options))
}

/// Visits the built scene with a closure-like visitor, for tests that need the core scene itself.
pub fn with_core_scene<V: SceneVisitor>(desc: &SceneDescription, visitor: V) -> V::Output {
    with_scene(desc, volpt_render::path_settings(desc), visitor)
}

/// Per pixel and channel, the mean of the renderer's samples and the variance of that mean (the
/// sample variance over `spp`): the standard error every per-pixel window is derived from.
pub fn pixel_statistics(desc: &SceneDescription, spp: u32, seed: u32) -> Vec<[(f64, f64); 3]> {
    with_core_scene(desc, PixelStatistics { spp, seed })
}

/// [`pixel_statistics`] with the integrator settings `settings`.
pub fn pixel_statistics_with(
    desc: &SceneDescription,
    spp: u32,
    seed: u32,
    settings: PathSettings,
) -> Vec<[(f64, f64); 3]> {
    with_scene(desc, settings, PixelStatistics { spp, seed })
}

struct PixelStatistics {
    spp: u32,
    seed: u32,
}

impl SceneVisitor for PixelStatistics {
    type Output = Vec<[(f64, f64); 3]>;

    /// Rows are shared out over the available cores (pixels are independent: each has its own
    /// random streams, so the result does not depend on the number of threads).
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        let camera = scene.camera();
        let n = self.spp as f64;
        let pixel = |x: u32, y: u32| {
            let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
            for s in 0..self.spp {
                let mut path = PathState::from_camera(scene, x, y, s, self.seed);
                volpt_core::path::trace(scene, &mut path);
                for (c, v) in path.radiance.to_array().into_iter().enumerate() {
                    sum[c] += v as f64;
                    sum2[c] += v as f64 * v as f64;
                }
            }
            std::array::from_fn(|c| {
                let mean = sum[c] / n;
                let var = (sum2[c] / n - mean * mean).max(0.0) * n / (n - 1.0);
                (mean, var / n)
            })
        };
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
        let rows: Vec<Vec<[(f64, f64); 3]>> = std::thread::scope(|s| {
            let workers: Vec<_> = (0..threads)
                .map(|t| {
                    s.spawn(move || {
                        (t..camera.height)
                            .step_by(threads as usize)
                            .map(|y| (0..camera.width).map(|x| pixel(x, y)).collect())
                            .collect::<Vec<Vec<_>>>()
                    })
                })
                .collect();
            let done: Vec<Vec<Vec<_>>> = workers
                .into_iter()
                .map(|w| w.join().expect("worker"))
                .collect();
            (0..camera.height)
                .map(|y| done[(y % threads) as usize][(y / threads) as usize].clone())
                .collect()
        });
        rows.into_iter().flatten().collect()
    }
}

/// Per pixel, the mean over the renderer's own camera rays (same seed, so the same jittered rays)
/// of `L * exp(-tau)` along each ray, and the variance of the renderer's estimate of it: each path
/// either escapes unscattered with `L` (probability `T`) or is absorbed, so its variance is
/// `L^2 T (1 - T)`. tau is integrated by midpoint quadrature of the medium's own `sigma_t`.
struct ExpectedTransmittance {
    spp: u32,
    seed: u32,
    radiance: f32,
}

impl SceneVisitor for ExpectedTransmittance {
    type Output = (Vec<f64>, Vec<f64>);

    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        let camera = scene.camera();
        let (mut mean, mut var) = (Vec::new(), Vec::new());
        for y in 0..camera.height {
            for x in 0..camera.width {
                let (mut m, mut v) = (0.0f64, 0.0f64);
                for s in 0..self.spp {
                    let (_, t) = camera_ray_transmittance(scene, (x, y), s, self.seed, 4000);
                    m += t;
                    v += t * (1.0 - t);
                }
                let l = self.radiance as f64;
                let n = self.spp as f64;
                mean.push(l * m / n);
                var.push(l * l * v / (n * n));
            }
        }
        (mean, var)
    }
}

/// `image`, rendered from `desc` with `spp` samples and `seed`, is a pure absorber lit by `radiance`:
/// every pixel within 5 standard deviations of its expectation (5 sigma: a false alarm among 1024
/// pixels has probability below 1e-3), and the whole image within 4 standard errors, which a 1%
/// bias in transmittance would exceed by far.
pub fn assert_matches_transmittance(
    desc: &SceneDescription,
    image: &Image,
    radiance: f32,
    spp: u32,
    seed: u32,
) {
    let (mean, var) = with_scene(
        desc,
        volpt_render::path_settings(desc),
        ExpectedTransmittance {
            spp,
            seed,
            radiance,
        },
    );
    let (mut sum_diff, mut sum_var) = (0.0, 0.0);
    for (i, px) in image.pixels.iter().enumerate() {
        let sd = var[i].sqrt();
        for c in px {
            let diff = *c as f64 - mean[i];
            // 1 / spp covers the binomial's discreteness where the normal approximation is poor.
            let bound = 5.0 * sd + 1e-5 + if sd > 0.0 { 1.0 / spp as f64 } else { 0.0 };
            assert!(
                diff.abs() <= bound,
                "pixel {i}: {c} vs expected {} (sd {sd})",
                mean[i]
            );
        }
        sum_diff += px[0] as f64 - mean[i];
        sum_var += var[i];
    }
    // An image of rays that all miss or all cross an opaque medium has no variance: the per-pixel
    // bounds above then already ask for the exact values.
    if sum_var > 0.0 {
        let z = sum_diff / sum_var.sqrt();
        assert!(z.abs() < 4.0, "image-wide z = {z}");
    }
    let bias = sum_diff / mean.iter().sum::<f64>();
    assert!(bias.abs() < 0.01, "image-wide relative bias {bias}");
}

/// The camera ray of sample `sample` of pixel `(x, y)` (the very ray the renderer traces) and its
/// transmittance `exp(-tau)` through the medium, with `tau` by the midpoint rule in `steps` steps.
pub fn camera_ray_transmittance<S: Scene>(
    scene: &S,
    (x, y): (u32, u32),
    sample: u32,
    seed: u32,
    steps: u32,
) -> (Ray, f64) {
    let ray = PathState::from_camera(scene, x, y, sample, seed).ray;
    let transmittance = match scene.bounds().entry(&ray) {
        None => 1.0,
        Some(hit) => {
            let inner = Ray::new(hit.point, ray.dir);
            let exit = scene.bounds().exit(&inner);
            let dt = exit.t / steps as f32;
            let tau: f64 = (0..steps)
                .map(|i| {
                    let p = inner.at((i as f32 + 0.5) * dt);
                    scene.medium().sigma_t(p) as f64 * dt as f64
                })
                .sum();
            (-tau).exp()
        }
    };
    (ray, transmittance)
}
