//! A majorant grid: a coarse grid over the medium's box whose cells bound the extinction inside
//! them, so that delta and ratio tracking pay for the density where the ray is, not for the densest
//! voxel of the whole medium (pbrt-v4's `MajorantGrid` and `DDAMajorantIterator`, Pharr et al. 2023,
//! section 11.4.3; Szirmay-Kalos et al. 2011 for per-cell majorants).
//!
//! The cells tile the box uniformly, x fastest. A ray is walked through them with a 3D DDA
//! (Amanatides & Woo 1987) whose whole state is a cell index, the distance to the next crossing and
//! the distance between crossings per axis: a few scalars, no arrays.

use bytemuck::{Pod, Zeroable};

use core::ops::RangeInclusive;

use crate::grid::{Grid, GridLayout, BRICK};
use crate::sparse::{self, BLOCK_SAMPLES};
use crate::{Aabb, Ray, Vec3};

/// Per-cell upper bounds of the extinction over `bounds`.
#[derive(Clone, Copy, Debug)]
pub struct MajorantGrid<'a> {
    pub data: &'a [f32],
    pub res: [u32; 3],
    pub bounds: Aabb,
}

/// The part of a cell a point may be assigned to by the DDA although rounding puts it just outside:
/// each cell's bound covers its box grown by this fraction of a cell on every side.
pub(crate) const CELL_MARGIN: f32 = 0.01;

impl<'a> MajorantGrid<'a> {
    /// `data.len()` must be `res_x * res_y * res_z`, every resolution at least 1.
    pub fn new(data: &'a [f32], res: [u32; 3], bounds: Aabb) -> Self {
        assert!(res.iter().all(|&r| r >= 1), "empty majorant grid");
        assert_eq!(
            data.len(),
            res[0] as usize * res[1] as usize * res[2] as usize,
            "majorant grid data does not match its resolution"
        );
        Self { data, res, bounds }
    }

    /// The cells of a grid of `resolution` cells along the longest axis of `bounds`, the other axes
    /// in proportion (at least one cell each).
    pub fn resolution_for(bounds: Aabb, resolution: u32) -> [u32; 3] {
        let extent = bounds.extent();
        let longest = extent.max_element();
        let along = |e: f32| {
            if longest > 0.0 {
                libm::ceilf(resolution as f32 * e / longest).clamp(1.0, resolution as f32) as u32
            } else {
                1
            }
        };
        [along(extent.x), along(extent.y), along(extent.z)]
    }

    /// The majorant of cell `(x, y, z)`.
    #[inline]
    pub fn at(&self, x: u32, y: u32, z: u32) -> f32 {
        self.data[((z * self.res[1] + y) * self.res[0] + x) as usize]
    }

    /// The majorant of the cell around `p` (the nearest cell for a point outside the box).
    pub fn at_point(&self, p: Vec3) -> f32 {
        let q = (p - self.bounds.min) / self.bounds.extent();
        let cell = |a: usize| {
            libm::floorf(q[a] * self.res[a] as f32).clamp(0.0, (self.res[a] - 1) as f32) as u32
        };
        self.at(cell(0), cell(1), cell(2))
    }

    /// The world-space box of cell `(x, y, z)`.
    pub fn cell_bounds(&self, x: u32, y: u32, z: u32) -> Aabb {
        let extent = self.bounds.extent();
        let corner = |i: [u32; 3]| {
            self.bounds.min
                + extent
                    * Vec3::new(
                        i[0] as f32 / self.res[0] as f32,
                        i[1] as f32 / self.res[1] as f32,
                        i[2] as f32 / self.res[2] as f32,
                    )
        };
        Aabb::new(corner([x, y, z]), corner([x + 1, y + 1, z + 1]))
    }
}

