//! `volpt`: render solid participating media from Mitsuba scene files.

mod backend;
mod bench;
mod checkpoint;
mod compare;
mod converge;
mod info;
mod plot;
mod print;
mod volume;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use tracing_subscriber::EnvFilter;
use volpt::{
    preview_path, Backend, BackendOptions, Effects, Estimator, GridLookup, Image, Math, Named,
    RenderSettings, RenderStats, Roulette, Scene, Tracking, Variant,
};

use backend::{BackendKind, GpuArgs, Terminal};

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
          default_value_t = volpt::limits::DEFAULT_MEMORY_LIMIT)]
    memory_limit: u64,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to OpenEXR, with a PNG preview beside it; or some of its samples to a film
    /// file (--samples A..B --film FILE), to merge with the others' (`volpt merge`).
    Render(RenderArgs),
    /// Add up the film files of one render's sample ranges (rendered anywhere) into its image, in
    /// a fixed order: the same films give the same bits. Films of another scene, settings, seed or
    /// size, and films holding the same samples, are refused; samples in no film are reported.
    Merge(MergeArgs),
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
    /// index takers, texture lookups), the kernels' math functions and the viewer's tone mapping
    /// on the GPU against plain CPU implementations.
    Selftest {
        /// Which kernels: `exact` must give the CPU's bits, `fast` the documented accuracy of
        /// its approximate instructions.
        #[arg(long, value_parser = named::<Math>(), default_value = Math::Exact.name())]
        math: Math,
    },
    /// Serve an interactive viewer as a web page: orbit, pan and zoom, progressive refinement,
    /// parameters, snapshots (open the printed URL; over SSH, `ssh -L PORT:localhost:PORT HOST`).
    View(ViewArgs),
    /// Colour 3D printing: compensate a print's scattering (docs/printing.md).
    #[command(subcommand)]
    Print(print::PrintCommand),
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
    /// Scene file: Mitsuba XML, a volpt TOML scene, a grid file (.mha, .mhd, .vtk, .vti, .vol, .vdb,
    /// .nrrd, .nhdr, .tif, .tiff, .dcm), or a folder (a TIFF stack or a DICOM series).
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
    /// Depth from which Russian roulette starts, Mitsuba's rr_depth; -1 disables it (a path whose
    /// weight falls below 2^-40 still faces it: unbiased, docs/guide.md).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i64).range(-1..=u32::MAX as i64))]
    rr_depth: Option<i64>,
    /// Render with the most general variant (grid density and albedo, Henyey-Greenstein, lat-long
    /// map) instead of the one specialised to the scene's effects: what specialisation saves.
    #[arg(long)]
    general: bool,
    /// Delta and ratio tracking under one global majorant or a majorant grid (default: chosen per
    /// scene by the tracking work along camera rays, `volpt info` says which and why; `grid`
    /// without --majorant-resolution: the scene's grid, else 32 cells along the longest axis).
    #[arg(long, value_parser = named::<Tracking>())]
    tracking: Option<Tracking>,
    /// Cells of the majorant grid along the box's longest axis (1 is the global majorant).
    #[arg(long, value_name = "CELLS")]
    majorant_resolution: Option<u32>,
    /// How paths gather the environment's light (default: nee for a lat-long map behind an
    /// index-matched or around a rough boundary, pt elsewhere; a smooth dielectric rules nee out).
    #[arg(long, value_parser = named::<Estimator>())]
    estimator: Option<Estimator>,
    /// How the medium's grids are reconstructed between samples (default: stochastic on a GPU
    /// with fast math where textures fit in its memory, else trilinear).
    #[arg(long, value_parser = named::<GridLookup>())]
    lookup: Option<GridLookup>,
    /// Russian roulette's survival probability (default: mitsuba); where it starts is --rr-depth.
    #[arg(long, value_parser = named::<Roulette>())]
    roulette: Option<Roulette>,
}

/// The value parser of a flag that takes one of the library's choices ([`volpt::Named`]): its
/// names and their help come from the library's table, so the CLI keeps none of its own.
pub(crate) fn named<T: Named>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(
        T::all()
            .iter()
            .map(|v| clap::builder::PossibleValue::new(v.name()).help(v.about())),
    )
    .map(|name| volpt::names::parse::<T>(&name).expect("clap takes only the table's names"))
}

