//! Phase functions. Directions are *propagation* directions: `wi` is the direction the light travelled
//! before the scattering event and `wo` after it, so `cos_theta = wi . wo` and `g > 0` scatters forward.

use bytemuck::{Pod, Zeroable};

use crate::abi::{Component, NoParams, Upload};
use crate::math::{clamp, INV_4PI};
use crate::sampling::{direction_about, sample_uniform_sphere};
use crate::{Vec2, Vec3};

/// A sampled direction and its density. Phase functions are sampled exactly, so the path weight is 1.
#[derive(Clone, Copy, Debug)]
pub struct PhaseSample {
    pub wo: Vec3,
    pub pdf: f32,
}

pub trait PhaseFunction: Copy {
    /// The phase function value, which is also the density of `sample`.
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32;
    fn sample(&self, wi: Vec3, u: Vec2) -> PhaseSample;
    /// This phase function with asymmetry `g`, a collision's material's
    /// ([`crate::Medium::phase_g`]); a function without asymmetry is itself.
    fn with_g(&self, g: f32) -> Self;
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Isotropic;

impl PhaseFunction for Isotropic {
    #[inline]
    fn eval(&self, _wi: Vec3, _wo: Vec3) -> f32 {
        INV_4PI
    }

    #[inline]
    fn sample(&self, _wi: Vec3, u: Vec2) -> PhaseSample {
        PhaseSample {
            wo: sample_uniform_sphere(u),
            pdf: INV_4PI,
        }
    }

    #[inline]
    fn with_g(&self, _g: f32) -> Self {
        Isotropic
    }
}

/// Henyey & Greenstein 1941: `p(cos) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2))`.
#[derive(Clone, Copy, Debug)]
pub struct HenyeyGreenstein {
    pub g: f32,
}

impl HenyeyGreenstein {
    /// The phase function of the cosine between the incident and scattered propagation directions.
    #[inline]
    pub fn eval_cos(&self, cos_theta: f32) -> f32 {
        let g = self.g;
        let denom = 1.0 + g * g - 2.0 * g * cos_theta;
        INV_4PI * (1.0 - g * g) / (denom * crate::math::sqrt(denom))
    }

    /// Inverts the HG cumulative distribution of `cos_theta` at `u`.
    ///
    /// The textbook inverse `(1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g)` divides two
    /// quantities that vanish with g, so it loses all precision near g = 0 and is usually patched with
    /// an isotropic branch that is wrong for small g. With `xi = 2u - 1` and `t = 1 + g xi` the same
    /// value expands exactly into `(xi + g (xi^2 + 3) / 2 + g^2 xi + g^3 (xi^2 - 1) / 2) / t^2`, which
    /// has no cancellation and is exact for every g in (-1, 1), g = 0 included.
    #[inline]
    pub fn sample_cos(&self, u: f32) -> f32 {
        let g = self.g;
        let xi = 2.0 * u - 1.0;
        let t = 1.0 + g * xi;
        let num = xi + g * (0.5 * (xi * xi + 3.0) + g * (xi + g * 0.5 * (xi * xi - 1.0)));
        clamp(num / (t * t), -1.0, 1.0)
    }
}

impl PhaseFunction for HenyeyGreenstein {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.eval_cos(wi.dot(wo))
    }

    #[inline]
    fn sample(&self, wi: Vec3, u: Vec2) -> PhaseSample {
        let cos_theta = self.sample_cos(u.x);
        PhaseSample {
            wo: direction_about(wi, cos_theta, u.y),
            pdf: self.eval_cos(cos_theta),
        }
    }

    #[inline]
    fn with_g(&self, g: f32) -> Self {
        Self { g }
    }
}

impl Component for Isotropic {
    const NAME: &'static str = "isotropic";
    type Params = NoParams;

    fn to_params(&self, _upload: &mut Upload<'_>) {}
    #[inline]
    unsafe fn from_params(_p: &NoParams) -> Self {
        Isotropic
    }
}

/// Device parameters of Henyey-Greenstein, padded to a multiple of 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct HenyeyGreensteinParams {
    pub g: f32,
    pub padding: u32,
}

impl Component for HenyeyGreenstein {
    const NAME: &'static str = "henyey_greenstein";
    type Params = HenyeyGreensteinParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> HenyeyGreensteinParams {
        HenyeyGreensteinParams {
            g: self.g,
            padding: 0,
        }
    }
    #[inline]
    unsafe fn from_params(p: &HenyeyGreensteinParams) -> Self {
        Self { g: p.g }
    }
}
