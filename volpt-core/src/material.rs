//! Material-indexed volumes: one material index per voxel and a table of materials, each with its
//! RGB extinction, RGB albedo and Henyey-Greenstein `g` (a colour 3D print: five resins, one per
//! voxel; Elek et al. 2017). The index grid stays one byte a voxel on the device (two for a table
//! of more than 256 materials: a print of many mixtures), not the 28 of expanded coefficients; a
//! collision reads its voxel's index, then the table.
//!
//! The voxels tile the grid's box (cell-centred, Mitsuba 3's convention) and are read nearest:
//! the coefficients at `p` are those of the voxel containing `p`, constant inside it, with no
//! medium outside the box. A majorant-grid cell bounds each channel by that channel's largest
//! extinction among the materials of the voxels it may read ([`build_material_channel_majorants`]),
//! and every channel by the largest of those ([`build_material_majorants`]).
//!
//! [`crate::ChromaticMedium`] carries an optional table as a run-time branch: an indexed volume
//! adds no kernel. A grid whose voxels all hold one material renders as that material's
//! homogeneous medium, bit for bit ([`MaterialGrid::only`]).

use bytemuck::{Pod, Zeroable};

use crate::abi::Upload;
use crate::majorant::{MajorantGrid, CELL_MARGIN};
use crate::{Aabb, Spectrum, Vec3};

/// The `f32`s of one material in a table: extinction RGB, `g`, albedo RGB, the extinction's
/// largest channel. Eight, so that a material is one aligned 32-byte read on a GPU.
pub const MATERIAL_FLOATS: usize = 8;

/// The most materials a table holds: indices are at most 16 bits.
pub const MAX_MATERIALS: usize = 1 << 16;

/// The most materials a table of byte indices holds; a larger table's indices are 16 bits
/// ([`wide_indices`]).
pub const MAX_BYTE_MATERIALS: usize = 256;

/// Whether a table of `materials` materials has 16-bit indices (two to a `u32`) rather than
/// bytes (four to a `u32`): the storage is the table's choice, a run-time branch of the one
/// lookup, so that more materials add no kernel.
pub const fn wide_indices(materials: usize) -> bool {
    materials > MAX_BYTE_MATERIALS
}

/// The `u32` words that hold `voxels` indices into a table of `materials` materials.
pub const fn index_words(voxels: usize, materials: usize) -> usize {
    if wide_indices(materials) {
        voxels.div_ceil(2)
    } else {
        voxels.div_ceil(4)
    }
}

/// One material's coefficients, as a table row holds them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Extinction per channel, per world unit (`sigma_s + sigma_a`).
    pub sigma_t: Spectrum,
    /// Single-scattering albedo per channel (`sigma_s / sigma_t`; 0 where `sigma_t` is 0).
    pub albedo: Spectrum,
    /// Henyey-Greenstein asymmetry, in (-1, 1).
    pub g: f32,
}

impl Material {
    /// The material of scattering `sigma_s` and absorption `sigma_a` per channel.
    pub fn from_coefficients(sigma_s: [f32; 3], sigma_a: [f32; 3], g: f32) -> Self {
        let t = [0, 1, 2].map(|c| sigma_s[c] + sigma_a[c]);
        let albedo = [0, 1, 2].map(|c| if t[c] > 0.0 { sigma_s[c] / t[c] } else { 0.0 });
        Self {
            sigma_t: Spectrum::from_array(t),
            albedo: Spectrum::from_array(albedo),
            g,
        }
    }

    /// The material's row of a table.
    pub fn row(&self) -> [f32; MATERIAL_FLOATS] {
        let (t, a) = (self.sigma_t, self.albedo);
        [t.x, t.y, t.z, self.g, a.x, a.y, a.z, t.max_element()]
    }
}