impl SceneArgs {
    /// The library's settings: these flags over the scene file, with `sampling`'s seed and
    /// threads.
    fn settings(&self, sampling: Option<&SamplingArgs>) -> RenderSettings {
        RenderSettings {
            params: self.params.clone(),
            spp: self.spp,
            resolution: self.resolution,
            max_depth: self.max_depth.map(depth),
            rr_depth: self.rr_depth.map(depth),
            tracking: self.tracking,
            majorant_resolution: self.majorant_resolution,
            estimator: self.estimator,
            lookup: self.lookup,
            roulette: self.roulette,
            effects: if self.general {
                Effects::General
            } else {
                Effects::Specialised
            },
            seed: sampling.map_or(0, |s| s.seed),
            threads: sampling.and_then(|s| s.threads),
        }
    }

    fn load(&self, sampling: Option<&SamplingArgs>) -> Result<Scene> {
        Ok(Scene::load(&self.scene, &self.settings(sampling))?)
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
    #[arg(long, value_parser = named::<BackendKind>(), default_value_t = BackendKind::Cpu)]
    backend: BackendKind,
    #[command(flatten)]
    gpu: GpuArgs,
    #[command(flatten)]
    volumes: volume::VolumeArgs,
}

impl SamplingArgs {
    /// Opens the backend these flags name; flags that do not apply to it are refused.
    fn open(&self) -> Result<Backend> {
        Ok(Backend::open(&BackendOptions {
            kind: self.backend,
            gpu: self.gpu.options(&self.volumes),
        })?)
    }
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Output OpenEXR file, named `.exr`; the PNG preview gets the same name with `.png`. A path
    /// that exists and is not a regular file (`/dev/null`, a pipe) gets the EXR and no preview.
    /// [default: out.exr, or no image with --film]
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Render only samples A..B (A included, B not) of every pixel: one part of a render split
    /// across processes, machines or cluster tasks. The scene's own sample count is then unused;
    /// the image, if written, averages these samples.
    #[arg(long, value_name = "A..B", value_parser = parse_samples,
          conflicts_with_all = ["spp", "checkpoint", "resume"])]
    samples: Option<std::ops::Range<u32>>,
    /// Write the film (every pixel's sums, the sample range, the scene's fingerprint, the seed) to
    /// FILE, for `volpt merge`. With --film, the image is written only if -o names it.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["checkpoint", "resume"])]
    film: Option<PathBuf>,
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
struct ViewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Address and port to serve on. A non-loopback address requires the random token printed in
    /// the URL on every request; port 0 picks a free one.
    #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:8765")]
    bind: std::net::SocketAddr,
    /// Require the token on a loopback bind too (on a shared machine, every user reaches its
    /// loopback ports).
    #[arg(long)]
    token: bool,
    /// Stream the linear image to the tev HDR viewer listening at HOST:PORT (tev's default is
    /// 127.0.0.1:14158) as well, reconnecting when tev restarts.
    #[arg(long, value_name = "HOST:PORT")]
    tev: Option<String>,
}

