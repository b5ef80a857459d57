//! The strategies' kernel bodies: who traces which path, and how results reach the film.
//!
//! Both trace the same paths as the CPU: path `(pixel, sample)` is `PathState::from_camera` with the
//! launch's seed, run by the shared `path::step`. They differ only in scheduling (the thesis' first
//! two strategies, after Novák, Havran & Dachsbacher 2010):
//!
//! - [`naive_sk`] (naiveSK): one thread per pixel traces that pixel's samples in order and sums them in
//!   `f64`, exactly as the CPU does, so the image is bit-identical to the CPU's. A warp waits for its
//!   longest path, and there are only `width * height` threads.
//! - [`regeneration_sk`] (regenerationSK): a persistent grid sized to fill the GPU; a thread advances its
//!   path one step at a time, and as soon as the path ends it records it and takes the next path index
//!   from a global counter (one atomic per warp and refill), so lanes do not idle behind long paths.
//!   Radiance reaches the film through `f64` atomic additions, whose order varies: the image agrees
//!   with the CPU's up to the rounding of the sums.

use volpt_core::path::{sample_pixel, step, PathCounters, PathState, Truncation};
use volpt_core::Scene;

use crate::launch::{path_of, LaunchParams, BLOCK_SIZE};
use crate::nvptx::{
    atomic_add_u64, ballot, block_broadcast_u64, block_exclusive_count, global_thread_index,
    lane_id, lanemask_lt, opaque, red_add_f64, red_add_u64, shared_address, shared_to_generic,
    shfl_idx_u64, sync_threads, sync_threads_or, thread_index, warp_sum_u64,
};

/// Adds the warp's counters to the launch's totals (warp-collective: every lane calls it).
#[inline(always)]
unsafe fn add_counters<P>(c: &PathCounters, lp: &LaunchParams<P>) {
    let totals = lp.counters as *mut u64;
    let values = [
        c.paths,
        c.segments,
        c.tracking_steps,
        c.truncated,
        c.truncated_tracking,
    ];
    let lane0 = lane_id() == 0;
    for (k, v) in values.into_iter().enumerate() {
        let sum = warp_sum_u64(v);
        if lane0 && sum != 0 {
            // SAFETY: `counters` holds `launch::COUNTERS` values.
            unsafe { red_add_u64(totals.add(k), sum) };
        }
    }
}

/// A thread's counts of the paths it finished, in 32 bits: three registers across the path loop
/// instead of five 64-bit totals (or contended 64-bit shared-memory atomics). A count that would
/// overflow goes to the launch's totals at once; the rest goes there at the end ([`Self::flush`]);
/// the rare truncated paths go there directly.
#[derive(Default)]
struct ThreadCounters {
    paths: u32,
    segments: u32,
    tracking_steps: u32,
}

impl ThreadCounters {
    /// # Safety
    /// `totals` must be the launch's `launch::COUNTERS` totals.
    #[inline(always)]
    unsafe fn record(&mut self, path: &PathState, totals: *mut u64) {
        // SAFETY: the caller's contract; the indices are those of `launch::COUNTERS`.
        unsafe {
            Self::add(&mut self.paths, 1, totals);
            Self::add(&mut self.segments, path.segments, totals.add(1));
            Self::add(&mut self.tracking_steps, path.tracking_steps, totals.add(2));
            if path.truncated != Truncation::None {
                red_add_u64(totals.add(3), 1);
                if path.truncated == Truncation::TrackingSteps {
                    red_add_u64(totals.add(4), 1);
                }
            }
        }
    }

    /// # Safety
    /// `total` must be a valid global `u64`.
    #[inline(always)]
    unsafe fn add(count: &mut u32, v: u32, total: *mut u64) {
        match count.checked_add(v) {
            Some(sum) => *count = sum,
            None => {
                // SAFETY: the caller's contract.
                unsafe { red_add_u64(total, *count as u64 + v as u64) };
                *count = 0;
            }
        }
    }