/// Fills `out` (one value per cell of a `res` grid over `bounds`, x fastest) with the largest
/// extinction `scale * density` that a trilinear lookup can return inside each cell.
///
/// A lookup interpolates the two samples around its index coordinate on every axis, clamped so
/// that it never exceeds the larger of them ([`Grid::lookup`]); the bound of a cell is therefore the
/// largest sample whose index lies within one of the cell's index range, grown by
/// [`CELL_MARGIN`]. Outside the density grid's box the extinction is zero, below any bound.
/// Conservative by construction: every index a lookup inside the cell can read is in the range.
pub fn build_majorants(
    density: &Grid<'_, 1>,
    scale: f32,
    bounds: Aabb,
    res: [u32; 3],
    out: &mut [f32],
) {
    assert_eq!(
        out.len(),
        res[0] as usize * res[1] as usize * res[2] as usize,
        "majorant grid data does not match its resolution"
    );
    let cells = MajorantGrid {
        data: &[],
        res,
        bounds,
    };
    let cell = bounds.extent() / Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
    let last = [
        density.res[0] as i64 - 1,
        density.res[1] as i64 - 1,
        density.res[2] as i64 - 1,
    ];
    let mut last_read = SlotMax::NONE;
    for (i, bound) in out.iter_mut().enumerate() {
        let x = (i % res[0] as usize) as u32;
        let y = ((i / res[0] as usize) % res[1] as usize) as u32;
        let z = (i / (res[0] as usize * res[1] as usize)) as u32;
        let b = cells.cell_bounds(x, y, z);
        let lo = density
            .mapping
            .to_index_space(b.min - cell * CELL_MARGIN)
            .floor();
        let hi = density
            .mapping
            .to_index_space(b.max + cell * CELL_MARGIN)
            .floor();
        let range = |a: usize| {
            let from = (lo[a] as i64 - 1).clamp(0, last[a]);
            let to = (hi[a] as i64 + 1).clamp(0, last[a]);
            from as u32..=to as u32
        };
        let max = match density.layout {
            GridLayout::Sparse => {
                sparse_max(density, [range(0), range(1), range(2)], &mut last_read)
            }
            _ => {
                let mut max = 0.0f32;
                for sz in range(2) {
                    for sy in range(1) {
                        for sx in range(0) {
                            max = max.max(density.sample(sx, sy, sz)[0]);
                        }
                    }
                }
                max
            }
        };
        *bound = scale * max;
    }
}

/// The last stored brick [`sparse_max`] read: its slot, its largest sample, and whether all
/// its samples are that one value (a VDB tile's brick, shared by every brick the tile covers).
#[derive(Clone, Copy)]
struct SlotMax {
    slot: u32,
    max: f32,
    uniform: bool,
}

impl SlotMax {
    const NONE: Self = Self {
        slot: u32::MAX,
        max: 0.0,
        uniform: false,
    };
}

/// The largest sample of a [`GridLayout::Sparse`] grid in the index ranges `ranges`, block by
/// block of the brick table ([`crate::sparse`]): a uniform block (the background, a VDB tile's
/// region, up to 4096^3 voxels) is one stored brick read once per run of cells that share it
/// (`last`), not once per brick it stands for (billions of reads of one brick for a 4096^3 tile);
/// a mixed block is read brick by brick, the background brick (slot 0, one value) once, not
/// once per sample. The same maximum as reading every sample, so a sparse grid's majorants
/// equal its dense copy's.
fn sparse_max(density: &Grid<'_, 1>, ranges: [RangeInclusive<u32>; 3], last: &mut SlotMax) -> f32 {
    let blocks = |r: &RangeInclusive<u32>| (r.start() / BLOCK_SAMPLES)..=(r.end() / BLOCK_SAMPLES);
    let part = |r: &RangeInclusive<u32>, k: u32| {
        let o = k * BLOCK_SAMPLES;
        (*r.start()).max(o)..=(*r.end()).min(o + (BLOCK_SAMPLES - 1))
    };
    let mut max = 0.0f32;
    let [rx, ry, rz] = &ranges;
    for kz in blocks(rz) {
        for ky in blocks(ry) {
            for kx in blocks(rx) {
                let parts = [part(rx, kx), part(ry, ky), part(rz, kz)];
                let m = match sparse::block(density.data, density.res, [kx, ky, kz]) {
                    sparse::Block::Uniform(slot) => shared_brick_max(density, slot, parts, last),
                    sparse::Block::Mixed => bricks_max(density, parts, last),
                };
                max = max.max(m);
            }
        }
    }
    max
}

/// [`SlotMax`] of the stored brick `slot`, from `last` if that is the brick it read last.
fn slot_max(density: &Grid<'_, 1>, slot: u32, last: &mut SlotMax) -> SlotMax {
    if slot != last.slot {
        let brick = stored_brick(density, slot);
        *last = SlotMax {
            slot,
            max: brick.iter().fold(0.0f32, |m, &v| m.max(v)),
            uniform: brick.iter().all(|&v| v == brick[0]),
        };
    }
    *last
}

/// The samples of stored brick `slot` of a sparse grid.
fn stored_brick<'a>(density: &Grid<'a, 1>, slot: u32) -> &'a [f32] {
    let samples = (BRICK * BRICK * BRICK) as usize;
    &density.data[slot as usize * samples..][..samples]
}

