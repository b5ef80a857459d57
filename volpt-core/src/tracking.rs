//! Free-flight sampling by delta (Woodcock) tracking and transmittance by ratio tracking, both over
//! the medium's majorants: one global bound, or a majorant grid walked cell by cell.

use crate::chromatic::rescale;
use crate::flight::FlightEnd;
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
///
/// The walk samples the tentative collisions of a region (the whole ray, or a majorant-grid
/// cell) at the rate [`TentativeCollision::rate`] returns for it, and reports where it leaves
/// each region without stopping ([`TentativeCollision::leave`]): plain delta and ratio tracking
/// sample at the medium's bound and ignore the regions; a chromatic path samples at its hero
/// channel's own majorant and needs every channel's optical depth between events
/// ([`spectral_delta_tracking`]).
pub trait TentativeCollision {
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, bits: u64) -> bool;

    /// The rate of tentative collisions in a region whose bound of the extinction (of every
    /// channel) is `bound`: the majorant-grid cell of index `cell`, or with `None` the whole ray
    /// under the medium's global majorant. A region whose rate is not positive is crossed
    /// without a step.
    #[inline(always)]
    fn rate(&mut self, bound: f32, _cell: Option<usize>) -> f32 {
        bound
    }

    /// The walk leaves the current region at `t` (its end, or where the walk escapes) without
    /// a collision after the last one it stopped at.
    #[inline(always)]
    fn leave(&mut self, _t: f32) {}
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
    mut t_max: impl FlightEnd,
    rng: &mut Rng,
    steps: &mut u32,
    max_steps: u32,
    mut at: impl TentativeCollision,
) -> FreeFlight {
    let Some(grid) = medium.majorant_grid() else {
        let majorant = at.rate(medium.majorant(), None);
        if majorant <= 0.0 {
            at.leave(t_max.exact());
            return FreeFlight::Escaped;
        }
        let majorant = normal_majorant(majorant);
        let inv_majorant = 1.0 / majorant;
        let mut t = 0.0;
        loop {
            let bits = rng.next_u64();
            t -= ln(1.0 - unit_f32(bits)) * inv_majorant;
            if t_max.reached(t) {
                at.leave(t_max.exact());
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
    let mut cell = Cell::new(&dda, grid, &mut t_max, start, &mut at);
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
        at.leave(cell.end);
        // Anything but `end < t_max` ends the walk, a NaN `end` or `t_max` included.
        if !t_max.before(cell.end) {
            return FreeFlight::Escaped;
        }
        start = start.max(cell.end);
        dda.advance(grid, ray.dir);
        cell = Cell::new(&dda, grid, &mut t_max, start, &mut at);
    }
}

/// The majorant-grid walk's current cell: its rate of tentative collisions (its bound, or what
/// [`TentativeCollision::rate`] makes of it; raised by [`normal_majorant`] where positive), the
/// rate's reciprocal, where the walk leaves it and the distance sampled so far.
struct Cell {
    majorant: f32,
    inv_majorant: f32,
    end: f32,
    t: f32,
}

impl Cell {
    #[inline(always)]
    fn new(
        dda: &Dda,
        grid: &crate::majorant::MajorantGrid<'_>,
        t_max: &mut impl FlightEnd,
        start: f32,
        at: &mut impl TentativeCollision,
    ) -> Self {
        let (bound, cell_end) = dda.segment(grid);
        let majorant = at.rate(bound, Some(dda.cell_index(grid)));
        // A cell of bound 0 (or NaN) is crossed without a step; its bound is left as it is.
        let majorant = if majorant > 0.0 {
            normal_majorant(majorant)
        } else {
            majorant
        };
        Self {
            majorant,
            inv_majorant: 1.0 / majorant,
            end: t_max.clip(cell_end),
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
    t_max: impl FlightEnd,
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

/// Delta tracking of a chromatic medium ([`crate::chromatic`]) by the path's hero channel, with
/// the single-sample spectral MIS of Miller, Georgiev and Jarosz 2019 in pbrt-v4's form (its
/// `VolPathIntegrator`: the path's densities under every channel, rescaled, `r_u`).
///
/// Each channel `c` has its own majorant `m_c` per region ([`Medium::majorant_rgb`]: a homogeneous
/// medium's is its exact `sigma_t,c`, so it has no null collision in any channel). The walk samples
/// tentative collisions at the hero's rate `m_h`; one at `x` is real with probability
/// `sigma_t,h(x) / m_h`. Under channel `c`'s own tracking the same event has density
/// `exp(-tau_c) sigma_t,c(x)` (real) or `exp(-tau_c) (m_c - sigma_t,c(x))` (null), and reaching
/// `t_max` has `exp(-tau_c)`, with `tau_c` the optical depth of `m_c` since the last event; each
/// event rescales `r_u` by those ([`rescale`]). The throughput's factors are each channel's own
/// ratio of contribution to density (the albedo at a real collision, 1 at a null one or the
/// escape, whatever the majorants), as in a grey medium. A path whose `r_u` becomes zero stops at
/// the collision (the caller ends it).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn spectral_delta_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: impl FlightEnd,
    rng: &mut Rng,
    hero: u8,
    r_u: &mut Spectrum,
    steps: &mut u32,
    max_steps: u32,
) -> FreeFlight {
    let mut hero = SpectralAcceptance {
        medium,
        ray,
        hero: hero as usize,
        r_u,
        majorant: Spectrum::ZERO,
        depth: Spectrum::ZERO,
        last: 0.0,
    };
    let flight = walk_majorants(medium, ray, t_max, rng, steps, max_steps, &mut hero);
    if flight == FreeFlight::Escaped {
        rescale(hero.r_u, relative_transmittance(hero.depth));
    }
    flight
}

/// Spectral delta tracking's state: the current region's majorant per channel, each channel's
/// optical depth under its majorant since the path's last event (or the flight's start), and
/// where that was.
struct SpectralAcceptance<'a, M> {
    medium: &'a M,
    ray: &'a Ray,
    hero: usize,
    r_u: &'a mut Spectrum,
    majorant: Spectrum,
    depth: Spectrum,
    last: f32,
}

impl<M: Medium> TentativeCollision for &mut SpectralAcceptance<'_, M> {
    #[inline(always)]
    fn rate(&mut self, bound: f32, cell: Option<usize>) -> f32 {
        let m = self.medium.majorant_rgb(bound, cell);
        // The rates the walk samples at: positive ones raised as it raises its own, so that
        // the hero's density here is that of its steps.
        self.majorant = Spectrum::new(channel_rate(m.x), channel_rate(m.y), channel_rate(m.z));
        self.majorant[self.hero]
    }

    #[inline(always)]
    fn leave(&mut self, t: f32) {
        self.depth += self.majorant * (t - self.last);
        self.last = t;
    }

    #[inline(always)]
    fn stop_at(&mut self, rng: &mut Rng, t: f32, majorant: f32, _bits: u64) -> bool {
        self.leave(t);
        // Each channel's real part of its majorant (clamped: a bound rounded below the
        // extinction by an ulp takes it).
        let real = self
            .medium
            .sigma_t_rgb(self.ray.at(t))
            .max(Spectrum::ZERO)
            .min(self.majorant);
        let h = real[self.hero];
        // A homogeneous medium's hero is always real: no random number for it.
        let is_real = h >= majorant || rng.next_f32() * majorant < h;
        let density = if is_real { real } else { self.majorant - real };
        let scale = 1.0 / self.majorant.max_element();
        rescale(
            self.r_u,
            relative_transmittance(self.depth) * density * scale,
        );
        self.depth = Spectrum::ZERO;
        is_real || *self.r_u == Spectrum::ZERO
    }
}

/// A channel's majorant as [`walk_majorants`] samples it: raised by [`normal_majorant`] where
/// positive, 0 where not, NaN kept (the step budget ends such a walk).
#[inline(always)]
fn channel_rate(m: f32) -> f32 {
    if m > 0.0 {
        normal_majorant(m)
    } else if m <= 0.0 {
        0.0
    } else {
        m
    }
}

/// `exp(-tau_c)` per channel up to a common factor, the largest being 1: `exp(-(tau_c -
/// min tau))`, which cannot overflow and underflows only for a channel whose density is below
/// f32's range relative to another's (NaN stays NaN, which [`rescale`] turns into the end of
/// the path).
#[inline(always)]
fn relative_transmittance(depth: Spectrum) -> Spectrum {
    let d = depth - Spectrum::splat(depth.min_element());
    Spectrum::new(exp(-d.x), exp(-d.y), exp(-d.z))
}

/// `sigma_t(p) / majorant` per channel, clamped to `[0, 1]`: each channel's probability that a
/// tentative collision at `p` is real under one majorant for all channels.
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