    /// Adds the counts to the launch's totals (warp-collective: every lane calls it).
    ///
    /// # Safety
    /// As [`add_counters`].
    #[inline(always)]
    unsafe fn flush<P>(self, lp: &LaunchParams<P>) {
        let counters = PathCounters {
            paths: self.paths as u64,
            segments: self.segments as u64,
            tracking_steps: self.tracking_steps as u64,
            truncated: 0,
            truncated_tracking: 0,
        };
        // SAFETY: forwarded.
        unsafe { add_counters(&counters, lp) };
    }
}

/// Records a finished path: its counts, and its radiance added to its pixel's `f64` sums.
///
/// # Safety
/// `film` must hold the `3 * pixels` sums and `pixel` be inside it; `totals` must be the launch's
/// `launch::COUNTERS` totals.
#[inline(always)]
unsafe fn finish_path(
    path: &PathState,
    pixel: u32,
    film: *mut f64,
    counters: &mut ThreadCounters,
    totals: *mut u64,
) {
    // SAFETY: the caller's contract.
    unsafe { counters.record(path, totals) };
    for c in 0..3 {
        let value = path.radiance[c];
        if value != 0.0 {
            // SAFETY: the caller's contract.
            unsafe { red_add_f64(film.add(3 * pixel as usize + c), value as f64) };
        }
    }
}

/// naiveSK: thread `i` renders the tile's pixel `i`, adding this launch's samples to its `f64` sum with the
/// CPU's own per-pixel loop, so the sums are the CPU's bit for bit.
///
/// # Safety
/// `lp.film` must hold `3 * width * height` `f64`s and `lp.counters` `launch::COUNTERS` `u64`s.
#[inline(always)]
pub unsafe fn naive_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    let width = scene.camera().width;
    let i = global_thread_index();
    let mut counters = PathCounters::default();
    if (i as u64) < lp.tile.pixels() {
        let (px, py, pixel) = lp.tile.film_pixel(i, width);
        // SAFETY: `pixel` is inside the film (the tile is), and no other thread touches it.
        let sum = unsafe { &mut *(lp.film as *mut [f64; 3]).add(pixel as usize) };
        let samples = lp.first_sample..lp.first_sample + lp.samples;
        sample_pixel(scene, (px, py), samples, lp.seed, sum, &mut counters);
    }
    // SAFETY: forwarded.
    unsafe { add_counters(&counters, lp) };
}

/// The lanes of the warp with `need` take consecutive indices from the counter `next`, in lane
/// order, with one atomic per warp (warp-collective). `None` if no lane of the warp needs one;
/// otherwise `Some` index, which is this lane's if it has `need`.
///
/// # Safety
/// `next` must be the device address of one `u64`.
#[inline(always)]
pub unsafe fn warp_take_indices(need: bool, next: *mut u64) -> Option<u64> {
    let wanting = ballot(need);
    if wanting == 0 {
        return None;
    }
    let leader = wanting.trailing_zeros();
    let mut base = 0;
    if lane_id() == leader {
        // SAFETY: the caller's contract.
        base = unsafe { atomic_add_u64(next, wanting.count_ones() as u64) };
    }
    let base = shfl_idx_u64(base, leader);
    Some(base + (wanting & lanemask_lt()).count_ones() as u64)
}

/// The threads of the block with `need` take consecutive indices from the counter `next`, in
/// thread order, with one atomic per block (block-collective: a block-wide exclusive scan and a
/// broadcast). `None` if no thread of the block needs one; otherwise `Some` index, which is this
/// thread's if it has `need`.
///
/// # Safety
/// `next` must be the device address of one `u64`.
#[inline(always)]
pub unsafe fn block_take_indices(need: bool, next: *mut u64) -> Option<u64> {
    let (rank, wanting) = block_exclusive_count(need);
    if wanting == 0 {
        return None;
    }
    // SAFETY: the caller's contract.
    let base = block_broadcast_u64(|| unsafe { atomic_add_u64(next, wanting as u64) });
    Some(base + rank as u64)
}

