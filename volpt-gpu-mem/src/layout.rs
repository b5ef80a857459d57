//! The host side of [`GridLayout::Bricked`]: a dense grid's samples rewritten brick by brick.

use rayon::prelude::*;
use volpt_core::grid::BRICK;
use volpt_core::GridLayout;

/// Samples in one brick.
const BRICK_SAMPLES: usize = (BRICK * BRICK * BRICK) as usize;

/// The values a grid of `res` samples of `channels` channels takes in `layout`, if its sample
/// indices fit the lookup's `u32` arithmetic (`None` otherwise: such a grid stays dense).
pub fn values_in(layout: GridLayout, res: [u32; 3], channels: u32) -> Option<u64> {
    let samples = layout.values(res, 1)?;
    (samples <= 1 << 32).then_some(samples * u64::from(channels))
}

/// Writes the dense samples `dense` (`res`, `channels` interleaved) into `out` in the bricked
/// layout; `out` must hold `GridLayout::Bricked.values(res, channels)` values. Padding samples
/// become 0. Bricks are written in parallel: each is a contiguous run of `out`, and each of its
/// rows of [`BRICK`] samples is a contiguous run of `dense`.
pub fn brick_into(dense: &[f32], res: [u32; 3], channels: u32, out: &mut [f32]) {
    let c = channels as usize;
    assert_eq!(
        Some(dense.len() as u64),
        GridLayout::Dense.values(res, channels),
        "dense grid does not match its resolution"
    );
    assert_eq!(
        Some(out.len() as u64),
        GridLayout::Bricked.values(res, channels),
        "bricked grid does not match its resolution"
    );
    let bricks = res.map(|r| r.div_ceil(BRICK));
    out.par_chunks_mut(BRICK_SAMPLES * c)
        .enumerate()
        .for_each(|(brick, chunk)| {
            let brick = brick as u32;
            let origin = [
                brick % bricks[0] * BRICK,
                brick / bricks[0] % bricks[1] * BRICK,
                brick / (bricks[0] * bricks[1]) * BRICK,
            ];
            let row_len = (res[0] - origin[0]).min(BRICK) as usize * c;
            for lz in 0..BRICK {
                for ly in 0..BRICK {
                    let (y, z) = (origin[1] + ly, origin[2] + lz);
                    let to = ((lz * BRICK + ly) * BRICK) as usize * c;
                    let row = &mut chunk[to..to + BRICK as usize * c];
                    if y < res[1] && z < res[2] {
                        let from = GridLayout::Dense.index(res, origin[0], y, z) as usize * c;
                        row[..row_len].copy_from_slice(&dense[from..from + row_len]);
                        row[row_len..].fill(0.0);
                    } else {
                        row.fill(0.0);
                    }
                }
            }
        });
}

/// [`brick_into`] a new vector, or `None` if the host cannot allocate it.
pub fn bricked(dense: &[f32], res: [u32; 3], channels: u32) -> Option<Vec<f32>> {
    let len = usize::try_from(GridLayout::Bricked.values(res, channels)?).ok()?;
    let mut out = Vec::new();
    out.try_reserve_exact(len).ok()?;
    out.resize(len, 0.0);
    brick_into(dense, res, channels, &mut out);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use volpt_core::{Aabb, Grid, GridMapping, Vec3};

    fn values(n: usize) -> Vec<f32> {
        (0..n)
            .map(|i| (i as f32 * 0.618_034).fract() + i as f32)
            .collect()
    }

    #[test]
    fn every_sample_lands_where_the_lookup_reads_it() {
        for (res, c) in [
            ([1, 1, 1], 1),
            ([8, 8, 8], 1),
            ([9, 17, 3], 1),
            ([13, 7, 21], 3),
            ([2048, 2, 1], 1),
        ] {
            let n = res.iter().product::<u32>() as usize * c as usize;
            let dense = values(n);
            let out = bricked(&dense, res, c).unwrap();
            let cu = c as usize;
            for z in 0..res[2] {
                for y in 0..res[1] {
                    for x in 0..res[0] {
                        let d = GridLayout::Dense.index(res, x, y, z) as usize * cu;
                        let b = GridLayout::Bricked.index(res, x, y, z) as usize * cu;
                        assert_eq!(out[b..b + cu], dense[d..d + cu], "{res:?} ({x},{y},{z})");
                    }
                }
            }
            // Everything else is padding, and zero.
            let real: f64 = dense.iter().map(|&v| v as f64).sum();
            let all: f64 = out.iter().map(|&v| v as f64).sum();
            assert_eq!(real, all);
        }
    }

    #[test]
    fn bricked_grids_look_up_bit_identically() {
        let res = [19, 11, 10];
        let dense = values(res.iter().product::<u32>() as usize);
        let out = bricked(&dense, res, 1).unwrap();
        let mapping = GridMapping::vertex_centred(Aabb::new(Vec3::ZERO, Vec3::ONE), res);
        let a = Grid::<1>::new(&dense, res, mapping);
        let b = Grid::<1>::with_layout(&out, res, mapping, GridLayout::Bricked);
        for i in 0..10_000u32 {
            let p = Vec3::new(
                (i as f32 * 0.754_877_7).fract(),
                (i as f32 * 0.569_840_3).fract(),
                (i as f32 * 0.137_016_7).fract(),
            );
            assert_eq!(a.lookup(p)[0].to_bits(), b.lookup(p)[0].to_bits(), "{p:?}");
        }
    }

    #[test]
    fn grids_beyond_u32_indices_stay_dense() {
        assert_eq!(
            values_in(GridLayout::Dense, [2048, 1024, 1024], 1),
            Some(1 << 31)
        );
        assert_eq!(
            values_in(GridLayout::Bricked, [2048, 1024, 1024], 1),
            Some(1 << 31)
        );
        // 2^32 samples exactly still index with u32 (the largest index is 2^32 - 1).
        assert_eq!(
            values_in(GridLayout::Dense, [2048, 2048, 1024], 1),
            Some(1 << 32)
        );
        // Padding 2047 to 2048 on every axis pushes past 2^32 samples.
        assert_eq!(values_in(GridLayout::Bricked, [2047, 2047, 1025], 1), None);
        assert_eq!(values_in(GridLayout::Bricked, [u32::MAX; 3], 3), None);
    }
}
