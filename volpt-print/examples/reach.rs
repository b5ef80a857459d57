//! Where a target's remaining error is, and how low any print of these materials could take it:
//! the per-region CIEDE2000 of the naive and the compensated prints, beside two lower bounds.
//!
//! ```sh
//! cargo run --release -p volpt-print --example reach -- TARGET.png M.toml SPP ITERATIONS EVAL_SPP [UPDATE...]
//! ```
//!
//! 100 layers (40 of colour: `VOLPT_COLOUR_LAYERS` sets another count for every print), IOR
//! 1.5, on the CPU. Rows, each a mean CIEDE2000 per region and over the target:
//! - the two lower bounds below;
//! - the naive print, a blank one (every texel white: no ink at all), and the naive aims
//!   lightened towards white by each fraction in `VOLPT_LIGHTEN` (e.g. `"0.3 0.6 0.85"`: how the
//!   ink trades against the white beside it), and the naive print's noise floor (two predictions'
//!   CIEDE2000 over sqrt 2);
//! - for each UPDATE (`cross-talk`, `per-texel`; default `cross-talk`): the target compensated
//!   from `SPP` samples per texel (no noise control) for `ITERATIONS` predictions, its kept print
//!   predicted again with another seed (it was chosen on its own prediction's noise: an
//!   independent one measures it without that selection); and the optimum of the cross-talk
//!   update's linear model fitted to that run's iterations (1000 projected-gradient steps from the
//!   kept print): where the model says no aims do better.
//!
//! Every prediction but the compensation's is made at `EVAL_SPP`.
//!
//! **Regions** of the target ([`volpt_print::regions`]): `ink` (a texel not white), `edge`
//! (white, within 2 texels of ink, Chebyshev), `near` (white, 3 to 6 texels away), `far` (white,
//! farther).
//!
//! **Bounds** (each texel's CIEDE2000 to the nearest colour of a box of linear RGB, the mean over
//! the region's texels):
//! - `proof`: the box `[R0, 1]^3`, `R0 = ((n - 1) / (n + 1))^2` for the resin's IOR `n`. Every
//!   texel's expected colour lies in it whatever the print: the camera's ray meets the smooth top
//!   face at normal incidence and brings back `R0` times the environment's radiance 1 by
//!   reflection, plus what it refracts (not negative); and a passive scene (albedo <= 1, no
//!   emission) under a radiance-1 environment shows no radiance above 1 outside it.
//! - `uniform`: the box from a uniform print of black (the darkest, every colour layer black) to
//!   one of white, measured here at `EVAL_SPP` (their texel means): a tighter bound if no texel
//!   of any print is darker than the black print's or lighter than the white print's in any
//!   channel (adding ink near a texel only takes light from it; not proven, measured).

use volpt::Backend;
use volpt_print::colour::{ciede2000, Lab, LinearRgb};
use volpt_print::compensate::{compensate, print_for, Options, Predictor, Setup, Update};
use volpt_print::crosstalk::Response;
use volpt_print::halftone::Halftone;
use volpt_print::predict::RenderPredictor;
use volpt_print::regions::{regions, Region};
use volpt_print::target::Target;
use volpt_print::{Inks, MaterialFile};

const LAYERS: u32 = 100;
const IOR: f64 = 1.5;