/// Where regeneration waits before an idle lane takes a new path (the thesis's synchronisation
/// levels of regenerationSK).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Refill {
    /// Idle lanes refill once `LaunchParams::refill_at` of them are idle (the host's default: 8),
    /// or when no lane of the warp is busy; the warp's idle lanes share one atomic.
    Thread,
    /// The warp refills only when all its lanes are idle: one atomic per 32 paths, and a warp's
    /// lanes start (and tend to end) together.
    Warp,
}

/// regenerationSK: persistent threads step their paths and refill finished lanes from a global
/// path counter. Path index `k` is sample `k / pixels` of pixel `k % pixels`, so the paths in flight
/// at any time are spread over the image and the film's atomics rarely collide.
///
/// # Safety
/// As [`naive_sk`]; and `lp.next_path` must be one zeroed `u64`, and the block size a multiple of 32.
#[inline(always)]
pub unsafe fn regeneration_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { regeneration(scene, lp, Refill::Thread) }
}

/// regenerationSK at warp level: see [`Refill::Warp`].
///
/// # Safety
/// As [`regeneration_sk`].
#[inline(always)]
pub unsafe fn regeneration_warp_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { regeneration(scene, lp, Refill::Warp) }
}

/// # Safety
/// As [`regeneration_sk`].
#[inline(always)]
unsafe fn regeneration<S: Scene, P>(scene: &S, lp: &LaunchParams<P>, refill: Refill) {
    let width = scene.camera().width;
    let pixels = lp.tile.pixels();
    let film = lp.film as *mut f64;
    let next_path = lp.next_path as *mut u64;
    let mut counters = ThreadCounters::default();
    let totals = lp.counters as *mut u64;
    // A placeholder until the first refill; `active` says whether `path` is a live path.
    let mut path = PathState::from_camera(scene, 0, 0, 0, lp.seed);
    let mut pixel = 0u32;
    let mut active = false;
    let mut exhausted = false;
    loop {
        // Refill: the lanes without a path take consecutive indices with one atomic per warp.
        let ready = match refill {
            // The threshold is the same for every lane, so every ballot is warp-uniform.
            Refill::Thread => {
                lp.refill_at <= 1
                    || ballot(!active && !exhausted).count_ones() >= lp.refill_at
                    || ballot(active) == 0
            }
            Refill::Warp => ballot(active) == 0,
        };
        let need = ready && !active && !exhausted;
        // SAFETY: `next_path` is one `u64` (the caller's contract).
        if let Some(index) = unsafe { warp_take_indices(need, next_path) } {
            if need {
                if index < lp.total_paths {
                    let sample;
                    let tile_pixel;
                    (tile_pixel, sample) = path_of(index, pixels, lp.first_sample);
                    let (px, py);
                    (px, py, pixel) = lp.tile.film_pixel(tile_pixel, width);
                    path = PathState::from_camera(scene, px, py, sample, lp.seed);
                    active = true;
                } else {
                    exhausted = true;
                }
            }
        }
        if ballot(active) == 0 {
            break;
        }
        if active {
            step(scene, &mut path);
            if !path.alive {
                // SAFETY: `pixel` is inside the film.
                unsafe { finish_path(&path, pixel, film, &mut counters, totals) };
                active = false;
            }
        }
    }
    // SAFETY: `lp.counters` holds `COUNTERS` totals.
    unsafe { counters.flush(lp) };
}

/// regenerationSK at block level: after every step the block counts its idle lanes (a block-wide
/// scan), takes that many path indices with one atomic, and hands them out in thread order.
///
/// # Safety
/// As [`regeneration_sk`]; every thread of the block runs it.
#[inline(always)]
pub unsafe fn regeneration_block_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    let width = scene.camera().width;
    let pixels = lp.tile.pixels();
    let film = lp.film as *mut f64;
    let next_path = lp.next_path as *mut u64;
    let mut counters = ThreadCounters::default();
    let totals = lp.counters as *mut u64;
    let mut path = PathState::from_camera(scene, 0, 0, 0, lp.seed);
    let mut pixel = 0u32;
    let mut active = false;
    let mut exhausted = false;
    loop {
        let need = opaque(!active && !exhausted);
        // SAFETY: `next_path` is one `u64` (the caller's contract).
        if let Some(index) = unsafe { block_take_indices(need, next_path) } {
            if need {
                if index < lp.total_paths {
                    let sample;
                    let tile_pixel;
                    (tile_pixel, sample) = path_of(index, pixels, lp.first_sample);
                    let (px, py);
                    (px, py, pixel) = lp.tile.film_pixel(tile_pixel, width);
                    path = PathState::from_camera(scene, px, py, sample, lp.seed);
                    active = true;
                } else {
                    exhausted = true;
                }
            }
        }
        if !sync_threads_or(opaque(active)) {
            break;
        }
        if active {
            step(scene, &mut path);
            if !path.alive {
                // SAFETY: `pixel` is inside the film.
                unsafe { finish_path(&path, pixel, film, &mut counters, totals) };
                active = false;
            }
        }
    }
    // SAFETY: `lp.counters` holds `COUNTERS` totals.
    unsafe { counters.flush(lp) };
}

