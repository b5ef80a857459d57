//! `volpt converge`: what accuracy costs in time.
//!
//! Each configuration (one value of every `--setting`) renders progressively: round `r` adds two
//! independent batches of `2^r` samples per pixel, one to each half of the samples. After every
//! round the estimate (the mean of both halves) is compared with a reference:
//!
//! - MSE and RMSE over all pixel channels, and relative MSE `(x - ref)^2 / (ref^2 + 0.01)`;
//! - variance of the estimate: the halves are independent, so `((a - b) / 2)^2` estimates it per
//!   pixel channel without bias;
//! - bias: `sqrt(max(MSE - variance - reference variance, 0))`, what more samples will not remove
//!   (a depth limit's); a rendered reference is two independent halves too, so its own noise is
//!   estimated the same way and not taken for bias (a given reference counts as exact);
//! - efficiency `1 / (MSE x time)`, with time the render time of the samples so far.
//!
//! The reference is a given OpenEXR, the analytic value of a white furnace, or a render at
//! `--reference-spp` with the scene's own settings (roulette from depth 5 at the latest, which
//! changes the noise, not the mean), cached in the output directory.
//!
//! Settings are knobs the renderer really has ([`Choice`]): integrator limits, the grid lookup,
//! the film's precision and the GPU strategy. A knob of the GPU backend (as GPU math will be) is a
//! variant there that sets a field of the configuration's [`SamplingArgs`], from which each
//! configuration opens its own backend.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use volpt::scene_files::description::{AlbedoDesc, BsdfDesc, EnvironmentDesc};
use volpt::{
    Accumulation, Backend, Estimator, Film, GridLookup, Math, Named, PathSettings, Quiet,
    RenderRequest, RenderSettings, Roulette, Scene, SceneDescription, Strategy, StrategyChoice,
};

use volpt::metrics::{errors_of_halves, Reference};

use crate::backend::BackendKind;
use crate::plot::{log_log_png, log_log_svg, Series};
use crate::{SamplingArgs, SceneArgs};

#[derive(Args)]
pub struct ConvergeArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// A knob and the values to compare, e.g. `rr_depth=1,5,-1`, `roulette=on,off`,
    /// `roulette_rule=mitsuba,throughput`,
    /// `max_depth=2,4,8,-1`, `lookup=trilinear,nearest`, `accumulation=f64,f32` (CPU),
    /// `strategy=naive-sk,regeneration-sk` (GPU). Several give every combination. Without any, the
    /// scene's own settings.
    #[arg(long = "setting", value_name = "NAME=A,B,...", value_parser = parse_setting)]
    settings: Vec<Vec<Choice>>,
    /// Reference image (OpenEXR); default: the analytic value of a white furnace, or a render at
    /// --reference-spp cached in the output directory.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Samples per pixel of a rendered reference.
    #[arg(long, default_value_t = 4096)]
    reference_spp: u32,
    /// Render time budget per configuration, in seconds (the round running at the budget finishes).
    #[arg(long, default_value_t = 10.0)]
    time: f64,
    /// Stop a configuration at this many samples per pixel even within its time budget.
    #[arg(long, default_value_t = 1 << 16)]
    max_spp: u32,
    /// RMSE for the time-to-error column (default: the largest final RMSE, so every
    /// configuration reaches it).
    #[arg(long)]
    target_rmse: Option<f64>,
    /// Output directory: converge.csv, rmse.svg, rel-mse.svg, table.md, the cached reference.
    #[arg(short, long, default_value = "converge")]
    out: PathBuf,
}

/// One value of one knob.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// Russian roulette from the scene's `rr_depth` (5 if it has none), or never (but for paths of
    /// negligible weight, `volpt_core::path::NEGLIGIBLE_WEIGHT`).
    Roulette(bool),
    /// Roulette from this depth; `None` never (but for paths of negligible weight).
    RrDepth(Option<u32>),
    /// Longest path; `None` unlimited.
    MaxDepth(Option<u32>),
    /// Path tracing or next-event estimation (where the boundary allows it).
    Estimator(Estimator),
    /// Cells of the majorant grid along the longest axis; 1 is the global majorant.
    MajorantResolution(u32),
    /// Trilinear or nearest-sample reconstruction of the medium's grids.
    Lookup(GridLookup),
    /// The precision the film adds samples in (the CPU backend's; the GPU film sums in f64).
    Accumulation(Accumulation),
    /// The GPU scheduling strategy.
    Strategy(Strategy),
    /// Exact or fast GPU kernels.
    Math(Math),
    /// Russian roulette's survival probability.
    RouletteRule(Roulette),
}

