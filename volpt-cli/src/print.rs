//! `volpt print`: colour 3D printing (docs/printing.md). `volpt print compensate TARGET.png
//! --materials M.toml` runs the scattering compensation (volpt-print's `job::run`, which Python's
//! `volpt.compensate_print` runs too) with a progress bar and a line per iteration; Ctrl-C ends it
//! after the iterations finished, whose record is written as any.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Result;
use clap::{Args, Subcommand};
use volpt::{Backend, BackendOptions, Observer};
use volpt_print::compensate::{Options, Update};
use volpt_print::job::{run, Job};
use volpt_print::predict::RenderPredictor;

use crate::backend::{BackendKind, GpuArgs, Terminal};
use crate::volume::VolumeArgs;

#[derive(Subcommand)]
pub enum PrintCommand {
    /// Compensate a print's scattering: predict the naive print of TARGET (a PNG), correct the
    /// colours its layers aim for by the predicted error, repeat; write every iteration's
    /// prediction and ΔE map, iterations.csv, a plot (delta_e.svg) and the best print's slice
    /// stack (slices/, with its materials.toml) to --out.
    Compensate(CompensateArgs),
    /// The CIEDE2000 between a target PNG and a rendered image of the print (an OpenEXR, linear
    /// RGB, one pixel a texel: `volpt render print.toml`, or another renderer's image of the
    /// record's scene): mean and 95th percentile, non-finite pixels left out and counted. The
    /// target may be an OpenEXR too: two renders of one scene with independent seeds measure
    /// the noise floor (docs/printing.md).
    DeltaE {
        /// The target (PNG, sRGB; or OpenEXR, linear RGB).
        target: PathBuf,
        /// The rendered image (OpenEXR), the target's size.
        image: PathBuf,
        /// Compare the image's rows in reverse order: a camera's image of a record's print.toml
        /// has the print's far edge (a slice's bottom row) at its top.
        #[arg(long)]
        flip_rows: bool,
        /// Also the mean per region of a PNG target: its ink (texels not white), the white
        /// within 2 texels of ink, 3 to 6 texels away, and farther (docs/printing.md, "Where the
        /// lines' error is").
        #[arg(long)]
        regions: bool,
    },
}

#[derive(Args)]
pub struct CompensateArgs {
    /// The target image: a PNG (sRGB), one texel of the print's top surface per pixel.
    target: PathBuf,
    /// The material table: `[[materials]]` with name, colour, sigma_s, sigma_a, g (per unit of
    /// the voxel size), five of them named cyan, magenta, yellow, black and white; optionally
    /// `voxel_size` (a slice stack's materials.toml is one).
    #[arg(long, value_name = "M.toml")]
    materials: PathBuf,
    /// The folder the record goes to (created; must not hold a record's slices already).
    #[arg(short, long, default_value = "compensation")]
    out: PathBuf,
    /// The print's depth in voxel layers.
    #[arg(long, default_value_t = 100)]
    layers: u32,
    /// The layers under each texel that hold its colour (white below them).
    #[arg(long, default_value_t = 40)]
    colour_layers: u32,
    /// The voxel size X,Y,Z (Z the layer height), in the unit the coefficients are per [default:
    /// the material table's, else 0.0423,0.0423,0.027: 600 dpi and 27 um layers, in mm].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_size)]
    voxel_size: Option<[f64; 3]>,
    /// Samples per texel of the first prediction; the noise control raises it (fourfold at a
    /// time) while a prediction's noise exceeds --noise-ratio of the update's step.
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// The most samples per texel the noise control may raise --spp to.
    #[arg(long, default_value_t = RenderPredictor::MAX_SPP)]
    max_spp: u32,
    /// The most predictions, the naive one included.
    #[arg(long, default_value_t = Options::default().max_iterations)]
    iterations: usize,
    /// The update's step, in (0, 1].
    #[arg(long, default_value_t = Options::default().step)]
    step: f64,
    /// A prediction's noise (the mean CIEDE2000 of one standard error) may be at most this
    /// fraction of the update's step (step times the mean CIEDE2000); 0 turns the control off.
    #[arg(long, default_value_t = Options::default().noise_ratio.unwrap_or(0.0))]
    noise_ratio: f64,
    /// How the update corrects the aims: `cross-talk` through the print's cross-texel response,
    /// fitted from its predictions; `per-texel` each texel by its own error (docs/printing.md).
    #[arg(long, default_value = "cross-talk", value_parser = parse_update)]
    update: Update,
    /// The resin surface's index of refraction (a smooth dielectric); 1 renders no surface.
    #[arg(long, default_value_t = 1.5)]
    ior: f32,
    /// Seed of the renders' random streams and of the halftone.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Where to render [default: a GPU where one is usable (or the GPU flags are given), else the
    /// CPU; the choice and why are printed first].
    #[arg(long, value_parser = crate::named::<BackendKind>())]
    backend: Option<BackendKind>,
    #[command(flatten)]
    gpu: GpuArgs,
    #[command(flatten)]
    volumes: VolumeArgs,
    /// No progress bar or per-iteration lines; the summary alone.
    #[arg(short, long)]
    quiet: bool,
}

/// An update's name ([`Update::name`]).
fn parse_update(s: &str) -> Result<Update, String> {
    s.parse()
}

/// `X,Y,Z` as three numbers.
fn parse_size(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<_> = s.split(',').map(|v| v.trim().parse::<f64>()).collect();
    match parts.as_slice() {
        [Ok(x), Ok(y), Ok(z)] => Ok([*x, *y, *z]),
        _ => Err(format!("expected X,Y,Z (three numbers), found {s:?}")),
    }
}