/// A material-indexed volume: `res` voxels tiling `bounds`, x fastest, each index a byte packed
/// four to a `u32` (little end first; 16 bits, two to a `u32`, where `wide`), and the table's
/// rows ([`MATERIAL_FLOATS`] each), whose
/// extinctions `scale` multiplies. Borrowed, so that the same type wraps host memory and device
/// memory.
#[derive(Clone, Copy, Debug)]
pub struct MaterialGrid<'a> {
    pub indices: &'a [u32],
    pub res: [u32; 3],
    pub bounds: Aabb,
    pub table: &'a [f32],
    pub scale: f32,
    /// The one material every voxel holds, or [`MaterialGrid::MIXED`].
    pub only: u32,
    /// 16-bit indices ([`wide_indices`] of the table's length).
    pub wide: bool,
}

impl<'a> MaterialGrid<'a> {
    /// [`MaterialGrid::only`] of a grid of more than one material.
    pub const MIXED: u32 = u32::MAX;

    /// `indices` must hold `res_x * res_y * res_z` indices ([`index_words`] words: bytes, or 16
    /// bits for a table of more than 256 materials), each below the table's length; the loaders
    /// check both and return errors first.
    pub fn new(
        indices: &'a [u32],
        res: [u32; 3],
        bounds: Aabb,
        table: &'a [f32],
        scale: f32,
    ) -> Self {
        let voxels = res.iter().map(|&r| r as usize).product::<usize>();
        assert!(table.len().is_multiple_of(MATERIAL_FLOATS) && !table.is_empty());
        let materials = table.len() / MATERIAL_FLOATS;
        assert!(materials <= MAX_MATERIALS, "table size");
        assert_eq!(
            indices.len(),
            index_words(voxels, materials),
            "index grid size"
        );
        let mut grid = Self {
            indices,
            res,
            bounds,
            table,
            scale,
            only: Self::MIXED,
            wide: wide_indices(materials),
        };
        let first = grid.index(0);
        assert!(
            (first as usize) < materials,
            "material index out of the table"
        );
        let mut uniform = true;
        for i in 0..voxels {
            let k = grid.index(i);
            assert!((k as usize) < materials, "material index out of the table");
            uniform &= k == first;
        }
        if uniform {
            grid.only = first;
        }
        grid
    }

    /// The material index of voxel `i` (x fastest).
    #[inline(always)]
    pub fn index(&self, i: usize) -> u32 {
        if self.wide {
            (self.indices[i >> 1] >> ((i & 1) * 16)) & 0xffff
        } else {
            (self.indices[i >> 2] >> ((i & 3) * 8)) & 0xff
        }
    }

    /// The row of the material in the voxel containing `p`, or `None` outside the grid's box.
    #[inline(always)]
    fn row_at(&self, p: Vec3) -> Option<usize> {
        let k = if self.only != Self::MIXED {
            self.only
        } else {
            let q = (p - self.bounds.min) / self.bounds.extent();
            let voxel = |a: usize| {
                let v = q[a] * self.res[a] as f32;
                // Not `v < 0.0`: a NaN position reads no voxel.
                #[allow(clippy::neg_cmp_op_on_partial_ord)]
                if !(v >= 0.0) || v >= self.res[a] as f32 {
                    None
                } else {
                    Some((v as u32).min(self.res[a] - 1) as usize)
                }
            };
            let (x, y, z) = (voxel(0)?, voxel(1)?, voxel(2)?);
            let (nx, ny) = (self.res[0] as usize, self.res[1] as usize);
            self.index((z * ny + y) * nx + x)
        };
        Some(k as usize * MATERIAL_FLOATS)
    }

    /// The extinction per channel at `p` (zero outside the box).
    #[inline(always)]
    pub fn sigma_t(&self, p: Vec3) -> Spectrum {
        match self.row_at(p) {
            Some(r) => {
                Spectrum::new(self.table[r], self.table[r + 1], self.table[r + 2]) * self.scale
            }
            None => Spectrum::ZERO,
        }
    }

    /// The albedo per channel at `p` (zero outside the box, where nothing collides).
    #[inline(always)]
    pub fn albedo(&self, p: Vec3) -> Spectrum {
        match self.row_at(p) {
            Some(r) => Spectrum::new(self.table[r + 4], self.table[r + 5], self.table[r + 6]),
            None => Spectrum::ZERO,
        }
    }

