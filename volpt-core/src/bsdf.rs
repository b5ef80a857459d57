//! The medium's boundary: index-matched, smooth dielectric or GGX rough dielectric.
//!
//! Conventions: `n` is the boundary's outward unit normal and `d` the ray's propagation direction when
//! it reaches the boundary, from either side. The sample is the new propagation direction. `eta` is
//! `n_inside / n_outside`.

use bytemuck::{Pod, Zeroable};

use crate::abi::{Component, NoParams, Upload};
use crate::frame::Frame;
use crate::fresnel::fresnel_dielectric_cos;
use crate::microfacet::Ggx;
use crate::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// New propagation direction.
    pub wo: Vec3,
    /// `f * |cos| / pdf` of the sample, including the radiance scaling `1 / eta^2` on refraction.
    pub weight: f32,
    /// The path crossed the boundary.
    pub transmitted: bool,
    /// Relative index `n_t / n_i` the path crossed (1 when reflected); Russian roulette divides the
    /// radiance scaling back out with it, as Mitsuba does.
    pub eta: f32,
}

/// The BSDF in one direction, for next-event estimation through the boundary and the MIS weight of
/// [`Bsdf::sample`]'s directions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BsdfEval {
    /// `f(d -> wo) |cos(wo)|`, with the same radiance scaling `1 / eta^2` on refraction as
    /// [`BsdfSample::weight`], so that `value = weight * pdf` for a direction `sample` returns.
    pub value: f32,
    /// Solid-angle density with which [`Bsdf::sample`] returns `wo` (lobe choice included).
    pub pdf: f32,
}

pub trait Bsdf {
    /// An index-matched boundary: crossing it changes nothing and is not an interaction, so the path
    /// step skips the BSDF and its random numbers entirely.
    const IS_NULL: bool = false;

    /// A BSDF without delta lobes: it has a density in every direction, so next-event estimation
    /// can look at the environment through it ([`Bsdf::eval`]).
    const IS_ROUGH: bool = false;

    /// Samples the interaction of a ray travelling along `d` with the boundary of outward normal `n`,
    /// or `None` when the sample carries no energy.
    fn sample(&self, n: Vec3, d: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample>;

    /// The BSDF and the density of [`Bsdf::sample`] for the new direction `wo` of a ray travelling
    /// along `d` to the boundary of outward normal `n`; zero for a BSDF that is not
    /// [`Bsdf::IS_ROUGH`] (its lobes are deltas, which no other direction than its own meets).
    #[inline]
    fn eval(&self, _n: Vec3, _d: Vec3, _wo: Vec3) -> BsdfEval {
        BsdfEval::default()
    }
}

/// Index-matched (Mitsuba's `null`) boundary.
#[derive(Clone, Copy, Debug, Default)]
pub struct NullBoundary;

impl Bsdf for NullBoundary {
    const IS_NULL: bool = true;

    #[inline]
    fn sample(&self, _n: Vec3, d: Vec3, _u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        Some(BsdfSample {
            wo: d,
            weight: 1.0,
            transmitted: true,
            eta: 1.0,
        })
    }
}

/// Smooth dielectric interface: specular reflection with probability F, refraction otherwise.
#[derive(Clone, Copy, Debug)]
pub struct SmoothDielectric {
    pub eta: f32,
}

impl Bsdf for SmoothDielectric {
    #[inline]
    fn sample(&self, n: Vec3, d: Vec3, u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        scatter_off_microfacet(n, d, self.eta, u_lobe, |_wi| (Vec3::Z, None))
    }
}

/// GGX rough dielectric interface (Walter et al. 2007), sampled with the distribution of visible
/// normals (Heitz 2018). Masking is Smith's separable form, as in Mitsuba's `roughdielectric`.
#[derive(Clone, Copy, Debug)]
pub struct RoughDielectric {
    pub eta: f32,
    pub distribution: Ggx,
}

impl Bsdf for RoughDielectric {
    const IS_ROUGH: bool = true;

    #[inline]
    fn sample(&self, n: Vec3, d: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let ggx = self.distribution;
        scatter_off_microfacet(n, d, self.eta, u_lobe, |wi| {
            (ggx.sample_visible_normal(wi, u), Some(ggx))
        })
    }

