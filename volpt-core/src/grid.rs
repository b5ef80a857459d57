//! Dense 3D grids with trilinear (or nearest-sample) reconstruction.

use crate::{Aabb, Vec3};

/// Maps world positions to continuous voxel coordinates, in which sample `i` sits at coordinate `i`.
///
/// Mitsuba 0.5/0.6 place samples on the box's faces (`i / (res - 1)`); Mitsuba 3 at cell centres
/// (`(i + 0.5) / res`). Both are `index = (p - min) / (max - min) * scale + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridMapping {
    pub bounds: Aabb,
    scale: Vec3,
    offset: Vec3,
}

impl GridMapping {
    /// Samples on the faces of `bounds` (Mitsuba 0.5/0.6 `gridvolume`).
    pub fn vertex_centred(bounds: Aabb, res: [u32; 3]) -> Self {
        let res = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        Self {
            bounds,
            scale: (res - Vec3::ONE).max(Vec3::ZERO),
            offset: Vec3::ZERO,
        }
    }

    /// Samples at the centres of `res` cells tiling `bounds` (Mitsuba 3 `gridvolume`).
    pub fn cell_centred(bounds: Aabb, res: [u32; 3]) -> Self {
        let res = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        Self {
            bounds,
            scale: res,
            offset: Vec3::splat(-0.5),
        }
    }

    /// A mapping from its parts, as [`GridMapping::scale`] and [`GridMapping::offset`] return them
    /// (used to ship a mapping to a GPU bit for bit).
    pub fn from_parts(bounds: Aabb, scale: Vec3, offset: Vec3) -> Self {
        Self {
            bounds,
            scale,
            offset,
        }
    }

    /// Index-space units per unit of normalised box coordinate, per axis.
    pub fn scale(&self) -> Vec3 {
        self.scale
    }

    /// Index-space offset added after scaling.
    pub fn offset(&self) -> Vec3 {
        self.offset
    }

    #[inline]
    pub fn to_index_space(&self, p: Vec3) -> Vec3 {
        (p - self.bounds.min) / self.bounds.extent() * self.scale + self.offset
    }
}

/// How a grid reconstructs values between its samples (Mitsuba 3's `filter_type`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GridLookup {
    /// Trilinear interpolation of the eight samples around a point.
    #[default]
    Trilinear,
    /// The value of the nearest sample: one read instead of eight, a blockier field.
    Nearest,
}

/// A grid of `C`-channel samples, x fastest: `data[((z * res_y + y) * res_x + x) * C + c]`.
/// Borrowed, so that the same type wraps host memory and device memory.
#[derive(Clone, Copy, Debug)]
pub struct Grid<'a, const C: usize> {
    pub data: &'a [f32],
    pub res: [u32; 3],
    pub mapping: GridMapping,
    pub lookup: GridLookup,
}

impl<'a, const C: usize> Grid<'a, C> {
    /// `data.len()` must be `res_x * res_y * res_z * C`; lookups index within that.
    pub fn new(data: &'a [f32], res: [u32; 3], mapping: GridMapping) -> Self {
        assert_eq!(
            data.len(),
            res[0] as usize * res[1] as usize * res[2] as usize * C,
            "grid data does not match its resolution"
        );
        Self {
            data,
            res,
            mapping,
            lookup: GridLookup::Trilinear,
        }
    }

    /// The same grid, reconstructed as `lookup` says.
    pub fn with_lookup(self, lookup: GridLookup) -> Self {
        Self { lookup, ..self }
    }

    #[inline]
    fn at(&self, x: u32, y: u32, z: u32) -> [f32; C] {
        let i = (((z * self.res[1] + y) * self.res[0] + x) as usize) * C;
        let mut v = [0.0; C];
        v.copy_from_slice(&self.data[i..i + C]);
        v
    }

    /// The value at `p`, reconstructed as [`Grid::lookup`] says: zero outside the grid's box, and
    /// the edge samples held constant between the outermost sample and the box's faces. Either
    /// reconstruction stays within the samples' range, so a majorant of the samples bounds it.
    #[inline]
    pub fn lookup(&self, p: Vec3) -> [f32; C] {
        if !self.mapping.bounds.contains(p) {
            return [0.0; C];
        }
        let max_index = Vec3::new(
            (self.res[0] - 1) as f32,
            (self.res[1] - 1) as f32,
            (self.res[2] - 1) as f32,
        );
        let q = self
            .mapping
            .to_index_space(p)
            .max(Vec3::ZERO)
            .min(max_index);
        match self.lookup {
            GridLookup::Trilinear => self.trilinear(q, max_index),
            GridLookup::Nearest => {
                let n = q.round();
                self.at(n.x as u32, n.y as u32, n.z as u32)
            }
        }
    }

    /// Trilinear interpolation around index-space `q`, which lies in `[0, max_index]`.
    #[inline]
    fn trilinear(&self, q: Vec3, max_index: Vec3) -> [f32; C] {
        let base = q.floor().min((max_index - Vec3::ONE).max(Vec3::ZERO));
        let f = q - base;
        let (x0, y0, z0) = (base.x as u32, base.y as u32, base.z as u32);
        let x1 = (x0 + 1).min(self.res[0] - 1);
        let y1 = (y0 + 1).min(self.res[1] - 1);
        let z1 = (z0 + 1).min(self.res[2] - 1);
        // Rounding can carry `a + (b - a) * t` one ulp above `max(a, b)`; clamped, no lookup ever
        // exceeds the largest sample, which the majorant of delta tracking relies on.
        let lerp_c = |a: [f32; C], b: [f32; C], t: f32| {
            let mut r = [0.0; C];
            for c in 0..C {
                r[c] = (a[c] + (b[c] - a[c]) * t).min(a[c].max(b[c]));
            }
            r
        };
        let c00 = lerp_c(self.at(x0, y0, z0), self.at(x1, y0, z0), f.x);
        let c10 = lerp_c(self.at(x0, y1, z0), self.at(x1, y1, z0), f.x);
        let c01 = lerp_c(self.at(x0, y0, z1), self.at(x1, y0, z1), f.x);
        let c11 = lerp_c(self.at(x0, y1, z1), self.at(x1, y1, z1), f.x);
        lerp_c(lerp_c(c00, c10, f.y), lerp_c(c01, c11, f.y), f.z)
    }
}
