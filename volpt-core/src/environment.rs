//! Light arriving from infinitely far away.

use bytemuck::{Pod, Zeroable};

use crate::abi::{Component, Upload};
use crate::math::{clamp, sin_cos_2pi, INV_4PI, INV_PI, PI};
use crate::sampling::sample_uniform_sphere;
use crate::{Spectrum, Vec2, Vec3};

/// A direction towards the environment, sampled for next-event estimation.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Look direction (light arrives along `-dir`).
    pub dir: Vec3,
    pub radiance: Spectrum,
    /// Solid-angle density of `dir`, positive.
    pub pdf: f32,
}

pub trait Environment {
    /// The same radiance from every direction. A path that leaves a rough boundary by its BSDF's
    /// sample sees such a light as well as a light sample would, so paths do not sample it where
    /// they meet the boundary: that next-event estimation is compiled out of its kernels, whose
    /// registers it would otherwise take at every boundary interaction.
    const IS_CONSTANT: bool = false;

    /// Radiance seen when looking along `dir` (arriving along `-dir`).
    fn radiance(&self, dir: Vec3) -> Spectrum;
    /// A look direction with density roughly proportional to the radiance, or `None` when there is
    /// none to sample (a black map, or a map without its distribution).
    fn sample(&self, u: Vec2) -> Option<LightSample>;
    /// The density with which [`Environment::sample`] returns `dir`.
    fn pdf(&self, dir: Vec3) -> f32;
}

/// What next-event estimation asks of an environment on the host: the distribution it samples
/// directions from, computed once per scene by the host and borrowed for `'a` (a map's). The
/// defaults fit an environment that samples without one (a constant). The device never calls
/// these: it receives the distribution through the part's parameters ([`Component`]).
pub trait SampledEnvironment<'a> {
    /// How many values the distribution has; 0 where the environment samples without one.
    fn distribution_size(&self) -> usize {
        0
    }

    /// Writes the distribution into `out` ([`SampledEnvironment::distribution_size`] values).
    fn write_distribution(&self, out: &mut [f32]) {
        let _ = out;
    }

    /// Samples from `distribution` (what [`SampledEnvironment::write_distribution`] wrote) from
    /// now on.
    fn sample_from(&mut self, distribution: &'a [f32]) {
        let _ = distribution;
    }
}

#[derive(Clone, Copy, Debug)]
pub struct ConstantEnvironment(pub Spectrum);

impl Environment for ConstantEnvironment {
    const IS_CONSTANT: bool = true;

    #[inline]
    fn radiance(&self, _dir: Vec3) -> Spectrum {
        self.0
    }

    #[inline]
    fn sample(&self, u: Vec2) -> Option<LightSample> {
        Some(LightSample {
            dir: sample_uniform_sphere(u),
            radiance: self.0,
            pdf: INV_4PI,
        })
    }

    #[inline]
    fn pdf(&self, _dir: Vec3) -> f32 {
        INV_4PI
    }
}

impl SampledEnvironment<'_> for ConstantEnvironment {}

/// Where the rows of a latitude-longitude map sit between the poles. Columns are the same in every
/// Mitsuba generation (pixel centres at `u = (i + 0.5) / width`, wrapping around); rows are not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LatLongRows {
    /// Mitsuba 0.5/0.6 (a MIP map lookup): row `j` at `v = (j + 0.5) / height`, the outer rows held
    /// constant up to the poles.
    CellCentred,
    /// Mitsuba 3: row `j` at `v = j / (height - 1)`, so the first and last rows lie on the poles.
    PoleToPole,
}

