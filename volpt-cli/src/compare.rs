//! `volpt compare A.exr B.exr`: how far apart two renders are.
//!
//! Renders of one scene and seed on the CPU and with the GPU's naiveSK trace the same paths and
//! sum them in the same order, so they must be bit-identical; other strategies sum in another
//! order and differ by rounding only. The report says which case holds. An image holding NaN or
//! Inf fails the comparison.
//!
//! Renders that trace different paths (other seeds, the GPU's fast math) can only agree in
//! expectation: `--independent` tests that, tile by tile ([`z_test`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;
use volpt_render::Image;

#[derive(Args)]
pub struct CompareArgs {
    a: PathBuf,
    b: PathBuf,
    /// Fail unless every pixel is bit-identical.
    #[arg(long)]
    identical: bool,
    /// Fail if any pixel channel differs by more than this, relative to max(|a|, |b|, 1e-3).
    #[arg(long, value_parser = parse_bound)]
    max_relative: Option<f64>,
    /// A and B are independent estimates of one image (e.g. other seeds): fail if the mean
    /// difference of any 16x16 tile and channel, or of the whole image, is significant.
    #[arg(long)]
    independent: bool,
}

/// Tile edge of the `--independent` test, in pixels.
const TILE: usize = 16;

/// The `--independent` test's bound on |z|: a false alarm has probability 3.8e-8 per tile and
/// channel (two-sided normal tail), so below 1e-4 over the 1 875 tests of a 400x400 image.
const Z_BOUND: f64 = 5.5;

/// The largest |z| of the tiles' mean differences, and the whole image's relative difference
/// `mean(a - b) / mean(a)` with its z.
///
/// The differences `d = a - b` of independent estimates are independent across pixels; under the
/// hypothesis that both have the same expectation, each has mean 0, and the sample variance of the
/// `n` differences of a tile estimates the mean of their variances, so `mean(d) / sqrt(s^2 / n)`
/// follows Student's t with `n - 1` degrees of freedom (about normal for `n = 256`). A tile whose
/// differences are all equal is significant unless they are all 0.
pub fn z_test(a: &Image, b: &Image) -> (f64, f64, f64) {
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
    let relative = all.iter().sum::<f64>() / all.len() as f64 / mean_a;
    (worst, relative, z(&all))
}

/// A tolerance: a finite number >= 0 (NaN would make every comparison pass).
fn parse_bound(s: &str) -> Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|b| b.is_finite() && *b >= 0.0)
        .ok_or_else(|| format!("expected a finite number >= 0, found {s:?}"))
}

/// Reads an EXR after checking what its header claims against the memory limit, and refuses
/// non-finite pixels: a render holding NaN or Inf is broken, whatever the other image holds.
fn read(path: &Path) -> Result<Image> {
    // `Image` keeps three f32 per pixel beside the decoded channels.
    volpt_scene::limits::check_exr(path, "the image", 12)?;
    let image = Image::read_exr(path)?;
    if let Some(i) = image
        .pixels
        .iter()
        .position(|p| p.iter().any(|v| !v.is_finite()))
    {
        let width = image.width as usize;
        bail!(
            "{}: pixel (x={}, y={}) is {:?}: expected finite values",
            path.display(),
            i % width,
            i / width,
            image.pixels[i]
        );
    }
    Ok(image)
}

pub fn run(args: &CompareArgs) -> Result<()> {
    let a = read(&args.a)?;
    let b = read(&args.b)?;
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "{} is {}x{} but {} is {}x{}",
            args.a.display(),
            a.width,
            a.height,
            args.b.display(),
            b.width,
            b.height
        );
    }
    let mut identical = 0usize;
    let mut max_abs = 0.0f64;
    let mut max_rel = 0.0f64;
    let (mut sum_a, mut sum_b, mut sum_squared) = (0.0f64, 0.0f64, 0.0f64);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        if pa.map(f32::to_bits) == pb.map(f32::to_bits) {
            identical += 1;
        }
        for (&x, &y) in pa.iter().zip(pb) {
            let (x, y) = (x as f64, y as f64);
            sum_a += x;
            sum_b += y;
            let diff = (x - y).abs();
            sum_squared += diff * diff;
            max_abs = max_abs.max(diff);
            max_rel = max_rel.max(diff / x.abs().max(y.abs()).max(1e-3));
        }
    }
    let n = a.pixels.len();
    println!(
        "{n} pixels: {identical} bit-identical ({:.4}%), max |a-b| {max_abs:.3e}, \
         max relative {max_rel:.3e}, mean a {:.6}, mean b {:.6}, mse {:.6e}",
        100.0 * identical as f64 / n as f64,
        sum_a / (3 * n) as f64,
        sum_b / (3 * n) as f64,
        sum_squared / (3 * n) as f64,
    );
    if args.identical && identical != n {
        bail!("{} pixels differ", n - identical);
    }
    if let Some(bound) = args.max_relative {
        if max_rel > bound {
            bail!("largest relative difference {max_rel:.3e} exceeds {bound:.3e}");
        }
    }
    if args.independent {
        let (worst, relative, z) = z_test(&a, &b);
        println!(
            "independent estimates: largest tile |z| {worst:.2}, image mean differs by \
             {:.4}% (z {z:.2}); bound |z| <= {Z_BOUND}",
            100.0 * relative
        );
        if worst > Z_BOUND || z.abs() > Z_BOUND {
            bail!(
                "the images' expectations differ: |z| {:.2} > {Z_BOUND}",
                worst.max(z.abs())
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 128x128 image of `mean * (1 + bias)` times uniform noise in [0.75, 1.25) from a 64-bit LCG.
    fn noisy(seed: u64, bias: f64) -> Image {
        let mut state = seed;
        let mut u = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let pixels = (0..128 * 128)
            .map(|i| {
                let mean = 0.2 + (i % 128) as f64 / 128.0;
                [0; 3].map(|_| (mean * (1.0 + bias) * (0.75 + 0.5 * u())) as f32)
            })
            .collect();
        Image {
            width: 128,
            height: 128,
            pixels,
        }
    }

    #[test]
    fn independent_estimates_of_one_image_pass() {
        for seed in 1..20 {
            let (worst, _, z) = z_test(&noisy(seed, 0.0), &noisy(seed + 100, 0.0));
            assert!(
                worst < Z_BOUND && z.abs() < Z_BOUND,
                "seed {seed}: {worst} {z}"
            );
        }
    }

    #[test]
    fn a_one_percent_bias_fails() {
        // 49 152 channels of 14% relative noise: the difference of the image means has a standard
        // error of ~0.09%, so a 1% bias is ~11 standard errors away from 0, and every seed must
        // see it (a 400x400 render at a few spp is in the same range).
        for seed in 1..10 {
            let (_, relative, z) = z_test(&noisy(seed, 0.01), &noisy(seed + 100, 0.0));
            assert!(z.abs() > Z_BOUND, "seed {seed}: relative {relative}, z {z}");
        }
    }

    #[test]
    fn identical_images_pass_and_a_constant_offset_fails() {
        let a = noisy(1, 0.0);
        assert_eq!(z_test(&a, &a).0, 0.0);
        let mut b = a.clone();
        for p in &mut b.pixels {
            p[1] += 1e-3;
        }
        assert!(z_test(&a, &b).0 > Z_BOUND);
    }
}