impl Choice {
    /// Sets the choice in `config`: path settings as [`RenderSettings`] over the scene's
    /// (`scene`), which checks them ([`RenderSettings::path_over`]).
    fn apply(self, config: &mut Configuration, scene: &PathSettings) {
        let settings = &mut config.settings;
        match self {
            Choice::Roulette(true) if scene.rr_depth == PathSettings::UNLIMITED => {
                settings.rr_depth = Some(Some(PathSettings::default().rr_depth))
            }
            Choice::Roulette(true) => settings.rr_depth = Some(Some(scene.rr_depth)),
            Choice::Roulette(false) => settings.rr_depth = Some(None),
            Choice::RrDepth(d) => settings.rr_depth = Some(d),
            Choice::MaxDepth(d) => settings.max_depth = Some(d),
            Choice::Estimator(e) => settings.estimator = Some(e),
            Choice::MajorantResolution(r) => settings.majorant_resolution = Some(r),
            Choice::Lookup(lookup) => config.lookup = Some(lookup),
            Choice::Accumulation(accumulation) => config.accumulation = accumulation,
            Choice::Strategy(strategy) => {
                config.sampling.gpu.strategy = Some(StrategyChoice::Fixed(strategy))
            }
            Choice::Math(math) => config.sampling.gpu.math = Some(math),
            Choice::RouletteRule(rule) => settings.roulette = Some(rule),
        }
    }

    fn label(self) -> String {
        let depth = |d: Option<u32>| d.map_or("-1".to_owned(), |d| d.to_string());
        match self {
            Choice::Roulette(on) => format!("roulette={}", if on { "on" } else { "off" }),
            Choice::RrDepth(d) => format!("rr_depth={}", depth(d)),
            Choice::MaxDepth(d) => format!("max_depth={}", depth(d)),
            Choice::Estimator(e) => format!("estimator={}", value_name(&e)),
            Choice::MajorantResolution(r) => format!("majorant_resolution={r}"),
            Choice::Lookup(lookup) => format!("lookup={}", value_name(&lookup)),
            Choice::Accumulation(a) => format!("accumulation={}", value_name(&a)),
            Choice::Strategy(strategy) => format!("strategy={}", value_name(&strategy)),
            Choice::Math(math) => format!("math={}", value_name(&math)),
            Choice::RouletteRule(rule) => format!("roulette_rule={}", value_name(&rule)),
        }
    }
}

/// A knob's value as the command line spells it (the library's name).
fn value_name<T: Named>(value: &T) -> &'static str {
    value.name()
}

/// A value of an enumerated knob, or the library's error listing the values it takes.
fn enum_value<T: Named>(v: &str) -> Result<T, String> {
    volpt::names::parse(v).map_err(|e| e.to_string())
}

fn parse_setting(s: &str) -> Result<Vec<Choice>, String> {
    let (name, values) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=A,B,..., found {s:?}"))?;
    let depth = |v: &str| match v {
        "-1" => Ok(None),
        _ => v
            .parse::<u32>()
            .map(Some)
            .map_err(|_| format!("{name}: expected a depth (an integer >= 0, or -1), found {v:?}")),
    };
    values
        .split(',')
        .map(|v| match name {
            "roulette" => match v {
                "on" => Ok(Choice::Roulette(true)),
                "off" => Ok(Choice::Roulette(false)),
                _ => Err(format!("roulette: expected on or off, found {v:?}")),
            },
            "rr_depth" => depth(v).map(Choice::RrDepth),
            "max_depth" => depth(v).map(Choice::MaxDepth),
            "estimator" => enum_value(v).map(Choice::Estimator),
            "majorant_resolution" => v
                .parse::<u32>()
                .map_err(|_| format!("{name}: expected an integer, found {v:?}"))
                .and_then(|r| volpt::check_majorant_resolution(r).map_err(|e| e.to_string()))
                .map(Choice::MajorantResolution),
            "lookup" => enum_value(v).map(Choice::Lookup),
            "accumulation" => enum_value(v).map(Choice::Accumulation),
            "strategy" => enum_value(v).map(Choice::Strategy),
            "math" => enum_value(v).map(Choice::Math),
            "roulette_rule" => enum_value(v).map(Choice::RouletteRule),
            _ => Err(format!(
                "unknown setting {name:?}: expected roulette, roulette_rule, rr_depth, max_depth, \
                 estimator, majorant_resolution, lookup, accumulation, strategy or math"
            )),
        })
        .collect()
}

