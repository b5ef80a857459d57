//! The brick table of a [`GridLayout::Sparse`](crate::grid::GridLayout::Sparse) grid: which
//! stored 8^3 brick each brick of the box reads, in two levels, so that a uniform region (the
//! empty background, a VDB tile) costs one entry however large it is, not one per brick.
//!
//! The box's bricks are grouped in *blocks* of [`BLOCK`]^3 bricks (128^3 samples: the span of
//! OpenVDB's lower internal node, so that its tiles of 128^3 and 4096^3 voxels are whole blocks).
//! The *coarse* table has one entry per block of the box, x fastest. A *mixed* block's entry
//! names [`BLOCK_BRICKS`] *fine* entries, one per brick of the block (x fastest), each the slot of
//! a stored brick; a *uniform* block (every brick of it the same stored brick) names one fine
//! entry, that slot, which stands for all its bricks. So an empty or tiled 4096^3 region costs
//! 32^3 coarse entries where a table of every brick took 2^27 (512 MiB), and the lookup reads
//! two entries instead of one.
//!
//! A sparse grid's `data` holds, in order (each table entry the `f32` bits of a `u32`):
//! 1. the stored bricks, [`BRICK`]^3 samples of `C` channels each, x fastest within a brick
//!    (the bricked layout's order); slot 0 is the background brick;
//! 2. the fine entries: slots of stored bricks;
//! 3. the coarse entries, [`coarse_len`]`(res)` of them: how far below the first coarse entry
//!    the block's fine entries start, with [`UNIFORM`] set for a uniform block;
//! 4. the number of fine entries (where the samples end, for the host: [`stored_values`]).
//!
//! [`slot`], the lookup every backend runs, finds the coarse table from `data.len()` and `res`
//! alone, and masks a uniform block's brick number within the block to 0 instead of branching.
//! [`parts`] checks every invariant the lookup relies on; [`TablePlan`] (host side) builds a
//! table from regions painted in order, in time and memory proportional to the regions and the
//! blocks they touch, not to the bricks they cover.
//!
//! The GPU reads a *flat* copy instead ([`flatten`], [`GridLayout::SparseFlat`]): the stored
//! bricks followed by one slot per brick of the box, so that each corner of a lookup costs one
//! dependent read of the table, not two. The second read's code was what the any-layout kernels
//! paid for in registers and spills (6-18% of their time on the bricked and sparse scenes,
//! `bench/results/2026-11-29-h200-session12`), whether a grid was sparse or not. A flat table
//! costs 4 bytes per brick of the box, so it is made only up to [`FLAT_MAX`] entries.
//!
//! [`GridLayout::SparseFlat`]: crate::grid::GridLayout::SparseFlat

use core::fmt;

use crate::grid::BRICK;

/// Bricks along each edge of a block of the coarse table.
pub const BLOCK: u32 = 16;
const BLOCK_SHIFT: u32 = BLOCK.trailing_zeros();
/// Fine entries of a mixed block: one per brick of the block.
pub const BLOCK_BRICKS: u32 = BLOCK * BLOCK * BLOCK;
/// Samples along each edge of a block.
pub const BLOCK_SAMPLES: u32 = BLOCK * BRICK;
const BLOCK_SAMPLES_SHIFT: u32 = BLOCK_SAMPLES.trailing_zeros();
/// The bit of a coarse entry that marks a uniform block.
pub const UNIFORM: u32 = 1 << 31;
/// Samples in a brick.
const BRICK_SAMPLES: u64 = (BRICK * BRICK * BRICK) as u64;

/// Blocks along each axis of a grid of `res` samples (each at least 1).
#[inline(always)]
pub fn blocks(res: [u32; 3]) -> [u32; 3] {
    // `(r - 1) / 128 + 1`: no overflow near `u32::MAX`, as a rounded-up sum would.
    res.map(|r| (r.max(1) - 1) >> BLOCK_SAMPLES_SHIFT)
        .map(|b| b + 1)
}

