//! Morton order of path positions, for the strategies that sort paths (streaming-sorted-sk) or their
//! albedo reads (sorting-sk) within a block so that neighbouring lanes read neighbouring voxels
//! (the thesis's sorting strategies, after Morton 1966's Z-order).

use volpt_core::{Aabb, Vec3};

/// The key of a lane with nothing to sort: after every Morton code, so that a sort also compacts.
pub const INACTIVE_KEY: u32 = u32::MAX;

/// The 30-bit Morton code of `p` in `bounds`: 10 bits per axis of the position in the box
/// (clamped to it), interleaved `x0 y0 z0 x1 y1 z1 ...` from the least significant bit, so that
/// points close in space tend to have close codes.
#[inline(always)]
pub fn morton30(p: Vec3, bounds: &Aabb) -> u32 {
    let extent = bounds.extent();
    let cell = |v: f32, min: f32, len: f32| -> u32 {
        let u = if len > 0.0 { (v - min) / len } else { 0.0 };
        // `as` saturates (and maps NaN to 0): every point of the box and beyond it has a cell.
        ((u * 1024.0) as u32).min(1023)
    };
    let x = cell(p.x, bounds.min.x, extent.x);
    let y = cell(p.y, bounds.min.y, extent.y);
    let z = cell(p.z, bounds.min.z, extent.z);
    spread_bits(x) | (spread_bits(y) << 1) | (spread_bits(z) << 2)
}

/// The 10 low bits of `v`, two zero bits after each: bit `i` moves to bit `3 i`.
#[inline(always)]
pub fn spread_bits(v: u32) -> u32 {
    let mut v = v & 0x3ff;
    v = (v | (v << 16)) & 0x0300_00ff;
    v = (v | (v << 8)) & 0x0300_f00f;
    v = (v | (v << 4)) & 0x030c_30c3;
    (v | (v << 2)) & 0x0924_9249
}