/// One configuration: its name and what it renders with.
#[derive(Clone)]
struct Configuration {
    label: String,
    /// Its path settings over the scene's (the others are left `None`).
    settings: RenderSettings,
    /// The grid lookup; `None` keeps the scene's (or `--lookup`'s).
    lookup: Option<GridLookup>,
    accumulation: Accumulation,
    /// Backend, GPU strategy: each configuration opens its own backend from these.
    sampling: SamplingArgs,
}

/// Every combination of the settings' values (the scene's own settings if there are none).
fn configurations(
    scene: &PathSettings,
    sampling: &SamplingArgs,
    settings: &[Vec<Choice>],
) -> Vec<Configuration> {
    let mut out = vec![Configuration {
        label: String::new(),
        settings: RenderSettings::default(),
        lookup: None,
        accumulation: Accumulation::F64,
        sampling: sampling.clone(),
    }];
    for values in settings {
        out = out
            .iter()
            .flat_map(|c| {
                values.iter().map(move |choice| {
                    let mut config = c.clone();
                    choice.apply(&mut config, scene);
                    config.label = if c.label.is_empty() {
                        choice.label()
                    } else {
                        format!("{} {}", c.label, choice.label())
                    };
                    config
                })
            })
            .collect();
    }
    if out.len() == 1 && out[0].label.is_empty() {
        out[0].label = "scene settings".to_owned();
    }
    out
}

/// The errors after one round.
#[derive(Clone, Copy, Debug)]
struct Row {
    round: u32,
    spp: u64,
    time_s: f64,
    mse: f64,
    rel_mse: f64,
    variance: f64,
    reference_variance: f64,
}

impl Row {
    fn rmse(&self) -> f64 {
        self.mse.sqrt()
    }
    fn bias(&self) -> f64 {
        volpt::metrics::bias(self.mse, self.variance, self.reference_variance)
    }
    fn efficiency(&self) -> f64 {
        1.0 / (self.mse * self.time_s)
    }
}

/// Both halves of the samples: two films that grow by a batch per round, in the configuration's
/// precision, each from its own seed.
struct Halves {
    films: [Film; 2],
    spp_each: u32,
}

impl Halves {
    /// MSE, relative MSE and the variance of the estimate, over all pixel channels.
    fn errors(&self, reference: &Reference) -> (f64, f64, f64) {
        let [a, b] = &self.films;
        let e = errors_of_halves(a, b, self.spp_each, reference);
        (e.mse, e.rel_mse, e.variance)
    }
}

/// Adds the samples `request` names to `film`: every batch of the runs.
fn add_batch(
    backend: &Backend,
    scene: &Scene,
    film: &mut Film,
    request: &RenderRequest,
) -> Result<Duration> {
    let stats = backend.render(scene, film, request, &Quiet)?.stats;
    if stats.counters.truncated > 0 {
        tracing::warn!(
            truncated = stats.counters.truncated,
            "paths reached a safety bound and were dropped"
        );
    }
    Ok(stats.elapsed)
}

