//! `volpt`: render solid participating media from Mitsuba scene files.

mod info;

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use tracing_subscriber::EnvFilter;
use volpt_core::Scene;
use volpt_render::image::preview_path;
use volpt_render::{
    path_settings, render, with_scene, Image, RenderOptions, RenderStats, SceneVisitor, Variant,
};
use volpt_scene::SceneDescription;

#[derive(Parser)]
#[command(name = "volpt", version, about = "A path tracer for solid participating media")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to OpenEXR, with a PNG preview beside it.
    Render(RenderArgs),
    /// Print what a scene file loads to, and the variant it renders with.
    Info(SceneArgs),
}

#[derive(Args)]
struct SceneArgs {
    /// Mitsuba XML scene file.
    scene: PathBuf,
    /// Scene parameter, as Mitsuba's `-D name=value` (fills `$name` and overrides `<default>`).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_param)]
    params: Vec<(String, String)>,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output OpenEXR file; the PNG preview gets the same name with `.png`.
    #[arg(short, long, default_value = "out.exr")]
    output: PathBuf,
    /// Samples per pixel (default: the scene's sampler).
    #[arg(long)]
    spp: Option<u32>,
    /// Seed of the random streams: the same seed gives the same image on every backend.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

fn parse_param(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((name, value)) if !name.is_empty() => Ok((name.to_owned(), value.to_owned())),
        _ => Err(format!("expected NAME=VALUE, found {s:?}")),
    }
}

fn main() -> Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(
            EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("info")),
        )
        .with_writer(std::io::stderr)
        .init();
    match Cli::parse().command {
        Command::Render(args) => render_command(args),
        Command::Info(args) => {
            let desc = load(&args)?;
            print!("{}", info::describe(&args.scene, &desc));
            Ok(())
        }
    }
}

fn load(args: &SceneArgs) -> Result<SceneDescription> {
    Ok(volpt_scene::load_mitsuba_with(&args.scene, &args.params)?)
}

fn render_command(args: RenderArgs) -> Result<()> {
    let desc = load(&args.scene)?;
    let options = RenderOptions {
        spp: args.spp.unwrap_or(desc.spp),
        seed: args.seed,
        threads: args.threads,
    };
    if options.threads == Some(0) {
        bail!("--threads must be at least 1");
    }
    let variant = Variant::of(&desc);
    tracing::info!(
        scene = %args.scene.scene.display(),
        %variant,
        width = desc.film.width,
        height = desc.film.height,
        spp = options.spp,
        "rendering on the CPU"
    );
    let (image, stats) = with_scene(&desc, path_settings(&desc), CpuRender { options })?;
    image
        .write_exr(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))?;
    let preview = preview_path(&args.output);
    image.write_png(&preview)?;
    println!(
        "{}",
        summary(&image, options.spp, &stats, &variant.to_string())
    );
    println!(
        "wrote {} and {}",
        args.output.display(),
        preview.display()
    );
    Ok(())
}

struct CpuRender {
    options: RenderOptions,
}

impl SceneVisitor for CpuRender {
    type Output = Result<(Image, RenderStats)>;

    fn visit<S: Scene + Sync>(self, scene: &S) -> Self::Output {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent}% eta {eta}",
            )
            .expect("static template"),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        let result = render(scene, &self.options, &|done, total| {
            bar.set_length(total);
            bar.set_position(done);
        });
        bar.finish_and_clear();
        Ok(result?)
    }
}

fn summary(image: &Image, spp: u32, stats: &RenderStats, variant: &str) -> String {
    let c = &stats.counters;
    let mut s = format!(
        "{}x{} at {} spp ({}) in {:.3} s: {:.3} M paths/s, {:.3} M segments/s, {:.3} M tracking steps/s \
         ({:.2} segments/path)",
        image.width,
        image.height,
        spp,
        variant,
        stats.elapsed.as_secs_f64(),
        stats.paths_per_second() * 1e-6,
        stats.segments_per_second() * 1e-6,
        stats.tracking_steps_per_second() * 1e-6,
        c.segments as f64 / c.paths.max(1) as f64,
    );
    if c.truncated > 0 {
        s += &format!(
            "\nwarning: {} paths reached the segment bound and were dropped (biased dark)",
            c.truncated
        );
    }
    s
}
