//! What several test files share: a five-ink material table, a seeded generator, and the linear
//! blur model of a print that the compensation loop's own tests use as their predictor.
#![allow(dead_code)]

use volpt_print::colour::{LinearRgb, Srgb};
use volpt_print::compensate::Predictor;
use volpt_print::{MaterialDesc, VoxelPrint};

/// The five-tone process's inks, palette colours as a slice stack names them. The coefficients
/// are of the order of the thesis's resins (per mm); these tests do not depend on them.
pub fn inks() -> Vec<MaterialDesc> {
    let ink = |name: &str, colour: [u8; 3], sigma_a: [f32; 3]| MaterialDesc {
        name: name.into(),
        colour: Some(colour),
        sigma_s: [10.0; 3],
        sigma_a,
        g: 0.0,
    };
    vec![
        ink("cyan", [0, 255, 255], [3.0, 0.1, 0.05]),
        ink("magenta", [255, 0, 255], [0.1, 3.0, 0.1]),
        ink("yellow", [255, 255, 0], [0.05, 0.1, 3.0]),
        ink("black", [0, 0, 0], [5.0; 3]),
        ink("white", [255, 255, 255], [0.01; 3]),
    ]
}

/// SplitMix64, for reproducible random cases.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0 .. n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A linear model of a print seen from above, for testing the loop (not a product path: the
/// real predictor renders the print). A texel's column colour is the mean of its voxels' ink
/// colours (each ink's palette colour, in linear RGB) weighted by depth, `rho^k` for the voxel
/// `k` layers down, normalised over the print's depth; the image is that column colour blurred
/// by a separable binomial kernel of `radius` (weights C(2r, r + d) / 4^r, edges clamped), but
/// for a share `own` of it that stays at its texel. The kernel's spectrum is cos^(2r), in [0, 1],
/// and the depth weights sum to 1: a linear, symmetric transport of norm at most 1, on which the
/// loop's update contracts. With `own` > 0 it is a print's point spread in miniature: a sharp
/// part (light remitted near where it entered) over a wide tail (light that wandered). With
/// `absorption` > 0 the tail is not the blurred colour but `exp(-absorption * blur(1 - colour))`:
/// light that wandered through inked columns absorbed along its way (Beer-Lambert), so a white
/// texel beside ink darkens more than in proportion to it, as in a real print (not linear).
pub struct BlurModel {
    pub rho: f64,
    pub radius: usize,
    pub own: f64,
    pub absorption: f64,
}

impl Predictor for BlurModel {
    type Error = std::convert::Infallible;

    fn predict(&mut self, print: &VoxelPrint) -> Result<Vec<LinearRgb>, Self::Error> {
        let [w, h, d] = print.resolution().map(|n| n as usize);
        let colours: Vec<[f64; 3]> = print
            .materials()
            .iter()
            .map(|m| {
                Srgb::from_u8(m.colour.expect("a palette colour"))
                    .to_linear()
                    .0
            })
            .collect();
        let weights: Vec<f64> = (0..d).map(|k| self.rho.powi(k as i32)).collect();
        let total: f64 = weights.iter().sum();
        let mut column = vec![[0.0; 3]; w * h];
        for (k, weight) in weights.iter().enumerate() {
            let layer = print.layer((d - 1 - k) as u32);
            for (c, &m) in column.iter_mut().zip(layer) {
                for ch in 0..3 {
                    c[ch] += weight / total * colours[usize::from(m)][ch];
                }
            }
        }
        let r = self.radius;
        let binomial: Vec<f64> = (0..=2 * r)
            .map(|i| (0..i).fold(1.0, |b, j| b * (2 * r - j) as f64 / (j + 1) as f64))
            .map(|b| b / 4f64.powi(r as i32))
            .collect();
        let blur = |image: &[[f64; 3]], step: [usize; 2]| -> Vec<[f64; 3]> {
            let mut out = vec![[0.0; 3]; w * h];
            for y in 0..h {
                for x in 0..w {
                    for (i, b) in binomial.iter().enumerate() {
                        let off = i as isize - r as isize;
                        let sx = (x as isize + off * step[0] as isize).clamp(0, w as isize - 1);
                        let sy = (y as isize + off * step[1] as isize).clamp(0, h as isize - 1);
                        let s = image[sx as usize + w * sy as usize];
                        for ch in 0..3 {
                            out[x + w * y][ch] += b * s[ch];
                        }
                    }
                }
            }
            out
        };
        let tail = if self.absorption > 0.0 {
            let ink: Vec<[f64; 3]> = column.iter().map(|c| c.map(|v| 1.0 - v)).collect();
            let blurred = blur(&blur(&ink, [1, 0]), [0, 1]);
            blurred
                .into_iter()
                .map(|u| u.map(|v| (-self.absorption * v).exp()))
                .collect()
        } else {
            blur(&blur(&column, [1, 0]), [0, 1])
        };
        Ok(tail
            .into_iter()
            .zip(&column)
            .map(|(b, c)| {
                LinearRgb([0, 1, 2].map(|ch| self.own * c[ch] + (1.0 - self.own) * b[ch]))
            })
            .collect())
    }
}

/// [`BlurModel`] seen through noise, as a render with `spp` samples is: every texel and channel
/// gets Gaussian noise of standard deviation `sigma_1 / sqrt(spp)` (Box-Muller on a seeded
/// generator), which it reports as its standard error; [`Predictor::more_samples`] quadruples
/// `spp` up to `max_spp`. Counts the samples it has spent per texel.
pub struct NoisyBlur {
    pub model: BlurModel,
    pub sigma_1: f64,
    pub spp: u32,
    pub max_spp: u32,
    pub rng: Rng,
    pub spent: u64,
    error: Vec<LinearRgb>,
}

impl NoisyBlur {
    pub fn new(model: BlurModel, sigma_1: f64, spp: u32, max_spp: u32, seed: u64) -> Self {
        NoisyBlur {
            model,
            sigma_1,
            spp,
            max_spp,
            rng: Rng(seed),
            spent: 0,
            error: Vec::new(),
        }
    }
}

impl Predictor for NoisyBlur {
    type Error = std::convert::Infallible;

    fn predict(&mut self, print: &VoxelPrint) -> Result<Vec<LinearRgb>, Self::Error> {
        let exact = self.model.predict(print)?;
        let sigma = self.sigma_1 / f64::from(self.spp).sqrt();
        self.spent += u64::from(self.spp);
        self.error = vec![LinearRgb([sigma; 3]); exact.len()];
        let rng = &mut self.rng;
        Ok(exact
            .into_iter()
            .map(|c| {
                LinearRgb(c.0.map(|v| {
                    let (u, w) = (1.0 - rng.unit(), rng.unit());
                    v + sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * w).cos()
                }))
            })
            .collect())
    }

    fn standard_error(&self) -> Option<&[LinearRgb]> {
        Some(&self.error)
    }

    fn more_samples(&mut self) -> bool {
        let more = (4 * self.spp).min(self.max_spp);
        let grew = more > self.spp;
        self.spp = more;
        grew
    }

    fn samples(&self) -> Option<u32> {
        Some(self.spp)
    }
}