/// An environment map in latitude-longitude layout (Mitsuba's `envmap`): the look direction `v` in the
/// map's local frame maps to `u = atan2(v.x, -v.z) / 2 pi`, `v = acos(v.y) / pi`, so the image's top
/// row is the +y pole and its centre column looks along -z. Pixels are bilinearly interpolated,
/// wrapping in `u`; where the rows sit is [`LatLongRows`], applied as `row = v * row_scale + row_offset`
/// (like [`crate::GridMapping`], so that a GPU receives the very same two numbers).
#[derive(Clone, Copy, Debug)]
pub struct LatLongEnvironment<'a> {
    /// RGB, row-major from the top-left pixel: `3 * width * height` values.
    pub rgb: &'a [f32],
    pub width: u32,
    pub height: u32,
    /// Rows of the world-to-map rotation.
    pub world_to_map: [Vec3; 3],
    /// Multiplies every texel (Mitsuba's `scale`).
    pub scale: f32,
    pub row_scale: f32,
    pub row_offset: f32,
    /// The sampling distribution [`LatLongEnvironment::fill_distribution`] writes, or empty (then
    /// the map is not sampled).
    pub distribution: &'a [f32],
}

impl<'a> LatLongEnvironment<'a> {
    /// `rgb.len()` must be `3 * width * height`, with `width` and `height` at least 1; lookups index
    /// within that.
    pub fn new(
        rgb: &'a [f32],
        width: u32,
        height: u32,
        rows: LatLongRows,
        world_to_map: [Vec3; 3],
        scale: f32,
    ) -> Self {
        assert!(width > 0 && height > 0, "empty environment map");
        assert_eq!(
            rgb.len(),
            3 * width as usize * height as usize,
            "environment map data does not match its resolution"
        );
        let (row_scale, row_offset) = match rows {
            LatLongRows::CellCentred => (height as f32, -0.5),
            LatLongRows::PoleToPole => ((height - 1) as f32, 0.0),
        };
        Self {
            rgb,
            width,
            height,
            world_to_map,
            scale,
            row_scale,
            row_offset,
            distribution: &[],
        }
    }

    /// Values of the sampling distribution of a `width x height` map.
    pub fn distribution_len(width: u32, height: u32) -> usize {
        height as usize * (width as usize + 1) + height as usize + 1
    }

    /// Writes the map's sampling distribution into `out` ([`Self::distribution_len`] values): a
    /// piecewise-constant density over `width x height` cells of `(u, v)`, cell `(i, j)` weighted by
    /// the brightest channel of the texels its bilinear lookups can read (the 3x3 around texel
    /// `(i, j)`, so no lit direction has density 0) times `sin(theta)` at the cell's centre. The
    /// layout is each row's running sum (`width + 1` values from 0) and then the running sum of the
    /// rows' totals (`height + 1` values from 0); sums are taken in `f64`.
    pub fn fill_distribution(&self, out: &mut [f32]) {
        let (w, h) = (self.width as usize, self.height as usize);
        assert_eq!(out.len(), Self::distribution_len(self.width, self.height));
        let (rows, marginal) = out.split_at_mut(h * (w + 1));
        let mut total = 0.0f64;
        marginal[0] = 0.0;
        for j in 0..h {
            let sin_theta = libm::sin(PI as f64 * (j as f64 + 0.5) / h as f64);
            let row = &mut rows[j * (w + 1)..(j + 1) * (w + 1)];
            let mut sum = 0.0f64;
            row[0] = 0.0;
            for i in 0..w {
                let mut brightest = 0.0f32;
                for dj in [-1i64, 0, 1] {
                    let y = (j as i64 + dj).clamp(0, h as i64 - 1) as u32;
                    for di in [-1i64, 0, 1] {
                        let x = (i as i64 + di).rem_euclid(w as i64) as u32;
                        brightest = brightest.max(self.texel(x, y).max_element());
                    }
                }
                sum += brightest as f64 * sin_theta;
                row[i + 1] = sum as f32;
            }
            total += row[w] as f64;
            marginal[j + 1] = total as f32;
        }
    }

    /// Map-space direction to its world direction (the rotation's transpose).
    #[inline]
    fn map_dir_to_world(&self, v: Vec3) -> Vec3 {
        self.world_to_map[0] * v.x + self.world_to_map[1] * v.y + self.world_to_map[2] * v.z
    }

    /// `(u, v)` of a world look direction, as the lookup computes them.
    #[inline]
    fn uv(&self, dir: Vec3) -> (f32, f32) {
        let v = Vec3::new(
            self.world_to_map[0].dot(dir),
            self.world_to_map[1].dot(dir),
            self.world_to_map[2].dot(dir),
        );
        let u = libm::atan2f(v.x, -v.z) * (0.5 * INV_PI);
        let u = u - libm::floorf(u);
        let t = libm::acosf(clamp(v.y, -1.0, 1.0)) * INV_PI;
        (u, t)
    }

