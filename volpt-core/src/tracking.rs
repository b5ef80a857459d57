//! Free-flight sampling by delta (Woodcock) tracking and transmittance by ratio tracking, both over
//! the medium's majorants: one global bound, or a majorant grid walked cell by cell.

use crate::chromatic::rescale;
use crate::majorant::Dda;
use crate::math::{exp, ln};
use crate::medium::Medium;
use crate::rng::{unit_f32, Rng};
use crate::{Ray, Spectrum};

/// How a free flight ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FreeFlight {
    /// A real collision at this distance along the ray.
    Collision(f32),
    /// The ray reached `t_max` first.
    Escaped,
    /// `steps` reached the budget before either: the caller must end the path.
    OutOfSteps,
}

/// What a walk over the majorants does at each tentative collision: `stop_at(rng, t, majorant,
/// bits)` returns true to end the walk at distance `t`; `bits` is the 64-bit number whose top 24
/// bits drew `t`, so its low 40 are free random bits for a stochastic grid lookup at `t`
/// ([`Medium::sigma_t_random`]). Closures implement it (tests); the trackers use
/// named types whose method is always inlined, because the walk calls it from two loops and LLVM
/// then keeps a closure's body as a function of its own, which on a GPU takes the medium, and the
/// whole scene with it, by address into local memory (a ~500-byte stack frame per thread).
pub trait TentativeCollision {
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, bits: u64) -> bool;
}

impl<F: FnMut(&mut Rng, f32, f32) -> bool> TentativeCollision for F {
    #[inline(always)]
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, _bits: u64) -> bool {
        self(rng, t, majorant)
    }
}

/// Samples tentative collisions along `ray` up to `t_max`, exponentially distributed under the
/// medium's majorant, and calls `at.stop_at(rng, t, majorant)` at each until it returns true (then the
/// walk ends at `t`, `FreeFlight::Collision(t)`). `steps` counts tentative collisions; the walk
/// gives up once it reaches `max_steps`.
///
/// With one global majorant this is Woodcock et al. 1965's loop. With a majorant grid the ray is
/// walked through the cells (pbrt-v4's `SampleT_maj`): within a cell the steps are exponential under
/// that cell's bound; a step past the cell's end is discarded and sampling restarts at the
/// boundary under the next cell's bound, which the exponential's lack of memory makes exact. A
/// cell of majorant 0 is crossed without a step.
///
/// The expected number of steps is the integral of the majorant along the ray: an enormous bound
/// (one dense voxel among empty ones) or a non-finite one (where `t` never grows) would spin for
/// ever, so the budget bounds the work. It is checked before a step is counted, so `steps` never
/// exceeds `max_steps` (nor overflows). The global loop's random numbers and arithmetic are those of
/// plain delta tracking.
#[inline(always)]
pub fn walk_majorants<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    steps: &mut u32,
    max_steps: u32,
    mut at: impl TentativeCollision,
) -> FreeFlight {
    let Some(grid) = medium.majorant_grid() else {
        let majorant = medium.majorant();
        if majorant <= 0.0 {
            return FreeFlight::Escaped;
        }
        let majorant = normal_majorant(majorant);
        let inv_majorant = 1.0 / majorant;
        let mut t = 0.0;
        loop {
            let bits = rng.next_u64();
            t -= ln(1.0 - unit_f32(bits)) * inv_majorant;
            if t >= t_max {
                return FreeFlight::Escaped;
            }
            if *steps >= max_steps {
                return FreeFlight::OutOfSteps;
            }
            *steps += 1;
            if at.stop_at(rng, t, majorant, bits) {
                return FreeFlight::Collision(t);
            }
        }
    };
    // One loop, not a loop over cells around a loop over the steps in a cell: each iteration
    // takes one step and, if it left the cell (or the cell is empty), moves to the next cell, so
    // the lanes of a GPU warp, whose paths cross cells at different steps, take their steps
    // together instead of waiting at the inner loop's end for the lane with the most steps in
    // its cell. The same numbers drawn in the same order, the same arithmetic.
    let mut dda = Dda::new(grid, ray);
    let mut start = 0.0f32;
    let mut cell = Cell::new(&dda, grid, t_max, start);
    loop {
        if cell.majorant > 0.0 {
            let bits = rng.next_u64();
            cell.t -= ln(1.0 - unit_f32(bits)) * cell.inv_majorant;
            // Not `t < end`: a NaN `t` or `end` takes the step (the budget ends such a walk).
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(cell.t >= cell.end) {
                if *steps >= max_steps {
                    return FreeFlight::OutOfSteps;
                }
                *steps += 1;
                if at.stop_at(rng, cell.t, cell.majorant, bits) {
                    return FreeFlight::Collision(cell.t);
                }
                continue;
            }
        }
        // Anything but `end < t_max` ends the walk, a NaN `end` or `t_max` included.
        if cell.end.partial_cmp(&t_max) != Some(core::cmp::Ordering::Less) {
            return FreeFlight::Escaped;
        }
        start = start.max(cell.end);
        dda.advance(grid, ray.dir);
        cell = Cell::new(&dda, grid, t_max, start);
    }
}

