//! `volpt`: render solid participating media from Mitsuba scene files.

mod auto;
mod backend;
mod bench;
mod checkpoint;
mod compare;
mod converge;
mod info;
mod plot;
mod volume;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use tracing_subscriber::EnvFilter;
use volpt_core::grid::HALF_MAX;
use volpt_film::Accumulation;
use volpt_render::factory::{Effects, Parts};
use volpt_render::image::preview_path;
use volpt_render::{path_settings, Image, RenderOptions, RenderStats, Variant};
use volpt_scene::{AlbedoDesc, Config, DensityDesc, GridLookup, SceneAssembler, SceneDescription};

use backend::{Backend, BackendKind, GpuArgs, RenderJob};
use volpt_core::{Estimator, PathSettings, Roulette};

#[derive(Parser)]
#[command(
    name = "volpt",
    version,
    about = "A path tracer for solid participating media"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The most memory one piece of loaded data (a grid, a map, the film) may take, in bytes or
    /// with a K, M, G suffix (powers of 1024); input that claims more is refused before it is read.
    #[arg(long, global = true, value_name = "BYTES", value_parser = parse_bytes,
          default_value_t = volpt_scene::limits::DEFAULT_MEMORY_LIMIT)]
    memory_limit: u64,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to OpenEXR, with a PNG preview beside it.
    Render(RenderArgs),
    /// Time repeated renders of a scene (the first trial is a discarded warm-up).
    Bench(BenchArgs),
    /// Print what a scene file loads to, and the variant it renders with.
    Info(SceneArgs),
    /// Work on the included scenes.
    #[command(subcommand)]
    Scene(SceneCommand),
    /// Compare two OpenEXR images pixel by pixel (e.g. a CPU and a GPU render of one seed).
    Compare(compare::CompareArgs),
    /// Error against time for each setting: progressive renders, CSV, SVG and PNG plots, a table.
    Converge(converge::ConvergeArgs),
    /// Test the GPU strategies' collective building blocks (block scan and sort, warp and block
    /// index takers, texture lookups) and the kernels' math functions on the GPU against plain
    /// CPU implementations.
    Selftest {
        /// Which kernels: `exact` must give the CPU's bits, `fast` the documented accuracy of
        /// its approximate instructions.
        #[arg(long, value_enum, default_value_t = volpt_cuda::Math::Exact)]
        math: volpt_cuda::Math,
    },
    /// Plot a `volpt converge` run again from the converge.csv in DIR (SVG and PNG).
    Plot {
        dir: PathBuf,
        /// Title of the plots (default: DIR's name).
        #[arg(long)]
        title: Option<String>,
    },
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Write the generated inputs of the included scenes (the grids of cgg-logo and ad, the sky map
    /// of envmap-cube, smoke's stand-in grid) under DIR.
    Generate {
        /// The `scenes/` directory of a volpt checkout or bundle.
        #[arg(default_value = "scenes")]
        dir: PathBuf,
    },
    /// Write the scene as volpt loads it (after -D, --spp, --resolution, ...) as a Mitsuba 3 scene:
    /// OUT/NAME.xml with its grids (.vol) and environment map (.exr) beside it.
    Export {
        #[command(flatten)]
        scene: SceneArgs,
        /// Directory to write into (created if missing).
        #[arg(short, long)]
        out: PathBuf,
        /// Base name of the written files (default: the scene's directory name, or its file stem
        /// when that is not `scene`).
        #[arg(long)]
        name: Option<String>,
    },
}