/// Bricks along each axis of a grid of `res` samples.
pub fn bricks(res: [u32; 3]) -> [u32; 3] {
    res.map(|r| r.div_ceil(BRICK))
}

/// Entries of the coarse table of a grid of `res` samples (`None`: more than `u64` holds).
pub fn coarse_len(res: [u32; 3]) -> Option<u64> {
    blocks(res)
        .iter()
        .try_fold(1u64, |acc, &b| acc.checked_mul(u64::from(b)))
}

/// The slot of the stored brick that brick `brick` (brick coordinates, inside the box) of a
/// sparse grid of `res` samples reads: its block's coarse entry, then one fine entry.
#[inline(always)]
pub fn slot(data: &[f32], res: [u32; 3], brick: [u32; 3]) -> u32 {
    let [nx, ny, nz] = blocks(res);
    let coarse = data.len() - 1 - (nx * ny * nz) as usize;
    let [bx, by, bz] = brick;
    let block = ((bz >> BLOCK_SHIFT) * ny + (by >> BLOCK_SHIFT)) * nx + (bx >> BLOCK_SHIFT);
    let entry = data[coarse + block as usize].to_bits();
    let m = BLOCK - 1;
    let within = ((((bz & m) << BLOCK_SHIFT) | (by & m)) << BLOCK_SHIFT) | (bx & m);
    // A uniform block's one fine entry stands for each of its bricks: a select, not a branch.
    let within = if entry & UNIFORM != 0 { 0 } else { within };
    data[coarse - (entry & !UNIFORM) as usize + within as usize].to_bits()
}

/// Entries of a flat table ([`flatten`]) that a GPU renderer makes: 2^28 (1 GiB), a box of
/// 5120^3 samples. Keeps the flat lookup's arithmetic in `u32` and the copy a fraction of a
/// second; a larger box of tiles renders on the CPU, which reads the two-level table.
pub const FLAT_MAX: u64 = 1 << 28;

/// Entries of the flat table of a grid of `res` samples, one per brick of the box (`None`: more
/// than [`FLAT_MAX`]).
pub fn flat_len(res: [u32; 3]) -> Option<u64> {
    let n = bricks(res).iter().map(|&b| u64::from(b)).product::<u64>();
    (n <= FLAT_MAX).then_some(n)
}

/// The slot of the stored brick that brick `brick` of a [`GridLayout::SparseFlat`] grid of
/// `res` samples reads: its entry of the table at the end of `data`.
///
/// [`GridLayout::SparseFlat`]: crate::grid::GridLayout::SparseFlat
#[inline(always)]
pub fn flat_slot(data: &[f32], res: [u32; 3], brick: [u32; 3]) -> u32 {
    let [nx, ny, nz] = bricks(res);
    let table = data.len() - (nx * ny * nz) as usize;
    let [bx, by, bz] = brick;
    data[table + ((bz * ny + by) * nx + bx) as usize].to_bits()
}

/// What a block of the coarse table is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Every brick of the block reads the stored brick of this slot.
    Uniform(u32),
    /// Its bricks read their own fine entries ([`slot`]).
    Mixed,
}

/// Block `block` (block coordinates, inside the box) of a sparse grid of `res` samples.
pub fn block(data: &[f32], res: [u32; 3], block: [u32; 3]) -> Block {
    let [nx, ny, nz] = blocks(res);
    let coarse = data.len() - 1 - (nx * ny * nz) as usize;
    let entry = data[coarse + ((block[2] * ny + block[1]) * nx + block[0]) as usize].to_bits();
    if entry & UNIFORM != 0 {
        Block::Uniform(data[coarse - (entry & !UNIFORM) as usize].to_bits())
    } else {
        Block::Mixed
    }
}