    /// The Henyey-Greenstein `g` at `p` (0 outside the box).
    #[inline(always)]
    pub fn g(&self, p: Vec3) -> f32 {
        match self.row_at(p) {
            Some(r) => self.table[r + 3],
            None => 0.0,
        }
    }

    /// The only material's extinction, if every voxel holds one material.
    #[inline(always)]
    pub fn uniform_sigma_t(&self) -> Option<Spectrum> {
        (self.only != Self::MIXED).then(|| {
            let r = self.only as usize * MATERIAL_FLOATS;
            Spectrum::new(self.table[r], self.table[r + 1], self.table[r + 2]) * self.scale
        })
    }

    /// The largest extinction of any channel of any material the grid holds.
    pub fn max_extinction(&self) -> f32 {
        let present = self.present();
        (0..MAX_MATERIALS)
            .filter(|&k| present.contains(k))
            .map(|k| self.table[k * MATERIAL_FLOATS + 7] * self.scale)
            .fold(0.0, f32::max)
    }

    /// Per channel, the largest extinction of any material the grid holds.
    pub fn max_extinction_rgb(&self) -> Spectrum {
        let present = self.present();
        (0..MAX_MATERIALS)
            .filter(|&k| present.contains(k))
            .map(|k| self.row_sigma_t(k))
            .fold(Spectrum::ZERO, Spectrum::max)
    }

    /// The extinction of material `k`, scaled.
    #[inline(always)]
    fn row_sigma_t(&self, k: usize) -> Spectrum {
        let r = k * MATERIAL_FLOATS;
        Spectrum::new(self.table[r], self.table[r + 1], self.table[r + 2]) * self.scale
    }

    /// Which materials the grid holds.
    pub fn present(&self) -> Present {
        let mut present = Present([0; MAX_MATERIALS / 64]);
        let voxels = self.res.iter().map(|&r| r as usize).product::<usize>();
        for i in 0..voxels {
            let k = self.index(i) as usize;
            present.0[k / 64] |= 1 << (k % 64);
        }
        present
    }

    /// The index grid's bytes on the device: one a voxel (two where `wide`).
    pub fn device_bytes(&self) -> u64 {
        self.indices.len() as u64 * 4
    }
}

/// A set of material indices (8 KiB: one bit a possible material).
pub struct Present([u64; MAX_MATERIALS / 64]);

impl Present {
    pub fn contains(&self, k: usize) -> bool {
        k < MAX_MATERIALS && self.0[k / 64] & (1 << (k % 64)) != 0
    }
}

/// Fills `out` (one value per cell of a `res` grid over `bounds`, x fastest) with the largest
/// extinction of any channel a lookup of `grid` can return inside each cell
/// ([`build_material_channel_majorants`]'s largest channel).
pub fn build_material_majorants(
    grid: &MaterialGrid<'_>,
    bounds: Aabb,
    res: [u32; 3],
    out: &mut [f32],
) {
    for_each_cell_bound(grid, bounds, res, out.len(), |i, bound| {
        out[i] = bound.max_element()
    });
}

/// Fills `out` (three values per cell of a `res` grid over `bounds`, x fastest) with each
/// channel's largest extinction that a lookup of `grid` can return inside each cell: the largest
/// of the materials of the voxels that overlap the cell grown by [`CELL_MARGIN`] (and one voxel
/// more on every side, so that rounding at a voxel's face cannot escape it). Conservative by
/// construction; outside the index grid's box the extinction is zero, below any bound.
pub fn build_material_channel_majorants(
    grid: &MaterialGrid<'_>,
    bounds: Aabb,
    res: [u32; 3],
    out: &mut [f32],
) {
    assert_eq!(out.len() % 3, 0, "three channel majorants a cell");
    for_each_cell_bound(grid, bounds, res, out.len() / 3, |i, bound| {
        out[3 * i..3 * i + 3].copy_from_slice(&bound.to_array())
    });
}