/// The largest sample in `ranges` (inside one block) where every brick is stored brick `slot`:
/// per axis, the places inside a brick that the range covers in any of its bricks (all 8 where
/// it spans 8 samples or more).
fn shared_brick_max(
    density: &Grid<'_, 1>,
    slot: u32,
    ranges: [RangeInclusive<u32>; 3],
    last: &mut SlotMax,
) -> f32 {
    if slot == 0 {
        // The background brick is one value.
        return density.data[0];
    }
    let brick = slot_max(density, slot, last);
    if brick.uniform {
        return brick.max;
    }
    let covered = |r: &RangeInclusive<u32>| -> [bool; BRICK as usize] {
        let mut c = [r.end() - r.start() + 1 >= BRICK; BRICK as usize];
        for i in r.clone().take(BRICK as usize) {
            c[(i % BRICK) as usize] = true;
        }
        c
    };
    let [cx, cy, cz] = ranges.each_ref().map(covered);
    if [cx, cy, cz].iter().all(|c| c.iter().all(|&v| v)) {
        return brick.max;
    }
    let samples = stored_brick(density, slot);
    let mut max = 0.0f32;
    for (z, _) in cz.iter().enumerate().filter(|(_, &c)| c) {
        for (y, _) in cy.iter().enumerate().filter(|(_, &c)| c) {
            let row = (z * BRICK as usize + y) * BRICK as usize;
            for (x, _) in cx.iter().enumerate().filter(|(_, &c)| c) {
                max = max.max(samples[row + x]);
            }
        }
    }
    max
}

/// The largest sample in `ranges` (inside one mixed block), brick by brick: one table lookup
/// per brick, not per sample, and one pass over a brick's 512 values per run of bricks that
/// share it.
fn bricks_max(density: &Grid<'_, 1>, ranges: [RangeInclusive<u32>; 3], last: &mut SlotMax) -> f32 {
    let [rx, ry, rz] = ranges;
    let bricks = |r: &RangeInclusive<u32>| (r.start() / BRICK)..=(r.end() / BRICK);
    let clip = |r: &RangeInclusive<u32>, o: u32| {
        (*r.start()).max(o) - o..=(*r.end()).min(o + BRICK - 1) - o
    };
    let whole = |r: &RangeInclusive<u32>| *r.start() == 0 && *r.end() == BRICK - 1;
    let mut max = 0.0f32;
    let background = density.data[0];
    for bz in bricks(&rz) {
        for by in bricks(&ry) {
            for bx in bricks(&rx) {
                let (x0, y0, z0) = (bx * BRICK, by * BRICK, bz * BRICK);
                // Slot 0 (the background brick) is one value: a single read stands for all.
                let slot = density.sample_slot(x0, y0, z0);
                if slot == 0 {
                    max = max.max(background);
                    continue;
                }
                let brick = slot_max(density, slot, last);
                let (cx, cy, cz) = (clip(&rx, x0), clip(&ry, y0), clip(&rz, z0));
                // Most bricks lie inside the cell's range; a uniform brick's every part has its
                // one value.
                if (whole(&cx) && whole(&cy) && whole(&cz)) || brick.uniform {
                    max = max.max(brick.max);
                    continue;
                }
                let samples = stored_brick(density, slot);
                for z in cz {
                    for y in cy.clone() {
                        let row = ((z * BRICK + y) * BRICK) as usize;
                        for x in cx.clone() {
                            max = max.max(samples[row + x as usize]);
                        }
                    }
                }
            }
        }
    }
    max
}

/// Where a ray is in the majorant grid: the current cell and, per axis, the distance along the ray
/// to the next cell boundary and between boundaries. Named scalars, not arrays: a GPU keeps them in
/// registers, where an array indexed by a computed axis would go to local memory.
#[derive(Clone, Copy, Debug)]
pub struct Dda {
    cell: [i32; 3],
    next_crossing: Vec3,
    delta: Vec3,
}

/// One axis of [`Dda::new`]: the cell of grid coordinate `origin` (clamped into `0..res`), the
/// distance to its boundary along the direction `dir` (grid units per unit of `t`) and between
/// boundaries; infinite along an axis the ray does not move on.
#[inline(always)]
fn start_axis(origin: f32, dir: f32, res: f32) -> (i32, f32, f32) {
    // Clamped first, then truncated: the same cell as `floor` then clamp, in one conversion
    // instead of libm's software `floorf` (a GPU has no `floorf`); a NaN origin, whose cell
    // becomes 0 instead of NaN, leaves the crossing NaN either way.
    let cell = crate::math::floor_non_negative(origin.clamp(0.0, res - 1.0));
    if dir > 0.0 {
        (cell as i32, (cell + 1.0 - origin) / dir, 1.0 / dir)
    } else if dir < 0.0 {
        (cell as i32, (cell - origin) / dir, -1.0 / dir)
    } else {
        (cell as i32, f32::INFINITY, f32::INFINITY)
    }
}

