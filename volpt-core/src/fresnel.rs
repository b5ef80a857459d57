//! Fresnel reflectance of a smooth dielectric interface, for unpolarised light.

use crate::math::{clamp, safe_sqrt};

/// Reflectance and transmitted cosine at an interface with relative index `eta = n_t / n_i`, for an
/// incident cosine `cos_i >= 0` measured on the incident side. `cos_t` is 0 under total internal
/// reflection (reflectance 1).
///
/// Born & Wolf, "Principles of Optics", section 1.5.2; the same form as pbrt-v4's `FrDielectric`.
#[inline]
pub fn fresnel_dielectric_cos(cos_i: f32, eta: f32) -> (f32, f32) {
    let cos_i = clamp(cos_i, 0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = safe_sqrt(1.0 - sin2_t);
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (
        0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular),
        cos_t,
    )
}

/// Reflectance for a signed cosine against a normal that points into the medium of index `n_i`
/// (`eta = n_t / n_i` across the normal): a negative `cos_i` means the light arrives from the other side.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    if cos_i < 0.0 {
        fresnel_dielectric_cos(-cos_i, 1.0 / eta).0
    } else {
        fresnel_dielectric_cos(cos_i, eta).0
    }
}