/// The majorant-grid walk's current cell: its bound (raised by [`normal_majorant`] where
/// positive), the bound's reciprocal, where the walk leaves it and the distance sampled so far.
struct Cell {
    majorant: f32,
    inv_majorant: f32,
    end: f32,
    t: f32,
}

impl Cell {
    #[inline(always)]
    fn new(dda: &Dda, grid: &crate::majorant::MajorantGrid<'_>, t_max: f32, start: f32) -> Self {
        let (majorant, cell_end) = dda.segment(grid);
        // A cell of bound 0 (or NaN) is crossed without a step; its bound is left as it is.
        let majorant = if majorant > 0.0 {
            normal_majorant(majorant)
        } else {
            majorant
        };
        Self {
            majorant,
            inv_majorant: 1.0 / majorant,
            end: cell_end.min(t_max),
            t: start,
        }
    }
}

/// `majorant` (positive, or NaN), raised to at least `f32::MIN_POSITIVE`. The reciprocal of a
/// subnormal majorant overflows to infinity, and a step drawn from `u = 0` is then `0 * inf`: a NaN
/// `t` that no comparison ends, so the walk spun to the step budget (smoke's grid has subnormal
/// voxels: one path in ~80 million took 2^26 steps, 20 s of one GPU thread). A larger majorant is
/// still a majorant, so tracking stays exact (a homogeneous medium, which accepts every tentative
/// collision, then collides at rate 1.2e-38 instead of its subnormal `sigma_t`: no f32 image can
/// show the difference); a NaN stays NaN (the budget catches it).
#[inline(always)]
fn normal_majorant(majorant: f32) -> f32 {
    if majorant < f32::MIN_POSITIVE {
        f32::MIN_POSITIVE
    } else {
        majorant
    }
}

/// Samples the distance to the next real collision along `ray` before `t_max`: delta tracking,
/// accepting a tentative collision at `x` with probability `sigma_t(x) / majorant(x)`. The accepted
/// distances follow `sigma_t(t) exp(-int_0^t sigma_t)` exactly for any majorant `>= sigma_t`
/// (Woodcock et al. 1965; Galtier et al. 2013 for piecewise majorants). A homogeneous medium
/// accepts every collision, so it samples the exponential once.
#[inline]
pub fn delta_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    steps: &mut u32,
    max_steps: u32,
) -> FreeFlight {
    walk_majorants(
        medium,
        ray,
        t_max,
        rng,
        steps,
        max_steps,
        DeltaAcceptance { medium, ray },
    )
}

/// Delta tracking's test: a tentative collision is real with probability `sigma_t / majorant`.
struct DeltaAcceptance<'a, M> {
    medium: &'a M,
    ray: &'a Ray,
}

impl<M: Medium> TentativeCollision for DeltaAcceptance<'_, M> {
    #[inline(always)]
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, bits: u64) -> bool {
        M::HOMOGENEOUS
            || rng.next_f32() * majorant < self.medium.sigma_t_random(self.ray.at(t), bits)
    }
}

/// An unbiased estimate of the transmittance `exp(-int_0^t_max sigma_t)` along `ray`, or `None`
/// when the step budget ran out.
///
/// Ratio tracking (Cramer 1978; Novák et al. 2014): the product of `1 - sigma_t(x) / majorant(x)`
/// over the tentative collisions. Once the product falls below 1/8, Russian roulette ends it with
/// probability 1/2 (doubling it otherwise), so that a dense medium costs a bounded number of steps
/// per shadow ray without bias. A homogeneous medium needs no estimate: `exp(-sigma_t t_max)`.
///
/// Always inlined: as a call on a GPU it takes the medium by address, which moves the whole scene
/// into local memory (a ~450-byte stack frame per thread).
#[inline(always)]
pub fn ratio_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    steps: &mut u32,
    max_steps: u32,
) -> Option<f32> {
    if M::HOMOGENEOUS {
        return Some(exp(-medium.majorant() * t_max));
    }
    let mut ratio = RatioProduct {
        medium,
        ray,
        transmittance: 1.0,
    };
    let flight = walk_majorants(medium, ray, t_max, rng, steps, max_steps, &mut ratio);
    match flight {
        FreeFlight::OutOfSteps => None,
        FreeFlight::Collision(_) => Some(0.0),
        FreeFlight::Escaped => Some(ratio.transmittance),
    }
}

