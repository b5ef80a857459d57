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

/// Threads in the whole one-dimensional launch.
#[inline(always)]
pub fn grid_threads() -> u32 {
    // SAFETY: special-register reads.
    unsafe { nvptx::_grid_dim_x() * nvptx::_block_dim_x() }
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

/// `v` of lane `lane - delta`, or this lane's own `v` below lane `delta` (warp-collective).
#[inline(always)]
fn shfl_up_u32(v: u32, delta: u32) -> u32 {
    let r: u32;
    // SAFETY: a warp shuffle; every lane calls it.
    unsafe {
        asm!(
            "shfl.sync.up.b32 {r}, {v}, {d}, 0, 0xffffffff;",
            r = out(reg32) r,
            v = in(reg32) v,
            d = in(reg32) delta,
            options(nomem, nostack)
        )
    };
    r
}

/// `b`, hidden from the optimiser: an opaque copy at the top of a loop that runs collectives keeps
/// LLVM from threading a value it knows on one edge (a path that just ended is inactive) into a
/// copy of the loop's collective code, where lanes would vote or wait at different instructions.
#[inline(always)]
pub fn opaque(b: bool) -> bool {
    let r: u32;
    // SAFETY: a register copy; not `pure`, so it is neither folded nor moved.
    unsafe {
        asm!("mov.b32 {r}, {v};", r = out(reg32) r, v = in(reg32) b as u32, options(nomem, nostack))
    };
    r != 0
}

/// `v`, hidden from the optimiser, as [`opaque`].
#[inline(always)]
pub fn opaque_u32(v: u32) -> u32 {
    let r: u32;
    // SAFETY: a register copy; not `pure`, so it is neither folded nor moved.
    unsafe {
        asm!("mov.b32 {r}, {v};", r = out(reg32) r, v = in(reg32) v, options(nomem, nostack))
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

/// The index of this thread in its (one-dimensional) block.
#[inline(always)]
pub fn thread_index() -> u32 {
    // SAFETY: a special-register read.
    unsafe { nvptx::_thread_idx_x() }
}

/// Waits for every thread of the block (`bar.sync 0`): every thread must call it.
#[inline(always)]
pub fn sync_threads() {
    // SAFETY: a barrier; the callers keep it in block-uniform control flow.
    unsafe { nvptx::_syncthreads() }
}

/// Whether `pred` holds in any thread of the block, as a barrier (`bar.red.or`): every thread must
/// call it.
#[inline(always)]
pub fn sync_threads_or(pred: bool) -> bool {
    let r: u32;
    // SAFETY: a barrier with a reduction; the callers keep it in block-uniform control flow.
    unsafe {
        asm!(
            "{{ .reg .pred p, q; setp.ne.u32 p, {v}, 0; bar.red.or.pred q, 0, p; selp.u32 {r}, 1, 0, q; }}",
            v = in(reg32) pred as u32,
            r = out(reg32) r,
            options(nostack)
        )
    };
    r != 0
}

// Block-collective scratch: one count per warp of the block, and one value broadcast to the block.
core::arch::global_asm!(
    ".shared .align 4 .b32 volpt_warp_counts[32];",
    ".shared .align 8 .b64 volpt_block_value;",
);

/// The shared-memory address of a module-scope shared variable, by name.
macro_rules! shared_address {
    ($name:literal) => {{
        let a: u64;
        // SAFETY: the address of a module-scope shared variable.
        unsafe {
            core::arch::asm!(concat!("mov.u64 {a}, ", $name, ";"), a = out(reg64) a,
                options(pure, nomem, nostack))
        };
        a
    }};
}
pub(crate) use shared_address;

/// The number of threads before this one in the block (in thread order) whose `pred` is true, and
/// the number over the whole block: a block-wide exclusive scan of `pred` by warp ballots and one
/// count per warp in shared memory (block-collective: every thread must call it; two barriers).
#[inline(always)]
pub fn block_exclusive_count(pred: bool) -> (u32, u32) {
    let votes = ballot(pred);
    let warp = thread_index() / 32;
    let warps = crate::launch::BLOCK_SIZE / 32;
    let counts = shared_address!("volpt_warp_counts");
    if lane_id() == 0 {
        // SAFETY: `warp < 32` words of `volpt_warp_counts`.
        unsafe {
            asm!("st.shared.u32 [{a}], {v};", a = in(reg64) counts + 4 * warp as u64,
                v = in(reg32) votes.count_ones(), options(nostack))
        };
    }
    sync_threads();
    let mut before = 0;
    let mut total = 0;
    for w in 0..warps {
        let n: u32;
        // SAFETY: `w < 32` words of `volpt_warp_counts`, written before the barrier.
        unsafe {
            asm!("ld.shared.u32 {n}, [{a}];", n = out(reg32) n, a = in(reg64) counts + 4 * w as u64,
                options(nostack))
        };
        if w < warp {
            before += n;
        }
        total += n;
    }
    // The counts are read before any thread can overwrite them in the next call.
    sync_threads();
    (before + (votes & lanemask_lt()).count_ones(), total)
}

// Scratch of the block-wide radix sort: the count of each 4-bit digit in each warp, and the
// (key, source thread) pairs exchanged after each pass.
core::arch::global_asm!(
    ".shared .align 4 .b32 volpt_digit_counts[{n}];",
    ".shared .align 8 .b64 volpt_sort_pairs[{b}];",
    n = const 16 * crate::launch::BLOCK_SIZE / 32,
    b = const crate::launch::BLOCK_SIZE,
);

/// This thread's place in a stable counting sort of the block's 4-bit `digit`s (`digit < 16`):
/// the threads with a smaller digit, plus those before this one with the same digit
/// (block-collective: every thread must call it; two barriers). Each warp votes once per digit
/// value and its lane `v` stores the count of digit `v`; then lane `v` of every warp sums digit
/// `v` over the block and over the warps before its own, and a scan over the first 16 lanes turns
/// the block's counts into the first place of each digit.
#[inline(always)]
pub fn block_digit_rank(digit: u32) -> u32 {
    let warp = thread_index() / 32;
    let warps = crate::launch::BLOCK_SIZE / 32;
    let lane = lane_id();
    let counts = shared_address!("volpt_digit_counts");
    let mut same = 0;
    for v in 0..16 {
        let votes = ballot(digit == v);
        if digit == v {
            same = votes;
        }
        if lane == v {
            // SAFETY: `16 * warp + v` is inside `volpt_digit_counts`.
            unsafe {
                asm!("st.shared.u32 [{a}], {n};", a = in(reg64) counts + 4 * (16 * warp + v) as u64,
                    n = in(reg32) votes.count_ones(), options(nostack))
            };
        }
    }
    sync_threads();
    // Lane `v < 16`: digit `v`'s count over the block and over the warps before this one.
    let (mut total, mut before) = (0u32, 0u32);
    if lane < 16 {
        for w in 0..warps {
            let n: u32;
            // SAFETY: written before the barrier.
            unsafe {
                asm!("ld.shared.u32 {n}, [{a}];", n = out(reg32) n,
                    a = in(reg64) counts + 4 * (16 * w + lane) as u64, options(nostack))
            };
            total += n;
            if w < warp {
                before += n;
            }
        }
    }
    // The counts are read before any thread can overwrite them in the next call.
    sync_threads();
    // Inclusive scan of `total` over the lanes; lanes from 16 on hold 0.
    let mut scan = total;
    let mut delta = 1;
    while delta < 16 {
        let up = shfl_up_u32(scan, delta);
        if lane >= delta {
            scan += up;
        }
        delta <<= 1;
    }
    let first = scan - total + before;
    shfl_idx_u32(first, digit) + (same & lanemask_lt()).count_ones()
}

/// The block's 32-bit keys sorted ascending (stably: equal keys in thread order): this thread's
/// place's key and the thread that held it. A least-significant-digit radix sort, eight passes of
/// [`block_digit_rank`] on 4-bit digits, each followed by an exchange of (key, source) pairs
/// through shared memory (block-collective: every thread must call it).
#[inline(always)]
pub fn block_sort_u32(key: u32) -> (u32, u32) {
    let pairs = shared_to_generic(shared_address!("volpt_sort_pairs")) as *mut u64;
    let thread = thread_index();
    let (mut key, mut source) = (key, thread);
    for pass in 0..8 {
        let rank = block_digit_rank((key >> (4 * pass)) & 15);
        // SAFETY: `rank < BLOCK_SIZE` pairs; the ranks of the block are a permutation.
        unsafe {
            pairs
                .add(rank as usize)
                .write(((key as u64) << 32) | source as u64)
        };
        sync_threads();
        // SAFETY: written before the barrier.
        let pair = unsafe { pairs.add(thread as usize).read() };
        (key, source) = ((pair >> 32) as u32, pair as u32);
        // Read before the next pass writes.
        sync_threads();
    }
    (key, source)
}

/// Thread 0's `f()`, seen by every thread of the block (block-collective; two barriers).
#[inline(always)]
pub fn block_broadcast_u64(f: impl FnOnce() -> u64) -> u64 {
    let slot = shared_address!("volpt_block_value");
    if thread_index() == 0 {
        let v = f();
        // SAFETY: one `u64` of shared memory.
        unsafe {
            asm!("st.shared.u64 [{a}], {v};", a = in(reg64) slot, v = in(reg64) v, options(nostack))
        };
    }
    sync_threads();
    let v: u64;
    // SAFETY: as above, written before the barrier.
    unsafe {
        asm!("ld.shared.u64 {v}, [{a}];", v = out(reg64) v, a = in(reg64) slot, options(nostack))
    };
    // Read before thread 0 can write the next value.
    sync_threads();
    v
}

/// A generic pointer to shared-memory address `shared` (`cvta.shared`), for plain loads and stores.
#[inline(always)]
pub fn shared_to_generic(shared: u64) -> u64 {
    let p: u64;
    // SAFETY: an address conversion.
    unsafe {
        asm!("cvta.shared.u64 {p}, {s};", p = out(reg64) p, s = in(reg64) shared,
            options(pure, nomem, nostack))
    };
    p
}
