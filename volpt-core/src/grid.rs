//! Dense 3D grids with trilinear (or nearest-sample) reconstruction.

use crate::{Aabb, Vec3};

/// [`crate::math::floor_non_negative`] per component.
#[inline(always)]
fn floor_non_negative(q: Vec3) -> Vec3 {
    use crate::math::floor_non_negative as floor;
    Vec3::new(floor(q.x), floor(q.y), floor(q.z))
}

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

/// How a grid's samples are ordered in memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GridLayout {
    /// x fastest: sample `(x, y, z)` at `((z * res_y + y) * res_x + x) * C`.
    #[default]
    Dense,
    /// Bricks of [`BRICK`]^3 samples, each stored contiguously (x fastest inside a brick), the
    /// bricks themselves x fastest. The 8 corners of a lookup lie in one brick (rarely 2 to 8),
    /// i.e. in a few 2 KiB blocks instead of 4 rows of planes `res_x * res_y` apart: a GPU reading
    /// the grid over PCIe (zero-copy, managed memory) fetches fewer, fuller lines.
    /// Axes that are not a multiple of [`BRICK`] are padded; padding is never read.
    Bricked,
    /// Only the bricks that hold something: a sparse volume (a VDB's active 8^3 leaves and its
    /// tiles) without a dense copy of its box. `data` is the stored bricks, each [`BRICK`]^3
    /// samples laid out as in [`GridLayout::Bricked`], followed by a two-level *brick table*
    /// ([`crate::sparse`]) that gives every brick of the box the slot of the stored brick it
    /// reads. Slot 0 is the background brick, one value everywhere; a uniform region (empty, or a
    /// tile) costs one table entry per 128^3 block, and reads like any other region, so the lookup
    /// has no extra branch ([`Grid::sparse`]). The GPU's kernels do not read this table: they
    /// read its flat copy, [`GridLayout::SparseFlat`].
    Sparse,
    /// A sparse grid's stored bricks followed by a one-level table, the slot of every brick of
    /// the box ([`crate::sparse::flatten`]): one dependent read per corner where the two-level
    /// table takes two. What a GPU renderer uploads a [`GridLayout::Sparse`] grid as.
    SparseFlat,
}

/// Samples along each edge of a brick of [`GridLayout::Bricked`].
pub const BRICK: u32 = 8;
const BRICK_SHIFT: u32 = BRICK.trailing_zeros();

impl GridLayout {
    /// Values a grid of `res` samples of `channels` channels takes in this layout (with its
    /// padding), or `None` if that does not fit in `u64` or, for [`GridLayout::Sparse`], depends
    /// on how many bricks are stored.
    pub fn values(self, res: [u32; 3], channels: u32) -> Option<u64> {
        let samples = match self {
            GridLayout::Dense => res.map(u64::from),
            GridLayout::Bricked => res.map(|r| u64::from(r.div_ceil(BRICK)) * u64::from(BRICK)),
            GridLayout::Sparse | GridLayout::SparseFlat => return None,
        };
        samples
            .iter()
            .try_fold(u64::from(channels), |acc, &r| acc.checked_mul(r))
    }

    /// The sample index (before multiplying by the channel count) of `(x, y, z)` in a grid of
    /// `res` samples. Arithmetic is `u32`, as the lookup's: a grid's padded sample count must be
    /// below 2^32 ([`GridLayout::values`]). A sparse grid's index depends on its brick table:
    /// this is its index in the box's bricked layout, and [`Grid::sample`] reads it.
    #[inline]
    pub fn index(self, res: [u32; 3], x: u32, y: u32, z: u32) -> u32 {
        match self {
            GridLayout::Dense => dense_index(res, x, y, z),
            GridLayout::Bricked | GridLayout::Sparse | GridLayout::SparseFlat => {
                bricked_index(res, x, y, z)
            }
        }
    }

    /// The layout's number in [`crate::abi::GridParams`] (any unknown number reads as dense).
    pub fn to_u32(self) -> u32 {
        match self {
            GridLayout::Dense => 0,
            GridLayout::Bricked => 1,
            GridLayout::Sparse => 2,
            GridLayout::SparseFlat => 3,
        }
    }

    pub fn from_u32(n: u32) -> Self {
        match n {
            1 => GridLayout::Bricked,
            2 => GridLayout::Sparse,
            3 => GridLayout::SparseFlat,
            _ => GridLayout::Dense,
        }
    }
}

#[inline]
fn dense_index(res: [u32; 3], x: u32, y: u32, z: u32) -> u32 {
    (z * res[1] + y) * res[0] + x
}

#[inline]
fn bricked_index(res: [u32; 3], x: u32, y: u32, z: u32) -> u32 {
    let bricks_x = (res[0] + BRICK - 1) >> BRICK_SHIFT;
    let bricks_y = (res[1] + BRICK - 1) >> BRICK_SHIFT;
    let brick =
        ((z >> BRICK_SHIFT) * bricks_y + (y >> BRICK_SHIFT)) * bricks_x + (x >> BRICK_SHIFT);
    let mask = BRICK - 1;
    let inner = (((z & mask) << BRICK_SHIFT) + (y & mask)) << BRICK_SHIFT | (x & mask);
    (brick << (3 * BRICK_SHIFT)) | inner
}

/// The sample index of `(x, y, z)` in a [`GridLayout::Sparse`] grid's `data`: the brick's slot
/// from the brick table ([`crate::sparse::slot`]), then the sample's place inside the brick.
/// `u32` like the other layouts: the stored samples must number below 2^32 (checked on the host).
#[inline(always)]
fn sparse_index(data: &[f32], res: [u32; 3], x: u32, y: u32, z: u32) -> u32 {
    let brick = [x >> BRICK_SHIFT, y >> BRICK_SHIFT, z >> BRICK_SHIFT];
    in_brick(crate::sparse::slot(data, res, brick), x, y, z)
}

/// [`sparse_index`] of a [`GridLayout::SparseFlat`] grid: the slot from the one-level table.
#[inline(always)]
fn flat_index(data: &[f32], res: [u32; 3], x: u32, y: u32, z: u32) -> u32 {
    let brick = [x >> BRICK_SHIFT, y >> BRICK_SHIFT, z >> BRICK_SHIFT];
    in_brick(crate::sparse::flat_slot(data, res, brick), x, y, z)
}