/// Values of the stored bricks at the start of a sparse grid's `data` (unchecked: 0 where
/// `data` is too short; [`parts`] checks).
pub fn stored_values(data: &[f32], res: [u32; 3]) -> usize {
    let coarse = coarse_len(res).unwrap_or(u64::MAX);
    let Some(&count) = data.last() else {
        return 0;
    };
    (data.len() as u64)
        .saturating_sub(1)
        .saturating_sub(coarse)
        .saturating_sub(u64::from(count.to_bits())) as usize
}

/// The sizes of a sparse grid's parts, as [`parts`] found them valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Parts {
    /// Stored bricks.
    pub slots: u64,
    /// Values of the stored bricks (`slots` x 512 x channels).
    pub values: u64,
    pub fine: u64,
    pub coarse: u64,
}

/// Why `data` is not a sparse grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableError {
    /// The coarse table of the box has more entries than `u32` indexes.
    TooManyBlocks { blocks: u64 },
    /// `data` is shorter than its coarse table, count and the fine entries the count claims.
    TooShort { len: u64, tables: u64 },
    /// The stored values are not whole bricks of `brick` values, at least one.
    NotWholeBricks { values: u64, brick: u64 },
    /// More bricks than a `u32` sample index reaches.
    TooManyBricks { slots: u64 },
    /// More fine entries than a coarse entry can name.
    TooManyFine { fine: u64 },
    /// Coarse entry `block` names fine entries outside the fine table.
    BadCoarse { block: u64, entry: u32, fine: u64 },
    /// Fine entry `entry` names a brick that is not stored.
    BadFine { entry: u64, slot: u32, slots: u64 },
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TableError::TooManyBlocks { blocks } => write!(
                f,
                "the box has {blocks} blocks of 128^3 samples: at most 2^32 - 1"
            ),
            TableError::TooShort { len, tables } => write!(
                f,
                "{len} values cannot hold the brick tables' {tables} entries"
            ),
            TableError::NotWholeBricks { values, brick } => write!(
                f,
                "{values} stored values are not whole bricks of {brick} values (at least one)"
            ),
            TableError::TooManyBricks { slots } => {
                write!(f, "{slots} bricks: at most 2^23 bricks can be stored")
            }
            TableError::TooManyFine { fine } => {
                write!(f, "{fine} fine table entries: at most 2^31 - 1")
            }
            TableError::BadCoarse { block, entry, fine } => write!(
                f,
                "coarse table entry {block} ({entry:#x}) names entries outside the {fine} of the \
                 fine table"
            ),
            TableError::BadFine { entry, slot, slots } => write!(
                f,
                "fine table entry {entry} names brick {slot}, but {slots} are stored"
            ),
        }
    }
}

/// Checks that `data` is a sparse grid of `res` samples of `channels` channels, as [`slot`]
/// reads it: every coarse entry names fine entries inside the fine table, every fine entry a
/// stored brick, and every index fits the lookup's `u32` arithmetic. Time proportional to the
/// tables, not to the box.
pub fn parts(data: &[f32], res: [u32; 3], channels: u32) -> Result<Parts, TableError> {
    let coarse = coarse_len(res).unwrap_or(u64::MAX);
    if coarse > u64::from(u32::MAX) {
        return Err(TableError::TooManyBlocks { blocks: coarse });
    }
    let len = data.len() as u64;
    let fine = data.last().map_or(0, |v| u64::from(v.to_bits()));
    let tables = coarse + 1 + fine;
    if len < tables {
        return Err(TableError::TooShort { len, tables });
    }
    if fine >= u64::from(UNIFORM) {
        return Err(TableError::TooManyFine { fine });
    }
    let values = len - tables;
    let brick = BRICK_SAMPLES * u64::from(channels);
    if brick == 0 || values < brick || !values.is_multiple_of(brick) {
        return Err(TableError::NotWholeBricks { values, brick });
    }
    let slots = values / brick;
    if slots * BRICK_SAMPLES > u64::from(u32::MAX) {
        return Err(TableError::TooManyBricks { slots });
    }
    let first_coarse = (values + fine) as usize;
    for (block, e) in data[first_coarse..data.len() - 1].iter().enumerate() {
        let entry = e.to_bits();
        let back = u64::from(entry & !UNIFORM);
        let needed = if entry & UNIFORM != 0 {
            1
        } else {
            u64::from(BLOCK_BRICKS)
        };
        if back > fine || back < needed {
            return Err(TableError::BadCoarse {
                block: block as u64,
                entry,
                fine,
            });
        }
    }
    let fine_entries = &data[values as usize..first_coarse];
    if let Some((entry, slot)) = fine_entries
        .iter()
        .map(|v| v.to_bits())
        .enumerate()
        .find(|&(_, s)| u64::from(s) >= slots)
    {
        return Err(TableError::BadFine {
            entry: entry as u64,
            slot,
            slots,
        });
    }
    Ok(Parts {
        slots,
        values,
        fine,
        coarse,
    })
}