pub fn run(args: &ConvergeArgs) -> Result<()> {
    let scene = args.scene.load(Some(&args.sampling))?;
    let seed = scene.seed();
    let configurations = configurations(&scene.path_settings(), &args.sampling, &args.settings);
    // Every configuration's path settings checked before anything renders.
    let paths = (configurations.iter())
        .map(|c| c.settings.path_over(scene.path_settings()))
        .collect::<Result<Vec<_>, _>>()?;
    // Before the reference, so that a configuration a backend cannot render costs nothing.
    if let Some(c) = configurations
        .iter()
        .find(|c| c.sampling.backend == BackendKind::Cuda && c.accumulation == Accumulation::F32)
    {
        bail!(
            "{}: the GPU film sums in f64 only; compare accumulations with --backend cpu",
            c.label
        );
    }
    let backend = args.sampling.open()?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let reference = reference(args, &scene, &backend)?;
    drop(backend);
    let (w, h) = scene.resolution();

    let mut results = Vec::new();
    for (k, (config, path)) in configurations.iter().zip(paths).enumerate() {
        let bar = ProgressBar::new((args.time * 1000.0) as u64);
        bar.set_style(
            ProgressStyle::with_template("{spinner} {prefix} [{elapsed_precise}] {wide_bar} {msg}")
                .expect("static template"),
        );
        bar.set_prefix(format!(
            "{}/{} {}",
            k + 1,
            configurations.len(),
            config.label
        ));
        let backend = config.sampling.open()?;
        // The configuration's lookup, if it names one; else `--lookup`'s, else its backend's
        // default.
        let request = RenderRequest {
            path: Some(path),
            lookup: config.lookup,
            ..RenderRequest::default()
        };
        let film = Film::new(w, h).with_accumulation(config.accumulation);
        let mut halves = Halves {
            films: [film.clone(), film],
            spp_each: 0,
        };
        let mut time = 0.0;
        let mut rows = Vec::new();
        for round in 0.. {
            // Each half's samples are u32 sample numbers: the rounds stop where they run out.
            let Some(end) = halves.spp_each.checked_add(1u32 << round.min(20)) else {
                break;
            };
            let (spp, samples) = (end - halves.spp_each, halves.spp_each..end);
            for (half, film) in (0u32..).zip(&mut halves.films) {
                // One seed per half (not the reference's); each round continues its samples.
                let batch = RenderRequest {
                    samples: samples.clone(),
                    seed: Some(seed.wrapping_add(half + 1)),
                    ..request.clone()
                };
                time += add_batch(&backend, &scene, film, &batch)?.as_secs_f64();
            }
            halves.spp_each += spp;
            let (mse, rel_mse, variance) = halves.errors(&reference);
            let row = Row {
                round,
                spp: 2 * halves.spp_each as u64,
                time_s: time,
                mse,
                rel_mse,
                variance,
                reference_variance: reference.variance(),
            };
            bar.set_position((time * 1000.0) as u64);
            bar.set_message(format!(
                "{} spp, RMSE {:.3e}, bias {:.3e}",
                row.spp,
                row.rmse(),
                row.bias()
            ));
            rows.push(row);
            if time >= args.time || row.spp >= args.max_spp as u64 {
                break;
            }
        }
        bar.finish_and_clear();
        results.push((config.label.clone(), rows));
    }
    write_outputs(args, &results)
}

/// The reference the errors are measured against.
fn reference(args: &ConvergeArgs, scene: &Scene, backend: &Backend) -> Result<Reference> {
    let desc = scene.description();
    let (w, h) = (desc.film.width, desc.film.height);
    if let Some(path) = &args.reference {
        let image = volpt::read_exr(path, "the reference image")?;
        if (image.width, image.height) != (w, h) {
            bail!(
                "{}: the reference is {}x{} but the render is {w}x{h}",
                path.display(),
                image.width,
                image.height
            );
        }
        return Ok(Reference::Image {
            image,
            variance: 0.0,
        });
    }
    if let Some(rgb) = white_furnace(desc) {
        tracing::info!(
            ?rgb,
            "white furnace: the reference is the environment's radiance"
        );
        return Ok(Reference::Constant(rgb));
    }
    // `--lookup`'s, if given; else the backend's default.
    let lookup = if scene.lookup_chosen() {
        desc.medium.lookup
    } else {
        backend.default_lookup(scene)
    };
    let seed = scene.seed();
    let spp = args.reference_spp.div_ceil(2);
    // Seeds no batch of the runs uses (they count up from the base seed).
    let requests = [0, 1].map(|half| {
        RenderRequest::samples(0..spp)
            .with_path(reference_settings(scene))
            .with_lookup(lookup)
            .with_seed(seed.wrapping_sub(1 + half))
    });
    // Named by what makes a render the same render (the library's fingerprint of the scene, its
    // grids and the request) and by its samples and seed: a changed scene renders a new one.
    let cached = requests.iter().enumerate().map(|(half, request)| {
        let fingerprint = backend.fingerprint(scene, request)?;
        let seed = request.seed.unwrap_or(seed);
        let name = format!("reference-{fingerprint:016x}-{seed:08x}-{spp}spp-{half}.exr");
        anyhow::Ok(args.out.join(name))
    });
    let cached = cached.collect::<Result<Vec<_>>>()?;
    if cached.iter().all(|p| p.exists()) {
        tracing::info!(path = %cached[0].display(), "using the cached reference");
        let [a, b] = [&cached[0], &cached[1]].map(|p| volpt::read_exr(p, "the cached reference"));
        return Ok(Reference::from_halves(&a?, &b?));
    }
    tracing::info!(spp = args.reference_spp, "rendering the reference");
    let mut halves = Vec::new();
    for (request, path) in requests.iter().zip(&cached) {
        let terminal = crate::backend::Terminal::new(true);
        let mut film = scene.film();
        backend.render(scene, &mut film, request, &terminal)?;
        terminal.finish();
        let image = film.image(spp);
        image.write_exr(path)?;
        halves.push(image);
    }
    Ok(Reference::from_halves(&halves[0], &halves[1]))
}

