//! A medium volpt does not ship, written by a library user: a smooth ball of extinction,
//! `sigma_t(p) = sigma_max * max(0, 1 - |p - c|^2 / r^2)`, with a constant albedo.
//!
//! To render it a medium needs [`Medium`] (the physics: extinction, its majorant, albedo); to render
//! it on a GPU it also needs [`Component`] (its `#[repr(C)]` parameters and its name in kernel entry
//! points), and a kernels crate that exports it (`kernels/`, one `export_kernels!` line). The crate is
//! `no_std`, because the same code is compiled into those kernels.
#![no_std]

use bytemuck::{Pod, Zeroable};
use volpt_core::abi::{Component, Upload};
use volpt_core::{Medium, Spectrum, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct SmoothBall {
    pub centre: Vec3,
    pub radius: f32,
    /// Extinction at the centre, the largest anywhere: the majorant.
    pub sigma_max: f32,
    pub albedo: Spectrum,
}

impl Medium for SmoothBall {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;

    #[inline]
    fn majorant(&self) -> f32 {
        self.sigma_max
    }

    #[inline]
    fn sigma_t(&self, p: Vec3) -> f32 {
        let r2 = (p - self.centre).length_squared() / (self.radius * self.radius);
        self.sigma_max * (1.0 - r2).max(0.0)
    }

    #[inline]
    fn albedo(&self, _p: Vec3) -> Spectrum {
        self.albedo
    }
}

/// What a kernel receives: every field, padded to a multiple of 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SmoothBallParams {
    pub centre: [f32; 3],
    pub radius: f32,
    pub albedo: [f32; 3],
    pub sigma_max: f32,
}

impl Component for SmoothBall {
    const NAME: &'static str = "smooth_ball";
    type Params = SmoothBallParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> SmoothBallParams {
        SmoothBallParams {
            centre: self.centre.to_array(),
            radius: self.radius,
            albedo: self.albedo.to_array(),
            sigma_max: self.sigma_max,
        }
    }

    #[inline]
    unsafe fn from_params(p: &SmoothBallParams) -> Self {
        Self {
            centre: Vec3::from_array(p.centre),
            radius: p.radius,
            sigma_max: p.sigma_max,
            albedo: Spectrum::from_array(p.albedo),
        }
    }
}

impl SmoothBall {
    /// The optical depth along `origin + t dir` (`dir` of unit length) for `t` in `[t0, t1]`, in closed
    /// form: with `s = t - t_c` measured from the point nearest the centre and `d^2` that point's
    /// squared distance, `sigma_t = sigma_max (1 - (d^2 + s^2) / r^2)` on `|s| <= h`,
    /// `h^2 = r^2 - d^2`, whose integral is a cubic in `s`.
    pub fn optical_depth(&self, origin: Vec3, dir: Vec3, t0: f32, t1: f32) -> f64 {
        let to_centre = (self.centre - origin).as_dvec3();
        let dir = dir.as_dvec3();
        let t_c = to_centre.dot(dir);
        let d2 = (to_centre - dir * t_c).length_squared();
        let r2 = self.radius as f64 * self.radius as f64;
        if d2 >= r2 {
            return 0.0;
        }
        let h = libm::sqrt(r2 - d2);
        let lo = (t0 as f64 - t_c).clamp(-h, h);
        let hi = (t1 as f64 - t_c).clamp(-h, h);
        let antiderivative = |s: f64| (1.0 - d2 / r2) * s - s * s * s / (3.0 * r2);
        self.sigma_max as f64 * (antiderivative(hi) - antiderivative(lo))
    }
}
