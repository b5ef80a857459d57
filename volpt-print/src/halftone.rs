//! The printer's naive assignment and its halftoning: each surface texel's colour as a mix of the
//! five inks (cyan, magenta, yellow, black, white), put in the `layers` voxel layers under the
//! texel, white below, and halftoned so that each voxel holds one material.
//!
//! **Mix model** ([`naive_mix`]): in linear RGB clamped to [0, 1], CMY = 1 - RGB; black is the
//! grey component K = min(C, M, Y), removed from C, M and Y (full under-colour removal); white is
//! the rest, W = 1 - (C + M + Y + K). Where C + M + Y + K exceeds 1 (saturated colours mixing two
//! inks) the four are scaled to sum to 1 and W = 0. For a translucent stack whose colour is the
//! mean of its inks' colours (cyan = (0, 1, 1), ..., white = (1, 1, 1)), this mix reproduces
//! every colour with C + M + Y + K <= 1 exactly: it is the assignment a printer driver makes
//! before any scattering compensation.
//!
//! **Halftoning: 3D ordered dithering, column-stratified.** Voxel `k` layers under the surface of
//! texel `(x, y)` gets threshold `t = frac(b(x, y) + k / L)` (`L` = `layers`), where `b` is a
//! 16 x 16 Bayer matrix's value at the texel, and takes the ink whose interval
//! `[F_{i-1}, F_i)` of the cumulative mix contains `t`. Why ordered dithering and not 3D error
//! diffusion:
//! - a column's `L` thresholds are the lattice `b + k/L` mod 1, which puts in every ink's
//!   interval of length `f_i` either floor(`L f_i`) or ceil(`L f_i`) points: each texel's mean mix
//!   is within **1/L** of its aim in every ink (strictly), a bound error diffusion cannot give per
//!   texel, since its error flows between columns;
//! - each layer is the Bayer pattern shifted by `k/L`: every layer, the surface included, is
//!   dithered laterally within 1/256 over each 16 x 16 tile;
//! - a voxel depends on its own texel's aim alone, so the compensation loop's change to one
//!   texel's aim changes only that texel's column (error diffusion would reshuffle everything
//!   downstream, which the next prediction would see as noise); and every voxel is independent
//!   (one pass, parallel, GPU-able).
//!
//! The seed picks the Bayer matrix's offset on the print and a phase added to `b`: a print's
//! halftone is a function of (aims, layers, depth, seed).

use crate::colour::LinearRgb;
use crate::material::Inks;

/// The number of inks of the five-tone process, in [`Inks::indices`]' order.
pub const INKS: usize = 5;

/// Fractions of cyan, magenta, yellow, black and white; non-negative, summing to 1.
pub type Mix = [f64; INKS];

/// The printer's naive ink mix for a linear RGB colour (see the module docs).
pub fn naive_mix(colour: LinearRgb) -> Mix {
    let [c, m, y] = colour.0.map(|v| 1.0 - v.clamp(0.0, 1.0));
    let k = c.min(m).min(y);
    let mut mix = [c - k, m - k, y - k, k, 0.0];
    let inked: f64 = mix[..4].iter().sum();
    if inked > 1.0 {
        mix[..4].iter_mut().for_each(|f| *f /= inked);
    }
    mix[4] = (1.0 - mix[..4].iter().sum::<f64>()).max(0.0);
    mix
}

/// The side of the Bayer matrix: 256 threshold levels per layer.
const BAYER_SIDE: usize = 16;

/// The `side` x `side` Bayer (recursive dispersed-dot) matrix, values `0 .. side^2`, row-major:
/// B(2n) = [[4B, 4B + 2], [4B + 3, 4B + 1]] (Bayer 1973).
fn bayer(side: usize) -> Vec<u32> {
    let mut m = vec![0u32];
    let mut n = 1;
    while n < side {
        let mut next = vec![0u32; 4 * n * n];
        for y in 0..n {
            for x in 0..n {
                let v = 4 * m[x + n * y];
                for (dx, dy, add) in [(0, 0, 0), (1, 0, 2), (0, 1, 3), (1, 1, 1)] {
                    next[(x + dx * n) + 2 * n * (y + dy * n)] = v + add;
                }
            }
        }
        m = next;
        n *= 2;
    }
    m
}

/// SplitMix64 (Steele, Lea, Flood 2014): the seed's offsets.
fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Halftones a print's colour layers.
#[derive(Clone, Debug)]
pub struct Halftone {
    /// Layers under each texel that hold its colour (`L`); white below them.
    pub layers: u32,
    /// The print's depth in voxel layers, at least `layers`.
    pub depth: u32,
    pub inks: Inks,
    pub seed: u64,
}

impl Halftone {
    /// The material indices of a print (x fastest, then y, then z, bottom layer first: a
    /// [`crate::print::VoxelPrint`]'s order) whose surface texels aim for `mixes` (`width` x
    /// `height`, row-major).
    pub fn indices(&self, mixes: &[Mix], width: u32, height: u32) -> Vec<u8> {
        assert!(self.layers >= 1 && self.depth >= self.layers);
        let [w, h] = [width as usize, height as usize];
        assert_eq!(mixes.len(), w * h, "one mix per surface texel");
        let mut state = self.seed;
        let offset = [0, 1].map(|_| (splitmix64(&mut state) % BAYER_SIDE as u64) as usize);
        // A phase within one Bayer level, so that seeds differ below its resolution too.
        let phase = (splitmix64(&mut state) >> 11) as f64
            / (1u64 << 53) as f64
            / (BAYER_SIDE * BAYER_SIDE) as f64;
        let matrix = bayer(BAYER_SIDE);
        let levels = (BAYER_SIDE * BAYER_SIDE) as f64;
        let inks = self.inks.indices();
        let depth = self.depth as usize;
        let mut out = vec![self.inks.white; w * h * depth];
        let cumulative: Vec<Mix> = mixes
            .iter()
            .map(|mix| {
                let mut sum = 0.0;
                mix.map(|f| {
                    sum += f;
                    sum
                })
            })
            .collect();
        for k in 0..self.layers as usize {
            let z = depth - 1 - k;
            let shift = k as f64 / f64::from(self.layers) + phase;
            for y in 0..h {
                for x in 0..w {
                    let cell =
                        (x + offset[0]) % BAYER_SIDE + BAYER_SIDE * ((y + offset[1]) % BAYER_SIDE);
                    let b = (f64::from(matrix[cell]) + 0.5) / levels;
                    let t = (b + shift).fract();
                    let ink = cumulative[x + w * y]
                        .iter()
                        .position(|&f| t < f)
                        // Rounding may leave the last cumulative value a hair under 1.
                        .unwrap_or(INKS - 1);
                    out[x + w * (y + h * z)] = inks[ink];
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bayer_matrix_is_a_permutation_of_its_levels() {
        let mut m = bayer(BAYER_SIDE);
        m.sort_unstable();
        assert_eq!(m, (0..(BAYER_SIDE * BAYER_SIDE) as u32).collect::<Vec<_>>());
        assert_eq!(bayer(2), vec![0, 2, 3, 1]);
    }
}
