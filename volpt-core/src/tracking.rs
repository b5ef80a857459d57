//! Free-flight sampling by delta (Woodcock) tracking.

use crate::math::ln;
use crate::medium::Medium;
use crate::rng::Rng;
use crate::Ray;

/// Samples the distance to the next real collision along `ray` before `t_max`, or `None` if the ray
/// reaches `t_max` first. `steps` counts tentative collisions.
///
/// Woodcock et al. 1965: fly exponential steps of the constant majorant `sigma_bar` and accept a
/// tentative collision at `x` with probability `sigma_t(x) / sigma_bar`. The accepted distances follow
/// `sigma_t(t) exp(-int_0^t sigma_t)` exactly, for any `sigma_bar >= sigma_t`. A homogeneous medium
/// accepts every collision, so it samples the exponential once. `1 - u` lies in (0, 1], so the
/// logarithm is finite; a zero majorant means vacuum and never loops.
#[inline]
pub fn delta_tracking<M: Medium>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    steps: &mut u32,
) -> Option<f32> {
    let majorant = medium.majorant();
    if majorant <= 0.0 {
        return None;
    }
    let inv_majorant = 1.0 / majorant;
    let mut t = 0.0;
    loop {
        t -= ln(1.0 - rng.next_f32()) * inv_majorant;
        if t >= t_max {
            return None;
        }
        *steps += 1;
        if M::HOMOGENEOUS || rng.next_f32() * majorant < medium.sigma_t(ray.at(t)) {
            return Some(t);
        }
    }
}