/// The sample index of `(x, y, z)` in stored brick `slot`.
#[inline(always)]
fn in_brick(slot: u32, x: u32, y: u32, z: u32) -> u32 {
    let mask = BRICK - 1;
    let inner = (((z & mask) << BRICK_SHIFT) + (y & mask)) << BRICK_SHIFT | (x & mask);
    (slot << (3 * BRICK_SHIFT)) | inner
}

/// How a grid reconstructs values between its samples (Mitsuba 3's `filter_type`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GridLookup {
    /// Trilinear interpolation of the eight samples around a point.
    #[default]
    Trilinear,
    /// The value of the nearest sample: one read instead of eight, a blockier field.
    Nearest,
    /// One of the eight samples around a point, chosen with probability equal to its trilinear
    /// weight ([`stochastic_corner`]): an unbiased estimate of `Trilinear`'s value for one read,
    /// where the reader supplies random bits ([`Grid::lookup_random`]); without them
    /// ([`Grid::lookup`]) it is `Trilinear`, the value it estimates.
    Stochastic,
}

/// A grid of `C`-channel samples, ordered as its [`GridLayout`] says (dense: x fastest,
/// `data[((z * res_y + y) * res_x + x) * C + c]`).
/// Borrowed, so that the same type wraps host memory and device memory.
#[derive(Clone, Copy, Debug)]
pub struct Grid<'a, const C: usize> {
    pub data: &'a [f32],
    pub res: [u32; 3],
    pub mapping: GridMapping,
    pub layout: GridLayout,
    pub lookup: GridLookup,
    /// A CUDA texture object holding the same samples, read by [`TextureTrilinear`] on a GPU
    /// (0 elsewhere: the CPU filters `data` as the texture unit would).
    pub texture: u64,
    /// What such a texture holds per sample.
    pub texel: TexelFormat,
}

impl<'a, const C: usize> Grid<'a, C> {
    /// A dense grid: `data.len()` must be `res_x * res_y * res_z * C`; lookups index within that.
    pub fn new(data: &'a [f32], res: [u32; 3], mapping: GridMapping) -> Self {
        Self::with_layout(data, res, mapping, GridLayout::Dense)
    }

    /// The same grid, reconstructed as `lookup` says.
    pub fn with_lookup(self, lookup: GridLookup) -> Self {
        Self { lookup, ..self }
    }

    /// A grid in `layout`: `data.len()` must be `layout.values(res, C)`.
    pub fn with_layout(
        data: &'a [f32],
        res: [u32; 3],
        mapping: GridMapping,
        layout: GridLayout,
    ) -> Self {
        assert_eq!(
            Some(data.len() as u64),
            layout.values(res, C as u32),
            "grid data does not match its resolution"
        );
        Self {
            data,
            res,
            mapping,
            layout,
            lookup: GridLookup::Trilinear,
            texture: 0,
            texel: TexelFormat::F32,
        }
    }

    /// A [`GridLayout::Sparse`] grid: `data` is whole bricks of `C`-channel samples (at least
    /// the background brick, slot 0) followed by the brick table ([`crate::sparse`]). Panics if
    /// `data` is not shaped so ([`crate::sparse::parts`]; the loaders check it and return errors
    /// first).
    pub fn sparse(data: &'a [f32], res: [u32; 3], mapping: GridMapping) -> Self {
        if let Err(e) = crate::sparse::parts(data, res, C as u32) {
            panic!("sparse grid data does not match its resolution: {e}");
        }
        Self {
            data,
            res,
            mapping,
            layout: GridLayout::Sparse,
            lookup: GridLookup::Trilinear,
            texture: 0,
            texel: TexelFormat::F32,
        }
    }

