//! The few PTX instructions the strategies need beyond `core::arch::nvptx`: lane queries, warp vote
//! and shuffle, global atomics, and the panic handler.
//!
//! Warp-collective helpers use the full mask: every lane of the warp must call them together
//! (the strategies keep them in warp-uniform control flow).

use core::arch::asm;
use core::arch::nvptx;

/// A panic (an out-of-bounds grid index, say) aborts the kernel: the host sees a launch failure
/// instead of a wrong image.
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    // SAFETY: `trap` ends the kernel.
    unsafe { nvptx::trap() }
}

/// The global index of this thread in a one-dimensional launch.
#[inline(always)]
pub fn global_thread_index() -> u32 {
    // SAFETY: special-register reads.
    unsafe { nvptx::_block_idx_x() * nvptx::_block_dim_x() + nvptx::_thread_idx_x() }
}

#[inline(always)]
pub fn lane_id() -> u32 {
    let r: u32;
    // SAFETY: a special-register read.
    unsafe { asm!("mov.u32 {r}, %laneid;", r = out(reg32) r, options(nomem, nostack)) };
    r
}

/// The lanes below this one, as a bit mask.
#[inline(always)]
pub fn lanemask_lt() -> u32 {
    let r: u32;
    // SAFETY: a special-register read.
    unsafe { asm!("mov.u32 {r}, %lanemask_lt;", r = out(reg32) r, options(nomem, nostack)) };
    r
}

/// The lanes of the warp whose `pred` is true (warp-collective).
#[inline(always)]
pub fn ballot(pred: bool) -> u32 {
    let r: u32;
    // SAFETY: a warp vote; every lane calls it (see the module docs).
    unsafe {
        asm!(
            "{{ .reg .pred p; setp.ne.u32 p, {v}, 0; vote.sync.ballot.b32 {r}, p, 0xffffffff; }}",
            v = in(reg32) pred as u32,
            r = out(reg32) r,
            options(nomem, nostack)
        )
    };
    r
}

/// `v` of lane `src` (warp-collective).
#[inline(always)]
fn shfl_idx_u32(v: u32, src: u32) -> u32 {
    let r: u32;
    // SAFETY: a warp shuffle; every lane calls it.
    unsafe {
        asm!(
            "shfl.sync.idx.b32 {r}, {v}, {s}, 0x1f, 0xffffffff;",
            r = out(reg32) r,
            v = in(reg32) v,
            s = in(reg32) src,
            options(nomem, nostack)
        )
    };
    r
}

/// `v` of lane `lane + delta`, or this lane's own `v` past the warp's end (warp-collective).
#[inline(always)]
fn shfl_down_u32(v: u32, delta: u32) -> u32 {
    let r: u32;
    // SAFETY: a warp shuffle; every lane calls it.
    unsafe {
        asm!(
            "shfl.sync.down.b32 {r}, {v}, {d}, 0x1f, 0xffffffff;",
            r = out(reg32) r,
            v = in(reg32) v,
            d = in(reg32) delta,
            options(nomem, nostack)
        )
    };
    r
}

/// `v` of lane `src` (warp-collective).
#[inline(always)]
pub fn shfl_idx_u64(v: u64, src: u32) -> u64 {
    let lo = shfl_idx_u32(v as u32, src) as u64;
    let hi = shfl_idx_u32((v >> 32) as u32, src) as u64;
    lo | (hi << 32)
}

/// The sum of `v` over the warp, valid in lane 0 (warp-collective).
#[inline(always)]
pub fn warp_sum_u64(mut v: u64) -> u64 {
    let mut delta = 16;
    while delta > 0 {
        let lo = shfl_down_u32(v as u32, delta) as u64;
        let hi = shfl_down_u32((v >> 32) as u32, delta) as u64;
        v = v.wrapping_add(lo | (hi << 32));
        delta >>= 1;
    }
    v
}

/// Atomically adds `v` to `*addr` and returns the old value.
///
/// # Safety
/// `addr` must be a valid, aligned global-memory address.
#[inline(always)]
pub unsafe fn atomic_add_u64(addr: *mut u64, v: u64) -> u64 {
    let old: u64;
    // SAFETY: the caller's contract.
    unsafe {
        asm!(
            "atom.global.add.u64 {old}, [{a}], {v};",
            old = out(reg64) old,
            a = in(reg64) addr,
            v = in(reg64) v,
            options(nostack)
        )
    };
    old
}

/// Atomically adds `v` to `*addr`, returning nothing (a reduction, cheaper than an atomic).
///
/// # Safety
/// `addr` must be a valid, aligned global-memory address.
#[inline(always)]
pub unsafe fn red_add_u64(addr: *mut u64, v: u64) {
    // SAFETY: the caller's contract.
    unsafe {
        asm!(
            "red.global.add.u64 [{a}], {v};",
            a = in(reg64) addr,
            v = in(reg64) v,
            options(nostack)
        )
    };
}

/// Atomically adds `v` to `*addr` (IEEE round-to-nearest; the order of concurrent additions is not
/// defined, so sums differ from a sequential sum by rounding).
///
/// # Safety
/// `addr` must be a valid, aligned global-memory address.
#[inline(always)]
pub unsafe fn red_add_f64(addr: *mut f64, v: f64) {
    // SAFETY: the caller's contract.
    unsafe {
        asm!(
            "red.global.add.f64 [{a}], {v};",
            a = in(reg64) addr,
            v = in(reg64) v,
            options(nostack)
        )
    };
}