pub fn run_command(command: PrintCommand) -> Result<()> {
    match command {
        PrintCommand::Compensate(args) => compensate(args),
        PrintCommand::DeltaE {
            target,
            image,
            flip_rows,
            regions,
        } => delta_e(&target, &image, flip_rows, regions),
    }
}

fn delta_e(
    target: &std::path::Path,
    image: &std::path::Path,
    flip_rows: bool,
    regions: bool,
) -> Result<()> {
    use volpt_print::colour::{ciede2000, LinearRgb};
    use volpt_print::regions::{region_means, Region};
    let exr = |path: &std::path::Path| {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    };
    if regions && exr(target) {
        anyhow::bail!(
            "{}: --regions expected a PNG target (its white and ink), found an OpenEXR",
            target.display()
        );
    }
    let target = if exr(target) {
        let image = volpt::read_exr(target, "the reference image")?;
        volpt_print::target::Target {
            texels: (0..image.height)
                .flat_map(|y| (0..image.width).map(move |x| (x, y)))
                .map(|(x, y)| LinearRgb(image.pixel(x, y).map(f64::from)))
                .collect(),
            size: [image.width, image.height],
        }
    } else {
        volpt_print::target::Target::read(target)?
    };
    let rendered = volpt::read_exr(image, "the rendered image")?;
    let [w, h] = target.size;
    if [rendered.width, rendered.height] != [w, h] {
        anyhow::bail!(
            "{}: expected an image of the target's {w} x {h} pixels, found {} x {}",
            image.display(),
            rendered.width,
            rendered.height
        );
    }
    let class = volpt_print::regions::regions(&target.texels, target.size);
    let (mut delta_e, mut classes) = (Vec::new(), Vec::new());
    for y in 0..h {
        let row = if flip_rows { h - 1 - y } else { y };
        for x in 0..w {
            let p = LinearRgb(rendered.pixel(x, row).map(f64::from));
            let i = (x + w * y) as usize;
            let t = target.texels[i];
            if p.0.iter().chain(&t.0).all(|v| v.is_finite()) {
                delta_e.push(ciede2000(p.to_lab(), t.to_lab()));
                classes.push(class[i]);
            }
        }
    }
    let skipped = (w * h) as usize - delta_e.len();
    if delta_e.is_empty() {
        anyhow::bail!("{}: no finite pixel", image.display());
    }
    let mean = delta_e.iter().sum::<f64>() / delta_e.len() as f64;
    println!(
        "mean ΔE00 {mean:.4}, p95 {:.4} over {} texels ({skipped} not finite, left out)",
        volpt::metrics::quantile(&delta_e, 0.95),
        delta_e.len()
    );
    if regions {
        let parts: Vec<String> = Region::ALL
            .iter()
            .zip(region_means(&delta_e, &classes))
            .map(|(r, (share, mean))| {
                let mean = mean.map_or("-".into(), |m| format!("{m:.4}"));
                format!("{} {mean} ({:.1}%)", r.name(), 100.0 * share)
            })
            .collect();
        println!("regions: mean ΔE00 {}", parts.join(", "));
    }
    Ok(())
}

fn compensate(args: CompensateArgs) -> Result<()> {
    let gpu = args.gpu.options(&args.volumes);
    let (backend, chosen) = match args.backend {
        Some(kind) => (
            Backend::open(&BackendOptions { kind, gpu })?,
            "--backend".to_owned(),
        ),
        None => {
            let p = Backend::open_preferred(&gpu)?;
            (p.backend, format!("no --backend: {}", p.reason))
        }
    };
    let mut job = Job::new(args.target, args.materials, args.out);
    job.layers = args.layers;
    job.colour_layers = args.colour_layers;
    job.voxel_size = args.voxel_size;
    job.spp = args.spp;
    job.max_spp = args.max_spp;
    job.seed = args.seed;
    job.ior = (args.ior != 1.0).then_some(args.ior);
    job.options = Options {
        max_iterations: args.iterations,
        step: args.step,
        noise_ratio: (args.noise_ratio > 0.0).then_some(args.noise_ratio),
        update: args.update,
        ..Options::default()
    };
    let terminal = Arc::new(Terminal::new(!args.quiet).interruptible(
        "\ninterrupted: writing the iterations finished so far (Ctrl-C again to quit now)",
    )?);
    if !args.quiet {
        terminal.note(&format!(
            "compensating {} on {} ({chosen}; {} layers, {} colour, voxel {})\n",
            job.target.display(),
            backend.device_name(),
            job.layers,
            job.colour_layers,
            job.voxel_size
                .map_or("from the material table".into(), |s| format!("{s:?}"))
        ));
    }
    let quiet = args.quiet;
    let shown = terminal.clone();
    let outcome = run(&job, &backend, terminal.clone(), |k, it| {
        if !quiet {
            let spp = it.samples.map_or(String::new(), |s| format!(", {s} spp"));
            shown.note(&format!(
                "iteration {k}: mean ΔE00 {:.3}, p95 {:.3}, noise {:.3}{spp}\n",
                it.mean, it.p95, it.noise
            ));
        }
    })?;
    terminal.finish();
    let c = &outcome.compensation;
    let [w, h] = outcome.size;
    println!(
        "{w} x {h} texels: {} iteration(s) in {:.2} s{}; mean ΔE00 naive {:.3}, best {:.3} \
         (iteration {}), p95 {:.3} -> {:.3}; record in {}",
        c.iterations.len(),
        outcome.seconds,
        if c.interrupted { " (interrupted)" } else { "" },
        c.iterations[0].mean,
        c.iterations[c.best].mean,
        c.best,
        c.iterations[0].p95,
        c.iterations[c.best].p95,
        job.out.display()
    );
    if c.interrupted {
        // As an interrupted `volpt render` does: what was done is kept, the exit says it was cut.
        std::process::exit(130);
    }
    Ok(())
}