/// Ratio tracking's running product, with its roulette; it stops the walk once it is zero.
struct RatioProduct<'a, M> {
    medium: &'a M,
    ray: &'a Ray,
    transmittance: f32,
}

impl<M: Medium> TentativeCollision for &mut RatioProduct<'_, M> {
    #[inline(always)]
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, bits: u64) -> bool {
        self.transmittance *= 1.0 - self.medium.sigma_t_random(self.ray.at(t), bits) / majorant;
        if self.transmittance < 0.125 {
            if rng.next_f32() < 0.5 {
                self.transmittance *= 2.0;
            } else {
                self.transmittance = 0.0;
            }
        }
        self.transmittance <= 0.0
    }
}

/// Delta tracking of a chromatic medium ([`crate::chromatic`]): the tentative collisions of
/// [`walk_majorants`] (one majorant for every channel), each real with probability `w_hero`, where
/// `w = sigma_t(x) / majorant` per channel; each real or null collision rescales the path densities
/// `r_u` by `w` or `1 - w` ([`rescale`]), the single-sample spectral MIS of Miller et al. 2019. A
/// path whose `r_u` becomes zero stops at the collision (the caller ends it).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn spectral_delta_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    hero: u8,
    r_u: &mut Spectrum,
    steps: &mut u32,
    max_steps: u32,
) -> FreeFlight {
    walk_majorants(
        medium,
        ray,
        t_max,
        rng,
        steps,
        max_steps,
        SpectralAcceptance {
            medium,
            ray,
            hero: hero as usize,
            r_u,
        },
    )
}

/// Spectral delta tracking's test and its rescaling of the path densities.
struct SpectralAcceptance<'a, M> {
    medium: &'a M,
    ray: &'a Ray,
    hero: usize,
    r_u: &'a mut Spectrum,
}

impl<M: Medium> TentativeCollision for SpectralAcceptance<'_, M> {
    #[inline(always)]
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, _bits: u64) -> bool {
        let w = collision_probabilities(self.medium, self.ray.at(t), majorant);
        let real = rng.next_f32() < w[self.hero];
        rescale(self.r_u, if real { w } else { Spectrum::ONE - w });
        real || *self.r_u == Spectrum::ZERO
    }
}

/// `sigma_t(p) / majorant` per channel, clamped to `[0, 1]`: each channel's probability that a
/// tentative collision at `p` is real.
#[inline(always)]
fn collision_probabilities<M: Medium>(medium: &M, p: crate::Vec3, majorant: f32) -> Spectrum {
    (medium.sigma_t_rgb(p) / majorant).clamp(Spectrum::ZERO, Spectrum::ONE)
}

/// [`ratio_tracking`] in every channel of a chromatic medium: the product of `1 - sigma_t,c /
/// majorant` over the tentative collisions under one majorant for all channels is an unbiased
/// estimate of each channel's transmittance (no hero is needed); the roulette watches the largest
/// channel. A uniform extinction needs no estimate: `exp(-sigma_t t_max)` per channel. Every
/// factor is in `[0, 1]`, so the estimate is finite.
#[inline(always)]
pub fn spectral_ratio_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    steps: &mut u32,
    max_steps: u32,
) -> Option<Spectrum> {
    if let Some(sigma_t) = medium.uniform_sigma_t_rgb() {
        let tau = sigma_t * t_max;
        return Some(Spectrum::new(exp(-tau.x), exp(-tau.y), exp(-tau.z)));
    }
    let mut ratio = SpectralRatioProduct {
        medium,
        ray,
        transmittance: Spectrum::ONE,
    };
    let flight = walk_majorants(medium, ray, t_max, rng, steps, max_steps, &mut ratio);
    match flight {
        FreeFlight::OutOfSteps => None,
        FreeFlight::Collision(_) => Some(Spectrum::ZERO),
        FreeFlight::Escaped => Some(ratio.transmittance),
    }
}

/// Spectral ratio tracking's running product, with its roulette; it stops the walk once it is zero.
struct SpectralRatioProduct<'a, M> {
    medium: &'a M,
    ray: &'a Ray,
    transmittance: Spectrum,
}

impl<M: Medium> TentativeCollision for &mut SpectralRatioProduct<'_, M> {
    #[inline(always)]
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, _bits: u64) -> bool {
        let w = collision_probabilities(self.medium, self.ray.at(t), majorant);
        self.transmittance *= Spectrum::ONE - w;
        if self.transmittance.max_element() < 0.125 {
            if rng.next_f32() < 0.5 {
                self.transmittance *= 2.0;
            } else {
                self.transmittance = Spectrum::ZERO;
            }
        }
        self.transmittance.max_element() <= 0.0
    }
}