    /// The stored samples without a sparse grid's brick table (all of `data` otherwise).
    pub fn samples(&self) -> &'a [f32] {
        match self.layout {
            GridLayout::Sparse => &self.data[..crate::sparse::stored_values(self.data, self.res)],
            GridLayout::SparseFlat => {
                let table = crate::sparse::bricks(self.res).iter().product::<u32>() as usize;
                &self.data[..self.data.len() - table]
            }
            _ => self.data,
        }
    }

    /// The sample `(x, y, z)` (inside the grid) in any layout.
    pub fn sample(&self, x: u32, y: u32, z: u32) -> [f32; C] {
        let i = match self.layout {
            GridLayout::Sparse => sparse_index(self.data, self.res, x, y, z),
            GridLayout::SparseFlat => flat_index(self.data, self.res, x, y, z),
            layout => layout.index(self.res, x, y, z),
        } as usize
            * C;
        let mut v = [0.0; C];
        v.copy_from_slice(&self.data[i..i + C]);
        v
    }

    /// The slot of the brick holding sample `(x, y, z)` of a [`GridLayout::Sparse`] grid (0: the
    /// background brick).
    pub fn sample_slot(&self, x: u32, y: u32, z: u32) -> u32 {
        debug_assert_eq!(self.layout, GridLayout::Sparse);
        crate::sparse::slot(self.data, self.res, [x, y, z].map(|v| v >> BRICK_SHIFT))
    }

    /// The same grid, in a texture of `texel`s when read by [`TextureTrilinear`].
    pub fn with_texel(self, texel: TexelFormat) -> Self {
        Self { texel, ..self }
    }

    /// The value at `p`, reconstructed as [`Grid::lookup`] says: zero outside the grid's box, and
    /// the edge samples held constant between the outermost sample and the box's faces. Either
    /// reconstruction stays within the samples' range, so a majorant of the samples bounds it.
    ///
    /// Always inlined: on a GPU a call takes the grid, and with it the whole scene, by address,
    /// which moves the scene into local memory (a 456-byte stack frame per thread, 1.5x the time
    /// of cgg-logo on an H100).
    #[inline(always)]
    pub fn lookup(&self, p: Vec3) -> [f32; C] {
        // One branch per lookup, not per corner: each layout gets its own copy of the
        // interpolation, and the dense copy is exactly the code of a grid without layouts.
        match self.layout {
            GridLayout::Dense => self.interpolate(p, dense_index, self.lookup, None),
            GridLayout::Bricked => self.interpolate(p, bricked_index, self.lookup, None),
            // Not in the kernels: a GPU renderer uploads sparse grids flat, and this arm's
            // second table read cost every any-layout kernel registers (`crate::sparse`).
            #[cfg(not(target_arch = "nvptx64"))]
            GridLayout::Sparse => self.interpolate(
                p,
                |res, x, y, z| sparse_index(self.data, res, x, y, z),
                self.lookup,
                None,
            ),
            #[cfg(target_arch = "nvptx64")]
            GridLayout::Sparse => [0.0; C],
            GridLayout::SparseFlat => self.interpolate(
                p,
                |res, x, y, z| flat_index(self.data, res, x, y, z),
                self.lookup,
                None,
            ),
        }
    }

    /// [`Grid::lookup`], where a [`GridLookup::Stochastic`] grid reads the one sample that the
    /// low 39 bits of `bits` choose (random bits independent of everything else the caller
    /// draws); every other lookup ignores `bits` and is [`Grid::lookup`] bit for bit.
    #[inline(always)]
    pub fn lookup_random(&self, p: Vec3, bits: u64) -> [f32; C] {
        match self.layout {
            GridLayout::Dense => self.interpolate(p, dense_index, self.lookup, Some(bits)),
            GridLayout::Bricked => self.interpolate(p, bricked_index, self.lookup, Some(bits)),
            // Not in the kernels: a GPU renderer uploads sparse grids flat, and this arm's
            // second table read cost every any-layout kernel registers (`crate::sparse`).
            #[cfg(not(target_arch = "nvptx64"))]
            GridLayout::Sparse => self.interpolate(
                p,
                |res, x, y, z| sparse_index(self.data, res, x, y, z),
                self.lookup,
                Some(bits),
            ),
            #[cfg(target_arch = "nvptx64")]
            GridLayout::Sparse => [0.0; C],
            GridLayout::SparseFlat => self.interpolate(
                p,
                |res, x, y, z| flat_index(self.data, res, x, y, z),
                self.lookup,
                Some(bits),
            ),
        }
    }

    /// [`Grid::lookup`] of a dense grid with trilinear reconstruction, the grid's `layout` and
    /// `lookup` not read: the code a kernel needs when the variant fixes them ([`DenseTrilinear`]).
    #[inline(always)]
    pub fn lookup_dense_trilinear(&self, p: Vec3) -> [f32; C] {
        debug_assert!(self.layout == GridLayout::Dense && self.lookup == GridLookup::Trilinear);
        self.interpolate(p, dense_index, GridLookup::Trilinear, None)
    }

    /// [`Grid::lookup`] of a dense grid read nearest, without the other layouts' code.
    #[inline(always)]
    pub fn lookup_dense_nearest(&self, p: Vec3) -> [f32; C] {
        debug_assert!(self.layout == GridLayout::Dense);
        self.interpolate(p, dense_index, GridLookup::Nearest, None)
    }

    /// The index-space coordinates of the last sample along each axis.
    #[inline(always)]
    fn max_index(&self) -> Vec3 {
        Vec3::new(
            (self.res[0] - 1) as f32,
            (self.res[1] - 1) as f32,
            (self.res[2] - 1) as f32,
        )
    }

    #[inline(always)]
    fn interpolate<I>(&self, p: Vec3, index: I, lookup: GridLookup, bits: Option<u64>) -> [f32; C]
    where
        I: Fn([u32; 3], u32, u32, u32) -> u32,
    {
        if !self.mapping.bounds.contains(p) {
            return [0.0; C];
        }
        let at = |x: u32, y: u32, z: u32| {
            let i = index(self.res, x, y, z) as usize * C;
            let mut v = [0.0; C];
            v.copy_from_slice(&self.data[i..i + C]);
            v
        };
        let max_index = self.max_index();
        let q = self
            .mapping
            .to_index_space(p)
            .max(Vec3::ZERO)
            .min(max_index);
        match (lookup, bits) {
            (GridLookup::Nearest, _) => {
                let n = q.round();
                at(n.x as u32, n.y as u32, n.z as u32)
            }
            (GridLookup::Stochastic, Some(bits)) => {
                let [x, y, z] = stochastic_corner(q, max_index, self.res, bits);
                at(x, y, z)
            }
            _ => trilinear(q, max_index, self.res, at),
        }
    }
}

/// The cell corner a stochastic trilinear lookup at index-space `q` (in `[0, max_index]`) reads:
/// along each axis the upper sample with probability `f`, the fraction trilinear weighs it by,
/// independently (13 bits of `bits` per axis), so that corner `c` is read with probability equal
/// to its trilinear weight `prod f or (1 - f)`. Delta and ratio tracking use `sigma_t` only
/// through `sigma_t / majorant`, linearly, and the albedo scales the throughput linearly, so the
/// sample is an unbiased estimate of the trilinear value wherever it replaces it, and never above
/// the largest sample (Pharr, Wronski, Salvi, Fajardo 2024, "Filtering After Shading With
/// Stochastic Texture Filtering"). Each uniform is `(k + 0.5) / 2^13`: the probabilities are the
/// weights rounded to the nearest multiple of 2^-13 (the f32 weights themselves carry 2^-15 of
/// rounding at 256 samples per axis).
#[inline(always)]
pub fn stochastic_corner(q: Vec3, max_index: Vec3, res: [u32; 3], bits: u64) -> [u32; 3] {
    const STEPS: f32 = (1u32 << STOCHASTIC_BITS) as f32;
    const MASK: u64 = (1 << STOCHASTIC_BITS) - 1;
    // The same cell and fractions as `trilinear`.
    // `q` is clamped into [0, max_index]: truncation is its floor.
    let base = floor_non_negative(q).min((max_index - Vec3::ONE).max(Vec3::ZERO));
    let f = q - base;
    let axis = |base: f32, f: f32, shift: u32, res: u32| {
        let u = ((bits >> shift) & MASK) as f32 * (1.0 / STEPS) + 0.5 / STEPS;
        let lower = base as u32;
        if u < f {
            (lower + 1).min(res - 1)
        } else {
            lower
        }
    };
    [
        axis(base.x, f.x, 0, res[0]),
        axis(base.y, f.y, STOCHASTIC_BITS, res[1]),
        axis(base.z, f.z, 2 * STOCHASTIC_BITS, res[2]),
    ]
}