/// A path parked in shared memory while the block compacts: its state and its pixel.
#[derive(Clone, Copy)]
#[repr(C)]
struct Slot {
    path: PathState,
    pixel: u32,
}

// One slot per thread of the block, for streamingSK's compaction.
core::arch::global_asm!(
    ".shared .align 16 .b8 volpt_stream_slots[{n}];",
    n = const core::mem::size_of::<Slot>() * BLOCK_SIZE as usize,
);

/// streamingSK (the thesis's algorithm 5, with compaction in the block): persistent blocks; after
/// every step the block compacts its live paths to its first threads (a block-wide exclusive scan
/// gives each live path its slot in shared memory) and the idle tail takes new paths with one
/// atomic per block. Live paths stay dense in the first warps, so the idle lanes are whole warps at
/// the end of the block, which refill together.
///
/// # Safety
/// As [`regeneration_sk`]; every thread of the block runs it.
#[inline(always)]
pub unsafe fn streaming_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    let width = scene.camera().width;
    let pixels = lp.tile.pixels();
    let film = lp.film as *mut f64;
    let next_path = lp.next_path as *mut u64;
    let slots = shared_to_generic(shared_address!("volpt_stream_slots")) as *mut Slot;
    let thread = thread_index();
    let mut counters = ThreadCounters::default();
    let totals = lp.counters as *mut u64;
    let mut slot = Slot {
        path: PathState::from_camera(scene, 0, 0, 0, lp.seed),
        pixel: 0,
    };
    let mut active = false;
    let mut exhausted = false;
    loop {
        if active {
            step(scene, &mut slot.path);
            if !slot.path.alive {
                // SAFETY: `pixel` is inside the film.
                unsafe { finish_path(&slot.path, slot.pixel, film, &mut counters, totals) };
                active = false;
            }
        }
        // Compaction: live path `rank` moves to thread `rank`.
        let (rank, live) = block_exclusive_count(opaque(active));
        if active {
            // SAFETY: `rank < BLOCK_SIZE` slots.
            unsafe { slots.add(rank as usize).write(slot) };
        }
        sync_threads();
        active = thread < live;
        if active {
            // SAFETY: written before the barrier by the thread of that rank.
            slot = unsafe { slots.add(thread as usize).read() };
        }
        // The slots are read before the next compaction writes them: the barrier in
        // `block_exclusive_count` below orders them.
        let need = opaque(!active && !exhausted);
        // SAFETY: `next_path` is one `u64` (the caller's contract).
        if let Some(index) = unsafe { block_take_indices(need, next_path) } {
            if need {
                if index < lp.total_paths {
                    let sample;
                    let tile_pixel;
                    (tile_pixel, sample) = path_of(index, pixels, lp.first_sample);
                    let (px, py);
                    (px, py, slot.pixel) = lp.tile.film_pixel(tile_pixel, width);
                    slot.path = PathState::from_camera(scene, px, py, sample, lp.seed);
                    active = true;
                } else {
                    exhausted = true;
                }
            }
        }
        if !sync_threads_or(opaque(active)) {
            break;
        }
    }
    // SAFETY: `lp.counters` holds `COUNTERS` totals.
    unsafe { counters.flush(lp) };
}
