//! Renders the smooth ball, a medium of this crate's own, with volpt: on the CPU by default, on a GPU
//! with `--cuda` after `cargo xtask ptx volpt-example-smooth-ball-kernels`.
//!
//!     cargo run --release -p volpt-example-smooth-ball --example render -- ball.exr \
//!         [--cuda [--strategy naive-sk|regeneration-sk] [--ptx FILE]] [--spp N]
//!
//! The render factory only builds the scene types of volpt's registry from scene files; a library
//! user assembles a `VolumeScene` of their own parts directly and hands it to a backend.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use volpt_core::{
    Aabb, ConstantEnvironment, HenyeyGreenstein, NullBoundary, PathSettings, PerspectiveCamera,
    Spectrum, Vec2, Vec3, VolumeScene,
};
use volpt_cuda::{CudaRenderer, Strategy};
use volpt_example_smooth_ball::SmoothBall;
use volpt_film::{preview_path, RenderOptions};

type BallScene = VolumeScene<SmoothBall, NullBoundary, HenyeyGreenstein, ConstantEnvironment>;

/// The PTX that `cargo xtask ptx volpt-example-smooth-ball-kernels` writes.
const PTX: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/kernels/ptx/volpt_example_smooth_ball_kernels.ptx"
);

fn scene(size: u32) -> BallScene {
    VolumeScene {
        // Looking down -z from z = 3 (camera space: +z forward, +y up, +x to the image's left).
        camera: PerspectiveCamera {
            origin: Vec3::new(0.0, 0.0, 3.0),
            axis_x: Vec3::new(-1.0, 0.0, 0.0),
            axis_y: Vec3::Y,
            axis_z: Vec3::new(0.0, 0.0, -1.0),
            tan_half_fov: Vec2::splat(0.2),
            width: size,
            height: size,
            orthographic: false,
        },
        bounds: Aabb::new(Vec3::splat(-0.5), Vec3::splat(0.5)),
        medium: SmoothBall {
            centre: Vec3::ZERO,
            radius: 0.45,
            sigma_max: 20.0,
            albedo: Spectrum::new(0.95, 0.8, 0.6),
        },
        boundary: NullBoundary,
        phase: HenyeyGreenstein { g: 0.5 },
        environment: ConstantEnvironment(Spectrum::ONE),
        lights: volpt_core::Lights::NONE,
        settings: PathSettings::default(),
    }
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let mut output = PathBuf::from("smooth-ball.exr");
    let (mut cuda, mut spp, mut ptx) = (false, 64, PathBuf::from(PTX));
    let mut strategy = Strategy::RegenerationSk;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--cuda" => cuda = true,
            "--spp" => spp = args.next().context("--spp needs a value")?.parse()?,
            "--ptx" => ptx = args.next().context("--ptx needs a file")?.into(),
            "--strategy" => {
                let name = args.next().context("--strategy needs a name")?;
                strategy = *Strategy::ALL
                    .iter()
                    .find(|s| s.name() == name)
                    .with_context(|| format!("unknown strategy {name}"))?;
            }
            a if a.starts_with('-') => bail!("unknown option {a}"),
            path => output = path.into(),
        }
    }
    let scene = scene(200);
    let options = RenderOptions {
        spp,
        seed: 0,
        threads: None,
    };
    let (image, stats) = if cuda {
        let ptx = std::fs::read_to_string(&ptx).with_context(|| {
            format!(
                "reading {}: run `cargo xtask ptx volpt-example-smooth-ball-kernels` first",
                ptx.display()
            )
        })?;
        let renderer = CudaRenderer::with_ptx(0, ptx)?;
        renderer.render(&scene, strategy, &options, &|_, _| {})?
    } else {
        volpt_render::render(&scene, &options, &|_, _| {})?
    };
    image.write_exr(&output)?;
    image.write_png(&preview_path(&output))?;
    println!(
        "{} spp in {:.3} s ({:.2} M paths/s): wrote {}",
        spp,
        stats.elapsed.as_secs_f64(),
        stats.paths_per_second() * 1e-6,
        output.display()
    );
    Ok(())
}
