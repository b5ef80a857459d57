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

use volpt_core::medium::Medium;
use volpt_core::path::{fly, sample_pixel, scatter, step, PathCounters, PathState, Truncation};
use volpt_core::{Scene, Spectrum, Vec3};

use crate::launch::{
    path_of, LaunchParams, Regeneration, Slot, Stage, Wavefront, BLOCK_SIZE, SLOT_BYTES,
};
use crate::nvptx::{
    atomic_add_u64, ballot, block_broadcast_u64, block_exclusive_count, block_sort_u32,
    global_thread_index, grid_threads, lane_id, lanemask_lt, opaque, opaque_u32, red_add_f64,
    red_add_u64, shared_address, shared_to_generic, shfl_idx_u64, sync_threads, sync_threads_or,
    thread_index, warp_sum_u64,
};
use crate::order::{morton30, INACTIVE_KEY};

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

/// Path index `index` of the launch ([`path_of`]) over its tile's `pixels` pixels: its first
/// state, from the camera, and its film pixel. The callers count `pixels` once, before their
/// loops, as they did before this was shared: counted here, the multiplication moved into every
/// refill and the kernels' branches were laid out anew.
#[inline(always)]
fn start_path<S: Scene, P>(scene: &S, lp: &LaunchParams<P>, pixels: u64, index: u64) -> Slot {
    let (tile_pixel, sample) = path_of(index, pixels, lp.first_sample);
    let (px, py, pixel) = lp.tile.film_pixel(tile_pixel, scene.camera().width);
    Slot {
        path: PathState::from_camera(scene, px, py, sample, lp.seed),
        pixel,
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

impl Refill {
    /// Whether the warp refills its idle lanes now, for a lane whose path is `active` (or none
    /// is left to take: `exhausted`). Warp-collective: the threshold is the same for every lane,
    /// so every vote is warp-uniform.
    #[inline(always)]
    fn ready<P>(self, lp: &LaunchParams<P>, active: bool, exhausted: bool) -> bool {
        match self {
            Refill::Thread => {
                lp.refill_at <= 1
                    || ballot(!active && !exhausted).count_ones() >= lp.refill_at
                    || ballot(active) == 0
            }
            Refill::Warp => ballot(active) == 0,
        }
    }
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
    let pixels = lp.tile.pixels();
    let film = lp.film as *mut f64;
    let next_path = lp.next_path as *mut u64;
    let mut counters = ThreadCounters::default();
    let totals = lp.counters as *mut u64;
    // A placeholder until the first refill; `active` says whether `path` is a live path.
    let mut path = PathState::from_camera(scene, 0, 0, 0, lp.seed);
    let mut pixel = 0u32;
    let mut active = false;
    // Warp-uniform: the launch's paths are all handed out. From then on the warp only steps its
    // paths to their ends, without the refill's votes: that tail sets the pace of the launch's
    // last, longest paths (docs/strategies.md).
    let mut exhausted = false;
    loop {
        if !exhausted {
            // Refill: the lanes without a path take consecutive indices with one atomic per warp.
            let need = refill.ready(lp, active, false) && !active;
            // SAFETY: `next_path` is one `u64` (the caller's contract).
            if let Some(index) = unsafe { warp_take_indices(need, next_path) } {
                if need && index < lp.total_paths {
                    Slot { path, pixel } = start_path(scene, lp, pixels, index);
                    active = true;
                }
                exhausted = ballot(need && index >= lp.total_paths) != 0;
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

/// regenerationSK with two paths per thread (the thesis's instruction-level-parallelism study):
/// each thread keeps two paths and steps both in every iteration, so that the latency of one
/// path's memory reads and long arithmetic can overlap the other's, at the price of twice the
/// path state in registers (lower occupancy). Each of the two path slots refills as
/// [`Refill::Thread`] does.
///
/// The paths live in an array walked by a loop, so that one copy of the step's code serves both;
/// the array is indexed at run time and so kept in local memory (the one kernel that keeps more
/// than the counters' 64 bytes there, `volpt-cuda/tests/ptx_entries.rs`). Two named paths stay in
/// registers but inline the step twice: on an H100 (2026-11-24,
/// `bench/results/2026-11-24-h100-strategies-all/bench-2p-named-slots.txt`) that kernel was
/// 1.2-3.5x slower than this one on five of seven scenes and 1.1-1.6x faster on two (ad, the
/// index-matched cube), and slower than regeneration-sk on all seven, like this one.
///
/// # Safety
/// As [`regeneration_sk`].
#[inline(always)]
pub unsafe fn regeneration_2p_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { regeneration_paths::<S, P, 2>(scene, lp) }
}

/// # Safety
/// As [`regeneration_sk`].
#[inline(always)]
unsafe fn regeneration_paths<S: Scene, P, const K: usize>(scene: &S, lp: &LaunchParams<P>) {
    let pixels = lp.tile.pixels();
    let film = lp.film as *mut f64;
    let next_path = lp.next_path as *mut u64;
    let mut counters = ThreadCounters::default();
    let totals = lp.counters as *mut u64;
    let mut paths = [PathState::from_camera(scene, 0, 0, 0, lp.seed); K];
    let mut pixel = [0u32; K];
    let mut active = [false; K];
    let mut exhausted = false;
    loop {
        for k in 0..K {
            // Every lane votes for every slot, so the votes stay warp-uniform.
            let need = Refill::Thread.ready(lp, active[k], exhausted) && !active[k] && !exhausted;
            // SAFETY: `next_path` is one `u64` (the caller's contract).
            if let Some(index) = unsafe { warp_take_indices(need, next_path) } {
                if need {
                    if index < lp.total_paths {
                        Slot {
                            path: paths[k],
                            pixel: pixel[k],
                        } = start_path(scene, lp, pixels, index);
                        active[k] = true;
                    } else {
                        exhausted = true;
                    }
                }
            }
        }
        if ballot(active.iter().any(|&a| a)) == 0 {
            break;
        }
        for k in 0..K {
            if active[k] {
                step(scene, &mut paths[k]);
                if !paths[k].alive {
                    // SAFETY: `pixel[k]` is inside the film.
                    unsafe { finish_path(&paths[k], pixel[k], film, &mut counters, totals) };
                    active[k] = false;
                }
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
                    Slot { path, pixel } = start_path(scene, lp, pixels, index);
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

// One slot per thread of the block, where streaming parks its paths to compact or sort them.
core::arch::global_asm!(
    ".shared .align 16 .b8 volpt_stream_slots[{n}];",
    n = const core::mem::size_of::<Slot>() * BLOCK_SIZE as usize,
);

// sorting-sk's collision points and their albedos, one per thread of the block.
core::arch::global_asm!(
    ".shared .align 4 .b8 volpt_sort_points[{n}];",
    ".shared .align 4 .b8 volpt_sort_albedos[{n}];",
    n = const 12 * BLOCK_SIZE as usize,
);

/// How streaming regroups a block's paths after every step.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Regroup {
    /// Live paths to the first threads, in thread order (a block-wide exclusive scan).
    Compact,
    /// Live paths to the first threads, in the Morton order of their positions (a block-wide
    /// radix sort whose ended paths have the largest key).
    SortPaths,
    /// As `Compact`, and before that each collision's albedo is read by the lane of its place in
    /// the Morton order of the block's collision points (the thesis's sortingSK).
    SortAlbedoReads,
}

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
    // SAFETY: forwarded.
    unsafe { streaming(scene, lp, Regroup::Compact) }
}

/// streamingSK with Morton sorting (the thesis's sorting variant of algorithm 5): as
/// [`streaming_sk`], but the live paths are ordered by the Morton codes of their positions
/// ([`crate::order::morton30`]; ended paths last), so that the lanes of a warp track through
/// neighbouring cells and read neighbouring voxels.
///
/// # Safety
/// As [`regeneration_sk`]; every thread of the block runs it.
#[inline(always)]
pub unsafe fn streaming_sorted_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { streaming(scene, lp, Regroup::SortPaths) }
}

/// sortingSK: as [`streaming_sk`], but each step stops at its collision
/// ([`volpt_core::path::fly`]), the block sorts its collision points by Morton code, each lane
/// reads the albedo at the point of its place in that order (neighbouring lanes, neighbouring
/// voxels) and hands it back to the path's lane, which then scatters
/// ([`volpt_core::path::scatter`]). The paths are those of the CPU: the albedo draws no random
/// number (unlike the thesis's sortingSK, which applied roulette before the deferred albedo). A
/// medium of constant albedo has no reads to order, and the step runs whole.
///
/// # Safety
/// As [`regeneration_sk`]; every thread of the block runs it.
#[inline(always)]
pub unsafe fn sorting_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { streaming(scene, lp, Regroup::SortAlbedoReads) }
}

/// One step of the block's live paths with the albedo of their collisions read in Morton order
/// (block-collective).
#[inline(always)]
fn step_with_sorted_albedo_reads<S: Scene>(scene: &S, path: &mut PathState, active: bool) {
    let points = shared_to_generic(shared_address!("volpt_sort_points")) as *mut [f32; 3];
    let albedos = shared_to_generic(shared_address!("volpt_sort_albedos")) as *mut [f32; 3];
    let thread = thread_index() as usize;
    let collision = if active { fly(scene, path) } else { None };
    let key = match collision {
        Some(p) => {
            // SAFETY: one point per thread of the block.
            unsafe { points.add(thread).write(p.to_array()) };
            // The random bits of a stochastic albedo lookup (those `scatter` would peek at),
            // parked in the albedo's slot for the lane that reads this point.
            let bits = path.rng.peek_u64();
            // SAFETY: as above; the slot holds 12 bytes.
            unsafe {
                (albedos.add(thread) as *mut [u32; 3]).write([bits as u32, (bits >> 32) as u32, 0])
            };
            morton30(p, &scene.bounds())
        }
        None => INACTIVE_KEY,
    };
    // The sort's barriers order the points' writes before their reads below.
    let (sorted, source) = block_sort_u32(opaque_u32(key));
    if sorted != INACTIVE_KEY {
        // SAFETY: `source` is a thread of the block that wrote its point.
        let p = Vec3::from_array(unsafe { points.add(source as usize).read() });
        // SAFETY: the source lane wrote its bits before the sort's barriers.
        let [lo, hi, _] = unsafe { (albedos.add(source as usize) as *const [u32; 3]).read() };
        let bits = u64::from(lo) | (u64::from(hi) << 32);
        let albedo = scene.medium().albedo_random(p, bits).to_array();
        // SAFETY: one albedo per thread of the block.
        unsafe { albedos.add(source as usize).write(albedo) };
    }
    sync_threads();
    if let Some(p) = collision {
        // SAFETY: written before the barrier by the lane that read this path's albedo.
        let albedo = Spectrum::from_array(unsafe { albedos.add(thread).read() });
        scatter(scene, path, p, Some(albedo));
    }
    // The albedos and points are read before the next step's writes: the barriers of the
    // compaction that follows order them.
}

/// # Safety
/// As [`regeneration_sk`]; every thread of the block runs it.
#[inline(always)]
unsafe fn streaming<S: Scene, P>(scene: &S, lp: &LaunchParams<P>, regroup: Regroup) {
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
    let sort_albedo_reads = regroup == Regroup::SortAlbedoReads && !S::Medium::CONSTANT_ALBEDO;
    loop {
        // A path that ends is recorded inside the step's branch, as streaming-sk did before
        // sorting-sk shared this loop (one check after both branches changed its kernels' code).
        if sort_albedo_reads {
            step_with_sorted_albedo_reads(scene, &mut slot.path, opaque(active));
            if active && !slot.path.alive {
                // SAFETY: `pixel` is inside the film.
                unsafe { finish_path(&slot.path, slot.pixel, film, &mut counters, totals) };
                active = false;
            }
        } else if active {
            step(scene, &mut slot.path);
            if !slot.path.alive {
                // SAFETY: `pixel` is inside the film.
                unsafe { finish_path(&slot.path, slot.pixel, film, &mut counters, totals) };
                active = false;
            }
        }
        if regroup == Regroup::SortPaths {
            // Sorting: each thread parks its path at its own index and takes the path of its
            // place in the Morton order; ended paths sort last.
            let key = if active {
                morton30(slot.path.ray.origin, &scene.bounds())
            } else {
                INACTIVE_KEY
            };
            let (sorted, source) = block_sort_u32(opaque_u32(key));
            if active {
                // SAFETY: one slot per thread of the block.
                unsafe { slots.add(thread as usize).write(slot) };
            }
            sync_threads();
            active = sorted != INACTIVE_KEY;
            if active {
                // SAFETY: written before the barrier by thread `source`, which was live.
                slot = unsafe { slots.add(source as usize).read() };
            }
        } else {
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
        }
        // The slots are read before the next regrouping writes them: the barrier in
        // `block_exclusive_count` below orders them.
        let need = opaque(!active && !exhausted);
        // SAFETY: `next_path` is one `u64` (the caller's contract).
        if let Some(index) = unsafe { block_take_indices(need, next_path) } {
            if need {
                if index < lp.total_paths {
                    slot = start_path(scene, lp, pixels, index);
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

/// naiveMK (the thesis's first multi-kernel strategy): a batch of one sample of every pixel is
/// started and traced to its end, one segment per launch, before the next batch starts; see
/// [`wavefront`].
///
/// # Safety
/// As [`wavefront`].
#[inline(always)]
pub unsafe fn naive_mk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { wavefront(scene, lp, Regeneration::WhenEmpty) }
}

/// streamingMK (the thesis's multi-kernel streaming, with device-wide compaction): after every
/// extension new paths fill the room the finished ones left; see [`wavefront`].
///
/// # Safety
/// As [`wavefront`].
#[inline(always)]
pub unsafe fn streaming_mk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { wavefront(scene, lp, Regeneration::Continuous) }
}

/// The multi-kernel strategies' stages ([`Stage`]): paths live in two queues in device memory;
/// extension advances every path of one queue by a segment and appends the survivors to the
/// other (device-wide compaction: the warp's survivors take consecutive places with one atomic
/// on the queue's count), the plan stage ([`Wavefront::plan`]) sizes the next batch of new paths,
/// and regeneration starts them and traces their first segment (the camera ray to the box and
/// beyond: the thesis's generate-and-first-intersection kernel), appending those still alive.
/// Each launch reads its work from the counters in device memory, so the host queues iteration
/// after iteration without waiting.
///
/// # Safety
/// `lp.queues` must hold `2 * lp.capacity` slots of [`SLOT_BYTES`] and `lp.wavefront` one
/// [`Wavefront`], zeroed before the launch's first iteration; the film and counters as
/// [`naive_sk`]; blocks of `BLOCK_SIZE` threads.
#[inline(always)]
unsafe fn wavefront<S: Scene, P>(scene: &S, lp: &LaunchParams<P>, regeneration: Regeneration) {
    let state = lp.wavefront as *mut Wavefront;
    let slot_at = |queue: u32, i: u64| -> *mut Slot {
        let index = queue as u64 * lp.capacity as u64 + i;
        (lp.queues + index * SLOT_BYTES as u64) as *mut Slot
    };
    let film = lp.film as *mut f64;
    let totals = lp.counters as *mut u64;
    let mut counters = ThreadCounters::default();
    let (parity, regenerate) = match Stage::from_code(lp.stage) {
        Stage::Plan { parity } => {
            if global_thread_index() == 0 {
                // SAFETY: one `Wavefront` (the caller's contract), and this the only thread.
                let state = unsafe { &mut *state };
                state.plan(parity, lp.capacity as u64, lp.total_paths, regeneration);
            }
            return;
        }
        Stage::Extend { parity } => (parity, false),
        Stage::Regenerate { parity } => (parity, true),
    };
    // SAFETY: `state` is one `Wavefront`, written by earlier launches only (a launch reads what
    // it works on before any thread of it writes the output queue's count).
    let (work, batch_first) = unsafe {
        let state = &*state;
        let work = if regenerate {
            state.batch_len
        } else {
            state.count[parity as usize]
        };
        (work, state.batch_first)
    };
    let output = 1 - parity;
    // SAFETY: as above; the survivors' count of the output queue.
    let output_count = unsafe { &raw mut (*state).count[output as usize] };
    let pixels = lp.tile.pixels();
    // The warp's lanes take consecutive items; `base` is the same in every lane of the warp, so
    // the loop and the append's vote stay warp-uniform.
    let stride = grid_threads() as u64;
    let mut base = (global_thread_index() - lane_id()) as u64;
    while base < work {
        let i = base + lane_id() as u64;
        let mut survivor = None;
        if i < work {
            let mut slot = if regenerate {
                start_path(scene, lp, pixels, batch_first + i)
            } else {
                // SAFETY: `i` is below the queue's count, at most its capacity.
                unsafe { slot_at(parity, i).read() }
            };
            step(scene, &mut slot.path);
            if slot.path.alive {
                survivor = Some(slot);
            } else {
                // SAFETY: `pixel` is inside the film.
                unsafe { finish_path(&slot.path, slot.pixel, film, &mut counters, totals) };
            }
        }
        let survives = opaque(survivor.is_some());
        // SAFETY: the output queue's count; survivors never exceed the capacity (`plan`).
        if let Some(place) = unsafe { warp_take_indices(survives, output_count) } {
            if let Some(slot) = survivor {
                // SAFETY: `place` is below the capacity.
                unsafe { slot_at(output, place).write(slot) };
            }
        }
        base += stride;
    }
    // SAFETY: `lp.counters` holds `COUNTERS` totals.
    unsafe { counters.flush(lp) };
}