/// Moves one axis of a [`Dda`] to its next cell; where that would leave the grid the ray stays in
/// its cell for ever (the crossing becomes infinite).
#[inline(always)]
fn step_axis(cell: &mut i32, next_crossing: &mut f32, delta: f32, dir: f32, res: u32) {
    let next = *cell + if dir > 0.0 { 1 } else { -1 };
    if next < 0 || next >= res as i32 {
        *next_crossing = f32::INFINITY;
    } else {
        *cell = next;
        *next_crossing += delta;
    }
}

impl Dda {
    /// Starts at `ray.origin`, which lies in (or, by rounding, on the edge of) the grid's box; an
    /// origin just outside is clamped into the nearest cell.
    #[inline]
    pub fn new(grid: &MajorantGrid<'_>, ray: &Ray) -> Self {
        let res = Vec3::new(grid.res[0] as f32, grid.res[1] as f32, grid.res[2] as f32);
        let to_grid = res / grid.bounds.extent();
        let origin = (ray.origin - grid.bounds.min) * to_grid;
        let dir = ray.dir * to_grid;
        let (cx, nx, dx) = start_axis(origin.x, dir.x, res.x);
        let (cy, ny, dy) = start_axis(origin.y, dir.y, res.y);
        let (cz, nz, dz) = start_axis(origin.z, dir.z, res.z);
        Self {
            cell: [cx, cy, cz],
            next_crossing: Vec3::new(nx, ny, nz),
            delta: Vec3::new(dx, dy, dz),
        }
    }

    /// The majorant of the current cell and the distance at which the ray leaves it (infinite in
    /// the last cell the ray reaches: the caller's own end, the box's exit, ends the walk there).
    #[inline]
    pub fn segment(&self, grid: &MajorantGrid<'_>) -> (f32, f32) {
        let [x, y, z] = self.cell;
        (
            grid.at(x as u32, y as u32, z as u32),
            self.next_crossing.min_element(),
        )
    }

    /// The index of the current cell in the grid's data (x fastest).
    #[inline]
    pub fn cell_index(&self, grid: &MajorantGrid<'_>) -> usize {
        let [x, y, z] = self.cell;
        ((z as u32 * grid.res[1] + y as u32) * grid.res[0] + x as u32) as usize
    }

    /// Moves into the next cell along the ray, across the nearest boundary.
    #[inline]
    pub fn advance(&mut self, grid: &MajorantGrid<'_>, dir: Vec3) {
        let n = self.next_crossing;
        let [cx, cy, cz] = &mut self.cell;
        if n.x <= n.y && n.x <= n.z {
            step_axis(
                cx,
                &mut self.next_crossing.x,
                self.delta.x,
                dir.x,
                grid.res[0],
            );
        } else if n.y <= n.z {
            step_axis(
                cy,
                &mut self.next_crossing.y,
                self.delta.y,
                dir.y,
                grid.res[1],
            );
        } else {
            step_axis(
                cz,
                &mut self.next_crossing.z,
                self.delta.z,
                dir.z,
                grid.res[2],
            );
        }
    }
}

/// Device parameters of an optional majorant grid: `len` 0 means none (one global majorant).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MajorantGridParams {
    pub data: u64,
    pub len: u64,
    pub res: [u32; 3],
    pub padding: u32,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
}

impl MajorantGridParams {
    pub fn new(grid: Option<&MajorantGrid<'_>>, upload: &mut crate::abi::Upload<'_>) -> Self {
        match grid {
            None => Self::default(),
            Some(g) => Self {
                data: upload.values(g.data),
                len: g.data.len() as u64,
                res: g.res,
                padding: 0,
                bounds_min: g.bounds.min.to_array(),
                bounds_max: g.bounds.max.to_array(),
            },
        }
    }

    /// # Safety
    /// Unless `len` is 0, `data` must point to `len` `f32` values, valid and unchanged for `'a`,
    /// and `len` must equal `res_x * res_y * res_z`.
    #[inline]
    pub unsafe fn grid<'a>(&self) -> Option<MajorantGrid<'a>> {
        if self.len == 0 {
            return None;
        }
        Some(MajorantGrid {
            // SAFETY: the caller guarantees the address range.
            data: unsafe {
                core::slice::from_raw_parts(self.data as *const f32, self.len as usize)
            },
            res: self.res,
            bounds: Aabb::new(
                Vec3::from_array(self.bounds_min),
                Vec3::from_array(self.bounds_max),
            ),
        })
    }
}