/// Random bits per axis of [`stochastic_corner`]: 3 x 13 = 39, the low bits of a 64-bit random
/// number whose top 24 bits make a uniform `f32` ([`crate::rng::Rng::next_f32`]).
const STOCHASTIC_BITS: u32 = 13;

/// How a grid medium reads its grids, fixed by the variant: a kernel then carries the code of
/// one layout and one reconstruction instead of a branch between four copies of the
/// interpolation at every read (8-9% of the time of cgg-logo and bucky on an H100,
/// `docs/strategies.md`).
pub trait GridReads: Copy + Default + core::fmt::Debug {
    /// The name of these reads in the composed name of a medium that reads this way
    /// ([`crate::abi::name`]).
    const NAME: &'static str;

    /// Where the uploader must put a grid read this way.
    const PLACEMENT: GridPlacement;

    fn lookup<const C: usize>(grid: &Grid<'_, C>, p: Vec3) -> [f32; C];

    /// [`GridReads::lookup`] with random `bits` for a [`GridLookup::Stochastic`] grid
    /// ([`Grid::lookup_random`]); reads that fix the lookup to trilinear ignore them.
    #[inline(always)]
    fn lookup_random<const C: usize>(grid: &Grid<'_, C>, p: Vec3, _bits: u64) -> [f32; C] {
        Self::lookup(grid, p)
    }
}

/// Where a device keeps a grid, as the kernels that read it need.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridPlacement {
    /// Dense samples in memory.
    Dense,
    /// Samples in memory in a layout of the uploader's choice (dense or bricked).
    AnyLayout,
    /// A 3D texture of the grid's [`Grid::texel`]s, filtered by the texture unit.
    Texture,
}

/// What a grid texture holds per sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TexelFormat {
    #[default]
    F32,
    /// IEEE half precision, each sample rounded toward zero ([`half_toward_zero`]): half the
    /// memory and bandwidth of `F32`, and never above the sample, so every majorant of the
    /// samples bounds the texels too.
    F16,
}

impl TexelFormat {
    /// The format's number in [`crate::abi::GridParams`] (any unknown number reads as `F32`).
    pub fn to_u32(self) -> u32 {
        match self {
            TexelFormat::F32 => 0,
            TexelFormat::F16 => 1,
        }
    }

    pub fn from_u32(n: u32) -> Self {
        match n {
            1 => TexelFormat::F16,
            _ => TexelFormat::F32,
        }
    }

    /// A sample as a texel of this format holds it.
    #[inline]
    pub fn texel(self, x: f32) -> f32 {
        match self {
            TexelFormat::F32 => x,
            TexelFormat::F16 => half_toward_zero(x),
        }
    }
}

/// The largest finite half-precision value.
pub const HALF_MAX: f32 = 65504.0;

/// `x` (finite, non-negative) rounded toward zero to a half-precision value, saturating at
/// [`HALF_MAX`]: the result converts to `f16` exactly. Half has 10 fraction bits to f32's 23 and
/// subnormals below 2^-14, spaced 2^-24.
pub fn half_toward_zero(x: f32) -> f32 {
    const HALF_MIN_NORMAL: f32 = 1.0 / 16384.0;
    const SUBNORMAL_STEPS: f32 = 16_777_216.0;
    if x >= HALF_MAX {
        HALF_MAX
    } else if x >= HALF_MIN_NORMAL {
        f32::from_bits(x.to_bits() & !((1 << 13) - 1))
    } else {
        // Exact: scaling by a power of two and truncating lose nothing in this range.
        libm::truncf(x * SUBNORMAL_STEPS) / SUBNORMAL_STEPS
    }
}

/// Dense samples, trilinear reconstruction: every scene's grids unless the description asks for
/// nearest-sample lookups or bricked storage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DenseTrilinear;

impl GridReads for DenseTrilinear {
    const NAME: &'static str = "dense_trilinear";
    const PLACEMENT: GridPlacement = GridPlacement::Dense;

    #[inline(always)]
    fn lookup<const C: usize>(grid: &Grid<'_, C>, p: Vec3) -> [f32; C] {
        grid.lookup_dense_trilinear(p)
    }
}

/// Whatever each grid's `layout` and `lookup` say, read at every lookup.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AnyLayout;

impl GridReads for AnyLayout {
    const NAME: &'static str = "any_layout";
    const PLACEMENT: GridPlacement = GridPlacement::AnyLayout;

    #[inline(always)]
    fn lookup<const C: usize>(grid: &Grid<'_, C>, p: Vec3) -> [f32; C] {
        grid.lookup(p)
    }

    #[inline(always)]
    fn lookup_random<const C: usize>(grid: &Grid<'_, C>, p: Vec3, bits: u64) -> [f32; C] {
        grid.lookup_random(p, bits)
    }
}

/// Dense samples in a 3D texture, filtered trilinearly by the GPU's texture unit: one `tex`
/// instruction instead of eight loads and seven interpolations. The unit's weights have 8
/// fractional bits (CUDA C++ Programming Guide, "Texture Fetching", linear filtering), so a
/// lookup differs from [`DenseTrilinear`]'s by up to 1/512 of the span of a cell's samples per
/// axis: an accuracy/time knob (`docs/heterogeneous.md`), never the default. The CPU computes
/// the documented filter from the samples ([`Grid::lookup_texture_filter`]); the GPU's differs
/// from it by about a weight step at most (not bit for bit), measured by `volpt selftest`.
///
/// A [`GridLookup::Stochastic`] grid is read through the same texture, one texel at the centre of
/// the chosen sample (where the filter's weights are exactly 1 and 0): the texture path's memory
/// access with exact samples, so the CPU's software read of the same sample agrees bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TextureTrilinear;