#[cfg(feature = "alloc")]
pub use plan::{BrickTable, TablePlan};

/// The flat copy of sparse grid `data` of `res` samples (valid: [`parts`]): its stored bricks,
/// then the slot of every brick of the box, x fastest, as [`flat_slot`] reads them. `None` if
/// the box has more than [`FLAT_MAX`] bricks. Time proportional to the box's bricks: a uniform
/// block's are filled from its one entry, row by row.
#[cfg(feature = "alloc")]
pub fn flatten(data: &[f32], res: [u32; 3]) -> Option<alloc::vec::Vec<f32>> {
    let len = flat_len(res)?;
    let stored = stored_values(data, res);
    let mut flat = alloc::vec::Vec::with_capacity(stored + len as usize);
    flat.extend_from_slice(&data[..stored]);
    let table = flat.len();
    flat.resize(table + len as usize, 0.0);
    let bricks = bricks(res);
    let [nx, ny, _] = bricks;
    let last = blocks(res).map(|b| b - 1);
    plan::for_blocks([0; 3], last, |b| {
        let uniform = match block(data, res, b) {
            Block::Uniform(slot) => Some(slot),
            Block::Mixed => None,
        };
        let (lo, hi, _) = plan::clip([0; 3], bricks, b, bricks);
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                let row = table + ((z * ny + y) * nx) as usize;
                let entries = &mut flat[row + lo[0] as usize..row + hi[0] as usize];
                match uniform {
                    Some(slot) => entries.fill(f32::from_bits(slot)),
                    None => {
                        for (x, e) in (lo[0]..hi[0]).zip(entries) {
                            *e = f32::from_bits(slot(data, res, [x, y, z]));
                        }
                    }
                }
            }
        }
    });
    Some(flat)
}

#[cfg(feature = "alloc")]
mod plan {
    use alloc::collections::BTreeMap;
    use alloc::vec;
    use alloc::vec::Vec;

    use super::{blocks, bricks, Block, BLOCK, BLOCK_BRICKS, UNIFORM};

    /// The part of a box of bricks `[lo, hi)` inside block `b` of a box of `bricks` bricks per
    /// axis, and whether that is the block's every brick (blocks at the box's far faces are cut
    /// by it).
    pub(super) fn clip(
        lo: [u32; 3],
        hi: [u32; 3],
        b: [u32; 3],
        bricks: [u32; 3],
    ) -> ([u32; 3], [u32; 3], bool) {
        let start = b.map(|v| v * BLOCK);
        let end = [0, 1, 2].map(|a| (start[a] + BLOCK).min(bricks[a]));
        let from = [0, 1, 2].map(|a| lo[a].max(start[a]));
        let to = [0, 1, 2].map(|a| hi[a].min(end[a]));
        (from, to, from == start && to == end)
    }

    /// The blocks a box of bricks `[lo, hi)` (not empty) touches, `[first, last]`.
    fn touched(lo: [u32; 3], hi: [u32; 3]) -> ([u32; 3], [u32; 3]) {
        (lo.map(|v| v / BLOCK), hi.map(|v| (v - 1) / BLOCK))
    }

