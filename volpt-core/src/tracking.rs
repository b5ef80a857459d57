//! Free-flight sampling by delta (Woodcock) tracking.

use crate::math::ln;
use crate::medium::Medium;
use crate::rng::Rng;
use crate::Ray;

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

/// Samples the distance to the next real collision along `ray` before `t_max`. `steps` counts
/// tentative collisions; the flight gives up once it reaches `max_steps`.
///
/// Woodcock et al. 1965: fly exponential steps of the constant majorant `sigma_bar` and accept a
/// tentative collision at `x` with probability `sigma_t(x) / sigma_bar`. The accepted distances follow
/// `sigma_t(t) exp(-int_0^t sigma_t)` exactly, for any `sigma_bar >= sigma_t`. A homogeneous medium
/// accepts every collision, so it samples the exponential once. `1 - u` lies in (0, 1], so the
/// logarithm is finite; a zero majorant means vacuum and never loops.
///
/// The expected number of steps is `majorant * t_max`: an enormous majorant (one dense voxel among
/// empty ones) or a non-finite one (where `t` never grows) would spin for ever, so the budget bounds
/// the work. It is checked before a step is counted, so `steps` never exceeds `max_steps` (nor
/// overflows). Under the budget the random numbers and arithmetic are those of plain delta tracking.
#[inline]
pub fn delta_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    steps: &mut u32,
    max_steps: u32,
) -> FreeFlight {
    let majorant = medium.majorant();
    if majorant <= 0.0 {
        return FreeFlight::Escaped;
    }
    let inv_majorant = 1.0 / majorant;
    let mut t = 0.0;
    loop {
        t -= ln(1.0 - rng.next_f32()) * inv_majorant;
        if t >= t_max {
            return FreeFlight::Escaped;
        }
        if *steps >= max_steps {
            return FreeFlight::OutOfSteps;
        }
        *steps += 1;
        if M::HOMOGENEOUS || rng.next_f32() * majorant < medium.sigma_t(ray.at(t)) {
            return FreeFlight::Collision(t);
        }
    }
}
