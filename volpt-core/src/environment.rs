//! Light arriving from infinitely far away.

use bytemuck::{Pod, Zeroable};

use crate::abi::{Component, Upload};
use crate::math::{clamp, INV_PI};
use crate::{Spectrum, Vec3};

pub trait Environment {
    /// Radiance seen when looking along `dir` (arriving along `-dir`).
    fn radiance(&self, dir: Vec3) -> Spectrum;
}

#[derive(Clone, Copy, Debug)]
pub struct ConstantEnvironment(pub Spectrum);

impl Environment for ConstantEnvironment {
    #[inline]
    fn radiance(&self, _dir: Vec3) -> Spectrum {
        self.0
    }
}

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
        }
    }

    #[inline]
    fn texel(&self, x: u32, y: u32) -> Spectrum {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        Spectrum::new(self.rgb[i], self.rgb[i + 1], self.rgb[i + 2])
    }
}

impl Environment for LatLongEnvironment<'_> {
    #[inline]
    fn radiance(&self, dir: Vec3) -> Spectrum {
        let v = Vec3::new(
            self.world_to_map[0].dot(dir),
            self.world_to_map[1].dot(dir),
            self.world_to_map[2].dot(dir),
        );
        let u = libm::atan2f(v.x, -v.z) * (0.5 * INV_PI);
        let u = u - libm::floorf(u);
        let t = libm::acosf(clamp(v.y, -1.0, 1.0)) * INV_PI;
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
        }
    }
}