#[derive(Args)]
struct SceneArgs {
    /// Scene file: Mitsuba XML, a volpt TOML scene, or a grid file (.mha, .mhd, .vtk, .vti, .vol).
    scene: PathBuf,
    /// Scene parameter, as Mitsuba's `-D name=value` (fills `$name` and overrides `<default>`).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_param)]
    params: Vec<(String, String)>,
    /// Samples per pixel (default: the scene's sampler).
    #[arg(long)]
    spp: Option<u32>,
    /// Film size WIDTHxHEIGHT (default: the scene's film).
    #[arg(long, value_name = "WxH", value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// Longest path, Mitsuba's max_depth; -1 is unlimited (default: the scene's integrator).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i64).range(-1..=u32::MAX as i64))]
    max_depth: Option<i64>,
    /// Depth from which Russian roulette starts, Mitsuba's rr_depth; -1 disables it.
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i64).range(-1..=u32::MAX as i64))]
    rr_depth: Option<i64>,
    /// Render with the most general variant (grid density and albedo, Henyey-Greenstein, lat-long
    /// map) instead of the one specialised to the scene's effects: what specialisation saves.
    #[arg(long)]
    general: bool,
    /// Delta and ratio tracking under one global majorant or a majorant grid (default: chosen per
    /// scene by the tracking work along camera rays, `volpt info` says which and why; `grid`
    /// without --majorant-resolution: the scene's grid, else 32 cells along the longest axis).
    #[arg(long, value_enum)]
    tracking: Option<Tracking>,
    /// Cells of the majorant grid along the box's longest axis (1 is the global majorant).
    #[arg(long, value_name = "CELLS", value_parser = clap::value_parser!(u32).range(1..=1024))]
    majorant_resolution: Option<u32>,
    /// How paths gather the environment's light (default: nee for a lat-long map behind an
    /// index-matched boundary, pt elsewhere; nee needs an index-matched boundary).
    #[arg(long, value_enum)]
    estimator: Option<EstimatorArg>,
    /// How the medium's grids are reconstructed between samples (default: the scene's, trilinear).
    #[arg(long, value_enum)]
    lookup: Option<LookupArg>,
    /// Russian roulette's survival probability (default: mitsuba); where it starts is --rr-depth.
    #[arg(long, value_enum)]
    roulette: Option<RouletteArg>,
}

/// `--roulette`: Russian roulette's survival probability (`volpt_core::Roulette`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum RouletteArg {
    /// Mitsuba's: min(max(throughput) * eta^2, 0.95).
    Mitsuba,
    /// The thesis's: min(1, max(throughput)).
    Throughput,
}

impl From<RouletteArg> for Roulette {
    fn from(r: RouletteArg) -> Self {
        match r {
            RouletteArg::Mitsuba => Roulette::Mitsuba,
            RouletteArg::Throughput => Roulette::Throughput,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Tracking {
    /// One majorant, the densest voxel's extinction, everywhere.
    Global,
    /// A majorant per cell of a coarse grid, walked by a 3D DDA.
    Grid,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum EstimatorArg {
    /// Path tracing: light only where a path escapes.
    Pt,
    /// Next-event estimation of the environment at scattering events, with MIS.
    Nee,
}

/// `--lookup`: a grid's reconstruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum LookupArg {
    /// Trilinear interpolation of the eight samples around a point.
    Trilinear,
    /// The nearest sample's value: one read instead of eight.
    Nearest,
    /// Trilinear filtering by the GPU's texture unit (weights with 8 fractional bits; the CPU
    /// computes the same filter): one instruction per lookup, an approximation of trilinear.
    Texture,
    /// texture, of samples held in half precision (rounded toward zero; at most 65504).
    #[value(name = "texture-f16")]
    TextureF16,
}

impl From<LookupArg> for GridLookup {
    fn from(lookup: LookupArg) -> Self {
        match lookup {
            LookupArg::Trilinear => GridLookup::Trilinear,
            LookupArg::Nearest => GridLookup::Nearest,
            LookupArg::Texture => GridLookup::Texture,
            LookupArg::TextureF16 => GridLookup::TextureHalf,
        }
    }
}

/// Refuses a lookup the medium's grids cannot take: half-precision texels end at 65504.
fn check_lookup(desc: &SceneDescription) -> Result<()> {
    if desc.medium.lookup != GridLookup::TextureHalf {
        return Ok(());
    }
    let largest = [
        (
            "density",
            match &desc.medium.density {
                DensityDesc::Constant(v) => *v,
                DensityDesc::Grid(grid) => grid.max_value(),
            },
        ),
        (
            "albedo",
            match &desc.medium.albedo {
                AlbedoDesc::Constant(rgb) => rgb.iter().copied().fold(0.0, f32::max),
                AlbedoDesc::Grid(grid) => grid.max_value(),
            },
        ),
    ];
    for (name, largest) in largest {
        if largest > HALF_MAX {
            bail!(
                "--lookup texture-f16: the medium's largest {name} is {largest}, above half \
                 precision's largest value, {HALF_MAX} (use --lookup texture: f32 texels)"
            );
        }
    }
    Ok(())
}

/// The precision a film adds samples in (`volpt converge --setting accumulation=...`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum AccumulationArg {
    F64,
    F32,
}

impl From<AccumulationArg> for Accumulation {
    fn from(a: AccumulationArg) -> Self {
        match a {
            AccumulationArg::F64 => Accumulation::F64,
            AccumulationArg::F32 => Accumulation::F32,
        }
    }
}

impl SceneArgs {
    /// The scene's integrator settings with the command line's tracking and estimator.
    fn settings(&self, desc: &SceneDescription) -> Result<PathSettings> {
        let mut settings = path_settings(desc);
        settings.majorant_resolution = match (self.tracking, self.majorant_resolution) {
            (Some(Tracking::Global), Some(r)) if r > 1 => bail!(
                "--tracking global uses one majorant; --majorant-resolution {r} asks for a grid"
            ),
            (Some(Tracking::Global), _) => 1,
            (_, Some(r)) => r,
            (Some(Tracking::Grid), None) if settings.majorant_resolution <= 1 => {
                PathSettings::DEFAULT_MAJORANT_RESOLUTION
            }
            (_, None) => settings.majorant_resolution,
        };
        if let Some(roulette) = self.roulette {
            settings.roulette = roulette.into();
        }
        if let Some(estimator) = self.estimator {
            settings.estimator = match estimator {
                EstimatorArg::Pt => Estimator::PathTracing,
                EstimatorArg::Nee => Estimator::NextEvent,
            };
        }
        Ok(settings)
    }

    fn effects(&self) -> Effects {
        if self.general {
            Effects::General
        } else {
            Effects::Specialised
        }
    }

    /// The command line's part of the scene, for the assembler.
    fn config(&self) -> Config {
        Config {
            params: self.params.clone(),
            spp: self.spp,
            resolution: self.resolution,
            max_depth: self.max_depth.map(depth),
            rr_depth: self.rr_depth.map(depth),
        }
    }
}

#[derive(Args, Clone)]
struct SamplingArgs {
    /// Seed of the random streams: the same seed gives the same image on every backend.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// CPU worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Where to render.
    #[arg(long, value_enum, default_value_t = BackendKind::Cpu)]
    backend: BackendKind,
    #[command(flatten)]
    gpu: GpuArgs,
    #[command(flatten)]
    volumes: volume::VolumeArgs,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Output OpenEXR file, named `.exr`; the PNG preview gets the same name with `.png`. A path
    /// that exists and is not a regular file (`/dev/null`, a pipe) gets the EXR and no preview.
    #[arg(short, long, default_value = "out.exr")]
    output: PathBuf,
    /// Save the render's progress to FILE periodically and on Ctrl-C, to continue it with
    /// --resume FILE.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Continue the render saved in FILE (same scene, settings and seed; --spp may grow), saving
    /// progress back to it unless --checkpoint names another file.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// Seconds of rendering between checkpoints.
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    checkpoint_interval: f64,
}

#[derive(Args)]
struct BenchArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Timed trials, after one discarded warm-up trial (at most 10000).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=MAX_TRIALS))]
    trials: u32,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// The most `bench --trials`: more is a typo, not a benchmark.