    /// The solid-angle density of cell weight `f` at polar angle `theta`: the cell's probability
    /// `f / total` spread uniformly over its `(u, v)` area, divided by `d omega = 2 pi^2 sin(theta)
    /// du dv`.
    #[inline]
    fn density(&self, f: f32, total: f32, sin_theta: f32) -> f32 {
        if sin_theta <= 0.0 || total <= 0.0 {
            return 0.0;
        }
        f / total * (self.width as f32 * self.height as f32) / (2.0 * PI * PI * sin_theta)
    }

    #[inline]
    fn texel(&self, x: u32, y: u32) -> Spectrum {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        Spectrum::new(self.rgb[i], self.rgb[i + 1], self.rgb[i + 2])
    }
}

impl Environment for LatLongEnvironment<'_> {
    // Inlined into every kernel: called by address, it kept the scene in local memory
    // (`ptx_entries::no_kernel_keeps_the_scene_in_local_memory`). `sample` and `pdf` are inlined
    // without being forced (forcing them and `RoughDielectric::eval` cost 0.29 MB of CPU code).
    #[inline(always)]
    fn radiance(&self, dir: Vec3) -> Spectrum {
        let (u, t) = self.uv(dir);
        let x = u * self.width as f32 - 0.5;
        let y = clamp(
            t * self.row_scale + self.row_offset,
            0.0,
            (self.height - 1) as f32,
        );
        let (x0f, y0f) = (libm::floorf(x), libm::floorf(y));
        let (fx, fy) = (x - x0f, y - y0f);
        let wrap = |i: i32| i.rem_euclid(self.width as i32) as u32;
        let (x0, x1) = (wrap(x0f as i32), wrap(x0f as i32 + 1));
        let y0 = y0f as u32;
        let y1 = (y0 + 1).min(self.height - 1);
        let top = self.texel(x0, y0) * (1.0 - fx) + self.texel(x1, y0) * fx;
        let bottom = self.texel(x0, y1) * (1.0 - fx) + self.texel(x1, y1) * fx;
        (top * (1.0 - fy) + bottom * fy) * self.scale
    }

    #[inline]
    fn sample(&self, u: Vec2) -> Option<LightSample> {
        let (w, h) = (self.width as usize, self.height as usize);
        if self.distribution.len() != Self::distribution_len(self.width, self.height) {
            return None;
        }
        let (rows, marginal) = self.distribution.split_at(h * (w + 1));
        let total = marginal[h];
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let x = u.y * total;
        let j = find_interval(marginal, h, x);
        let row = &rows[j * (w + 1)..(j + 1) * (w + 1)];
        let dy = clamp(
            (x - marginal[j]) / (marginal[j + 1] - marginal[j]),
            0.0,
            1.0,
        );
        let xr = u.x * row[w];
        let i = find_interval(row, w, xr);
        let f = row[i + 1] - row[i];
        let dx = clamp((xr - row[i]) / f, 0.0, 1.0);
        let (cu, cv) = ((i as f32 + dx) / w as f32, (j as f32 + dy) / h as f32);
        // `sin_cos_2pi` of half a turn per unit: no argument reduction (see `math::sin_cos_2pi`).
        let (sin_theta, cos_theta) = sin_cos_2pi(0.5 * cv);
        let pdf = self.density(f, total, sin_theta);
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        let (sin_phi, cos_phi) = sin_cos_2pi(cu);
        let dir = crate::math::normalize(self.map_dir_to_world(Vec3::new(
            sin_theta * sin_phi,
            cos_theta,
            -sin_theta * cos_phi,
        )));
        Some(LightSample {
            dir,
            radiance: self.radiance(dir),
            pdf,
        })
    }

    #[inline]
    fn pdf(&self, dir: Vec3) -> f32 {
        let (w, h) = (self.width as usize, self.height as usize);
        if self.distribution.len() != Self::distribution_len(self.width, self.height) {
            return 0.0;
        }
        let (rows, marginal) = self.distribution.split_at(h * (w + 1));
        let (u, v) = self.uv(dir);
        let i = ((u * w as f32) as usize).min(w - 1);
        let j = ((v * h as f32) as usize).min(h - 1);
        let f = rows[j * (w + 1) + i + 1] - rows[j * (w + 1) + i];
        self.density(f, marginal[h], sin_cos_2pi(0.5 * v).0)
    }
}

