//! The GGX (Trowbridge-Reitz) microfacet distribution with Smith's masking, in the local frame of the
//! macro-surface (normal = +z).

use crate::math::{lerp, normalize, safe_sqrt, sqr, sqrt, PI};
use crate::sampling::sample_uniform_disk_polar;
use crate::{Vec2, Vec3};

/// Isotropic GGX with roughness `alpha` (Walter et al. 2007).
#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    pub alpha: f32,
}

impl Ggx {
    /// Normal distribution `D(m) = 1 / (pi a^2 ((m_x^2 + m_y^2) / a^2 + m_z^2)^2)` for `m_z > 0`.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = sqr(self.alpha);
        let t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
        1.0 / (PI * a2 * t * t)
    }

    /// Smith's monodirectional masking `G1(v, m) = 2 / (1 + sqrt(1 + a^2 tan^2 theta_v))`, zero when `v`
    /// sees the back of the microfacet `m` (Walter et al. 2007, eq. 34; Mitsuba's `smith_g1`).
    #[inline]
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let tan2 = (v.x * v.x + v.y * v.y) / (v.z * v.z);
        2.0 / (1.0 + sqrt(1.0 + sqr(self.alpha) * tan2))
    }

    /// Samples a microfacet normal from the distribution of normals visible from `wi` (`wi.z > 0`):
    /// `D_wi(m) = G1(wi, m) max(0, wi . m) D(m) / wi.z`.
    ///
    /// Heitz 2018, "Sampling the GGX Distribution of Visible Normals": stretch the view direction to
    /// the hemisphere configuration, sample the projected disk, unstretch.
    #[inline]
    pub fn sample_visible_normal(&self, wi: Vec3, u: Vec2) -> Vec3 {
        let wh = normalize(Vec3::new(self.alpha * wi.x, self.alpha * wi.y, wi.z));
        let t1 = if wh.z < 0.99999 {
            normalize(Vec3::Z.cross(wh))
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        let mut p = sample_uniform_disk_polar(u);
        let h = safe_sqrt(1.0 - p.x * p.x);
        p.y = lerp(0.5 * (1.0 + wh.z), h, p.y);
        let pz = safe_sqrt(1.0 - p.length_squared());
        let nh = t1 * p.x + t2 * p.y + wh * pz;
        normalize(Vec3::new(
            self.alpha * nh.x,
            self.alpha * nh.y,
            nh.z.max(1e-6),
        ))
    }

    /// The density of [`Self::sample_visible_normal`] with respect to solid angle around `m`.
    #[inline]
    pub fn pdf_visible_normal(&self, wi: Vec3, m: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        self.g1(wi, m) * wi.dot(m).max(0.0) * self.d(m) / wi.z
    }
}