#[derive(Args)]
struct MergeArgs {
    /// Film files of one render (`volpt render --samples A..B --film FILE`), or its checkpoints.
    #[arg(required = true, value_name = "FILMS")]
    parts: Vec<PathBuf>,
    /// Output OpenEXR file, named `.exr`, with its PNG preview beside it.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Write the merged film to FILE (it lists its sample ranges): to merge again later, or keep.
    #[arg(long, value_name = "FILE")]
    film: Option<PathBuf>,
    /// The render's samples per pixel: samples of 0..N that no film holds are gaps, and a film
    /// holding samples from N on is refused [default: up to the last sample held].
    #[arg(long, value_name = "N")]
    spp: Option<u32>,
    /// Merge despite gaps: the image averages the samples held (unbiased but noisier than the
    /// whole render), and --film lists the ranges held.
    #[arg(long)]
    allow_gaps: bool,
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

/// `--samples A..B`: a non-empty range of sample indices.
fn parse_samples(s: &str) -> Result<std::ops::Range<u32>, String> {
    let parsed = s
        .split_once("..")
        .and_then(|(a, b)| Some((a.trim().parse::<u32>().ok()?, b.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((a, b)) if a < b => Ok(a..b),
        Some((a, b)) => Err(format!(
            "expected A..B with A below B (samples A to B-1), found {a}..{b}, which holds none"
        )),
        None => Err(format!("expected A..B, e.g. 0..256, found {s:?}")),
    }
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
    run().map_err(spelled_as_flags)
}

/// A library error, each setting's key spelled as the flag that sets it
/// (`majorant_resolution`: `--majorant-resolution`, `--max-registers 8`); any other error as it
/// is.
fn spelled_as_flags(error: anyhow::Error) -> anyhow::Error {
    match error.downcast_ref::<volpt::Error>() {
        Some(library) if error.chain().count() == 1 => anyhow::anyhow!(library.spelled(&flag)),
        _ => error,
    }
}

/// A setting's flag, with its value where it has one: `--max-registers 8`.
fn flag(key: &str, value: Option<&str>) -> String {
    let flag = format!("--{}", key.replace('_', "-"));
    match value {
        Some(value) => format!("{flag} {value}"),
        None => flag,
    }
}

fn run() -> Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(
            EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("info")),
        )
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    volpt::limits::set_memory_limit(cli.memory_limit);
    match cli.command {
        Command::Render(args) => render_command(args),
        Command::Merge(args) => merge_command(args),
        Command::Bench(args) => bench_command(args),
        Command::Info(args) => {
            let scene = args.load(None)?;
            print!(
                "{}",
                info::describe(
                    &args.scene,
                    scene.description(),
                    scene.effects(),
                    &scene.path_settings()
                )
            );
            Ok(())
        }
        Command::Scene(SceneCommand::Export {
            scene: args,
            out,
            name,
        }) => {
            let scene = args.load(None)?;
            let name = name.unwrap_or_else(|| export_name(&args.scene));
            for path in
                volpt::scene_files::mitsuba::write_mitsuba3(scene.description(), &out, &name)?
            {
                println!("wrote {}", path.display());
            }
            Ok(())
        }
        Command::Scene(SceneCommand::Generate { dir }) => {
            for path in volpt::scene_files::generate::generate_scene_inputs(&dir)? {
                println!("wrote {}", path.display());
            }
            Ok(())
        }
        Command::Compare(args) => compare::run(&args),
        Command::View(args) => {
            let scene = args.scene.load(Some(&args.sampling))?;
            let options = volpt_view::ViewOptions {
                bind: args.bind,
                token: args.token,
                tev: args.tev,
                backend: BackendOptions {
                    kind: args.sampling.backend,
                    gpu: args.sampling.gpu.options(&args.sampling.volumes),
                },
            };
            Ok(volpt_view::serve(scene, options)?)
        }
        Command::Converge(args) => converge::run(&args),
        Command::Selftest { math } => selftest(math),
        Command::Print(command) => print::run_command(command),
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

fn render_command(args: RenderArgs) -> Result<()> {
    // With --film, an image only where -o asks for one.
    let output = match (&args.output, &args.film) {
        (Some(output), _) => Some(output.clone()),
        (None, Some(_)) => None,
        (None, None) => Some(PathBuf::from("out.exr")),
    };
    // Before the render, so that a bad name costs nothing.
    let preview = match &output {
        Some(output) => preview_for(output)?,
        None => None,
    };
    // Opening a GPU takes a fifth of a second (the driver's context): it opens while the scene
    // loads. A scene that does not load is still the error reported.
    let (scene, backend) = std::thread::scope(|threads| {
        let opening = threads.spawn(|| args.sampling.open());
        let scene = args.scene.load(Some(&args.sampling));
        let backend = opening
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (scene, backend)
    });
    let mut scene = scene?;
    let backend = backend?;
    // This one render's backend reads the grids in place (no copy of the description).
    backend.adopt(&mut scene);
    let spp = scene.spp();
    let variant = scene.variant();
    tracing::info!(
        scene = %args.scene.scene.display(),
        %variant,
        width = scene.resolution().0,
        height = scene.resolution().1,
        spp,
        samples = ?args.samples,
        device = %backend.device_name(),
        strategy = ?backend.strategy(),
        math = ?backend.math(),
        "rendering"
    );
    let save = checkpoint::save_path(args.checkpoint.as_deref(), args.resume.as_deref());
    let (image, stats, spp, schedule) = match save {
        None => {
            let samples = args.samples.clone().unwrap_or(0..spp);
            let request = volpt::RenderRequest::samples(samples.clone());
            let terminal = Terminal::new(true);
            let mut film = scene.film();
            let rendered = backend.render(&scene, &mut film, &request, &terminal)?;
            terminal.finish();
            let count = samples.end - samples.start;
            if let Some(path) = &args.film {
                let file = volpt::FilmFile {
                    fingerprint: backend.fingerprint(&scene, &request)?,
                    seed: scene.seed(),
                    ranges: vec![samples.clone()],
                    film,
                };
                file.write(path)
                    .with_context(|| format!("writing the film {}", path.display()))?;
                println!(
                    "wrote {}: samples {}..{} of render {:016x} (seed {})",
                    path.display(),
                    samples.start,
                    samples.end,
                    file.fingerprint,
                    file.seed
                );
                (file.image(), rendered.stats, count, rendered.schedule)
            } else {
                (film.image(count), rendered.stats, count, rendered.schedule)
            }
        }
        Some(save) => {
            if !(args.checkpoint_interval.is_finite() && args.checkpoint_interval > 0.0) {
                bail!("--checkpoint-interval must be a positive number of seconds");
            }
            let checkpointing = volpt::Checkpointing {
                save,
                resume: args.resume.clone(),
                interval: std::time::Duration::from_secs_f64(args.checkpoint_interval),
            };
            let terminal = Terminal::new(true).interruptible(
                "\ninterrupted: saving the samples finished so far (Ctrl-C again to quit now)",
            )?;
            let (film, rendered) =
                volpt::render_checkpointed(&backend, &scene, &checkpointing, &terminal)?;
            terminal.finish();
            if rendered.samples.end < spp {
                println!(
                    "interrupted after {} of {spp} samples per pixel: saved to {}; continue with \
                     --resume {}",
                    rendered.samples.end,
                    checkpointing.save.display(),
                    checkpointing.save.display()
                );
                std::process::exit(130);
            }
            (film.image(spp), rendered.stats, spp, rendered.schedule)
        }
    };
    println!(
        "{}",
        summary(
            &image,
            spp,
            &stats,
            variant,
            &configuration(&backend, &scene, schedule)
        )
    );
    let written = match output {
        Some(output) => write_image(&image, &output, preview.as_deref()),
        None => Ok(()),
    };
    // The process ends here, and the driver releases its GPU contexts as it exits: destroying
    // them first (the backend's drop) cost 0.11 s of a small render's 0.38 s on an H100
    // (bench/device/startup.py, 2026-11-26).
    std::mem::forget(backend);
    written
}

/// Writes `image` to `output` (OpenEXR) and its preview, if any, and says so.
fn write_image(image: &Image, output: &Path, preview: Option<&Path>) -> Result<()> {
    image
        .write_exr(output)
        .with_context(|| format!("writing {}", output.display()))?;
    match preview {
        Some(preview) => {
            image.write_png(preview)?;
            println!("wrote {} and {}", output.display(), preview.display());
        }
        None => println!("wrote {} (no preview for a non-file)", output.display()),
    }
    Ok(())
}

fn merge_command(args: MergeArgs) -> Result<()> {
    if args.output.is_none() && args.film.is_none() {
        bail!("nothing to write: name the image with -o IMAGE.exr, the merged film with --film FILE, or both");
    }
    let preview = match &args.output {
        Some(output) => preview_for(output)?,
        None => None,
    };
    let mut films = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        films.push((path.display().to_string(), volpt::read_film(path)?));
    }
    let count = films.len();
    let merged = volpt::merge_films(films, args.spp)?;
    let film = if args.allow_gaps {
        if !merged.missing.is_empty() {
            eprintln!(
                "warning: samples {} are in no film; the image averages the {} samples per pixel \
                 held ({})",
                volpt::format_ranges(&merged.missing),
                merged.film.samples(),
                volpt::format_ranges(&merged.film.ranges)
            );
        }
        merged.film
    } else {
        merged.complete()?
    };
    println!(
        "merged {count} films of render {:016x} (seed {}, {}x{}): samples {}, {} per pixel",
        film.fingerprint,
        film.seed,
        film.film.width,
        film.film.height,
        volpt::format_ranges(&film.ranges),
        film.samples()
    );
    if let Some(path) = &args.film {
        film.write(path)
            .with_context(|| format!("writing the film {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    match &args.output {
        Some(output) => write_image(&film.image(), output, preview.as_deref()),
        None => Ok(()),
    }
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

/// Which configuration renders: the device, the GPU's strategy and math, and the grid lookup of a
/// medium with grids (`--math`, `--lookup`; their defaults are the fastest correct ones).
/// What ran: the device, the strategy (for `auto`, the one it chose: `ran`), the math build and
/// the grids' lookup.
fn configuration(
    backend: &volpt::Backend,
    scene: &volpt::Scene,
    ran: Option<volpt::Schedule>,
) -> String {
    let mut s = backend.device_name();
    match (backend.strategy(), ran) {
        (Some(volpt::StrategyChoice::Auto), Some(ran)) => {
            let _ = write!(s, ", auto: {}", ran.strategy);
        }
        (Some(strategy), _) => {
            let _ = write!(s, ", {strategy}");
        }
        (None, _) => {}
    }
    if let Some(cap @ Some(_)) = ran.map(|ran| ran.max_registers) {
        let _ = write!(s, " with {}", volpt::registers(cap));
    }
    if let Some(math) = backend.math() {
        let _ = write!(s, ", {math} math");
    }
    let medium = &scene.description().medium;
    let grids = matches!(
        medium.density,
        volpt::scene_files::description::DensityDesc::Grid(_)
    ) || matches!(
        medium.albedo,
        volpt::scene_files::description::AlbedoDesc::Grid(_)
    );
    if grids {
        let _ = write!(s, ", {} lookup", lookup_name(medium.lookup));
    }
    s
}

/// A lookup by its `--lookup` name.
fn lookup_name(lookup: GridLookup) -> &'static str {
    match lookup {
        GridLookup::Trilinear => "trilinear",
        GridLookup::Nearest => "nearest",
        GridLookup::Texture => "texture",
        GridLookup::TextureHalf => "texture-f16",
        GridLookup::Stochastic => "stochastic",
    }
}

fn summary(
    image: &Image,
    spp: u32,
    stats: &RenderStats,
    variant: Variant,
    configuration: &str,
) -> String {
    let c = &stats.counters;
    let mut s = format!(
        "{}x{} at {} spp ({}; {}) in {:.3} s: {:.3} M paths/s, {:.3} M segments/s, \
         {:.3} M tracking steps/s ({:.2} segments/path)",
        image.width,
        image.height,
        spp,
        variant,
        configuration,
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
fn truncation_warning(c: &volpt::PathCounters) -> Option<String> {
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
    let mut scene = args.scene.load(Some(&args.sampling))?;
    let backend = args.sampling.open()?;
    backend.adopt(&mut scene);
    let spp = scene.spp();
    let mut trials = Vec::new();
    let mut last = None;
    for trial in 0..=args.trials {
        let mut film = scene.film();
        let stats = backend
            .render(&scene, &mut film, 0..spp, &Terminal::new(false))?
            .stats;
        tracing::debug!(trial, seconds = stats.elapsed.as_secs_f64(), "trial");
        if trial > 0 {
            trials.push(stats);
        }
        last = Some(film.image(spp));
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
        strategy: backend::strategy_name(backend.strategy()),
        math: backend::math_name(backend.math()),
        device: backend.device_name(),
        variant: scene.variant().to_string(),
        width: image.width,
        height: image.height,
        spp,
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

fn selftest(math: Math) -> Result<()> {
    let renderer = volpt::CudaRenderer::new(0, math)?;
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