    /// Walter et al. 2007 (eqs. 20-21, with the half-vectors of eqs. 13 and 16), written as the
    /// density of [`Self::sample`] times its weight: `m` is the microfacet that turns `wi` into
    /// `wo`, chosen with the visible-normal density `D_wi(m)` and its lobe with probability `F` (or
    /// `1 - F`); the change of variables from `m` to `wo` is `1 / (4 |wo . m|)` on reflection and
    /// `eta^2 |wo . m| / (wi . m + eta wo . m)^2` on refraction; the weight is `G1(wo, m) / eta^2`.
    #[inline]
    fn eval(&self, n: Vec3, d: Vec3, wo: Vec3) -> BsdfEval {
        let zero = BsdfEval::default();
        let outside = d.dot(n) < 0.0;
        let frame = Frame::from_z(if outside { n } else { -n });
        let (wi, wo) = (frame.to_local(-d), frame.to_local(wo));
        if wi.z <= 0.0 || wo.z == 0.0 {
            return zero;
        }
        let reflected = wo.z > 0.0;
        let eta = match (reflected, outside) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        let h = wi + wo * eta;
        let len2 = h.length_squared();
        if len2 <= 0.0 {
            return zero;
        }
        let m = h * (1.0 / crate::math::sqrt(len2));
        let m = if m.z < 0.0 { -m } else { m };
        let (cos_im, cos_om) = (wi.dot(m), wo.dot(m));
        // The microfacet must face `wi`, and `wo` leave it on the side of its lobe.
        if cos_im <= 0.0 || (cos_om > 0.0) != reflected {
            return zero;
        }
        let ggx = self.distribution;
        let (reflectance, _) =
            fresnel_dielectric_cos(cos_im, if outside { self.eta } else { 1.0 / self.eta });
        let visible = ggx.pdf_visible_normal(wi, m);
        let pdf = if reflected {
            visible * reflectance / (4.0 * cos_om)
        } else {
            let denom = cos_im + eta * cos_om;
            visible * (1.0 - reflectance) * eta * eta * -cos_om / (denom * denom)
        };
        if !(pdf.is_finite() && pdf > 0.0) {
            return zero;
        }
        BsdfEval {
            value: pdf * ggx.g1(wo, m) / (eta * eta),
            pdf,
        }
    }
}

/// Reflects or refracts at a microfacet `m` chosen by `pick_normal` (in the local frame where the
/// incident side is +z), choosing reflection with probability `F(wi . m)`.
///
/// With `m` drawn from the visible normals of `wi` and the lobe chosen by F, the estimator weight of
/// Walter's BSDF reduces to `G1(wo, m)` (Heitz 2018, sec. 4; Mitsuba's `roughdielectric`), times
/// `1 / eta^2` on refraction because radiance is not invariant across the interface (Veach 1997, 5.2).
#[inline]
fn scatter_off_microfacet(
    n: Vec3,
    d: Vec3,
    eta: f32,
    u_lobe: f32,
    pick_normal: impl FnOnce(Vec3) -> (Vec3, Option<Ggx>),
) -> Option<BsdfSample> {
    // Local frame whose +z is on the side the light arrives from.
    let outside = d.dot(n) < 0.0;
    let frame = Frame::from_z(if outside { n } else { -n });
    let wi = frame.to_local(-d);
    if wi.z <= 0.0 {
        return None;
    }
    let eta = if outside { eta } else { 1.0 / eta };
    let (m, ggx) = pick_normal(wi);
    let cos_im = wi.dot(m);
    if cos_im <= 0.0 {
        return None;
    }
    let (reflectance, cos_t) = fresnel_dielectric_cos(cos_im, eta);
    let reflected = u_lobe < reflectance;
    let (wo, relative_eta) = if reflected {
        (m * (2.0 * cos_im) - wi, 1.0)
    } else {
        (m * (cos_im / eta - cos_t) - wi / eta, eta)
    };
    // A reflection must stay on the incident side and a refraction must cross.
    if (wo.z > 0.0) != reflected {
        return None;
    }
    let masking = match ggx {
        Some(ggx) => ggx.g1(wo, m),
        None => 1.0,
    };
    let weight = masking / (relative_eta * relative_eta);
    if weight <= 0.0 {
        return None;
    }
    Some(BsdfSample {
        wo: crate::math::normalize(frame.to_world(wo)),
        weight,
        transmitted: !reflected,
        eta: relative_eta,
    })
}

impl Component for NullBoundary {
    const NAME: &'static str = "index_matched";
    type Params = NoParams;

    fn to_params(&self, _upload: &mut Upload<'_>) {}
    #[inline]
    unsafe fn from_params(_p: &NoParams) -> Self {
        NullBoundary
    }
}

/// Device parameters of a dielectric boundary; `alpha` is read by the rough one only.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DielectricParams {
    /// `n_inside / n_outside`.
    pub eta: f32,
    /// GGX roughness.
    pub alpha: f32,
}

impl Component for SmoothDielectric {
    const NAME: &'static str = "smooth_dielectric";
    type Params = DielectricParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> DielectricParams {
        DielectricParams {
            eta: self.eta,
            alpha: 0.0,
        }
    }
    #[inline]
    unsafe fn from_params(p: &DielectricParams) -> Self {
        Self { eta: p.eta }
    }
}

impl Component for RoughDielectric {
    const NAME: &'static str = "rough_dielectric";
    type Params = DielectricParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> DielectricParams {
        DielectricParams {
            eta: self.eta,
            alpha: self.distribution.alpha,
        }
    }
    #[inline]
    unsafe fn from_params(p: &DielectricParams) -> Self {
        Self {
            eta: p.eta,
            distribution: Ggx { alpha: p.alpha },
        }
    }
}