/// The CIEDE2000 from `target` to the nearest colour of the box `[lo, hi]` (per channel): a
/// grid of the box, then a pattern search from its best point.
fn to_box(target: Lab, lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let de = |c: [f64; 3]| ciede2000(LinearRgb(c).to_lab(), target);
    let n = 16;
    let at = |c: usize, k: usize| lo[c] + (hi[c] - lo[c]) * (k as f64 / n as f64).powf(2.2);
    let mut best = (f64::INFINITY, [0.0; 3]);
    for i in 0..=n {
        for j in 0..=n {
            for k in 0..=n {
                let c = [at(0, i), at(1, j), at(2, k)];
                let d = de(c);
                if d < best.0 {
                    best = (d, c);
                }
            }
        }
    }
    let mut h = 0.05;
    while h > 1e-6 {
        let mut moved = false;
        for c in 0..3 {
            for s in [-1.0, 1.0] {
                let mut x = best.1;
                x[c] = (x[c] + s * h).clamp(lo[c], hi[c]);
                let d = de(x);
                if d < best.0 {
                    best = (d, x);
                    moved = true;
                }
            }
        }
        if !moved {
            h *= 0.5;
        }
    }
    best.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some([target, materials, spp, iterations, eval_spp]) = args.first_chunk::<5>() else {
        return Err("expected TARGET.png M.toml SPP ITERATIONS EVAL_SPP [UPDATE...]".into());
    };
    let updates: Vec<Update> = match &args[5..] {
        [] => vec![Update::CrossTalk],
        names => names
            .iter()
            .map(|n| n.parse::<Update>())
            .collect::<Result<_, _>>()?,
    };
    // The colour layers (40 unless VOLPT_COLOUR_LAYERS says otherwise: for measuring how deep
    // the ink need go).
    let colour_layers: u32 = std::env::var("VOLPT_COLOUR_LAYERS").map_or(Ok(40), |v| v.parse())?;
    let (spp, iterations, eval_spp): (u32, usize, u32) =
        (spp.parse()?, iterations.parse()?, eval_spp.parse()?);
    let target = Target::read(target.as_ref())?;
    let table = MaterialFile::read(materials.as_ref())?;
    let setup = Setup {
        halftone: Halftone {
            layers: colour_layers,
            depth: LAYERS,
            inks: Inks::find(&table.materials)?,
            seed: 0,
        },
        voxel_size: table.voxel_size.unwrap_or(volpt_print::job::VOXEL_SIZE),
        materials: table.materials,
    };
    let [w, h] = target.size;
    let texels = target.texels.len();
    let lab: Vec<Lab> = target.texels.iter().map(|c| c.to_lab()).collect();

    let region: Vec<usize> = regions(&target.texels, target.size)
        .into_iter()
        .map(Region::index)
        .collect();
    let counts: Vec<usize> = (0..4)
        .map(|r| region.iter().filter(|&&k| k == r).count())
        .collect();
    // Per region and overall: the mean of `values` over the region's texels.
    let by_region = |values: &[f64]| -> [f64; 5] {
        let mut out = [0.0; 5];
        for (v, &r) in values.iter().zip(&region) {
            out[r] += v;
            out[4] += v;
        }
        for r in 0..4 {
            out[r] /= counts[r].max(1) as f64;
        }
        out[4] /= texels as f64;
        out
    };

    let backend = Backend::cpu();
    let evaluate =
        |aims: &[LinearRgb], seed: u32| -> Result<Vec<LinearRgb>, Box<dyn std::error::Error>> {
            let print = print_for(&setup, aims, w, h).map_err(|e| format!("{e:?}"))?;
            let mut predictor = RenderPredictor::new(&backend, eval_spp);
            predictor.seed = seed;
            Ok(predictor.predict(&print)?)
        };
    let delta_e = |p: &[LinearRgb]| -> Vec<f64> {
        p.iter()
            .zip(&lab)
            .map(|(p, t)| ciede2000(p.to_lab(), *t))
            .collect()
    };
    let mean_rgb = |p: &[LinearRgb]| -> [f64; 3] {
        [0, 1, 2].map(|c| p.iter().map(|t| t.0[c]).sum::<f64>() / p.len() as f64)
    };

    // Bounds.
    let r0 = ((IOR - 1.0) / (IOR + 1.0)).powi(2);
    let black = mean_rgb(&evaluate(&vec![LinearRgb([0.0; 3]); texels], 100)?);
    let blank = evaluate(&vec![LinearRgb([1.0; 3]); texels], 100)?;
    let white = mean_rgb(&blank);
    let mut cache = std::collections::HashMap::new();
    let mut bound = |lo: [f64; 3], hi: [f64; 3]| -> Vec<f64> {
        target
            .texels
            .iter()
            .zip(&lab)
            .map(|(c, l)| {
                let key = (c.0.map(f64::to_bits), lo.map(f64::to_bits));
                *cache.entry(key).or_insert_with(|| to_box(*l, lo, hi))
            })
            .collect()
    };
    let proof = by_region(&bound([r0; 3], [1.0; 3]));
    let uniform = by_region(&bound(black, white));
    println!(
        "{w} x {h} x {LAYERS} ({colour_layers} colour), IOR {IOR}: R0 {r0:.4}; uniform black \
         {black:.4?}, uniform white {white:.4?} ({eval_spp} spp)"
    );
    let header =
        "| | ink | edge (<= 2) | near (3-6) | far (> 6) | all |\n|---|---|---|---|---|---|";
    println!("{header}");
    let row = |name: &str, v: [f64; 5]| {
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            v[0], v[1], v[2], v[3], v[4]
        )
    };
    row(
        "share of texels",
        [0, 1, 2, 3, 4].map(|r| {
            if r == 4 {
                1.0
            } else {
                counts[r] as f64 / texels as f64
            }
        }),
    );
    row("lower bound, proof [R0, 1]", proof);
    row("lower bound, uniform prints' box", uniform);
    let naive = delta_e(&evaluate(&target.texels, 200)?);
    row(&format!("naive ({eval_spp} spp)"), by_region(&naive));
    row("blank (a uniform white print)", by_region(&delta_e(&blank)));
    // The naive aims lightened towards white by each fraction of VOLPT_LIGHTEN (a one-parameter
    // family of prints: how the lines' ink trades against the white beside them).
    for s in std::env::var("VOLPT_LIGHTEN")
        .unwrap_or_default()
        .split_whitespace()
    {
        let s: f64 = s.parse()?;
        let aims: Vec<LinearRgb> = target
            .texels
            .iter()
            .map(|t| LinearRgb(t.0.map(|v| v + s * (1.0 - v))))
            .collect();
        row(
            &format!("naive lightened by {s}"),
            by_region(&delta_e(&evaluate(&aims, 500)?)),
        );
    }
    let noise_floor = {
        let a = evaluate(&target.texels, 300)?;
        let b = evaluate(&target.texels, 302)?;
        let d: Vec<f64> = a
            .iter()
            .zip(&b)
            .map(|(a, b)| ciede2000(a.to_lab(), b.to_lab()) / std::f64::consts::SQRT_2)
            .collect();
        by_region(&d)
    };
    row("naive's noise floor", noise_floor);
    for update in updates {
        let start = std::time::Instant::now();
        let mut predictor = RenderPredictor::new(&backend, spp);
        let options = Options {
            max_iterations: iterations,
            noise_ratio: None,
            update,
            ..Options::default()
        };
        let result = compensate(
            &target.texels,
            target.size,
            &setup,
            &options,
            &mut predictor,
            |_| {},
        )?;
        let means: Vec<String> = result
            .iterations
            .iter()
            .map(|i| format!("{:.2}", i.mean))
            .collect();
        let best = &result.iterations[result.best];
        let p = evaluate(&best.aims, 400)?;
        row(
            &format!("{update:?} ({eval_spp} spp)"),
            by_region(&delta_e(&p)),
        );
        // The fitted linear model's own optimum around the kept print: where this update's model
        // of the print says no aims do better.
        let samples: Vec<_> = result
            .iterations
            .iter()
            .map(|i| (&i.aims[..], &i.prediction[..]))
            .collect();
        let response = Response::fit(&samples, target.size);
        let optimum = response.update(&best.aims, &best.prediction, &lab, target.size, 1000);
        let change: Vec<LinearRgb> = optimum
            .iter()
            .zip(&best.aims)
            .map(|(a, b)| LinearRgb([0, 1, 2].map(|c| a.0[c] - b.0[c])))
            .collect();
        let model: Vec<LinearRgb> = response
            .apply(&change, target.size)
            .iter()
            .zip(&best.prediction)
            .map(|(k, p)| LinearRgb([0, 1, 2].map(|c| (p.0[c] + k.0[c]).max(0.0))))
            .collect();
        row(
            &format!("{update:?}: its model's optimum"),
            by_region(&delta_e(&model)),
        );
        eprintln!("{update:?} response: {:.3?}", response.weights);
        let region_rgb = |r: usize| {
            let v: Vec<LinearRgb> = p
                .iter()
                .zip(&region)
                .filter(|(_, &k)| k == r)
                .map(|(c, _)| *c)
                .collect();
            mean_rgb(&v)
        };
        eprintln!(
            "{update:?}: {} iterations at {spp} spp in {:.0} s, means {means:?}, best {}; white's \
             mean linear RGB edge {:.3?} near {:.3?} far {:.3?}",
            result.iterations.len(),
            start.elapsed().as_secs_f64(),
            result.best,
            region_rgb(1),
            region_rgb(2),
            region_rgb(3),
        );
    }
    Ok(())
}
