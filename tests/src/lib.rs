//! Shared helpers for the integration tests: small scenes built directly as descriptions, and
//! rendering them through the same factory and CPU backend the CLI uses; [`reference`] holds the
//! independent `f64` references they are compared with, [`compare`] the comparisons.

pub mod compare;
pub mod reference;

use volpt_core::path::PathState;
use volpt_core::{PathSettings, Scene};
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
        camera: CameraDesc {
            to_world: look_at([2.0, 1.5, 2.5]),
            fov_degrees: 45.0,
            fov_axis: FovAxis::X,
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
    }
}

struct Cpu(RenderOptions);

impl SceneVisitor for Cpu {
    type Output = (Image, RenderStats);
    fn visit<S: Scene + Sync + volpt_core::launch::ToParams>(self, scene: &S) -> Self::Output {
        render(scene, &self.0, &|_, _| {}).expect("render")
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

struct PixelStatistics {
    spp: u32,
    seed: u32,
}

impl SceneVisitor for PixelStatistics {
    type Output = Vec<[(f64, f64); 3]>;

    fn visit<S: Scene + Sync + volpt_core::launch::ToParams>(self, scene: &S) -> Self::Output {
        let camera = scene.camera();
        let n = self.spp as f64;
        let mut out = Vec::new();
        for y in 0..camera.height {
            for x in 0..camera.width {
                let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
                for s in 0..self.spp {
                    let mut path = PathState::from_camera(scene, x, y, s, self.seed);
                    volpt_core::path::trace(scene, &mut path);
                    for (c, v) in path.radiance.to_array().into_iter().enumerate() {
                        sum[c] += v as f64;
                        sum2[c] += v as f64 * v as f64;
                    }
                }
                out.push(std::array::from_fn(|c| {
                    let mean = sum[c] / n;
                    let var = (sum2[c] / n - mean * mean).max(0.0) * n / (n - 1.0);
                    (mean, var / n)
                }));
            }
        }
        out
    }
}
