//! The real predictor (a volpt render on the CPU) against what cannot be tuned: absorbing prints
//! behind an index-matched surface under unit light transmit exp(-sigma_a * thickness) along
//! each texel's column, per channel, texel by texel; and the loop runs on it.

mod common;

use volpt::scene_files::BsdfDesc;
use volpt::Backend;
use volpt_print::compensate::{compensate, Options, Predictor, Setup};
use volpt_print::halftone::Halftone;
use volpt_print::predict::RenderPredictor;
use volpt_print::{Inks, Material, VoxelPrint};

fn absorber(name: &str, colour: [u8; 3], sigma_a: [f32; 3]) -> Material {
    Material {
        name: name.into(),
        colour,
        sigma_s: [0.0; 3],
        sigma_a,
        g: 0.0,
    }
}

#[test]
fn an_absorbing_print_transmits_exp_minus_sigma_a_thickness_per_texel_and_channel() {
    let materials = vec![
        absorber("a", [1, 0, 0], [0.5, 1.0, 2.0]),
        absorber("b", [2, 0, 0], [2.0, 0.25, 1.0]),
        absorber("c", [3, 0, 0], [0.0, 3.0, 0.5]),
    ];
    // Columns of one material each, in a pattern no flip or transpose of the image preserves.
    let [w, h, d] = [6u32, 4, 5];
    let material_of = |x: u32, y: u32| ((x + 2 * y + x * y) % 3) as u8;
    let indices = (0..w * h * d)
        .map(|i| material_of(i % w, (i / w) % h))
        .collect();
    let voxel = 0.1;
    let print =
        VoxelPrint::new(materials.clone(), [voxel, voxel, 0.2], [w, h, d], indices).unwrap();
    let thickness = f64::from(d) * 0.2;
    let spp = 4096;
    let mut predictor = RenderPredictor::new(Backend::cpu(), spp);
    predictor.boundary = BsdfDesc::Null;
    let texels = predictor.predict(&print).unwrap();
    let mut worst: f64 = 0.0;
    for y in 0..h {
        for x in 0..w {
            let m = &materials[usize::from(material_of(x, y))];
            for c in 0..3 {
                let expected = (-f64::from(m.sigma_a[c]) * thickness).exp();
                let found = texels[(x + w * y) as usize].0[c];
                // Each sample is in [0, 1] with mean p: its variance is at most p (1 - p).
                let sigma = (expected * (1.0 - expected) / f64::from(spp))
                    .sqrt()
                    .max(1e-6);
                let z = (found - expected).abs() / sigma;
                worst = worst.max(z);
                assert!(
                    z < 5.0,
                    "texel ({x}, {y}) channel {c}: {found} vs {expected} ({z:.1} sigma)"
                );
            }
        }
    }
    eprintln!("worst deviation {worst:.2} sigma");
    // The halves' standard error estimates the render's: its mean square over texels and channels
    // is the mean variance of a texel's mean, at most the Bernoulli p (1 - p) / spp of a [0, 1]
    // estimator (equal to it for delta tracking's all-or-nothing transmittance).
    let (mut estimated, mut bound) = (0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let m = &materials[usize::from(material_of(x, y))];
            for c in 0..3 {
                let p = (-f64::from(m.sigma_a[c]) * thickness).exp();
                bound += p * (1.0 - p) / f64::from(spp);
                estimated += predictor.standard_error()[(x + w * y) as usize].0[c].powi(2);
            }
        }
    }
    eprintln!(
        "mean square standard error {:.3e}, Bernoulli bound {:.3e}",
        estimated / f64::from(3 * w * h),
        bound / f64::from(3 * w * h)
    );
    assert!(
        estimated > 0.2 * bound && estimated < 2.0 * bound,
        "{estimated} vs {bound}"
    );
}

#[test]
fn the_loop_runs_on_rendered_predictions_and_keeps_its_best() {
    let materials = common::inks();
    let setup = Setup {
        halftone: Halftone {
            layers: 6,
            depth: 8,
            inks: Inks::find(&materials).unwrap(),
            seed: 1,
        },
        materials,
        voxel_size: [0.05, 0.05, 0.03],
    };
    let [w, h] = [8u32, 6];
    let target: Vec<_> = (0..w * h)
        .map(|i| {
            let v = if (i % w) < w / 2 {
                [200, 90, 90]
            } else {
                [90, 160, 220]
            };
            volpt_print::colour::Srgb::from_u8(v).to_linear()
        })
        .collect();
    let mut predictor = RenderPredictor::new(Backend::cpu(), 64);
    let options = Options {
        max_iterations: 3,
        ..Options::default()
    };
    let result = compensate(&target, [w, h], &setup, &options, &mut predictor, |_| {}).unwrap();
    for it in &result.iterations {
        assert!(it.mean.is_finite() && it.p95 >= 0.0 && it.delta_e.len() == (w * h) as usize);
    }
    // The same print predicts the same image (the predictor's seed is fixed).
    let again = predictor.predict(&result.print).unwrap();
    assert_eq!(again, result.iterations[result.best].prediction);
}

#[test]
fn compensation_lowers_the_error_of_rendered_predictions() {
    // Scattering inks of the order of the thesis's resins (per mm), a 1 mm slab.
    let ink = |name: &str, colour: [u8; 3], sigma_s: f32, sigma_a: [f32; 3]| Material {
        name: name.into(),
        colour,
        sigma_s: [sigma_s; 3],
        sigma_a,
        g: 0.0,
    };
    let materials = vec![
        ink("cyan", [0, 255, 255], 4.0, [6.0, 0.4, 0.1]),
        ink("magenta", [255, 0, 255], 4.0, [0.3, 6.0, 0.4]),
        ink("yellow", [255, 255, 0], 4.0, [0.1, 0.3, 6.0]),
        ink("black", [0, 0, 0], 2.0, [20.0; 3]),
        ink("white", [255, 255, 255], 20.0, [0.02; 3]),
    ];
    let setup = Setup {
        halftone: Halftone {
            layers: 16,
            depth: 24,
            inks: Inks::find(&materials).unwrap(),
            seed: 1,
        },
        materials,
        voxel_size: [0.05, 0.05, 0.04],
    };
    let [w, h] = [16u32, 16];
    let target: Vec<_> = (0..w * h)
        .map(|i| {
            let v = if (i % w) % 4 < 2 {
                [210, 110, 100]
            } else {
                [110, 170, 210]
            };
            volpt_print::colour::Srgb::from_u8(v).to_linear()
        })
        .collect();
    let mut predictor = RenderPredictor::new(Backend::cpu(), 128);
    let options = Options {
        max_iterations: 4,
        ..Options::default()
    };
    let result = compensate(&target, [w, h], &setup, &options, &mut predictor, |_| {}).unwrap();
    let means: Vec<f64> = result.iterations.iter().map(|i| i.mean).collect();
    eprintln!("mean dE00 per iteration: {means:?}");
    assert!(means[result.best] < 0.8 * means[0], "{means:?}");
}