const MAX_TRIALS: i64 = 10_000;

/// `1234`, `512K`, `64M`, `8G` (powers of 1024; `8GiB` too) as bytes.
fn parse_bytes(s: &str) -> Result<u64, String> {
    let original = s;
    let s = s.strip_suffix("iB").unwrap_or(s);
    let (digits, unit) = match s.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => (&s[..i], c.to_ascii_uppercase()),
        _ => (s, 'B'),
    };
    let shift = match unit {
        'B' => 0,
        'K' => 10,
        'M' => 20,
        'G' => 30,
        'T' => 40,
        _ => {
            return Err(format!(
                "expected bytes with an optional K, M, G or T, found {original:?}"
            ))
        }
    };
    digits
        .parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(1 << shift))
        .filter(|&n| n > 0)
        .ok_or_else(|| {
            format!("expected a positive number of bytes such as 8G, found {original:?}")
        })
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let parsed = s
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => Err(format!("expected WIDTHxHEIGHT, e.g. 400x400, found {s:?}")),
    }
}

/// Mitsuba's depth convention: -1 is unlimited (clap has checked the range).
fn depth(d: i64) -> Option<u32> {
    u32::try_from(d).ok()
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
    let cli = Cli::parse();
    volpt_scene::limits::set_memory_limit(cli.memory_limit);
    match cli.command {
        Command::Render(args) => render_command(args),
        Command::Bench(args) => bench_command(args),
        Command::Info(args) => {
            let desc = load(&args)?;
            let settings = args.settings(&desc)?;
            print!(
                "{}",
                info::describe(&args.scene, &desc, args.effects(), &settings)
            );
            Ok(())
        }
        Command::Scene(SceneCommand::Export { scene, out, name }) => {
            let desc = load(&scene)?;
            let name = name.unwrap_or_else(|| export_name(&scene.scene));
            for path in volpt_scene::mitsuba::write_mitsuba3(&desc, &out, &name)? {
                println!("wrote {}", path.display());
            }
            Ok(())
        }
        Command::Scene(SceneCommand::Generate { dir }) => {
            for path in volpt_scene::generate::generate_scene_inputs(&dir)? {
                println!("wrote {}", path.display());
            }
            Ok(())
        }
        Command::Compare(args) => compare::run(&args),
        Command::Converge(args) => converge::run(&args),
        Command::Selftest { math } => selftest(math),
        Command::Plot { dir, title } => {
            let title = title.unwrap_or_else(|| export_name(&dir));
            converge::replot(&dir, &title)
        }
    }
}

