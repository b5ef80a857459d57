//! One compensation as `volpt print compensate` runs it (volpt-print's `job::run`), without the
//! command line's crate: for measuring inks, layer counts and loop options on the CPU.
//!
//! ```sh
//! cargo run --release -p volpt-print --example job -- TARGET.png M.toml OUT LAYERS COLOUR_LAYERS SPP MAX_SPP ITERATIONS [IOR [UPDATE]]
//! ```

use std::sync::Arc;

use volpt::{Backend, Quiet};
use volpt_print::compensate::Update;
use volpt_print::job::{run, Job};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some([target, materials, out, layers, colour, spp, max_spp, iterations]), ior, update) =
        (args.first_chunk::<8>(), args.get(8), args.get(9))
    else {
        return Err(
            "expected TARGET.png M.toml OUT LAYERS COLOUR_LAYERS SPP MAX_SPP ITERATIONS \
                    [IOR [cross-talk|per-texel]]"
                .into(),
        );
    };
    let mut job = Job::new(target.into(), materials.into(), out.into());
    job.layers = layers.parse()?;
    job.colour_layers = colour.parse()?;
    job.spp = spp.parse()?;
    job.max_spp = max_spp.parse()?;
    job.options.max_iterations = iterations.parse()?;
    // 1: index-matched, no surface.
    if let Some(ior) = ior {
        let ior: f32 = ior.parse()?;
        job.ior = (ior != 1.0).then_some(ior);
    }
    job.options.update = match update.map(String::as_str) {
        None | Some("cross-talk") => Update::CrossTalk,
        Some("per-texel") => Update::PerTexel,
        Some(other) => {
            return Err(format!("expected cross-talk or per-texel, found {other}").into())
        }
    };
    let backend = Backend::cpu();
    let outcome = run(&job, &backend, Arc::new(Quiet), |k, it| {
        eprintln!(
            "iteration {k}: mean dE00 {:.3}, p95 {:.3}, noise {:.3}, {:?} spp",
            it.mean, it.p95, it.noise, it.samples
        );
    })?;
    let c = &outcome.compensation;
    println!(
        "{} x {}: {} iterations in {:.1} s; mean dE00 naive {:.3}, best {:.3} ({:.2}x)",
        outcome.size[0],
        outcome.size[1],
        c.iterations.len(),
        outcome.seconds,
        c.iterations[0].mean,
        c.iterations[c.best].mean,
        c.iterations[0].mean / c.iterations[c.best].mean
    );
    Ok(())
}