/// The scene's settings with Russian roulette from depth 5 at the latest: roulette is unbiased,
/// and without it a reference of a high-albedo scene costs many times more.
fn reference_settings(scene: &Scene) -> PathSettings {
    let scene = scene.path_settings();
    PathSettings {
        rr_depth: scene.rr_depth.min(PathSettings::default().rr_depth),
        ..scene
    }
}

/// A white furnace: albedo 1 everywhere, a lossless boundary, a constant environment and no depth
/// limit; every path returns exactly the environment's radiance.
fn white_furnace(desc: &SceneDescription) -> Option<[f32; 3]> {
    let lossless = matches!(
        desc.boundary.bsdf,
        BsdfDesc::Null | BsdfDesc::Dielectric { .. }
    );
    match (&desc.medium.albedo, &desc.environment) {
        (AlbedoDesc::Constant(a), EnvironmentDesc::Constant(rgb))
            if *a == [1.0; 3] && lossless && desc.integrator.max_depth.is_none() =>
        {
            Some(*rgb)
        }
        _ => None,
    }
}

/// Writes `bytes` to `dir/name`.
fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<PathBuf> {
    let path = dir.join(name);
    std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

const CSV_HEADER: &str =
    "setting,round,spp,time_s,rmse,rel_mse,variance,reference_variance,bias,efficiency";

fn write_outputs(args: &ConvergeArgs, results: &[(String, Vec<Row>)]) -> Result<()> {
    let mut csv = format!("{CSV_HEADER}\n");
    for (label, rows) in results {
        for r in rows {
            let _ = writeln!(
                csv,
                "{label},{},{},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
                r.round,
                r.spp,
                r.time_s,
                r.rmse(),
                r.rel_mse,
                r.variance,
                r.reference_variance,
                r.bias(),
                r.efficiency()
            );
        }
    }
    let mut written = vec![write(&args.out, "converge.csv", csv.as_bytes())?];
    let scene = args.scene.scene.display().to_string();
    written.extend(write_plots(&args.out, &scene, results)?);
    let table = table(results, args.target_rmse);
    print!("{table}");
    written.push(write(&args.out, "table.md", table.as_bytes())?);
    for path in written {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// `rmse` and `rel-mse` against render time, as SVG and PNG, in `dir`.
fn write_plots(dir: &Path, title: &str, results: &[(String, Vec<Row>)]) -> Result<Vec<PathBuf>> {
    let series = |f: fn(&Row) -> f64| -> Vec<Series> {
        results
            .iter()
            .map(|(label, rows)| Series {
                name: label.clone(),
                points: rows.iter().map(|r| (r.time_s, f(r))).collect(),
            })
            .collect()
    };
    /// A plot: its file name, its y axis and the row's value on it.
    type Plot = (&'static str, &'static str, fn(&Row) -> f64);
    let plots: [Plot; 2] = [
        ("rmse", "RMSE", Row::rmse),
        ("rel-mse", "relative MSE", |r| r.rel_mse),
    ];
    let mut written = Vec::new();
    for (name, y_label, y) in plots {
        let series = series(y);
        let svg = log_log_svg(title, "render time (s)", y_label, &series)?;
        written.push(write(dir, &format!("{name}.svg"), svg.as_bytes())?);
        let png = log_log_png(title, "render time (s)", y_label, &series)?;
        written.push(write(dir, &format!("{name}.png"), &png)?);
    }
    Ok(written)
}

/// `volpt plot DIR`: the plots of a run again, from its `converge.csv` (e.g. one made on a
/// machine whose plots did not come back), titled with `title`.
pub fn replot(dir: &Path, title: &str) -> Result<()> {
    let path = dir.join("converge.csv");
    // A regular file only: a FIFO named converge.csv would block the read for ever.
    let (file, _) = volpt::limits::open_regular(&path)?;
    let text =
        std::io::read_to_string(file).with_context(|| format!("reading {}", path.display()))?;
    let results = parse_csv(&text).with_context(|| format!("{}", path.display()))?;
    for path in write_plots(dir, title, &results)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The rows of a `converge.csv`, grouped by setting in the order they appear.
fn parse_csv(text: &str) -> Result<Vec<(String, Vec<Row>)>> {
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, header)) if header == CSV_HEADER => {}
        _ => bail!("line 1: expected the header {CSV_HEADER:?}"),
    }
    let mut results: Vec<(String, Vec<Row>)> = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').collect();
        let number = |k: usize| -> Result<f64> {
            fields
                .get(k)
                .and_then(|f| f.parse::<f64>().ok())
                .with_context(|| format!("line {}: field {k} is not a number: {line:?}", i + 1))
        };
        if fields.len() != CSV_HEADER.split(',').count() {
            bail!("line {}: expected 10 fields, found {line:?}", i + 1);
        }
        let rmse = number(4)?;
        let row = Row {
            round: number(1)? as u32,
            spp: number(2)? as u64,
            time_s: number(3)?,
            mse: rmse * rmse,
            rel_mse: number(5)?,
            variance: number(6)?,
            reference_variance: number(7)?,
        };
        match results.last_mut() {
            Some((label, rows)) if label == fields[0] => rows.push(row),
            _ => results.push((fields[0].to_owned(), vec![row])),
        }
    }
    Ok(results)
}