/// `scenes/bucky/scene.toml` -> `bucky`, `scenes/smoke/scene-mi3.xml` -> `scene-mi3`.
fn export_name(scene: &Path) -> String {
    let stem = scene
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene");
    let parent = scene
        .canonicalize()
        .ok()
        .and_then(|p| Some(p.parent()?.file_name()?.to_str()?.to_owned()));
    match parent {
        Some(parent) if stem == "scene" => parent,
        _ => stem.to_owned(),
    }
}

fn load(args: &SceneArgs) -> Result<SceneDescription> {
    let builder = volpt_scene::builder_for(&args.scene)?;
    let mut desc = SceneAssembler::new(args.config()).assemble(builder.as_ref())?;
    if let Some(lookup) = args.lookup {
        desc.medium.lookup = lookup.into();
        check_lookup(&desc)?;
    }
    Ok(desc)
}

fn options(desc: &SceneDescription, sampling: &SamplingArgs) -> Result<RenderOptions> {
    if let Some(threads) = sampling.threads {
        // Threads beyond the cores only cost memory and start-up; tens of thousands of them
        // exhaust the system before the render starts.
        let cores = std::thread::available_parallelism().map_or(1, usize::from);
        let most = 4 * cores;
        if !(1..=most).contains(&threads) {
            bail!(
                "--threads: expected 1 to {most} (4 x the {cores} cores of this machine), \
                 found {threads}"
            );
        }
    }
    Ok(RenderOptions {
        spp: desc.spp,
        seed: sampling.seed,
        threads: sampling.threads,
    })
}

fn render_command(args: RenderArgs) -> Result<()> {
    // Before the render, so that a bad name costs nothing.
    let preview = preview_for(&args.output)?;
    let mut desc = load(&args.scene)?;
    let mut backend = Backend::open(args.sampling.backend, args.sampling.gpu)?;
    backend.place_volumes(&args.sampling.volumes, &mut desc)?;
    let job = RenderJob {
        desc: &desc,
        settings: args.scene.settings(&desc)?,
        options: options(&desc, &args.sampling)?,
        effects: args.scene.effects(),
        show_progress: true,
    };
    let variant = Parts::of(&desc, job.effects).variant();
    tracing::info!(
        scene = %args.scene.scene.display(),
        %variant,
        width = desc.film.width,
        height = desc.film.height,
        spp = job.options.spp,
        device = %backend.device_name(),
        strategy = ?backend.strategy(),
        math = ?backend.math(),
        "rendering"
    );
    let save = checkpoint::save_path(args.checkpoint.as_deref(), args.resume.as_deref());
    let (image, stats) = match save {
        None => backend.render(&job)?,
        Some(save) => {
            if !(args.checkpoint_interval.is_finite() && args.checkpoint_interval > 0.0) {
                bail!("--checkpoint-interval must be a positive number of seconds");
            }
            let checkpointing = checkpoint::Checkpointing {
                save,
                resume: args.resume.clone(),
                interval: std::time::Duration::from_secs_f64(args.checkpoint_interval),
            };
            match checkpoint::render(&backend, &job, &checkpointing)? {
                Ok(done) => done,
                Err(stopped) => {
                    println!(
                        "interrupted after {} of {} samples per pixel: saved to {}; continue \
                         with --resume {}",
                        stopped.samples,
                        job.options.spp,
                        stopped.path.display(),
                        stopped.path.display()
                    );
                    std::process::exit(130);
                }
            }
        }
    };
    image
        .write_exr(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))?;
    println!("{}", summary(&image, job.options.spp, &stats, variant));
    match preview {
        Some(preview) => {
            image.write_png(&preview)?;
            println!("wrote {} and {}", args.output.display(), preview.display());
        }
        None => println!(
            "wrote {} (no preview for a non-file)",
            args.output.display()
        ),
    }
    Ok(())
}