impl GridReads for TextureTrilinear {
    const NAME: &'static str = "texture_trilinear";
    const PLACEMENT: GridPlacement = GridPlacement::Texture;

    #[inline(always)]
    fn lookup<const C: usize>(grid: &Grid<'_, C>, p: Vec3) -> [f32; C] {
        #[cfg(target_arch = "nvptx64")]
        {
            if !grid.mapping.bounds.contains(p) {
                return [0.0; C];
            }
            // Texel `i` covers texture coordinates [i, i + 1): its sample sits at i + 0.5.
            let t = texture_fetch(grid.texture, grid.mapping.to_index_space(p) + 0.5);
            let mut v = [0.0; C];
            v.copy_from_slice(&t[..C]);
            v
        }
        #[cfg(not(target_arch = "nvptx64"))]
        {
            if grid.lookup == GridLookup::Stochastic {
                // The value a stochastic lookup estimates (the GPU has no samples to compute it).
                return grid.lookup(p);
            }
            grid.lookup_texture_filter(p)
        }
    }

    #[inline(always)]
    fn lookup_random<const C: usize>(grid: &Grid<'_, C>, p: Vec3, bits: u64) -> [f32; C] {
        if grid.lookup != GridLookup::Stochastic {
            return Self::lookup(grid, p);
        }
        #[cfg(target_arch = "nvptx64")]
        {
            if !grid.mapping.bounds.contains(p) {
                return [0.0; C];
            }
            let max_index = grid.max_index();
            let q = grid
                .mapping
                .to_index_space(p)
                .max(Vec3::ZERO)
                .min(max_index);
            let [x, y, z] = stochastic_corner(q, max_index, grid.res, bits);
            let centre = Vec3::new(x as f32, y as f32, z as f32) + 0.5;
            let t = texture_fetch(grid.texture, centre);
            let mut v = [0.0; C];
            v.copy_from_slice(&t[..C]);
            v
        }
        #[cfg(not(target_arch = "nvptx64"))]
        {
            grid.lookup_random(p, bits)
        }
    }
}

/// `tex.3d.v4.f32.f32` of texture object `texture` at unnormalised coordinates `u`.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
fn texture_fetch(texture: u64, u: Vec3) -> [f32; 4] {
    let (r, g, b, a): (f32, f32, f32, f32);
    // SAFETY: reads through a texture object the host created for this grid and keeps alive
    // for the launch ([`crate::abi::Uploader::grid`]); no memory is written.
    unsafe {
        core::arch::asm!(
            "tex.3d.v4.f32.f32 {{{r}, {g}, {b}, {a}}}, [{t}, {{{x}, {y}, {z}, {z}}}];",
            r = out(reg32) r, g = out(reg32) g, b = out(reg32) b, a = out(reg32) a,
            t = in(reg64) texture, x = in(reg32) u.x, y = in(reg32) u.y, z = in(reg32) u.z,
            options(pure, readonly, nostack)
        );
    }
    [r, g, b, a]
}

impl<const C: usize> Grid<'_, C> {
    /// [`TextureTrilinear`]'s lookup as the texture unit computes it, from the dense samples as
    /// [`Grid::texel`]s: each weight rounded to 8 fractional bits, the edge samples repeated
    /// beyond the outermost ones (clamp addressing), zero outside the box.
    pub fn lookup_texture_filter(&self, p: Vec3) -> [f32; C] {
        debug_assert!(self.layout == GridLayout::Dense);
        if !self.mapping.bounds.contains(p) {
            return [0.0; C];
        }
        // The coordinate the kernel hands the texture unit; the unit takes the half texel off
        // again in its own fixed point (f64 holds the difference exactly). The unit's weights
        // are not all rounded as here: `volpt selftest` measures how far its lookups are from
        // this filter (docs/heterogeneous.md).
        let u = self.mapping.to_index_space(p) + 0.5;
        let max_index = self.max_index();
        let split = |u: f32| {
            let x = f64::from(u) - 0.5;
            let base = libm::floor(x);
            let steps = f64::from(TEXTURE_WEIGHT_STEPS);
            (
                base as f32,
                (libm::round((x - base) * steps) / steps) as f32,
            )
        };
        let ((bx, fx), (by, fy), (bz, fz)) = (split(u.x), split(u.y), split(u.z));
        let (base, f) = (Vec3::new(bx, by, bz), Vec3::new(fx, fy, fz));
        let at = |x: f32, y: f32, z: f32| {
            let clamped = Vec3::new(x, y, z).max(Vec3::ZERO).min(max_index);
            let i = dense_index(
                self.res,
                clamped.x as u32,
                clamped.y as u32,
                clamped.z as u32,
            ) as usize
                * C;
            let mut v = [0.0; C];
            for (v, &sample) in v.iter_mut().zip(&self.data[i..i + C]) {
                *v = self.texel.texel(sample);
            }
            v
        };
        blend_corners(base.to_array(), (base + Vec3::ONE).to_array(), f, at)
    }
}

/// The texture unit's filter weights are multiples of 1/256.
const TEXTURE_WEIGHT_STEPS: f32 = 256.0;

/// `a + (b - a) t` per channel, clamped to `max(a, b)` (rounding can carry it one ulp above:
/// no lookup may exceed the largest sample, which the majorant of delta tracking relies on).
#[inline(always)]
fn lerp<const C: usize>(a: [f32; C], b: [f32; C], t: f32) -> [f32; C] {
    let mut r = [0.0; C];
    for c in 0..C {
        r[c] = (a[c] + (b[c] - a[c]) * t).min(a[c].max(b[c]));
    }
    r
}