/// Final errors per configuration, the time each first reached the target RMSE, and its efficiency.
fn table(results: &[(String, Vec<Row>)], target: Option<f64>) -> String {
    let finals = results.iter().filter_map(|(_, rows)| rows.last());
    let target = target.unwrap_or_else(|| finals.map(Row::rmse).fold(0.0, f64::max));
    let mut s = format!(
        "| setting | spp | time (s) | RMSE | relative MSE | bias | time to RMSE {target:.2e} (s) | \
         efficiency 1/(MSE s) |\n|---|---:|---:|---:|---:|---:|---:|---:|\n"
    );
    for (label, rows) in results {
        let Some(last) = rows.last() else { continue };
        let reached = rows
            .iter()
            .find(|r| r.rmse() <= target)
            .map_or("-".to_owned(), |r| format!("{:.3}", r.time_s));
        let _ = writeln!(
            s,
            "| {label} | {} | {:.3} | {:.3e} | {:.3e} | {:.3e} | {reached} | {:.3e} |",
            last.spp,
            last.time_s,
            last.rmse(),
            last.rel_mse,
            last.bias(),
            last.efficiency()
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_parse_and_combine() {
        assert_eq!(
            parse_setting("rr_depth=1,-1").unwrap(),
            vec![Choice::RrDepth(Some(1)), Choice::RrDepth(None)]
        );
        assert!(parse_setting("roulette=maybe").is_err());
        assert!(parse_setting("depth=3")
            .unwrap_err()
            .contains("unknown setting"));
        assert_eq!(
            parse_setting("lookup=trilinear,nearest").unwrap(),
            vec![
                Choice::Lookup(GridLookup::Trilinear),
                Choice::Lookup(GridLookup::Nearest)
            ]
        );
        assert_eq!(
            parse_setting("accumulation=f32").unwrap(),
            vec![Choice::Accumulation(Accumulation::F32)]
        );
        assert_eq!(
            parse_setting("strategy=naive-sk").unwrap(),
            vec![Choice::Strategy(Strategy::NaiveSk)]
        );
        assert_eq!(
            parse_setting("lookup=cubic").unwrap_err(),
            "lookup: expected one of trilinear, nearest, texture, texture-f16, stochastic, found \"cubic\""
        );

        let scene = PathSettings::default();
        let sampling = SamplingArgs {
            seed: 0,
            threads: None,
            backend: BackendKind::Cpu,
            gpu: crate::backend::GpuArgs::default(),
            volumes: Default::default(),
        };
        let mut config = Configuration {
            label: String::new(),
            settings: RenderSettings::default(),
            lookup: None,
            accumulation: Accumulation::F64,
            sampling,
        };
        for choice in [
            Choice::MaxDepth(Some(3)),
            Choice::Roulette(false),
            Choice::Lookup(GridLookup::Nearest),
            Choice::Accumulation(Accumulation::F32),
            Choice::Strategy(Strategy::NaiveSk),
        ] {
            choice.apply(&mut config, &scene);
        }
        // Checked and applied over the scene's by the library.
        let s = config.settings.path_over(scene).unwrap();
        assert_eq!((s.max_depth, s.rr_depth), (3, PathSettings::UNLIMITED));
        assert_eq!(config.lookup, Some(GridLookup::Nearest));
        assert_eq!(config.accumulation, Accumulation::F32);
        assert_eq!(
            config.sampling.gpu.strategy,
            Some(StrategyChoice::Fixed(Strategy::NaiveSk))
        );
        assert_eq!(
            Choice::Accumulation(Accumulation::F32).label(),
            "accumulation=f32"
        );
    }

    /// Two halves that differ by +-d around an estimate that is off by e: the variance estimate is
    /// d^2, the MSE e^2 + 0 (the mean is the midpoint), and the bias what is left.
    #[test]
    fn errors_split_into_variance_and_bias() {
        let (r, e, d) = (0.5, 0.1, 0.2);
        let film = |v: f64| Film {
            sums: vec![[v; 3]; 4],
            ..Film::new(2, 2)
        };
        let halves = Halves {
            films: [film(r + e + d), film(r + e - d)],
            spp_each: 1,
        };
        let (mse, rel, var) = halves.errors(&Reference::Constant([r as f32; 3]));
        assert!((mse - e * e).abs() < 1e-6, "{mse}");
        assert!((var - d * d).abs() < 1e-12, "{var}");
        assert!((rel - e * e / (r * r + 0.01)).abs() < 1e-6, "{rel}");
        let row = Row {
            round: 0,
            spp: 2,
            time_s: 2.0,
            mse: 0.06,
            rel_mse: 0.0,
            variance: 0.01,
            reference_variance: 0.01,
        };
        assert!((row.bias() - 0.2).abs() < 1e-12);
        assert!((row.efficiency() - 1.0 / 0.12).abs() < 1e-9);
    }

    #[test]
    fn csv_parses_back_into_rows_per_setting() {
        let text = format!(
            "{CSV_HEADER}\na b,0,2,0.5,2.000000e-1,1e-2,1e-3,0,1e-1,5\n\
             a b,1,6,1.5,1.000000e-1,5e-3,1e-4,0,1e-2,6\nc,0,2,0.25,3e-1,1e-2,1e-3,0,0,1\n"
        );
        let results = parse_csv(&text).unwrap();
        assert_eq!(results.len(), 2);
        assert_eq!((results[0].0.as_str(), results[0].1.len()), ("a b", 2));
        let row = results[0].1[1];
        assert_eq!((row.round, row.spp, row.time_s), (1, 6, 1.5));
        assert!((row.rmse() - 0.1).abs() < 1e-12);
        assert!(parse_csv("spp,rmse\n")
            .unwrap_err()
            .to_string()
            .contains("header"));
        let short = format!("{CSV_HEADER}\nc,0,2\n");
        assert!(parse_csv(&short)
            .unwrap_err()
            .to_string()
            .contains("line 2"));
    }
}
