//! Halftoning: the naive mix's own values, each texel's mean ink mix within the derived 1/L
//! bound, a uniform colour's fractions per layer, white below the colour layers, and determinism.

mod common;

use common::Rng;
use volpt_print::colour::{LinearRgb, Srgb};
use volpt_print::halftone::{naive_mix, Halftone, Mix, INKS};
use volpt_print::Inks;

fn inks() -> Inks {
    Inks::find(&common::inks()).unwrap()
}

fn assert_mix(colour: [f64; 3], expected: Mix) {
    let mix = naive_mix(LinearRgb(colour));
    for i in 0..INKS {
        assert!(
            (mix[i] - expected[i]).abs() < 1e-12,
            "{colour:?}: {mix:?}, expected {expected:?}"
        );
    }
}

#[test]
fn naive_mix_is_cmy_with_full_black_and_white_the_rest() {
    assert_mix([1.0; 3], [0.0, 0.0, 0.0, 0.0, 1.0]);
    assert_mix([0.0; 3], [0.0, 0.0, 0.0, 1.0, 0.0]);
    assert_mix([0.25; 3], [0.0, 0.0, 0.0, 0.75, 0.25]);
    // Red: magenta and yellow, each 1 before scaling to sum to 1.
    assert_mix([1.0, 0.0, 0.0], [0.0, 0.5, 0.5, 0.0, 0.0]);
    // A light colour inside the inks' gamut: the mean of its inks' colours is the colour.
    let c = [0.6, 0.7, 0.9];
    let mix = naive_mix(LinearRgb(c));
    let ink_colours = [
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
        [0.0; 3],
        [1.0; 3],
    ];
    for ch in 0..3 {
        let mean: f64 = (0..INKS).map(|i| mix[i] * ink_colours[i][ch]).sum();
        assert!((mean - c[ch]).abs() < 1e-12);
    }
}

#[test]
fn every_mix_is_a_distribution() {
    let mut rng = Rng(7);
    for _ in 0..10_000 {
        let c = [0, 1, 2].map(|_| rng.unit() * 1.4 - 0.2);
        let mix = naive_mix(LinearRgb(c));
        assert!(mix.iter().all(|&f| f >= 0.0), "{c:?}: {mix:?}");
        assert!(
            (mix.iter().sum::<f64>() - 1.0).abs() < 1e-12,
            "{c:?}: {mix:?}"
        );
    }
}

/// Counts of each ink (in [`Inks::indices`]' order) in texel `(x, y)`'s top `layers` voxels.
fn column_counts(
    indices: &[u8],
    [w, h, d]: [usize; 3],
    x: usize,
    y: usize,
    layers: usize,
) -> [usize; INKS] {
    let order = inks().indices();
    let mut counts = [0; INKS];
    for k in 0..layers {
        let m = indices[x + w * (y + h * (d - 1 - k))];
        counts[order.iter().position(|&o| o == m).unwrap()] += 1;
    }
    counts
}

#[test]
fn each_texels_mean_mix_is_within_one_over_layers_of_its_aim() {
    let mut rng = Rng(38);
    for case in 0..30 {
        let [w, h] = [1 + rng.below(20) as usize, 1 + rng.below(20) as usize];
        let layers = 1 + rng.below(40) as u32;
        let depth = layers + rng.below(5) as u32;
        let mixes: Vec<Mix> = (0..w * h)
            .map(|_| naive_mix(LinearRgb([0, 1, 2].map(|_| rng.unit()))))
            .collect();
        let halftone = Halftone {
            layers,
            depth,
            inks: inks(),
            seed: rng.next(),
        };
        let indices = halftone.indices(&mixes, w as u32, h as u32);
        let res = [w, h, depth as usize];
        let l = f64::from(layers);
        for y in 0..h {
            for x in 0..w {
                let counts = column_counts(&indices, res, x, y, layers as usize);
                for i in 0..INKS {
                    // Derived in halftone.rs: |count - L f| < 1, strictly.
                    let error = (counts[i] as f64 - l * mixes[x + w * y][i]).abs();
                    assert!(
                        error < 1.0 + 1e-9,
                        "case {case}, texel ({x}, {y}), ink {i}: {counts:?} of {layers} vs {:?}",
                        mixes[x + w * y]
                    );
                }
                // Below the colour layers: white.
                for z in 0..(depth - layers) as usize {
                    assert_eq!(indices[x + w * (y + h * z)], inks().white);
                }
            }
        }
    }
}

#[test]
fn a_uniform_colour_gives_its_fractions_in_every_layer() {
    // Two 16 x 16 Bayer tiles each way: each layer's share of an ink is within 1/256 of the mix.
    let [w, h] = [32usize, 32];
    let colour = Srgb::from_u8([120, 180, 200]).to_linear();
    let mix = naive_mix(colour);
    assert!(mix.iter().filter(|&&f| f > 0.05).count() >= 3, "{mix:?}");
    let halftone = Halftone {
        layers: 12,
        depth: 16,
        inks: inks(),
        seed: 3,
    };
    let indices = halftone.indices(&vec![mix; w * h], w as u32, h as u32);
    let order = inks().indices();
    for k in 0..12 {
        let z = 15 - k;
        let layer = &indices[w * h * z..w * h * (z + 1)];
        for i in 0..INKS {
            let share = layer.iter().filter(|&&m| m == order[i]).count() as f64 / (w * h) as f64;
            assert!(
                (share - mix[i]).abs() <= 1.0 / 256.0 + 1e-12,
                "layer {k}, ink {i}: {share} vs {}",
                mix[i]
            );
        }
    }
}

#[test]
fn the_halftone_is_a_function_of_its_seed() {
    let mut rng = Rng(1);
    let mixes: Vec<Mix> = (0..24 * 24)
        .map(|_| naive_mix(LinearRgb([0, 1, 2].map(|_| rng.unit()))))
        .collect();
    let halftone = |seed| Halftone {
        layers: 10,
        depth: 12,
        inks: inks(),
        seed,
    };
    let a = halftone(5).indices(&mixes, 24, 24);
    assert_eq!(a, halftone(5).indices(&mixes, 24, 24));
    assert_ne!(a, halftone(6).indices(&mixes, 24, 24));
}