    /// `[lo, hi)` clamped to a box of `bricks` bricks; `None` if nothing is left.
    fn clamp(lo: [u32; 3], hi: [u32; 3], bricks: [u32; 3]) -> Option<([u32; 3], [u32; 3])> {
        let hi = [0, 1, 2].map(|a| hi[a].min(bricks[a]));
        (0..3).all(|a| lo[a] < hi[a]).then_some((lo, hi))
    }

    pub(super) fn for_blocks(first: [u32; 3], last: [u32; 3], mut f: impl FnMut([u32; 3])) {
        for z in first[2]..=last[2] {
            for y in first[1]..=last[1] {
                for x in first[0]..=last[0] {
                    f([x, y, z]);
                }
            }
        }
    }

    /// The first pass of building a brick table: which blocks end up uniform, from regions
    /// painted in order (a later region over an earlier one, as a later node of a file
    /// overrides an earlier one). Everything starts as the background brick, slot 0. Then
    /// [`TablePlan::fine_len`] says what the table will take, and [`TablePlan::into_table`]
    /// starts the second pass, which paints the same regions again into the mixed blocks.
    pub struct TablePlan {
        bricks: [u32; 3],
        blocks: [u32; 3],
        /// Per block: `UNIFORM | slot`, or 0 for a mixed block.
        coarse: Vec<u32>,
    }

    impl TablePlan {
        /// A plan for a grid of `res` samples: 4 bytes per block ([`super::coarse_len`], which the
        /// caller checks against its memory limit first).
        pub fn new(res: [u32; 3]) -> Self {
            let blocks = blocks(res);
            let n = blocks.iter().map(|&b| b as usize).product();
            Self {
                bricks: bricks(res),
                blocks,
                coarse: vec![UNIFORM; n],
            }
        }

        fn index(&self, b: [u32; 3]) -> usize {
            ((b[2] as usize * self.blocks[1] as usize) + b[1] as usize) * self.blocks[0] as usize
                + b[0] as usize
        }

        /// Bricks `[lo, hi)` (brick coordinates; the part outside the box is ignored) read the
        /// stored brick `slot` (below 2^31). Time proportional to the blocks the region touches.
        pub fn paint(&mut self, lo: [u32; 3], hi: [u32; 3], slot: u32) {
            let Some((lo, hi)) = clamp(lo, hi, self.bricks) else {
                return;
            };
            let (first, last) = touched(lo, hi);
            let bricks = self.bricks;
            let mut coarse = core::mem::take(&mut self.coarse);
            for_blocks(first, last, |b| {
                let entry = &mut coarse[self.index(b)];
                let (_, _, whole) = clip(lo, hi, b, bricks);
                if whole {
                    *entry = UNIFORM | slot;
                } else if *entry != UNIFORM | slot {
                    *entry = 0;
                }
            });
            self.coarse = coarse;
        }

        /// The uniform blocks' slots, each once, in order.
        fn uniform_slots(&self) -> BTreeMap<u32, u32> {
            let mut slots = BTreeMap::new();
            for &e in &self.coarse {
                if e & UNIFORM != 0 {
                    let next = slots.len() as u32;
                    slots.entry(e & !UNIFORM).or_insert(next);
                }
            }
            slots
        }

        /// Fine entries the table will have: [`BLOCK_BRICKS`] per mixed block, one per distinct
        /// slot of the uniform ones.
        pub fn fine_len(&self) -> u64 {
            let mixed = self.coarse.iter().filter(|&&e| e & UNIFORM == 0).count() as u64;
            mixed * u64::from(BLOCK_BRICKS) + self.uniform_slots().len() as u64
        }

        /// The table, its mixed blocks' fine entries all the background (slot 0) until the
        /// regions are painted again ([`BrickTable::paint`]).
        pub fn into_table(self) -> BrickTable {
            let uniform = self.uniform_slots();
            let mixed = self.coarse.iter().filter(|&&e| e & UNIFORM == 0).count();
            let mut next = 0u32;
            let coarse = self
                .coarse
                .iter()
                .map(|&e| {
                    if e & UNIFORM != 0 {
                        e
                    } else {
                        next += 1;
                        next - 1
                    }
                })
                .collect();
            BrickTable {
                bricks: self.bricks,
                blocks: self.blocks,
                coarse,
                fine: vec![0; mixed * BLOCK_BRICKS as usize],
                uniform,
            }
        }
    }

