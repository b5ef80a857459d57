//! A new scene source without touching the renderer: a procedural volume (a smooth spherical
//! shell) as a `SceneBuilder`, assembled with command-line style overrides and rendered on the CPU.
//!
//!     cargo run --release -p volpt-render --example procedural_source -- shell.exr

use std::path::PathBuf;

use volpt_render::{path_settings, render, with_scene, Image, RenderOptions, SceneVisitor};
use volpt_scene::{
    AlbedoDesc, BoundaryDesc, Bounds, BsdfDesc, CameraDesc, Config, DensityDesc, EnvironmentDesc,
    FilmDesc, FovAxis, GridConvention, GridDesc, IntegratorDesc, MediumDesc, PhaseDesc, Projection,
    SceneAssembler, SceneBuilder, SceneDescription, SceneError,
};

/// A shell of radius 0.35 and thickness ~0.1 in the unit cube, sampled on an `n`^3 grid.
struct Shell {
    n: u32,
}

impl SceneBuilder for Shell {
    fn source(&self) -> String {
        format!("procedural shell, {}^3", self.n)
    }

    fn build(&self, _params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        let n = self.n;
        let bounds = Bounds {
            min: [-0.5; 3],
            max: [0.5; 3],
        };
        let mut data = Vec::with_capacity((n * n * n) as usize);
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let p = [x, y, z].map(|i| (i as f32 + 0.5) / n as f32 - 0.5);
                    let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                    data.push((-((r - 0.35) / 0.05).powi(2)).exp());
                }
            }
        }
        let to_world = volpt_scene::toml_scene::look_at([2.0, 1.5, 3.0], [0.0; 3], [0.0, 1.0, 0.0])
            .expect("a valid camera");
        Ok(SceneDescription {
            lights: Default::default(),
            camera: CameraDesc {
                to_world,
                fov_degrees: 30.0,
                fov_axis: FovAxis::X,
                projection: Projection::Perspective,
            },
            film: FilmDesc {
                width: 256,
                height: 256,
            },
            spp: 64,
            integrator: IntegratorDesc {
                max_depth: None,
                rr_depth: Some(5),
            },
            boundary: BoundaryDesc {
                bounds,
                bsdf: BsdfDesc::Null,
                mesh: None,
            },
            medium: MediumDesc {
                density: DensityDesc::Grid(GridDesc {
                    layout: volpt_scene::SampleLayout::Dense,
                    resolution: [n; 3],
                    channels: 1,
                    bounds,
                    convention: GridConvention::Cell,
                    data,
                }),
                scale: 40.0,
                albedo: AlbedoDesc::Constant([0.95, 0.7, 0.4]),
                phase: PhaseDesc::HenyeyGreenstein { g: 0.3 },
                lookup: Default::default(),
                storage: Default::default(),
            },
            environment: EnvironmentDesc::Constant([1.0; 3]),
        })
    }
}

struct Cpu(RenderOptions);

impl SceneVisitor for Cpu {
    type Output = Result<Image, volpt_render::RenderError>;
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        render(scene, &self.0, &|_, _| {}).map(|(image, _)| image)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "shell.exr".into()),
    );
    // The same overrides `volpt render --spp 16 --resolution 128x128` would apply.
    let config = Config {
        spp: Some(16),
        resolution: Some((128, 128)),
        ..Config::default()
    };
    let desc = SceneAssembler::new(config).assemble(&Shell { n: 64 })?;
    let options = RenderOptions {
        spp: desc.spp,
        seed: 0,
        threads: None,
    };
    let image = with_scene(&desc, path_settings(&desc), Cpu(options))?;
    image.write_exr(&out)?;
    image.write_png(&volpt_render::image::preview_path(&out))?;
    println!("wrote {}", out.display());
    Ok(())
}