/// Trilinear interpolation around index-space `q`, which lies in `[0, max_index]`, of the samples
/// `at(x, y, z)` of a grid of `res` samples.
#[inline(always)]
fn trilinear<const C: usize>(
    q: Vec3,
    max_index: Vec3,
    res: [u32; 3],
    at: impl Fn(u32, u32, u32) -> [f32; C],
) -> [f32; C] {
    // `q` is clamped into [0, max_index]: truncation is its floor.
    let base = floor_non_negative(q).min((max_index - Vec3::ONE).max(Vec3::ZERO));
    let f = q - base;
    let (x0, y0, z0) = (base.x as u32, base.y as u32, base.z as u32);
    let x1 = (x0 + 1).min(res[0] - 1);
    let y1 = (y0 + 1).min(res[1] - 1);
    let z1 = (z0 + 1).min(res[2] - 1);
    blend_corners([x0, y0, z0], [x1, y1, z1], f, at)
}

/// The samples `at` the eight corners `lo`/`hi` of a cell, blended with weights `f` per axis:
/// along x, then y, then z (the one order every backend and both filters use).
#[inline(always)]
fn blend_corners<T: Copy, const C: usize>(
    [x0, y0, z0]: [T; 3],
    [x1, y1, z1]: [T; 3],
    f: Vec3,
    at: impl Fn(T, T, T) -> [f32; C],
) -> [f32; C] {
    let c00 = lerp(at(x0, y0, z0), at(x1, y0, z0), f.x);
    let c10 = lerp(at(x0, y1, z0), at(x1, y1, z0), f.x);
    let c01 = lerp(at(x0, y0, z1), at(x1, y0, z1), f.x);
    let c11 = lerp(at(x0, y1, z1), at(x1, y1, z1), f.x);
    lerp(lerp(c00, c10, f.y), lerp(c01, c11, f.y), f.z)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec;
    use std::vec::Vec;

    use super::*;

    /// The bricked form of dense samples, written with the layout's own index: what a host
    /// uploader does (volpt-gpu-mem), here only to test the lookup.
    fn brick<const C: usize>(dense: &[f32], res: [u32; 3]) -> Vec<f32> {
        let len = GridLayout::Bricked.values(res, C as u32).unwrap() as usize;
        let mut out = vec![0.0; len];
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    let from = GridLayout::Dense.index(res, x, y, z) as usize * C;
                    let to = GridLayout::Bricked.index(res, x, y, z) as usize * C;
                    out[to..to + C].copy_from_slice(&dense[from..from + C]);
                }
            }
        }
        out
    }

    /// A small counter-based generator, so that the test needs no dependency.
    fn hash(i: u32) -> f32 {
        let mut h = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
        h ^= h >> 15;
        h = h.wrapping_mul(0x2C1B_3C6D);
        h ^= h >> 12;
        (h >> 8) as f32 / (1 << 24) as f32
    }

    /// Grid shapes for the bricked layout: whole and partial bricks, one sample, a long line, and
    /// a resolution of whole bricks along x (and along y) under more than one brick across the
    /// other axes, where a miscounted number of bricks per row (or per slice) moves later
    /// bricks.
    const SHAPES: [[u32; 3]; 9] = [
        [1, 1, 1],
        [8, 8, 8],
        [9, 8, 17],
        [13, 7, 5],
        [2048, 1, 1],
        [3, 16, 24],
        [17, 17, 17],
        [16, 9, 9],
        [9, 15, 9],
    ];

    #[test]
    fn bricked_indices_are_a_permutation_into_the_padded_grid() {
        for res in SHAPES {
            let len = GridLayout::Bricked.values(res, 1).unwrap() as usize;
            let mut seen = vec![false; len];
            for z in 0..res[2] {
                for y in 0..res[1] {
                    for x in 0..res[0] {
                        let i = GridLayout::Bricked.index(res, x, y, z) as usize;
                        assert!(!seen[i], "{res:?}: ({x}, {y}, {z}) collides at {i}");
                        seen[i] = true;
                    }
                }
            }
            let padded: u64 = res.iter().map(|&r| u64::from(r.div_ceil(8) * 8)).product();
            assert_eq!(len as u64, padded);
        }
    }

    #[test]
    fn a_brick_is_contiguous_and_x_fastest() {
        let res = [20, 12, 9];
        // The second brick along x starts right after the first brick's 512 samples.
        assert_eq!(GridLayout::Bricked.index(res, 8, 0, 0), 512);
        assert_eq!(GridLayout::Bricked.index(res, 1, 0, 0), 1);
        assert_eq!(GridLayout::Bricked.index(res, 0, 1, 0), 8);
        assert_eq!(GridLayout::Bricked.index(res, 0, 0, 1), 64);
        // 3 bricks along x, 2 along y: brick (0, 0, 1) is the 6th.
        assert_eq!(GridLayout::Bricked.index(res, 0, 0, 8), 6 * 512);
        assert_eq!(GridLayout::Dense.index(res, 3, 2, 1), (12 + 2) * 20 + 3);
    }

    fn lookups_match<const C: usize>(res: [u32; 3], mapping: GridMapping) {
        let n = res.iter().product::<u32>() as usize * C;
        let dense: Vec<f32> = (0..n as u32).map(hash).collect();
        let bricked = brick::<C>(&dense, res);
        let a = Grid::<C>::new(&dense, res, mapping);
        let b = Grid::<C>::with_layout(&bricked, res, mapping, GridLayout::Bricked);
        let (min, extent) = (mapping.bounds.min, mapping.bounds.extent());
        for i in 0..4000u32 {
            // Points inside, on and slightly outside the box.
            let u = Vec3::new(hash(3 * i), hash(3 * i + 1), hash(3 * i + 2)) * 1.1 - 0.05;
            let p = min + u * extent;
            let (x, y) = (a.lookup(p), b.lookup(p));
            for c in 0..C {
                assert_eq!(x[c].to_bits(), y[c].to_bits(), "{res:?} at {p:?}");
            }
        }
    }

    /// `stored` bricks followed by the brick table that gives brick `i` of the box (x fastest)
    /// slot `slots[i]`.
    fn with_table(mut stored: Vec<f32>, res: [u32; 3], slots: &[u32]) -> Vec<f32> {
        crate::sparse::BrickTable::from_slots(res, slots).append_to(&mut stored);
        stored
    }

    /// The sparse form of dense samples: bricks whose samples are all zero point at the
    /// background brick (slot 0, zeros), the others are stored in order.
    fn sparsify<const C: usize>(dense: &[f32], res: [u32; 3]) -> (Vec<f32>, usize) {
        let bricked = brick::<C>(dense, res);
        let size = 512 * C;
        let mut stored = vec![0.0; size];
        let mut table = Vec::new();
        for b in bricked.chunks_exact(size) {
            if b.iter().all(|&v| v == 0.0) {
                table.push(0);
            } else {
                table.push((stored.len() / size) as u32);
                stored.extend_from_slice(b);
            }
        }
        let slots = stored.len() / size;
        (with_table(stored, res, &table), slots)
    }

    /// A density with zero bricks: hashed values inside a ball, zero outside.
    fn ball<const C: usize>(res: [u32; 3]) -> Vec<f32> {
        let mut out = Vec::new();
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    let d = |i: u32, r: u32| (i as f32 + 0.5) / r as f32 - 0.5;
                    let r2 = d(x, res[0]).powi(2) + d(y, res[1]).powi(2) + d(z, res[2]).powi(2);
                    for c in 0..C as u32 {
                        let i = ((z * res[1] + y) * res[0] + x) * C as u32 + c;
                        out.push(if r2 < 0.09 { hash(i) + 0.01 } else { 0.0 });
                    }
                }
            }
        }
        out
    }

    #[test]
    fn sparse_lookups_are_bit_identical_to_dense() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(3.0, 1.5, 2.25));
        // One block (128^3 samples) and several, some of them empty (uniform), some cut by the
        // box's faces.
        for res in [[40, 33, 17], [24, 24, 24], [64, 9, 70], [300, 20, 140]] {
            let one = ball::<1>(res);
            let (sparse, slots) = sparsify::<1>(&one, res);
            let bricks = crate::sparse::bricks(res).iter().product::<u32>() as usize;
            assert!(
                slots < bricks,
                "{res:?}: the test grid must have empty bricks"
            );
            for mapping in [
                GridMapping::vertex_centred(bounds, res),
                GridMapping::cell_centred(bounds, res),
            ] {
                let a = Grid::<1>::new(&one, res, mapping);
                let b = Grid::<1>::sparse(&sparse, res, mapping);
                assert_eq!(b.samples().len(), slots * 512);
                let flat = crate::sparse::flatten(&sparse, res).unwrap();
                let c = Grid {
                    data: &flat,
                    layout: GridLayout::SparseFlat,
                    ..b
                };
                assert_eq!(c.samples(), b.samples());
                let (min, extent) = (bounds.min, bounds.extent());
                let mut nonzero = 0;
                for i in 0..4000u32 {
                    let u = Vec3::new(hash(3 * i), hash(3 * i + 1), hash(3 * i + 2)) * 1.1 - 0.05;
                    let p = min + u * extent;
                    assert_eq!(a.lookup(p)[0].to_bits(), b.lookup(p)[0].to_bits(), "{p:?}");
                    assert_eq!(a.lookup(p)[0].to_bits(), c.lookup(p)[0].to_bits(), "{p:?}");
                    assert_eq!(a.lookup(p), AnyLayout::lookup(&b, p));
                    assert_eq!(a.lookup(p), AnyLayout::lookup(&c, p));
                    nonzero += usize::from(a.lookup(p)[0] > 0.0);
                }
                assert!(nonzero > 100, "{res:?}: {nonzero} lookups inside the ball");
            }
            let three = ball::<3>(res);
            let (sparse3, _) = sparsify::<3>(&three, res);
            let mapping = GridMapping::cell_centred(bounds, res);
            let a = Grid::<3>::new(&three, res, mapping);
            let b = Grid::<3>::sparse(&sparse3, res, mapping);
            let flat3 = crate::sparse::flatten(&sparse3, res).unwrap();
            let c = Grid {
                data: &flat3,
                layout: GridLayout::SparseFlat,
                ..b
            };
            for i in 0..2000u32 {
                let u = Vec3::new(hash(3 * i), hash(3 * i + 1), hash(3 * i + 2));
                let p = min_plus(bounds, u);
                assert_eq!(a.lookup(p), b.lookup(p), "{p:?}");
                assert_eq!(a.lookup(p), c.lookup(p), "{p:?}");
            }
        }
    }

    fn min_plus(bounds: Aabb, u: Vec3) -> Vec3 {
        bounds.min + u * bounds.extent()
    }

    /// A sparse grid's majorant grid equals its dense copy's, cell for cell: the background
    /// brick read once stands for every sample of every empty brick.
    #[test]
    fn sparse_majorants_equal_dense_majorants() {
        for res in [[64, 9, 70], [300, 20, 140]] {
            sparse_majorants_equal_dense_majorants_at(res);
        }
    }

    fn sparse_majorants_equal_dense_majorants_at(res: [u32; 3]) {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(3.0, 1.5, 2.25));
        let dense = ball::<1>(res);
        let (sparse, _) = sparsify::<1>(&dense, res);
        let mapping = GridMapping::cell_centred(bounds, res);
        for cells in [[16, 4, 16], [3, 1, 5], res] {
            let n = cells.iter().product::<u32>() as usize;
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            let grid = Grid::<1>::new(&dense, res, mapping);
            crate::majorant::build_majorants(&grid, 2.0, bounds, cells, &mut a);
            let grid = Grid::<1>::sparse(&sparse, res, mapping);
            crate::majorant::build_majorants(&grid, 2.0, bounds, cells, &mut b);
            assert_eq!(a, b, "{cells:?}");
            assert!(a.contains(&0.0), "{cells:?}: no empty cell tested");
        }
    }

    /// Where every brick of a block reads one stored brick whose samples differ (no loader
    /// writes that, but a table may say it), a majorant cell that covers part of the block reads
    /// the parts of the brick its samples cover: the same bounds as the dense copy's.
    #[test]
    fn a_block_of_one_varied_brick_has_the_majorants_of_its_dense_copy() {
        let res = [200, 24, 136];
        // Slot 1, hashed values, is every brick of the first block, painted as one region (as a
        // tile is); the rest is the background.
        let mut data = vec![0.0; 512];
        data.extend((0..512).map(|i| hash(i + 7)));
        let block = [crate::sparse::BLOCK; 3];
        let mut plan = crate::sparse::TablePlan::new(res);
        plan.paint([0; 3], block, 1);
        let mut table = plan.into_table();
        table.paint([0; 3], block, 1);
        table.append_to(&mut data);
        let bounds = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 0.24, 1.36));
        let mapping = GridMapping::cell_centred(bounds, res);
        let sparse = Grid::<1>::sparse(&data, res, mapping);
        assert_eq!(
            crate::sparse::block(&data, res, [0, 0, 0]),
            crate::sparse::Block::Uniform(1)
        );
        let mut dense = Vec::new();
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    dense.push(sparse.sample(x, y, z)[0]);
                }
            }
        }
        let grid = Grid::<1>::new(&dense, res, mapping);
        for cells in [[100, 12, 68], [33, 5, 17], [7, 3, 9], [1, 1, 1]] {
            let len = cells.iter().product::<u32>() as usize;
            let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
            crate::majorant::build_majorants(&grid, 1.0, bounds, cells, &mut a);
            crate::majorant::build_majorants(&sparse, 1.0, bounds, cells, &mut b);
            assert_eq!(a, b, "{cells:?}");
        }
    }

    #[test]
    #[should_panic(expected = "names brick 1, but 1 are stored")]
    fn a_sparse_table_must_name_stored_bricks() {
        let data = with_table(vec![0.0; 512], [8, 8, 8], &[1]);
        let mapping = GridMapping::cell_centred(Aabb::new(Vec3::ZERO, Vec3::ONE), [8, 8, 8]);
        Grid::<1>::sparse(&data, [8, 8, 8], mapping);
    }

    #[test]
    fn bricked_lookups_are_bit_identical_to_dense() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(3.0, 1.5, 2.25));
        for res in SHAPES {
            lookups_match::<1>(res, GridMapping::vertex_centred(bounds, res));
            lookups_match::<1>(res, GridMapping::cell_centred(bounds, res));
            lookups_match::<3>(res, GridMapping::cell_centred(bounds, res));
        }
    }

    /// Each `GridReads` is the lookup it names (the media specialised for it compute nothing
    /// else): `AnyLayout` reads the grid's own layout and lookup, `DenseTrilinear` the dense
    /// trilinear lookup, `TextureTrilinear` (on the CPU) the texture unit's filter. Nothing else
    /// compares them: the renderer's references never render an any-layout medium.
    #[test]
    fn each_grid_reads_is_the_lookup_it_names() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(3.0, 1.5, 2.25));
        let res = [9, 8, 17];
        let mapping = GridMapping::cell_centred(bounds, res);
        let dense: Vec<f32> = (0..res.iter().product::<u32>()).map(hash).collect();
        let bricked = brick::<1>(&dense, res);
        let grids = [
            Grid::<1>::new(&dense, res, mapping),
            Grid::<1>::new(&dense, res, mapping).with_lookup(GridLookup::Nearest),
            Grid::<1>::with_layout(&bricked, res, mapping, GridLayout::Bricked),
        ];
        let (min, extent) = (bounds.min, bounds.extent());
        let mut inside = 0;
        for i in 0..2000u32 {
            let u = Vec3::new(hash(3 * i), hash(3 * i + 1), hash(3 * i + 2)) * 1.1 - 0.05;
            let p = min + u * extent;
            for grid in &grids {
                assert_eq!(AnyLayout::lookup(grid, p), grid.lookup(p), "{p:?}");
            }
            let dense = &grids[0];
            assert_eq!(
                DenseTrilinear::lookup(dense, p),
                dense.lookup_dense_trilinear(p)
            );
            assert_eq!(
                TextureTrilinear::lookup(dense, p),
                dense.lookup_texture_filter(p)
            );
            inside += usize::from(dense.lookup(p)[0] > 0.0);
        }
        assert!(inside > 1000, "{inside} lookups were not zero");
    }

    /// `with_texel` sets the format that texture lookups (and the CPU's filter of them) read:
    /// 0.1 is no half value, so half texels hold the largest half below it.
    #[test]
    fn with_texel_sets_what_texture_lookups_read() {
        let data = [0.1f32; 8];
        let mapping = GridMapping::cell_centred(Aabb::new(Vec3::ZERO, Vec3::ONE), [2, 2, 2]);
        let grid = Grid::<1>::new(&data, [2, 2, 2], mapping);
        let p = Vec3::new(0.3, 0.6, 0.45);
        assert_eq!(TextureTrilinear::lookup(&grid, p), [0.1]);
        let half = half_toward_zero(0.1);
        assert!(half < 0.1);
        let grid = grid.with_texel(TexelFormat::F16);
        assert_eq!(grid.texel, TexelFormat::F16);
        assert_eq!(TextureTrilinear::lookup(&grid, p), [half]);
    }

    #[test]
    fn texel_formats_travel_as_their_codes() {
        for format in [TexelFormat::F32, TexelFormat::F16] {
            assert_eq!(TexelFormat::from_u32(format.to_u32()), format);
        }
        assert_eq!(TexelFormat::from_u32(7), TexelFormat::F32);
    }

    #[test]
    fn layout_sizes_overflow_cleanly() {
        assert_eq!(GridLayout::Dense.values([2, 3, 4], 3), Some(72));
        assert_eq!(GridLayout::Bricked.values([2, 3, 4], 3), Some(512 * 3));
        assert_eq!(GridLayout::Bricked.values([u32::MAX; 3], u32::MAX), None);
        assert_eq!(
            GridLayout::from_u32(GridLayout::Bricked.to_u32()),
            GridLayout::Bricked
        );
        assert_eq!(GridLayout::from_u32(7), GridLayout::Dense);
    }

    #[test]
    #[should_panic(expected = "does not match its resolution")]
    fn a_bricked_grid_must_hold_its_padding() {
        let data = [0.0; 8];
        let mapping = GridMapping::cell_centred(Aabb::new(Vec3::ZERO, Vec3::ONE), [2, 2, 2]);
        Grid::<1>::with_layout(&data, [2, 2, 2], mapping, GridLayout::Bricked);
    }
}