    /// The second pass of building a brick table ([`TablePlan`]).
    pub struct BrickTable {
        bricks: [u32; 3],
        blocks: [u32; 3],
        /// Per block: `UNIFORM | slot`, or the mixed block's number among the mixed ones.
        coarse: Vec<u32>,
        fine: Vec<u32>,
        /// The uniform blocks' distinct slots, each with its place after the mixed entries.
        uniform: BTreeMap<u32, u32>,
    }

    impl BrickTable {
        /// The table of a grid of `res` samples whose brick `i` (x fastest) reads slot
        /// `slots[i]`: a table of every brick, as a dense grid's sparse copy has, with each
        /// block whose bricks all read the background (slot 0) made uniform.
        pub fn from_slots(res: [u32; 3], slots: &[u32]) -> Self {
            let [bx, by, _] = bricks(res);
            let at = |i: usize| {
                let i = i as u32;
                [i % bx, (i / bx) % by, i / (bx * by)]
            };
            let mut plan = TablePlan::new(res);
            for (i, &s) in slots.iter().enumerate() {
                plan.paint(at(i), at(i).map(|v| v + 1), s);
            }
            let mut table = plan.into_table();
            for (i, &s) in slots.iter().enumerate() {
                table.paint(at(i), at(i).map(|v| v + 1), s);
            }
            table
        }

        /// [`TablePlan::paint`] again, with the same regions in the same order.
        pub fn paint(&mut self, lo: [u32; 3], hi: [u32; 3], slot: u32) {
            let Some((lo, hi)) = clamp(lo, hi, self.bricks) else {
                return;
            };
            let (first, last) = touched(lo, hi);
            let [nx, ny, _] = self.blocks;
            for_blocks(first, last, |b| {
                let entry = self.coarse[((b[2] * ny + b[1]) * nx + b[0]) as usize];
                if entry & UNIFORM != 0 {
                    return;
                }
                let fine = &mut self.fine[entry as usize * BLOCK_BRICKS as usize..]
                    [..BLOCK_BRICKS as usize];
                let (from, to, _) = clip(lo, hi, b, self.bricks);
                let o = b.map(|v| v * BLOCK);
                for z in from[2]..to[2] {
                    for y in from[1]..to[1] {
                        let row = (((z - o[2]) * BLOCK + (y - o[1])) * BLOCK) as usize;
                        fine[row + (from[0] - o[0]) as usize..row + (to[0] - o[0]) as usize]
                            .fill(slot);
                    }
                }
            });
        }

        /// What block `b` is.
        pub fn block(&self, b: [u32; 3]) -> Block {
            let [nx, ny, _] = self.blocks;
            let entry = self.coarse[((b[2] * ny + b[1]) * nx + b[0]) as usize];
            if entry & UNIFORM != 0 {
                Block::Uniform(entry & !UNIFORM)
            } else {
                Block::Mixed
            }
        }

