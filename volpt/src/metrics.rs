//! Error metrics of rendered estimates against a reference, and the test of two estimates for
//! one expectation: what `volpt converge` and `volpt compare` report, and what an application that
//! compares predictions with targets (the printing loop) reads per pixel.
//!
//! An estimate is the mean of two independent halves (films of the same samples under different
//! seeds): their difference estimates the estimate's variance without a reference, so the MSE
//! splits into variance and bias (`bias^2 = MSE - variance - the reference's variance`). A
//! reference is a constant (a white furnace) or an image of its own variance, itself the mean of
//! two independent halves ([`Reference::from_halves`]).

use volpt_film::{Film, Image};

/// What estimates are compared with, per pixel channel.
#[derive(Clone, Debug)]
pub enum Reference {
    /// Every pixel this colour (a white furnace: the albedo-1 medium's exact image).
    Constant([f32; 3]),
    /// An image and the variance of its pixels as estimates (the mean over pixel channels).
    Image { image: Image, variance: f64 },
}

impl Reference {
    /// The mean of two independent renders `a` and `b`, and the variance of that mean
    /// (`((a - b) / 2)^2` averaged over pixel channels).
    pub fn from_halves(a: &Image, b: &Image) -> Self {
        let mut mean = a.clone();
        let mut variance = 0.0;
        for (m, pb) in mean.pixels.iter_mut().zip(&b.pixels) {
            for c in 0..3 {
                variance += (0.5 * (m[c] as f64 - pb[c] as f64)).powi(2);
                m[c] = 0.5 * (m[c] + pb[c]);
            }
        }
        let count = 3.0 * a.pixels.len() as f64;
        Reference::Image {
            image: mean,
            variance: variance / count,
        }
    }

    /// The variance of the reference's pixels as estimates (0 for a constant).
    pub fn variance(&self) -> f64 {
        match self {
            Reference::Constant(_) => 0.0,
            Reference::Image { variance, .. } => *variance,
        }
    }

    /// Channel `channel` of pixel `pixel` (row-major).
    pub fn at(&self, pixel: usize, channel: usize) -> f64 {
        match self {
            Reference::Constant(rgb) => rgb[channel] as f64,
            Reference::Image { image, .. } => image.pixels[pixel][channel] as f64,
        }
    }
}

/// The errors of an estimate, each averaged over pixel channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Mean squared error against the reference.
    pub mse: f64,
    /// Relative MSE: each squared error over `reference^2 + 0.01` (the offset keeps black pixels
    /// from dominating).
    pub rel_mse: f64,
    /// The estimate's variance, from its halves' difference.
    pub variance: f64,
}

impl Errors {
    pub fn rmse(&self) -> f64 {
        self.mse.sqrt()
    }

    /// The bias left when the variances of the estimate and of `reference` are taken out of the
    /// MSE (0 where the noise of the MSE makes it negative).
    pub fn bias(&self, reference: &Reference) -> f64 {
        bias(self.mse, self.variance, reference.variance())
    }
}

/// The bias left of `mse` when the variances of the estimate and of the reference are taken out
/// (0 where the noise of the MSE makes it negative).
pub fn bias(mse: f64, variance: f64, reference_variance: f64) -> f64 {
    (mse - variance - reference_variance).max(0.0).sqrt()
}

/// The errors of the mean of films `a` and `b` (independent halves of `spp_each` samples each)
/// against `reference`.
pub fn errors_of_halves(a: &Film, b: &Film, spp_each: u32, reference: &Reference) -> Errors {
    let n = spp_each as f64;
    let (mut mse, mut rel, mut var) = (0.0, 0.0, 0.0);
    for (i, (a, b)) in a.sums.iter().zip(&b.sums).enumerate() {
        for c in 0..3 {
            let (ma, mb) = (a[c] / n, b[c] / n);
            let estimate = 0.5 * (ma + mb);
            let r = reference.at(i, c);
            let e2 = (estimate - r).powi(2);
            mse += e2;
            rel += e2 / (r * r + 0.01);
            var += (0.5 * (ma - mb)).powi(2);
        }
    }
    let count = 3.0 * a.sums.len() as f64;
    Errors {
        mse: mse / count,
        rel_mse: rel / count,
        variance: var / count,
    }
}