impl<'a> SampledEnvironment<'a> for LatLongEnvironment<'a> {
    fn distribution_size(&self) -> usize {
        Self::distribution_len(self.width, self.height)
    }

    fn write_distribution(&self, out: &mut [f32]) {
        self.fill_distribution(out);
    }

    fn sample_from(&mut self, distribution: &'a [f32]) {
        self.distribution = distribution;
    }
}

/// Device parameters of a constant environment, padded to a multiple of 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ConstantEnvironmentParams {
    pub radiance: [f32; 3],
    pub padding: u32,
}

impl Component for ConstantEnvironment {
    const NAME: &'static str = "constant";
    type Params = ConstantEnvironmentParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> ConstantEnvironmentParams {
        ConstantEnvironmentParams {
            radiance: self.0.to_array(),
            padding: 0,
        }
    }
    #[inline]
    unsafe fn from_params(p: &ConstantEnvironmentParams) -> Self {
        ConstantEnvironment(Spectrum::from_array(p.radiance))
    }
}

/// Device parameters of a lat-long map: its texels' address and every number [`LatLongEnvironment`]
/// holds.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LatLongParams {
    /// Device address of the map's `len` RGB `f32` values.
    pub texels: u64,
    pub len: u64,
    /// Rows of the world-to-map rotation.
    pub world_to_map: [[f32; 3]; 3],
    pub scale: f32,
    pub width: u32,
    pub height: u32,
    pub row_scale: f32,
    pub row_offset: f32,
    /// Device address of the `distribution_len` values of the sampling distribution (0 if none).
    pub distribution: u64,
    pub distribution_len: u64,
}

impl Component for LatLongEnvironment<'_> {
    const NAME: &'static str = "lat_long";
    type Params = LatLongParams;

    fn to_params(&self, upload: &mut Upload<'_>) -> LatLongParams {
        LatLongParams {
            texels: upload.values(self.rgb),
            len: self.rgb.len() as u64,
            world_to_map: self.world_to_map.map(|row| row.to_array()),
            scale: self.scale,
            width: self.width,
            height: self.height,
            row_scale: self.row_scale,
            row_offset: self.row_offset,
            distribution: if self.distribution.is_empty() {
                0
            } else {
                upload.values(self.distribution)
            },
            distribution_len: self.distribution.len() as u64,
        }
    }
    #[inline]
    unsafe fn from_params(p: &LatLongParams) -> Self {
        Self {
            // SAFETY: the caller guarantees the address range.
            rgb: unsafe { core::slice::from_raw_parts(p.texels as *const f32, p.len as usize) },
            width: p.width,
            height: p.height,
            world_to_map: p.world_to_map.map(Vec3::from_array),
            scale: p.scale,
            row_scale: p.row_scale,
            row_offset: p.row_offset,
            distribution: if p.distribution_len == 0 {
                &[]
            } else {
                // SAFETY: the caller guarantees the address range.
                unsafe {
                    core::slice::from_raw_parts(
                        p.distribution as *const f32,
                        p.distribution_len as usize,
                    )
                }
            },
        }
    }
}

/// The index `k` in `0..n` with `cdf[k] <= x < cdf[k + 1]` of a non-decreasing `cdf` of `n + 1`
/// values (the last interval of positive width if `x` rounds to the end).
#[inline]
fn find_interval(cdf: &[f32], n: usize, x: f32) -> usize {
    let (mut lo, mut hi) = (0usize, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if cdf[mid] <= x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    while lo > 0 && cdf[lo + 1] <= cdf[lo] {
        lo -= 1;
    }
    lo
}
