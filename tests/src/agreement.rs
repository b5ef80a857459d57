//! Two estimators of the same image agree: the statistics every estimator-against-estimator test
//! shares (NEE against path tracing, majorant grid against global, roulette against none, a lookup
//! against its reference).
//!
//! Per channel, the image mean is the mean of the pixels' means; pixels are independent (each
//! has its own random streams), so its variance is the sum of the pixels' variances of the mean
//! (from [`crate::pixel_statistics_with`]: the sample variance over the paths, divided by their
//! number) over the number of pixels squared. Channels are compared separately, because one
//! path's channels are correlated. Two renders with different seeds are independent, so the
//! standard error of the difference is `sqrt(se_a^2 + se_b^2)`.

use volpt_core::PathSettings;
use volpt_scene::description::SceneDescription;

/// A 1% difference of the image means must be at least this many standard errors of the
/// difference: a margin, not a coin toss at the window.
pub const MARGIN: f64 = 10.0;

/// Two estimates agree while they differ by less than this many standard errors: with
/// [`MARGIN`] 10, a bias of 0.5% of the image mean is outside it.
pub const WINDOW: f64 = 5.0;

/// Per channel, the image mean and the variance of that mean.
#[derive(Clone, Copy, Debug)]
pub struct ImageMean {
    pub mean: [f64; 3],
    pub var: [f64; 3],
}

impl ImageMean {
    pub fn of(stats: &[[(f64, f64); 3]]) -> Self {
        let n = stats.len() as f64;
        let mut out = Self {
            mean: [0.0; 3],
            var: [0.0; 3],
        };
        for px in stats {
            for (c, &(m, v)) in px.iter().enumerate() {
                out.mean[c] += m / n;
                out.var[c] += v / (n * n);
            }
        }
        out
    }

    /// Renders `desc` under `settings` with `spp` samples per pixel and `seed`.
    pub fn render(desc: &SceneDescription, spp: u32, seed: u32, settings: PathSettings) -> Self {
        Self::of(&crate::pixel_statistics_with(desc, spp, seed, settings))
    }
}

/// The z-scores of `b - a` per channel, asserting first that the renders are large enough:
/// per channel, [`MARGIN`] standard errors of the difference are at most 1% of `a`'s mean.
pub fn z_scores(name: &str, a: &ImageMean, b: &ImageMean) -> [f64; 3] {
    std::array::from_fn(|c| {
        let se = (a.var[c] + b.var[c]).sqrt();
        assert!(
            MARGIN * se <= 0.01 * a.mean[c],
            "{name}, channel {c}: a 1% bias of {:.5} is only {:.1} standard errors ({se:.2e}): \
             too few samples to see it",
            a.mean[c],
            0.01 * a.mean[c] / se
        );
        (b.mean[c] - a.mean[c]) / se
    })
}

/// `a` and `b` estimate the same image: per channel, their means within [`WINDOW`] standard errors
/// of the difference, at a sample count where 1% is [`MARGIN`] of them.
pub fn assert_agree(name: &str, a: &ImageMean, b: &ImageMean) {
    let z = z_scores(name, a, b);
    let margin: [f64; 3] = std::array::from_fn(|c| 0.01 * a.mean[c] / (a.var[c] + b.var[c]).sqrt());
    eprintln!(
        "{name}: means {:.5?} and {:.5?}, z {:.2?}; 1% is {:.1?} standard errors",
        a.mean, b.mean, z, margin
    );
    for (c, z) in z.iter().enumerate() {
        assert!(
            z.abs() < WINDOW,
            "{name}, channel {c}: {:.5} against {:.5}, z = {z:.2}",
            a.mean[c],
            b.mean[c]
        );
    }
}