/// Each pixel's squared error against `reference`, averaged over its channels (row-major): where
/// an estimate misses its target.
pub fn error_map(estimate: &Image, reference: &Reference) -> Vec<f64> {
    estimate
        .pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            (0..3)
                .map(|c| (p[c] as f64 - reference.at(i, c)).powi(2))
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

/// The `q`-quantile (`q` in [0, 1]) of `values`, linearly interpolated between order statistics
/// (NumPy's default); NaN for no values.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let at = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (at - lo as f64)
}

/// Tile edge of [`z_test`], in pixels.
pub const TILE: usize = 16;

/// The bound on |z| that [`z_test`]'s users hold estimates of one expectation to: a false alarm
/// has probability 3.8e-8 per tile and channel (two-sided normal tail), so below 1e-4 over the
/// 1 875 tests of a 400x400 image.
pub const Z_BOUND: f64 = 5.5;

/// What [`z_test`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZTest {
    /// The largest |z| of the tiles' mean differences.
    pub worst_tile: f64,
    /// The whole image's relative difference, `mean(a - b) / mean(a)`.
    pub relative: f64,
    /// The z of the whole image's mean difference.
    pub z: f64,
}

/// Whether independent estimates `a` and `b` have one expectation, tile by tile and as a whole.
///
/// The differences `d = a - b` of independent estimates are independent across pixels; under the
/// hypothesis that both have the same expectation, each has mean 0, and the sample variance of the
/// `n` differences of a tile estimates the mean of their variances, so `mean(d) / sqrt(s^2 / n)`
/// follows Student's t with `n - 1` degrees of freedom (about normal for `n = 256`). A tile whose
/// differences are all equal is significant unless they are all 0.
pub fn z_test(a: &Image, b: &Image) -> ZTest {
    let (w, h) = (a.width as usize, a.height as usize);
    let z = |ds: &[f64]| {
        let n = ds.len() as f64;
        let mean = ds.iter().sum::<f64>() / n;
        let var = ds.iter().map(|d| (d - mean) * (d - mean)).sum::<f64>() / (n - 1.0).max(1.0);
        match (mean == 0.0, var > 0.0) {
            (true, _) => 0.0,
            (false, true) => mean / (var / n).sqrt(),
            (false, false) => f64::INFINITY,
        }
    };
    let mut worst = 0.0f64;
    let mut ds = Vec::with_capacity(TILE * TILE);
    for ty in (0..h).step_by(TILE) {
        for tx in (0..w).step_by(TILE) {
            for c in 0..3 {
                ds.clear();
                for y in ty..(ty + TILE).min(h) {
                    for x in tx..(tx + TILE).min(w) {
                        let i = y * w + x;
                        ds.push(a.pixels[i][c] as f64 - b.pixels[i][c] as f64);
                    }
                }
                worst = worst.max(z(&ds).abs());
            }
        }
    }
    let all: Vec<f64> = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(pa, pb)| (0..3).map(move |c| pa[c] as f64 - pb[c] as f64))
        .collect();
    let mean_a = a.pixels.iter().flatten().map(|&v| v as f64).sum::<f64>() / all.len() as f64;
    ZTest {
        worst_tile: worst,
        relative: all.iter().sum::<f64>() / all.len() as f64 / mean_a,
        z: z(&all),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: Vec<[f32; 3]>, width: u32) -> Image {
        Image {
            width,
            height: pixels.len() as u32 / width,
            pixels,
        }
    }

    #[test]
    fn halves_split_the_mse_into_variance_and_bias() {
        // Halves r + e +- d of one sample each: the estimate is off by e, and the halves' half
        // difference is d.
        let (r, e, d) = (0.5, 0.125, 0.25);
        let film = |v: f64| Film {
            sums: vec![[v; 3]; 4],
            ..Film::new(2, 2)
        };
        let reference = Reference::Constant([r as f32; 3]);
        let errors = errors_of_halves(&film(r + e + d), &film(r + e - d), 1, &reference);
        assert_eq!(errors.mse, e * e);
        assert_eq!(errors.variance, d * d);
        assert!((errors.rel_mse - e * e / (r * r + 0.01)).abs() < 1e-15);
        assert_eq!(errors.rmse(), e);
        let noisy = Errors {
            mse: 0.06,
            rel_mse: 0.0,
            variance: 0.01,
        };
        let reference = Reference::Image {
            image: image(vec![[0.0; 3]], 1),
            variance: 0.01,
        };
        assert!((noisy.bias(&reference) - 0.2).abs() < 1e-12);
    }

    #[test]
    fn a_reference_of_halves_is_their_mean_with_its_variance() {
        let a = image(vec![[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]], 2);
        let b = image(vec![[3.0, 2.0, 1.0], [0.0, 0.0, 2.0]], 2);
        let reference = Reference::from_halves(&a, &b);
        assert_eq!(reference.at(0, 0), 2.0);
        assert_eq!(reference.at(1, 2), 1.0);
        // Half differences 1, 0, 1, 0, 0, 1 over six channels.
        assert_eq!(reference.variance(), 0.5);
    }

    #[test]
    fn error_maps_and_quantiles() {
        let estimate = image(vec![[1.0; 3], [0.0, 0.0, 3.0], [2.0; 3], [0.0; 3]], 2);
        let map = error_map(&estimate, &Reference::Constant([0.0; 3]));
        assert_eq!(map, [1.0, 3.0, 4.0, 0.0]);
        assert_eq!(quantile(&map, 0.0), 0.0);
        assert_eq!(quantile(&map, 1.0), 4.0);
        assert_eq!(quantile(&map, 0.5), 2.0);
        assert_eq!(quantile(&map, 0.25), 0.75);
        assert!(quantile(&[], 0.5).is_nan());
    }

    fn noisy(seed: u64, bias: f64) -> Image {
        let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        let mut u = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let pixels = (0..128 * 128)
            .map(|i| {
                let mean = 0.2 + (i % 128) as f64 / 128.0;
                [0; 3].map(|_| (mean * (1.0 + bias) * (0.75 + 0.5 * u())) as f32)
            })
            .collect();
        image(pixels, 128)
    }

    #[test]
    fn independent_estimates_of_one_image_pass() {
        for seed in 1..20 {
            let t = z_test(&noisy(seed, 0.0), &noisy(seed + 100, 0.0));
            assert!(
                t.worst_tile < Z_BOUND && t.z.abs() < Z_BOUND,
                "seed {seed}: {t:?}"
            );
        }
    }

    #[test]
    fn a_one_percent_bias_fails() {
        // 49 152 channels of 14% relative noise: the difference of the image means has a standard
        // error of ~0.09%, so a 1% bias is ~11 standard errors away from 0, and every seed must
        // see it (a 400x400 render at a few spp is in the same range).
        for seed in 1..10 {
            let t = z_test(&noisy(seed, 0.01), &noisy(seed + 100, 0.0));
            assert!(t.z.abs() > Z_BOUND, "seed {seed}: {t:?}");
        }
    }

    #[test]
    fn identical_images_pass_and_a_constant_offset_fails() {
        let a = noisy(1, 0.0);
        assert_eq!(z_test(&a, &a).worst_tile, 0.0);
        let mut b = a.clone();
        for p in &mut b.pixels {
            p[1] += 1e-3;
        }
        assert!(z_test(&a, &b).worst_tile > Z_BOUND);
    }
}