        /// Appends the table to the stored bricks `data`: the fine entries, the coarse entries
        /// and the fine entries' count, as [`super::slot`] reads them.
        pub fn append_to(self, data: &mut Vec<f32>) {
            let mixed = self.fine.len() as u32;
            let fine = mixed + self.uniform.len() as u32;
            let mut uniform: Vec<(u32, u32)> = self.uniform.iter().map(|(&s, &i)| (i, s)).collect();
            uniform.sort_unstable();
            data.reserve(fine as usize + self.coarse.len() + 1);
            let bits = |v: u32| f32::from_bits(v);
            data.extend(self.fine.iter().map(|&s| bits(s)));
            data.extend(uniform.iter().map(|&(_, s)| bits(s)));
            // Each coarse entry counts down from the coarse table to its block's fine entries.
            data.extend(self.coarse.iter().map(|&e| {
                if e & UNIFORM != 0 {
                    bits(UNIFORM | (fine - (mixed + self.uniform[&(e & !UNIFORM)])))
                } else {
                    bits(fine - e * BLOCK_BRICKS)
                }
            }));
            data.push(bits(fine));
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec;
    use std::vec::Vec;

    use super::*;

    /// A small counter-based generator, so that the test needs no dependency.
    fn hash(i: u32) -> u32 {
        let mut h = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
        h ^= h >> 15;
        h = h.wrapping_mul(0x2C1B_3C6D);
        h ^ (h >> 12)
    }

    /// Regions (boxes of bricks, slots) painted in order, as a VDB's tiles then leaves: large
    /// aligned ones (whole blocks), unaligned ones, single bricks, overlapping each other and
    /// the box's far faces.
    fn regions(bricks: [u32; 3], n: u32) -> Vec<([u32; 3], [u32; 3], u32)> {
        (0..n)
            .map(|i| {
                let size = [1, 3, 16, 32, 40][(hash(4 * i) % 5) as usize];
                let lo = [0, 1, 2].map(|a: usize| hash(4 * i + 1 + a as u32) % bricks[a]);
                let lo = if size % 16 == 0 {
                    lo.map(|v| v / 16 * 16)
                } else {
                    lo
                };
                (lo, lo.map(|v| v + size), hash(i) % 5)
            })
            .collect()
    }

    fn build(res: [u32; 3], regions: &[([u32; 3], [u32; 3], u32)]) -> (Vec<f32>, u64) {
        let mut plan = TablePlan::new(res);
        for &(lo, hi, s) in regions {
            plan.paint(lo, hi, s);
        }
        let fine = plan.fine_len();
        let mut table = plan.into_table();
        for &(lo, hi, s) in regions {
            table.paint(lo, hi, s);
        }
        // Five stored bricks of one channel.
        let mut data = vec![0.0; 5 * 512];
        table.append_to(&mut data);
        (data, fine)
    }

    #[test]
    fn every_brick_reads_the_last_region_painted_over_it() {
        for (res, n) in [([1, 1, 1], 3), ([300, 130, 257], 40), ([512, 8, 700], 200)] {
            let b = bricks(res);
            let regions = regions(b, n);
            let (data, fine) = build(res, &regions);
            let parts = parts(&data, res, 1).unwrap();
            assert_eq!(parts.fine, fine);
            assert_eq!((parts.slots, parts.values), (5, 5 * 512));
            assert_eq!(stored_values(&data, res), 5 * 512);
            // The flat table painted brick by brick.
            let mut flat = vec![0u32; b.iter().product::<u32>() as usize];
            for &(lo, hi, s) in &regions {
                for z in lo[2]..hi[2].min(b[2]) {
                    for y in lo[1]..hi[1].min(b[1]) {
                        for x in lo[0]..hi[0].min(b[0]) {
                            flat[((z * b[1] + y) * b[0] + x) as usize] = s;
                        }
                    }
                }
            }
            for z in 0..b[2] {
                for y in 0..b[1] {
                    for x in 0..b[0] {
                        let want = flat[((z * b[1] + y) * b[0] + x) as usize];
                        assert_eq!(slot(&data, res, [x, y, z]), want, "{res:?} ({x}, {y}, {z})");
                    }
                }
            }
        }
    }

    /// The flat copy's one-level table gives every brick the slot the two-level table gives it,
    /// uniform blocks (filled from one entry) and blocks cut by the box's faces included; the
    /// stored bricks come first, unchanged.
    #[test]
    fn the_flat_table_reads_every_brick_as_the_two_level_table() {
        for (res, n) in [([1, 1, 1], 3), ([300, 130, 257], 40), ([512, 8, 700], 200)] {
            let b = bricks(res);
            let (data, _) = build(res, &regions(b, n));
            let flat = flatten(&data, res).unwrap();
            let stored = stored_values(&data, res);
            assert_eq!(flat.len() as u64, stored as u64 + flat_len(res).unwrap());
            assert_eq!(flat[..stored], data[..stored]);
            for z in 0..b[2] {
                for y in 0..b[1] {
                    for x in 0..b[0] {
                        assert_eq!(
                            flat_slot(&flat, res, [x, y, z]),
                            slot(&data, res, [x, y, z]),
                            "{res:?} ({x}, {y}, {z})"
                        );
                    }
                }
            }
        }
    }

    /// A box of more than [`FLAT_MAX`] bricks has no flat copy (the GPU refuses it); the
    /// largest box within it has one.
    #[test]
    fn a_flat_table_has_at_most_flat_max_entries() {
        let side: u32 = 8 << 9; // 512 bricks
        assert_eq!(flat_len([side, side, 2 * side]), Some(FLAT_MAX));
        assert_eq!(flat_len([side, side, 2 * side + 1]), None);
        let (data, _) = build([16384; 3], &[([0; 3], [512; 3], 3)]);
        assert!(flatten(&data, [16384; 3]).is_none());
    }

    /// A region of 4096^3 samples (an OpenVDB root tile) in a box of 16384^3: 2^21 coarse
    /// entries and 2 fine ones, where one entry per brick was 2^33.
    #[test]
    fn a_uniform_region_costs_one_entry_per_block() {
        let res = [16384; 3];
        let (data, fine) = build(res, &[([0; 3], [512; 3], 3)]);
        assert_eq!(fine, 2, "the tile's slot and the background's");
        assert_eq!(
            data.len() as u64,
            5 * 512 + 2 + coarse_len(res).unwrap() + 1
        );
        assert_eq!(coarse_len(res), Some(1 << 21));
        assert_eq!(slot(&data, res, [511, 0, 300]), 3);
        assert_eq!(slot(&data, res, [512, 0, 300]), 0);
        assert_eq!(block(&data, res, [31, 0, 0]), Block::Uniform(3));
        assert_eq!(block(&data, res, [32, 0, 0]), Block::Uniform(0));
    }

    #[test]
    fn parts_refuses_tables_the_lookup_would_misread() {
        let res = [300, 8, 8];
        let (good, _) = build(
            res,
            &[([3, 0, 0], [5, 1, 1], 2), ([16, 0, 0], [32, 1, 1], 4)],
        );
        assert!(parts(&good, res, 1).is_ok());
        let coarse = good.len() - 1 - coarse_len(res).unwrap() as usize;
        let set = |i: usize, v: u32| {
            let mut d = good.clone();
            d[i] = f32::from_bits(v);
            d
        };
        let fine = good[good.len() - 1].to_bits();
        let cases = [
            (
                set(good.len() - 1, fine + 1),
                "the count claims one more fine entry",
            ),
            (set(good.len() - 1, u32::MAX), "a count beyond the data"),
            (set(coarse, fine + 1), "a mixed block below the fine table"),
            (
                set(coarse, 10),
                "a mixed block running into the coarse table",
            ),
            (
                set(coarse + 1, UNIFORM | (fine + 1)),
                "a uniform block below the fine table",
            ),
            (
                set(coarse + 1, UNIFORM),
                "a uniform block at the coarse table",
            ),
            (set(coarse - 1, 5), "a fine entry naming a brick not stored"),
            (
                good[1..].to_vec(),
                "stored values that are not whole bricks",
            ),
        ];
        for (data, what) in cases {
            assert!(parts(&data, res, 1).is_err(), "{what}");
        }
        assert!(matches!(
            parts(&good, [u32::MAX - 7; 3], 1),
            Err(TableError::TooManyBlocks { .. })
        ));
        assert!(parts(&[], res, 1).is_err());
        assert_eq!(parts(&good, res, 3).map(|p| p.slots).ok(), None);
    }
}