/// Where the preview goes: beside the EXR with `.png`, or nowhere when the output is not a file
/// path (`/dev/null`, a pipe). An output not named `.exr` is an error, so that the preview can
/// never overwrite the image (`-o x.png`) and a typo does not write an EXR under another name.
fn preview_for(output: &Path) -> Result<Option<PathBuf>> {
    if output.metadata().is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        return Ok(None);
    }
    let is_exr = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !is_exr {
        bail!(
            "-o {}: expected a file name ending in .exr (the image is OpenEXR; its PNG preview \
             is written beside it as NAME.png)",
            output.display()
        );
    }
    Ok(Some(preview_path(output)))
}

fn summary(image: &Image, spp: u32, stats: &RenderStats, variant: Variant) -> String {
    let c = &stats.counters;
    let mut s = format!(
        "{}x{} at {} spp ({}) in {:.3} s: {:.3} M paths/s, {:.3} M segments/s, \
         {:.3} M tracking steps/s ({:.2} segments/path)",
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
    if let Some(warning) = truncation_warning(c) {
        s += "\n";
        s += &warning;
    }
    s
}

/// What the safety bounds of the path settings cost the image, if they cut any path.
fn truncation_warning(c: &volpt_core::PathCounters) -> Option<String> {
    (c.truncated > 0).then(|| {
        format!(
            "warning: {} of {} paths reached a safety bound and were dropped (the image is biased \
             dark): {} the free-flight bound, {} the tracking-step bound",
            c.truncated,
            c.paths,
            c.truncated - c.truncated_tracking,
            c.truncated_tracking
        )
    })
}

fn bench_command(args: BenchArgs) -> Result<()> {
    let mut desc = load(&args.scene)?;
    let mut backend = Backend::open(args.sampling.backend, args.sampling.gpu)?;
    backend.place_volumes(&args.sampling.volumes, &mut desc)?;
    let job = RenderJob {
        desc: &desc,
        settings: args.scene.settings(&desc)?,
        options: options(&desc, &args.sampling)?,
        effects: args.scene.effects(),
        show_progress: false,
    };
    let mut trials = Vec::new();
    let mut last = None;
    for trial in 0..=args.trials {
        let (image, stats) = backend.render(&job)?;
        tracing::debug!(trial, seconds = stats.elapsed.as_secs_f64(), "trial");
        if trial > 0 {
            trials.push(stats);
        }
        last = Some(image);
    }
    let image = last.expect("at least one trial ran");
    let time = bench::time_stats(&trials);
    let counters = trials[0].counters;
    let mut image_mean = [0.0f64; 3];
    for p in &image.pixels {
        for c in 0..3 {
            image_mean[c] += p[c] as f64 / image.pixels.len() as f64;
        }
    }
    let report = bench::BenchReport {
        scene: args.scene.scene.display().to_string(),
        backend: format!("{:?}", args.sampling.backend).to_lowercase(),
        strategy: backend.strategy().map(|s| s.to_string()),
        math: backend.math().map(|m| m.name().to_owned()),
        device: backend.device_name(),
        variant: Parts::of(&desc, job.effects).variant().to_string(),
        width: image.width,
        height: image.height,
        spp: job.options.spp,
        trials: trials.len(),
        time_mean_s: time.mean,
        time_std_s: time.std,
        time_median_s: time.median,
        paths: counters.paths,
        segments: counters.segments,
        tracking_steps: counters.tracking_steps,
        truncated_paths: counters.truncated,
        truncated_tracking_paths: counters.truncated_tracking,
        paths_per_s: counters.paths as f64 / time.mean,
        segments_per_s: counters.segments as f64 / time.mean,
        tracking_steps_per_s: counters.tracking_steps as f64 / time.mean,
        image_mean,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("{}", report.table_row());
    }
    Ok(())
}

fn selftest(math: volpt_cuda::Math) -> Result<()> {
    let renderer = volpt_cuda::CudaRenderer::new(0, math)?;
    let mut failed = 0;
    for test in renderer.selftest()? {
        if test.failures.is_empty() {
            println!("PASS {} ({} threads)", test.name, test.threads);
        } else {
            failed += 1;
            println!(
                "FAIL {}: {} differences, first: {:?}",
                test.name,
                test.failures.len(),
                &test.failures[..test.failures.len().min(5)]
            );
        }
        if !test.measured.is_empty() {
            println!("     {}", test.measured);
        }
    }
    if failed > 0 {
        bail!("{failed} selftests failed on {}", renderer.device_name());
    }
    println!("all selftests passed on {}", renderer.device_name());
    Ok(())
}
