//! The compensation loop on the real predictor, timed: a synthetic target (fine bars over a
//! smooth gradient) of `SIZE` x `SIZE` texels, the naive print `LAYERS` colour layers deep in a
//! `DEPTH`-layer slab of the five inks, `SPP` samples per texel per prediction (one chromatic render), at
//! most `ITERATIONS` predictions, on the CPU or (`cuda`) a GPU; writes the record to `OUT`.
//!
//! ```sh
//! cargo run --release -p volpt-print --example compensate -- [cpu|cuda] SIZE DEPTH LAYERS SPP ITERATIONS OUT
//! cargo run --release -p volpt-print --example compensate -- cpu 64 100 40 16 4 /tmp/print
//! ```
//!
//! The inks' coefficients are of the order of the thesis's resins (per mm; not its measured
//! ones), voxels 0.0423 mm square and 0.027 mm high (600 dpi, the thesis's layer height).

use std::time::Instant;

use volpt::{Backend, BackendKind, BackendOptions};
use volpt_print::colour::{LinearRgb, Srgb};
use volpt_print::compensate::{compensate, Options, Setup};
use volpt_print::halftone::Halftone;
use volpt_print::predict::RenderPredictor;
use volpt_print::record::write_record;
use volpt_print::{Inks, MaterialDesc};

fn inks() -> Vec<MaterialDesc> {
    let ink = |name: &str, colour: [u8; 3], sigma_s: f32, sigma_a: [f32; 3]| MaterialDesc {
        name: name.into(),
        colour: Some(colour),
        sigma_s: [sigma_s; 3],
        sigma_a,
        g: 0.0,
    };
    vec![
        ink("cyan", [0, 255, 255], 4.0, [6.0, 0.4, 0.1]),
        ink("magenta", [255, 0, 255], 4.0, [0.3, 6.0, 0.4]),
        ink("yellow", [255, 255, 0], 4.0, [0.1, 0.3, 6.0]),
        ink("black", [0, 0, 0], 2.0, [20.0; 3]),
        ink("white", [255, 255, 255], 20.0, [0.02; 3]),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [kind, size, depth, layers, spp, iterations, out] = args.as_slice() else {
        return Err("usage: compensate cpu|cuda SIZE DEPTH LAYERS SPP ITERATIONS OUT".into());
    };
    let kind = match kind.as_str() {
        "cpu" => BackendKind::Cpu,
        "cuda" => BackendKind::Cuda,
        other => return Err(format!("backend: expected cpu or cuda, found {other}").into()),
    };
    let size: u32 = size.parse()?;
    let materials = inks();
    let setup = Setup {
        halftone: Halftone {
            layers: layers.parse()?,
            depth: depth.parse()?,
            inks: Inks::find(&materials)?,
            seed: 1,
        },
        materials,
        voxel_size: [0.0423, 0.0423, 0.027],
    };
    // Fine bars (one to four texels) over the left half, a smooth hue gradient on the right.
    let bars = [[200u8, 60, 60], [60, 120, 200], [240, 220, 120]];
    let target: Vec<LinearRgb> = (0..size * size)
        .map(|i| {
            let (x, y) = (i % size, i / size);
            if x < size / 2 {
                let bar = [1, 1, 2, 2, 4, 4, 4][(x % 7) as usize] + x / 7;
                Srgb::from_u8(bars[bar as usize % 3]).to_linear()
            } else {
                let t = f64::from(y) / f64::from(size);
                Srgb([0.3 + 0.6 * t, 0.8 - 0.4 * t, 0.5]).to_linear()
            }
        })
        .collect();
    let open = Instant::now();
    let backend = Backend::open(&BackendOptions {
        kind,
        ..BackendOptions::default()
    })?;
    eprintln!(
        "backend {} opened in {:.2} s",
        backend.device_name(),
        open.elapsed().as_secs_f64()
    );
    let mut predictor = RenderPredictor::new(&backend, spp.parse()?);
    // The samples stay as given: this example times a fixed number of samples per iteration.
    let options = Options {
        max_iterations: iterations.parse()?,
        noise_ratio: None,
        ..Options::default()
    };
    let start = Instant::now();
    let mut last = Instant::now();
    let result = compensate(
        &target,
        [size, size],
        &setup,
        &options,
        &mut predictor,
        |it| {
            eprintln!(
                "iteration: mean dE00 {:.3}, p95 {:.3}, {:.2} s",
                it.mean,
                it.p95,
                last.elapsed().as_secs_f64()
            );
            last = Instant::now();
        },
    )?;
    let total = start.elapsed().as_secs_f64();
    println!(
        "{size} x {size} texels, {} layers ({} colour), {} spp (one chromatic render): {} iterations in {total:.2} s \
         ({:.2} s each); mean dE00 naive {:.3}, best {:.3} (iteration {})",
        setup.halftone.depth,
        setup.halftone.layers,
        predictor.spp,
        result.iterations.len(),
        total / result.iterations.len() as f64,
        result.iterations[0].mean,
        result.iterations[result.best].mean,
        result.best
    );
    let last = &result.iterations[result.iterations.len() - 1];
    println!(
        "last prediction's noise: mean dE00 of one standard error {:.3}",
        last.noise
    );
    write_record(&result, &target, [size, size], out.as_ref())?;
    Ok(())
}