/// Calls `put(i, bound)` with each channel's bound of every cell `i` of a `res` grid over
/// `bounds`, which must have `cells` cells.
fn for_each_cell_bound(
    grid: &MaterialGrid<'_>,
    bounds: Aabb,
    res: [u32; 3],
    cells: usize,
    mut put: impl FnMut(usize, Spectrum),
) {
    assert_eq!(
        cells,
        res[0] as usize * res[1] as usize * res[2] as usize,
        "majorant grid data does not match its resolution"
    );
    let grid_cells = MajorantGrid {
        data: &[],
        res,
        bounds,
    };
    let cell = bounds.extent() / Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
    let voxel_scale = Vec3::new(grid.res[0] as f32, grid.res[1] as f32, grid.res[2] as f32)
        / grid.bounds.extent();
    for i in 0..cells {
        if grid.only != MaterialGrid::MIXED {
            put(i, grid.row_sigma_t(grid.only as usize));
            continue;
        }
        let x = (i % res[0] as usize) as u32;
        let y = ((i / res[0] as usize) % res[1] as usize) as u32;
        let z = (i / (res[0] as usize * res[1] as usize)) as u32;
        let b = grid_cells.cell_bounds(x, y, z);
        let lo = ((b.min - cell * CELL_MARGIN - grid.bounds.min) * voxel_scale).floor();
        let hi = ((b.max + cell * CELL_MARGIN - grid.bounds.min) * voxel_scale).floor();
        let range = |a: usize| {
            let last = grid.res[a] as i64 - 1;
            let from = (lo[a] as i64 - 1).clamp(0, last);
            let to = (hi[a] as i64 + 1).clamp(0, last);
            from as usize..=to as usize
        };
        let (nx, ny) = (grid.res[0] as usize, grid.res[1] as usize);
        let mut max = Spectrum::ZERO;
        for vz in range(2) {
            for vy in range(1) {
                for vx in range(0) {
                    max = max.max(grid.row_sigma_t(grid.index((vz * ny + vy) * nx + vx) as usize));
                }
            }
        }
        put(i, max);
    }
}

/// Device parameters of a material-indexed volume; `indices` 0 is none.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MaterialGridParams {
    /// Device address of the packed index words, and their count.
    pub indices: u64,
    pub words: u64,
    /// Device address of the table's `f32`s, and their count.
    pub table: u64,
    pub table_len: u64,
    pub res: [u32; 3],
    pub only: u32,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub scale: f32,
    /// 1: 16-bit indices ([`MaterialGrid::wide`]), 0: bytes.
    pub wide: u32,
}

impl MaterialGridParams {
    /// The parameters of `grid` (none: all zero), its indices and table placed by `upload`.
    pub fn new(grid: Option<&MaterialGrid<'_>>, upload: &mut Upload<'_>) -> Self {
        let Some(grid) = grid else {
            return Self::default();
        };
        Self {
            indices: upload.values(bytemuck::cast_slice(grid.indices)),
            words: grid.indices.len() as u64,
            table: upload.values(grid.table),
            table_len: grid.table.len() as u64,
            res: grid.res,
            only: grid.only,
            bounds_min: grid.bounds.min.to_array(),
            bounds_max: grid.bounds.max.to_array(),
            scale: grid.scale,
            wide: grid.wide as u32,
        }
    }

    /// The grid these parameters describe, if any.
    ///
    /// # Safety
    /// `indices` and `table` must point to `words` initialised `u32`s and `table_len` `f32`s
    /// that stay valid and unchanged for `'a` (or `indices` be 0).
    #[inline]
    pub unsafe fn grid<'a>(&self) -> Option<MaterialGrid<'a>> {
        if self.indices == 0 {
            return None;
        }
        // SAFETY: the caller guarantees both address ranges.
        let (indices, table) = unsafe {
            (
                core::slice::from_raw_parts(self.indices as *const u32, self.words as usize),
                core::slice::from_raw_parts(self.table as *const f32, self.table_len as usize),
            )
        };
        Some(MaterialGrid {
            indices,
            res: self.res,
            bounds: Aabb::new(
                Vec3::from_array(self.bounds_min),
                Vec3::from_array(self.bounds_max),
            ),
            table,
            scale: self.scale,
            only: self.only,
            wide: self.wide != 0,
        })
    }
}
