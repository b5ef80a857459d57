//! `volpt compare A.exr B.exr`: how far apart two renders are.
//!
//! Renders of one scene and seed on the CPU and with the GPU's naiveSK trace the same paths and
//! sum them in the same order, so they must be bit-identical; other strategies sum in another
//! order and differ by rounding only. The report says which case holds. An image holding NaN or
//! Inf fails the comparison.
//!
//! Renders that trace different paths (other seeds, the GPU's fast math) can only agree in
//! expectation: `--independent` tests that, tile by tile (`volpt::metrics::z_test`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;
use volpt::metrics::{z_test, ZTest, Z_BOUND};
use volpt::Image;

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
    let image = volpt::read_exr(path, "the image")?;
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
        let ZTest {
            worst_tile: worst,
            relative,
            z,
        } = z_test(&a, &b);
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
