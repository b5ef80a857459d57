//! Stochastic trilinear lookups (`GridLookup::Stochastic`) against dense trilinear ones on a
//! generated heterogeneous medium (density with holes, an albedo grid varying per voxel and
//! channel), on the CPU: free flights (delta tracking), shadow rays (ratio tracking, under NEE)
//! and albedo reads all take one random sample instead of the trilinear value, which is unbiased,
//! so the images agree up to noise:
//!
//! - the image means, within `agreement::WINDOW` standard errors at a sample count where 1% is
//!   `agreement::MARGIN` of them (asserted), as `estimators.rs` compares estimators;
//! - pixel by pixel: the sum over pixels and channels of the squared z-scores of the difference
//!   is chi-square distributed; it must not exceed its 1e-4 upper quantile.
//!
//! The stochastic reads are the texture path's for dense grids (one unfiltered texel on a GPU, the
//! samples in software on the CPU) and the any-layout reads for bricked ones, which must choose
//! the same samples: the same seed renders both bit for bit alike.
//! `volpt-core/tests/stochastic.rs` proves the lookup unbiased point by point (with a planted 1%
//! bias that fails). Seeds are fixed: the outcome is the same on every run.

use volpt_core::{Estimator, PathSettings};
use volpt_scene::description::*;
use volpt_tests::agreement::{assert_agree, ImageMean};
use volpt_tests::generated::{framed_scene, heterogeneous_medium, LOW_ALBEDO};
use volpt_tests::pixel_statistics_with;
use volpt_tests::plain_path_tracing;

const SIZE: u32 = 12;

/// Sized from a pilot render of 256 spp: 1% of the image mean was 2.0 standard errors of the
/// difference in the worst channel, against the 10 that `agreement::MARGIN` asks, so 256 x
/// (10 / 2.0)^2 x 1.3 to spare.
const SPP: u32 = 8320;

fn scene(lookup: GridLookup, storage: GridStorage) -> SceneDescription {
    let mut desc = framed_scene(
        SIZE,
        heterogeneous_medium(6.0, LOW_ALBEDO, 0.4),
        EnvironmentDesc::Constant([1.0, 0.9, 0.8]),
    );
    desc.medium.lookup = lookup;
    desc.medium.storage = storage;
    desc
}

/// `P(X >= x)` of a chi-square of `k` degrees of freedom, by the Wilson-Hilferty normal
/// approximation (good to ~1e-3 in the p-value at the hundreds of degrees of freedom here), as
/// the upper tail of a standard normal `z`.
fn chi_square_z(x: f64, k: f64) -> f64 {
    let v = 2.0 / (9.0 * k);
    ((x / k).cbrt() - (1.0 - v)) / v.sqrt()
}

/// The per-pixel comparison: `sum z^2` over pixels and channels must lie below the 1e-4 upper
/// quantile of its chi-square distribution (z = 3.72 in the Wilson-Hilferty normal).
fn assert_pixels_agree(name: &str, a: &[[(f64, f64); 3]], b: &[[(f64, f64); 3]]) {
    let mut x2 = 0.0;
    let mut k = 0.0;
    for (pa, pb) in a.iter().zip(b) {
        for c in 0..3 {
            let (ma, va) = pa[c];
            let (mb, vb) = pb[c];
            if va + vb > 0.0 {
                x2 += (ma - mb) * (ma - mb) / (va + vb);
                k += 1.0;
            }
        }
    }
    let z = chi_square_z(x2, k);
    eprintln!("{name}: per-pixel chi2 {x2:.1} on {k} dof (normal z {z:.2})");
    assert!(k > 300.0, "{name}: only {k} pixel channels with noise");
    assert!(z < 3.72, "{name}: chi2 {x2:.1} on {k} dof, z {z:.2}");
}

#[test]
fn stochastic_lookups_match_trilinear_on_a_generated_medium() {
    let start = std::time::Instant::now();
    let reference = scene(GridLookup::Trilinear, GridStorage::Dense);
    let a = pixel_statistics_with(&reference, SPP, 1, plain_path_tracing());
    let nee = PathSettings {
        estimator: Estimator::NextEvent,
        ..plain_path_tracing()
    };
    let a_nee = pixel_statistics_with(&reference, SPP, 2, nee);
    let dense = scene(GridLookup::Stochastic, GridStorage::Dense);
    let bricked = scene(GridLookup::Stochastic, GridStorage::Bricked);
    let candidates = [
        ("stochastic", &dense, plain_path_tracing(), &a, 3),
        ("stochastic under nee", &dense, nee, &a_nee, 4),
    ];
    for (name, desc, settings, a, seed) in candidates {
        let b = pixel_statistics_with(desc, SPP, seed, settings);
        assert_agree(name, &ImageMean::of(a), &ImageMean::of(&b));
        assert_pixels_agree(name, a, &b);
        if seed == 3 {
            // The any-layout reads of bricked grids choose the same samples as the texture path's.
            let any_layout = pixel_statistics_with(&bricked, SPP, seed, settings);
            assert!(
                any_layout == b,
                "bricked stochastic reads differ from dense ones"
            );
        }
    }
    eprintln!(
        "5 renders of {SPP} spp: {:.1} s",
        start.elapsed().as_secs_f64()
    );
}
