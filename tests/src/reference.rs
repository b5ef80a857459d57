//! Independent references: the camera, the box, trilinear grids, the environment and the single
//! scattering integral, written again in `f64` from the scene *description* and the documented
//! conventions (Mitsuba's camera and `envmap`, the grid conventions of `GridConvention`), sharing no
//! code with `volpt-core` or the render factory. A bug in the renderer's camera, grid lookup,
//! majorant or path step cannot cancel out of a comparison with these.
//!
//! Pixel values are integrals over the pixel's area (box reconstruction); they are computed with a
//! product Gauss-Legendre rule, whose error the tests estimate by comparing two orders.

use glam::DVec3;
use std::f64::consts::PI;
use volpt_scene::description::*;

/// Gauss-Legendre nodes and weights on [0, 1], by Newton's iteration on the Legendre polynomial.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            derivative = n as f64 * (x * p - p0) / (x * x - 1.0);
            let step = p / derivative;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        let weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
        rule.push((0.5 * (1.0 - x), 0.5 * weight));
    }
    rule
}

fn vec(a: [f32; 3]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

/// Column `j` of a row-major 4x4 transform.
fn column(m: &Matrix4, j: usize) -> DVec3 {
    DVec3::new(m[0][j] as f64, m[1][j] as f64, m[2][j] as f64)
}

/// Mitsuba's pinhole camera: camera space looks along +z, +y up, +x to the image's left; film
/// position `(sx, sy)` in [0, 1]^2 runs right and down from the top-left corner.
#[derive(Clone, Copy, Debug)]
pub struct RefCamera {
    pub origin: DVec3,
    axes: [DVec3; 3],
    tan_half: (f64, f64),
    pub width: u32,
    pub height: u32,
}

impl RefCamera {
    pub fn new(camera: &CameraDesc, film: &FilmDesc) -> Self {
        let (w, h) = (film.width as f64, film.height as f64);
        let t = (camera.fov_degrees as f64 * PI / 360.0).tan();
        let x_spans = match camera.fov_axis {
            FovAxis::X => true,
            FovAxis::Y => false,
            FovAxis::Smaller => w <= h,
            FovAxis::Larger => w >= h,
            FovAxis::Diagonal => {
                let d = w.hypot(h);
                return Self::with(camera, film, (t * w / d, t * h / d));
            }
        };
        let tan_half = if x_spans {
            (t, t * h / w)
        } else {
            (t * w / h, t)
        };
        Self::with(camera, film, tan_half)
    }

    fn with(camera: &CameraDesc, film: &FilmDesc, tan_half: (f64, f64)) -> Self {
        let m = &camera.to_world;
        Self {
            origin: column(m, 3),
            axes: [column(m, 0), column(m, 1), column(m, 2)],
            tan_half,
            width: film.width,
            height: film.height,
        }
    }

    /// The unit direction through film position `(px + fx, py + fy)`, in pixels.
    pub fn direction(&self, px: f64, py: f64) -> DVec3 {
        let x = (1.0 - 2.0 * px / self.width as f64) * self.tan_half.0;
        let y = (1.0 - 2.0 * py / self.height as f64) * self.tan_half.1;
        (self.axes[0] * x + self.axes[1] * y + self.axes[2]).normalize()
    }

    /// `f` integrated over pixel `(x, y)` (divided by its area), with an `n` x `n` Gauss rule.
    pub fn pixel_mean<T, F>(&self, x: u32, y: u32, rule: &[(f64, f64)], mut f: F) -> T
    where
        T: Default + std::ops::AddAssign + std::ops::Mul<f64, Output = T>,
        F: FnMut(DVec3) -> T,
    {
        let mut sum = T::default();
        for &(fy, wy) in rule {
            for &(fx, wx) in rule {
                sum += f(self.direction(x as f64 + fx, y as f64 + fy)) * (wx * wy);
            }
        }
        sum
    }
}

/// An axis-aligned box and the interval along which a ray is inside it.
#[derive(Clone, Copy, Debug)]
pub struct RefBox {
    pub min: DVec3,
    pub max: DVec3,
}

impl RefBox {
    pub fn new(b: &Bounds) -> Self {
        Self {
            min: vec(b.min),
            max: vec(b.max),
        }
    }

    /// `(t_near, t_far)` with `t_near >= 0`, if the ray from `o` along `d` crosses the box.
    pub fn interval(&self, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < self.min[a] || o[a] > self.max[a] {
                    return None;
                }
                continue;
            }
            let (ta, tb) = ((self.min[a] - o[a]) / d[a], (self.max[a] - o[a]) / d[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        (t0 < t1).then_some((t0, t1))
    }

    pub fn contains(&self, p: DVec3) -> bool {
        (0..3).all(|a| p[a] >= self.min[a] && p[a] <= self.max[a])
    }
}

/// A one-channel grid with trilinear interpolation, zero outside its box, the outermost samples
/// held up to the faces (cell-centred grids).
#[derive(Clone, Debug)]
pub struct RefGrid {
    bounds: RefBox,
    res: [usize; 3],
    convention: GridConvention,
    data: Vec<f64>,
}

impl RefGrid {
    pub fn new(g: &GridDesc) -> Self {
        assert_eq!(g.channels, 1, "reference grids are single-channel");
        Self {
            bounds: RefBox::new(&g.bounds),
            res: g.resolution.map(|r| r as usize),
            convention: g.convention,
            data: g.data.iter().map(|&v| v as f64).collect(),
        }
    }

    pub fn max(&self) -> f64 {
        self.data.iter().copied().fold(0.0, f64::max)
    }

    pub fn value(&self, p: DVec3) -> f64 {
        if !self.bounds.contains(p) {
            return 0.0;
        }
        let mut lo = [0usize; 3];
        let mut frac = [0.0f64; 3];
        for a in 0..3 {
            let n = self.res[a];
            let s = (p[a] - self.bounds.min[a]) / (self.bounds.max[a] - self.bounds.min[a]);
            // The sample index that sits at `p`, as a real number.
            let i = match self.convention {
                GridConvention::Vertex => s * (n as f64 - 1.0),
                GridConvention::Cell => s * n as f64 - 0.5,
            };
            let i = i.clamp(0.0, (n - 1) as f64);
            lo[a] = (i.floor() as usize).min(n.saturating_sub(2));
            frac[a] = i - lo[a] as f64;
        }
        let at = |x: usize, y: usize, z: usize| {
            let c = |a: usize, v: usize| v.min(self.res[a] - 1);
            self.data[(c(2, z) * self.res[1] + c(1, y)) * self.res[0] + c(0, x)]
        };
        let mut v = 0.0;
        for corner in 0..8 {
            let bit = |a: usize| (corner >> a) & 1;
            let w: f64 = (0..3)
                .map(|a| if bit(a) == 1 { frac[a] } else { 1.0 - frac[a] })
                .product();
            v += w * at(lo[0] + bit(0), lo[1] + bit(1), lo[2] + bit(2));
        }
        v
    }
}

/// Extinction inside the boundary box, from the medium's description.
#[derive(Clone, Debug)]
pub enum RefDensity {
    Constant(f64),
    Grid(RefGrid),
}

#[derive(Clone, Debug)]
pub struct RefMedium {
    pub bounds: RefBox,
    density: RefDensity,
    scale: f64,
    pub albedo: DVec3,
    /// Henyey-Greenstein asymmetry (0 for isotropic).
    pub g: f64,
}

impl RefMedium {
    /// The medium of `desc`, which must have a constant albedo.
    pub fn new(desc: &SceneDescription) -> Self {
        let m = &desc.medium;
        let AlbedoDesc::Constant(albedo) = m.albedo else {
            panic!("reference media have a constant albedo");
        };
        Self {
            bounds: RefBox::new(&desc.boundary.bounds),
            density: match &m.density {
                DensityDesc::Constant(d) => RefDensity::Constant(*d as f64),
                DensityDesc::Grid(g) => RefDensity::Grid(RefGrid::new(g)),
                // Each channel of a chromatic medium is the grey medium of its coefficients.
                DensityDesc::Rgb(_) | DensityDesc::Indexed(_) => {
                    panic!("reference media have a grey extinction")
                }
            },
            scale: m.scale as f64,
            albedo: vec(albedo),
            g: match m.phase {
                PhaseDesc::Isotropic => 0.0,
                PhaseDesc::HenyeyGreenstein { g } => g as f64,
            },
        }
    }

    pub fn sigma_t(&self, p: DVec3) -> f64 {
        self.scale
            * match &self.density {
                RefDensity::Constant(d) => *d,
                RefDensity::Grid(g) => g.value(p),
            }
    }

    pub fn max_sigma_t(&self) -> f64 {
        self.scale
            * match &self.density {
                RefDensity::Constant(d) => *d,
                RefDensity::Grid(g) => g.max(),
            }
    }

    /// Optical depth from `o` along unit `d` over `[t0, t1]`: the midpoint rule in `steps` steps for
    /// grids (piecewise cubic along a line), exact for constants.
    pub fn optical_depth(&self, o: DVec3, d: DVec3, (t0, t1): (f64, f64), steps: u32) -> f64 {
        match &self.density {
            RefDensity::Constant(c) => self.scale * c * (t1 - t0),
            RefDensity::Grid(_) => {
                let dt = (t1 - t0) / steps as f64;
                (0..steps)
                    .map(|i| self.sigma_t(o + d * (t0 + (i as f64 + 0.5) * dt)) * dt)
                    .sum()
            }
        }
    }

    /// Transmittance from `o` along `d` to where the ray leaves the box.
    pub fn transmittance_to_exit(&self, o: DVec3, d: DVec3, steps: u32) -> f64 {
        match self.bounds.interval(o, d) {
            Some(span) => (-self.optical_depth(o, d, span, steps)).exp(),
            None => 1.0,
        }
    }
}

/// The environment of the description: constant, or Mitsuba's lat-long `envmap` (bilinear, `u`
/// wrapping, rows per [`LatLongRows`]).
#[derive(Clone, Debug)]
pub struct RefEnvironment(EnvironmentDesc);

impl RefEnvironment {
    pub fn new(desc: &EnvironmentDesc) -> Self {
        Self(desc.clone())
    }

    /// Radiance seen looking along unit `d`.
    pub fn radiance(&self, d: DVec3) -> DVec3 {
        let map = match &self.0 {
            EnvironmentDesc::Constant(rgb) => return vec(*rgb),
            EnvironmentDesc::LatLong(map) => map,
        };
        // The inverse of a rotation is its transpose: the local direction's components are the
        // world direction's projections on the map frame's axes.
        let local = DVec3::new(
            d.dot(column(&map.to_world, 0)),
            d.dot(column(&map.to_world, 1)),
            d.dot(column(&map.to_world, 2)),
        );
        let u = (local.x.atan2(-local.z) / (2.0 * PI)).rem_euclid(1.0);
        let v = local.y.clamp(-1.0, 1.0).acos() / PI;
        let (w, h) = (map.width as usize, map.height as usize);
        let x = u * w as f64 - 0.5;
        let y = match map.rows {
            LatLongRows::CellCentred => v * h as f64 - 0.5,
            LatLongRows::PoleToPole => v * (h as f64 - 1.0),
        }
        .clamp(0.0, (h - 1) as f64);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |i: i64, j: usize| {
            let i = i.rem_euclid(w as i64) as usize;
            let j = j.min(h - 1);
            let k = 3 * (j * w + i);
            vec([map.rgb[k], map.rgb[k + 1], map.rgb[k + 2]])
        };
        let (i0, j0) = (x0 as i64, y0 as usize);
        let top = texel(i0, j0) * (1.0 - fx) + texel(i0 + 1, j0) * fx;
        let bottom = texel(i0, j0 + 1) * (1.0 - fx) + texel(i0 + 1, j0 + 1) * fx;
        (top * (1.0 - fy) + bottom * fy) * map.scale as f64
    }
}

/// Two orthonormal vectors perpendicular to unit `d`.
fn basis(d: DVec3) -> (DVec3, DVec3) {
    let helper = if d.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
    let a = d.cross(helper).normalize();
    (a, d.cross(a))
}

/// Quadrature orders of the single-scattering reference.
#[derive(Clone, Copy, Debug)]
pub struct Orders {
    /// Points along the camera ray's segment in the medium.
    pub along: usize,
    /// Cosine of the scattering angle (in HG's cumulative distribution, so the peak is resolved).
    pub cosine: usize,
    pub azimuth: usize,
    /// Midpoint steps of optical depths through grids.
    pub steps: u32,
}

/// Radiance along the camera ray from `o` along unit `d` with at most one scattering event
/// (`max_depth = 2`), through an index-matched boundary:
///
/// `L = T(t0, t1) L_env(d) + int_t0^t1 T(t0, t) sigma_t(t) albedo int p(d . w) T(x_t -> exit, w) L_env(w) dw dt`.
///
/// The inner integral is taken in the variable `u = CDF_HG(cos)`, which makes `p dw = du dphi / 2pi`.
pub fn single_scattered_radiance(
    medium: &RefMedium,
    env: &RefEnvironment,
    o: DVec3,
    d: DVec3,
    orders: Orders,
) -> DVec3 {
    let Some((t0, t1)) = medium.bounds.interval(o, d) else {
        return env.radiance(d);
    };
    let direct = env.radiance(d) * (-medium.optical_depth(o, d, (t0, t1), orders.steps)).exp();
    let (a, b) = basis(d);
    let along = gauss_legendre(orders.along);
    let cosines = gauss_legendre(orders.cosine);
    let g = medium.g;
    let inverse_cdf = |u: f64| {
        if g.abs() < 1e-6 {
            2.0 * u - 1.0
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
            (1.0 + g * g - s * s) / (2.0 * g)
        }
    };
    let mut scattered = DVec3::ZERO;
    for &(s, ws) in &along {
        let t = t0 + s * (t1 - t0);
        let x = o + d * t;
        let to_x = (-medium.optical_depth(o, d, (t0, t), orders.steps)).exp();
        let mut inner = DVec3::ZERO;
        for &(u, wu) in &cosines {
            let cos = inverse_cdf(u).clamp(-1.0, 1.0);
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            for k in 0..orders.azimuth {
                let phi = 2.0 * PI * (k as f64 + 0.5) / orders.azimuth as f64;
                let w = d * cos + (a * phi.cos() + b * phi.sin()) * sin;
                let out = medium.transmittance_to_exit(x, w, orders.steps);
                inner += env.radiance(w) * (out * wu / orders.azimuth as f64);
            }
        }
        scattered += inner * (ws * (t1 - t0) * to_x * medium.sigma_t(x));
    }
    direct + scattered * medium.albedo
}

/// The directional albedo of a GGX rough dielectric interface with Smith's separable masking
/// (Walter et al. 2007), energy-normalised (radiance scaled by `eta^2` on refraction, so that a
/// lossless interface has albedo 1): `rho(wi) = int D_wi(m) [F G1(wo_r) + (1 - F) G1(wo_t)] dm`
/// over the normals `D_wi` visible from `wi`. Below 1 by the light that single-scattering
/// microfacet theory loses to masking (Heitz et al. 2016).
///
/// Integrated over `m` in GGX's own variables (`tan^2 theta_m = a^2 u / (1 - u)`, uniform
/// azimuth, in which `D(m) cos theta_m dm = du dphi / 2 pi`), so the lobe is resolved at any alpha.
pub fn rough_dielectric_albedo(alpha: f64, eta: f64, cos_i: f64, orders: (usize, usize)) -> f64 {
    let a2 = alpha * alpha;
    let wi = DVec3::new((1.0 - cos_i * cos_i).max(0.0).sqrt(), 0.0, cos_i);
    let g1 = |v: DVec3, m: DVec3| {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let tan2 = (v.x * v.x + v.y * v.y) / (v.z * v.z);
        2.0 / (1.0 + (1.0 + a2 * tan2).sqrt())
    };
    let mut sum = 0.0;
    for (u, wu) in gauss_legendre(orders.0) {
        let tan2 = a2 * u / (1.0 - u);
        let cos_m = 1.0 / (1.0 + tan2).sqrt();
        let sin_m = (1.0 - cos_m * cos_m).max(0.0).sqrt();
        for k in 0..orders.1 {
            let phi = 2.0 * PI * (k as f64 + 0.5) / orders.1 as f64;
            let m = DVec3::new(sin_m * phi.cos(), sin_m * phi.sin(), cos_m);
            let c = wi.dot(m);
            if c <= 0.0 {
                continue;
            }
            // D_wi(m) dm = G1(wi) (wi . m) / (wi . n) D(m) dm.
            let visible = g1(wi, m) * c / (cos_i * cos_m);
            let sin2_t = (1.0 - c * c) / (eta * eta);
            let reflect = {
                let wo = m * (2.0 * c) - wi;
                if wo.z > 0.0 {
                    g1(wo, m)
                } else {
                    0.0
                }
            };
            let (fresnel, transmit) = if sin2_t >= 1.0 {
                (1.0, 0.0)
            } else {
                let cos_t = (1.0 - sin2_t).sqrt();
                let rs = (c - eta * cos_t) / (c + eta * cos_t);
                let rp = (eta * c - cos_t) / (eta * c + cos_t);
                let wo = m * (c / eta - cos_t) - wi / eta;
                let transmit = if wo.z < 0.0 { g1(wo, m) } else { 0.0 };
                (0.5 * (rs * rs + rp * rp), transmit)
            };
            sum +=
                wu / orders.1 as f64 * visible * (fresnel * reflect + (1.0 - fresnel) * transmit);
        }
    }
    sum
}
