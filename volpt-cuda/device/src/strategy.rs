//! The strategies' kernel bodies: who traces which path, and how results reach the film.
//!
//! Every strategy traces the CPU's paths: path index `k` of a launch is sample `k / pixels` of the
//! tile's pixel `k % pixels` ([`path_of`]), started by `PathState::from_camera` with the launch's
//! seed and advanced by the shared `path::step`. They differ only in scheduling (the thesis's
//! strategies, after Novák, Havran & Dachsbacher 2010):
//!
//! - [`naive_sk`]: one thread per pixel traces that pixel's samples in order and sums them in `f64`
//!   with the CPU's own loop, so its image is the CPU's bit for bit.
//! - The persistent strategies, each one [`persistent`] loop: a grid sized to fill the GPU, whose
//!   threads keep one or two path slots ([`Lane`]s) and repeat: refill idle lanes from the launch's
//!   path counter ([`Refill`]: at thread, warp or block level), stop once the refill's group has
//!   no live path, advance every live path by one step ([`Advance`]: in place, or followed by
//!   regrouping the block's paths). A thread's [`PathPool`] starts its paths and records the
//!   ended ones.
//! - The multi-kernel strategies ([`multi_kernel`]): paths queued in device memory, one step per
//!   launch.
//!
//! The persistent and multi-kernel strategies add radiance to the film with `f64` atomics in the
//! order paths end: their images agree with the CPU's up to the rounding of those sums.
//!
//! # Collectives
//!
//! A warp-collective operation (vote, shuffle) must be reached by every lane of the warp, a
//! block-collective one (barrier) by every thread of the block, at the same instruction; each
//! function says which it is. Collectives therefore sit outside branches on per-lane values, and
//! the loop's exit test is uniform over the group of the refill. Where a per-lane flag that a
//! branch just set feeds a collective, it passes through [`opaque`]: LLVM otherwise threads the
//! value it knows on one edge (a path that just ended is inactive) into a copy of the collective
//! code, and lanes vote or wait at different instructions.

use volpt_core::medium::Medium;
use volpt_core::path::{
    fly, sample_pixel, scatter, step, PathCounters, PathOf, PathState, SpectralOf, Truncation,
};
use volpt_core::{HeroChannel, SpectralState};
use volpt_core::{Scene, Spectrum, Vec3};

use crate::launch::{path_of, LaunchParams, Slot, Stage, Wavefront, BLOCK_SIZE, SLOT_BYTES};
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
    unsafe fn record<X>(&mut self, path: &PathState<X>, totals: *mut u64) {
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

/// A thread's side of a launch: where its paths start (path indices from the launch's counter,
/// the tile's pixels) and where an ended path goes (its pixel's `f64` sums, the path counts).
struct PathPool<'a, S, P> {
    scene: &'a S,
    lp: &'a LaunchParams<P>,
    /// The tile's pixel count, computed once per launch rather than at every refill.
    pixels: u64,
    film: *mut f64,
    next_path: *mut u64,
    totals: *mut u64,
    counters: ThreadCounters,
    /// Every path index of the launch has been handed out: a refill starts no path any more. The
    /// [`Refill`] policy sets it, and says whether it is uniform over its group.
    exhausted: bool,
}

impl<'a, S: Scene, P> PathPool<'a, S, P> {
    /// # Safety
    /// `lp.film` must hold the film's `3 * width * height` `f64` sums, `lp.counters` the
    /// `launch::COUNTERS` totals and `lp.next_path` one `u64`, all alive until the kernel ends:
    /// the pool's other methods rely on it.
    #[inline(always)]
    unsafe fn new(scene: &'a S, lp: &'a LaunchParams<P>) -> Self {
        PathPool {
            scene,
            lp,
            pixels: lp.tile.pixels(),
            film: lp.film as *mut f64,
            next_path: lp.next_path as *mut u64,
            totals: lp.counters as *mut u64,
            counters: ThreadCounters::default(),
            exhausted: false,
        }
    }

    /// A lane without a path: its path is a placeholder until a refill starts one.
    #[inline(always)]
    fn idle_lane(&self) -> Lane<SpectralOf<S>> {
        Lane {
            path: PathState::from_camera(self.scene, 0, 0, 0, self.lp.seed),
            pixel: 0,
            active: false,
        }
    }

    /// Path `index` of the launch ([`path_of`]): its first state, from the camera, and its film
    /// pixel.
    #[inline(always)]
    fn start(&self, index: u64) -> Slot<SpectralOf<S>> {
        let (tile_pixel, sample) = path_of(index, self.pixels, self.lp.first_sample);
        let (px, py, pixel) = self
            .lp
            .tile
            .film_pixel(tile_pixel, self.scene.camera().width);
        Slot {
            path: PathState::from_camera(self.scene, px, py, sample, self.lp.seed),
            pixel,
        }
    }

    /// Starts path `index` in `lane`, which becomes live.
    #[inline(always)]
    fn start_in(&self, lane: &mut Lane<SpectralOf<S>>, index: u64) {
        let Slot { path, pixel } = self.start(index);
        lane.path = path;
        lane.pixel = pixel;
        lane.active = true;
    }

    /// Records a finished path: its counts, and its radiance added to its pixel's `f64` sums.
    ///
    /// # Safety
    /// `pixel` must be a pixel of the launch's film (every [`Self::start`]ed path's is).
    #[inline(always)]
    unsafe fn record(&mut self, path: &PathOf<S>, pixel: u32) {
        // SAFETY: `totals` holds the launch's `launch::COUNTERS` totals.
        unsafe { self.counters.record(path, self.totals) };
        for c in 0..3 {
            let value = path.radiance[c];
            if value != 0.0 {
                // SAFETY: the film holds `3 * pixels` sums and `pixel` is inside it.
                unsafe { red_add_f64(self.film.add(3 * pixel as usize + c), value as f64) };
            }
        }
    }

    /// Records the path of a live `lane` if it has ended, and idles the lane.
    #[inline(always)]
    fn retire_if_ended(&mut self, lane: &mut Lane<SpectralOf<S>>) {
        if !lane.path.alive {
            // SAFETY: a live lane's pixel is its started path's.
            unsafe { self.record(&lane.path, lane.pixel) };
            lane.active = false;
        }
    }

    /// One step of `lane`'s path if it is live; an ended path is recorded and the lane idles.
    #[inline(always)]
    fn step(&mut self, lane: &mut Lane<SpectralOf<S>>) {
        if lane.active {
            step(self.scene, &mut lane.path);
            self.retire_if_ended(lane);
        }
    }

    /// Adds the thread's path counts to the launch's totals (warp-collective: every lane calls
    /// it, at the kernel's end).
    #[inline(always)]
    fn flush(self) {
        // SAFETY: `lp.counters` holds `launch::COUNTERS` totals.
        unsafe { self.counters.flush(self.lp) };
    }
}

/// One path slot of a thread: a path and its film pixel, traced while `active`. An idle lane's
/// path is a placeholder or the path it last finished, and is never stepped.
#[derive(Clone, Copy)]
struct Lane<X> {
    path: PathState<X>,
    pixel: u32,
    active: bool,
}

/// The lanes a thread keeps: one [`Lane`], or an array of them that one copy of the step's code
/// walks in turn.
trait Lanes: Copy {
    /// The spectral state of the lanes' paths.
    type X: SpectralState;
    fn idle(lane: Lane<Self::X>) -> Self;
    /// Calls `f` on every lane, in order.
    fn each(&mut self, f: impl FnMut(&mut Lane<Self::X>));
    /// Whether any of this thread's lanes is live (no vote).
    fn any_active(&self) -> bool;
}

impl<X: SpectralState> Lanes for Lane<X> {
    type X = X;

    #[inline(always)]
    fn idle(lane: Lane<X>) -> Self {
        lane
    }

    #[inline(always)]
    fn each(&mut self, mut f: impl FnMut(&mut Lane<X>)) {
        f(self)
    }

    #[inline(always)]
    fn any_active(&self) -> bool {
        self.active
    }
}

/// `K` lanes walked by a loop: the array is indexed at run time and so kept in local memory (the
/// one kind of kernel that keeps more than the counters' 64 bytes there,
/// `volpt-cuda/tests/ptx_entries.rs`). Unrolled, the step's code would be inlined `K` times.
impl<X: SpectralState, const K: usize> Lanes for [Lane<X>; K] {
    type X = X;

    #[inline(always)]
    fn idle(lane: Lane<X>) -> Self {
        [lane; K]
    }

    #[inline(always)]
    fn each(&mut self, mut f: impl FnMut(&mut Lane<X>)) {
        for lane in self.iter_mut() {
            f(lane)
        }
    }

    #[inline(always)]
    fn any_active(&self) -> bool {
        self.iter().any(|lane| lane.active)
    }
}

/// When idle lanes take new paths from the launch's counter, and over which group of threads
/// the persistent loop decides to go on (the thesis's synchronisation levels of regenerationSK).
trait Refill {
    /// The group is the block: [`Self::refill`] and [`Self::any_live`] are block-collective.
    /// Otherwise it is the warp, and they are warp-collective.
    const BLOCK: bool;

    /// Gives idle lanes the next path indices, in lane order, and sets `pool.exhausted` once the
    /// indices run out. Every thread of the group calls it at the same point with all its lanes.
    fn refill<S: Scene, P, L: Lanes<X = SpectralOf<S>>>(
        pool: &mut PathPool<'_, S, P>,
        lanes: &mut L,
    );

    /// Whether any lane of the group is live, given whether this thread's are: the same answer
    /// in every thread of the group, so that the group leaves the loop together.
    #[inline(always)]
    fn any_live(live: bool) -> bool {
        ballot(live) != 0
    }
}

/// Warp level, refilling by threshold: the warp's idle lanes take paths once
/// `LaunchParams::refill_at` of them are idle (the host's default: 8; 1: at once), or when no lane
/// of the warp is busy; they share one atomic.
struct ThreadRefill;

/// Warp level, refilling whole warps: the warp's lanes take paths only when all of them are idle
/// (one atomic per 32 paths), so they start, and tend to end, together.
struct WarpRefill;

/// Block level: after every step the block counts its idle lanes (a block-wide scan), takes that
/// many path indices with one atomic and hands them out in thread order.
struct BlockRefill;

/// The refill of the warp-level policies, which differ in when the warp is `ready` (a vote,
/// warp-uniform). `pool.exhausted` is warp-uniform: once one lane of the warp receives an index
/// past the launch's paths every later index is past them too, and from then on the warp only
/// steps its paths to their ends, without the refill's votes (that tail sets the pace of the
/// launch's last, longest paths, docs/strategies.md).
#[inline(always)]
fn warp_refill<S: Scene, P, L: Lanes<X = SpectralOf<S>>>(
    pool: &mut PathPool<'_, S, P>,
    lanes: &mut L,
    ready: impl Fn(&LaunchParams<P>, bool) -> bool,
) {
    if pool.exhausted {
        return;
    }
    lanes.each(
        #[inline(always)]
        |lane| {
            let need = ready(pool.lp, lane.active) && !lane.active;
            // SAFETY: `next_path` is the launch's one path counter.
            if let Some(index) = unsafe { warp_take_indices(need, pool.next_path) } {
                if need && index < pool.lp.total_paths {
                    pool.start_in(lane, index);
                }
                pool.exhausted = ballot(need && index >= pool.lp.total_paths) != 0;
            }
        },
    );
}

impl Refill for ThreadRefill {
    const BLOCK: bool = false;

    #[inline(always)]
    fn refill<S: Scene, P, L: Lanes<X = SpectralOf<S>>>(
        pool: &mut PathPool<'_, S, P>,
        lanes: &mut L,
    ) {
        warp_refill(
            pool,
            lanes,
            #[inline(always)]
            |lp, active| {
                lp.refill_at <= 1
                    || ballot(!active).count_ones() >= lp.refill_at
                    || ballot(active) == 0
            },
        )
    }
}

impl Refill for WarpRefill {
    const BLOCK: bool = false;

    #[inline(always)]
    fn refill<S: Scene, P, L: Lanes<X = SpectralOf<S>>>(
        pool: &mut PathPool<'_, S, P>,
        lanes: &mut L,
    ) {
        warp_refill(
            pool,
            lanes,
            #[inline(always)]
            |_, active| ballot(active) == 0,
        )
    }
}

/// `pool.exhausted` is per thread here: set in the threads that received an index past the
/// launch's paths, which take none after that.
impl Refill for BlockRefill {
    const BLOCK: bool = true;

    #[inline(always)]
    fn refill<S: Scene, P, L: Lanes<X = SpectralOf<S>>>(
        pool: &mut PathPool<'_, S, P>,
        lanes: &mut L,
    ) {
        lanes.each(
            #[inline(always)]
            |lane| {
                let need = opaque(!lane.active && !pool.exhausted);
                // SAFETY: `next_path` is the launch's one path counter.
                if let Some(index) = unsafe { block_take_indices(need, pool.next_path) } {
                    if need {
                        if index < pool.lp.total_paths {
                            pool.start_in(lane, index);
                        } else {
                            pool.exhausted = true;
                        }
                    }
                }
            },
        );
    }

    #[inline(always)]
    fn any_live(live: bool) -> bool {
        sync_threads_or(opaque(live))
    }
}

/// How one iteration of the persistent loop advances a thread's lanes `L`.
trait Advance<L: Lanes> {
    /// [`Self::advance`] is block-collective: it runs only under a block-level [`Refill`], whose
    /// exit test keeps the whole block in the loop.
    const BLOCK: bool;

    /// The loop advances before the refill (advance, refill, exit test) rather than after the
    /// exit test (refill, exit test, advance). Both orders do the same work, since the first
    /// advance finds every lane idle, but compile to different kernels: the regroupings keep
    /// the order their kernels were measured in; in the other, streaming-sk took +5% on the
    /// index-matched cube and -8% on the dielectric one (H100, 2026-11-26,
    /// `bench/results/2026-11-26-h100-pool/ab.txt`).
    const FIRST: bool;

    /// What the advance computes once, before the loop (the shared-memory slots' address).
    type Setup: Copy;
    fn setup() -> Self::Setup;

    fn advance<S: Scene<Medium: Medium<Spectral = L::X>>, P>(
        setup: Self::Setup,
        pool: &mut PathPool<'_, S, P>,
        lanes: &mut L,
    );
}

/// Each lane steps its own path (no collective).
struct InPlace;

/// streamingSK's compaction: after the step the block's live paths move to its first threads, in
/// thread order (a block-wide exclusive scan gives each its slot in shared memory), so that the
/// idle lanes are whole warps at the block's end, which refill together.
struct Compact;

/// streamingSK with Morton sorting (the thesis's sorting variant of its algorithm 5): after the
/// step the block's live paths move to its first threads in the Morton order of their positions
/// ([`crate::order::morton30`]; a block-wide radix sort in which ended paths have the largest
/// key), so that the lanes of a warp track through neighbouring cells and read neighbouring voxels.
struct SortPaths;

/// sortingSK: each step stops at its collision ([`volpt_core::path::fly`]), the block sorts its
/// collision points by Morton code, each lane reads the albedo at the point of its place in that
/// order (neighbouring lanes, neighbouring voxels) and hands it back to the path's lane, which then
/// scatters ([`volpt_core::path::scatter`]); then the block compacts as [`Compact`]. The paths are
/// those of the CPU: the albedo draws no random number (unlike the thesis's sortingSK, which
/// applied roulette before the deferred albedo). A medium of constant albedo has no reads to
/// order, and the step runs whole.
struct SortAlbedoReads;

impl<L: Lanes> Advance<L> for InPlace {
    const BLOCK: bool = false;
    const FIRST: bool = false;
    type Setup = ();

    #[inline(always)]
    fn setup() {}

    #[inline(always)]
    fn advance<S: Scene<Medium: Medium<Spectral = L::X>>, P>(
        _: (),
        pool: &mut PathPool<'_, S, P>,
        lanes: &mut L,
    ) {
        lanes.each(
            #[inline(always)]
            |lane| pool.step(lane),
        );
    }
}

impl<X: SpectralState> Advance<Lane<X>> for Compact {
    const BLOCK: bool = true;
    const FIRST: bool = true;
    type Setup = BlockSlots;

    #[inline(always)]
    fn setup() -> BlockSlots {
        BlockSlots::new()
    }

    #[inline(always)]
    fn advance<S: Scene<Medium: Medium<Spectral = X>>, P>(
        block: BlockSlots,
        pool: &mut PathPool<'_, S, P>,
        lane: &mut Lane<X>,
    ) {
        pool.step(lane);
        compact(block, lane);
    }
}

impl<X: SpectralState> Advance<Lane<X>> for SortPaths {
    const BLOCK: bool = true;
    const FIRST: bool = true;
    type Setup = BlockSlots;

    #[inline(always)]
    fn setup() -> BlockSlots {
        BlockSlots::new()
    }

    #[inline(always)]
    fn advance<S: Scene<Medium: Medium<Spectral = X>>, P>(
        block: BlockSlots,
        pool: &mut PathPool<'_, S, P>,
        lane: &mut Lane<X>,
    ) {
        pool.step(lane);
        // Each thread parks its live path at its own index and takes the path of its place in
        // the Morton order.
        let (slots, thread) = (block.of::<X>(), block.thread);
        let key = if lane.active {
            morton30(lane.path.ray.origin, &pool.scene.bounds())
        } else {
            INACTIVE_KEY
        };
        let (sorted, source) = block_sort_u32(opaque_u32(key));
        if lane.active {
            // SAFETY: one slot per thread of the block.
            unsafe { slots.add(thread as usize).write(lane.slot()) };
        }
        sync_threads();
        lane.active = sorted != INACTIVE_KEY;
        if lane.active {
            // SAFETY: written before the barrier by thread `source`, which was live.
            lane.set_slot(unsafe { slots.add(source as usize).read() });
        }
        // The slots are read before the next regrouping writes them: the barriers of the next
        // refill's block-wide scan order them.
    }
}

impl<X: SpectralState> Advance<Lane<X>> for SortAlbedoReads {
    const BLOCK: bool = true;
    const FIRST: bool = true;
    type Setup = BlockSlots;

    #[inline(always)]
    fn setup() -> BlockSlots {
        BlockSlots::new()
    }

    #[inline(always)]
    fn advance<S: Scene<Medium: Medium<Spectral = X>>, P>(
        block: BlockSlots,
        pool: &mut PathPool<'_, S, P>,
        lane: &mut Lane<X>,
    ) {
        if S::Medium::CONSTANT_ALBEDO {
            pool.step(lane);
        } else {
            step_with_sorted_albedo_reads(pool.scene, &mut lane.path, opaque(lane.active));
            if lane.active {
                pool.retire_if_ended(lane);
            }
        }
        compact(block, lane);
    }
}

impl<X: SpectralState> Lane<X> {
    #[inline(always)]
    fn slot(&self) -> Slot<X> {
        Slot {
            path: self.path,
            pixel: self.pixel,
        }
    }

    #[inline(always)]
    fn set_slot(&mut self, slot: Slot<X>) {
        self.path = slot.path;
        self.pixel = slot.pixel;
    }
}

// One slot per thread of the block, where the regroupings park its paths: the largest slot, a
// chromatic path's (one array serves every kernel of the module).
core::arch::global_asm!(
    ".shared .align 16 .b8 volpt_stream_slots[{n}];",
    n = const core::mem::size_of::<Slot<HeroChannel>>() * BLOCK_SIZE as usize,
);

/// The block's path slots in shared memory, one per thread, and this thread's index there;
/// computed once per kernel, before the loop (the address comes from asm, which LLVM does not
/// hoist out of a loop). The slots' type is the paths' ([`BlockSlots::of`]).
#[derive(Clone, Copy)]
struct BlockSlots {
    slots: *mut u8,
    thread: u32,
}

impl BlockSlots {
    #[inline(always)]
    fn new() -> Self {
        BlockSlots {
            slots: shared_to_generic(shared_address!("volpt_stream_slots")) as *mut u8,
            thread: thread_index(),
        }
    }

    /// The slots as slots of paths of spectral state `X` (at most as large as the array's).
    #[inline(always)]
    fn of<X: SpectralState>(self) -> *mut Slot<X> {
        const { assert!(core::mem::size_of::<Slot<X>>() <= core::mem::size_of::<Slot<HeroChannel>>()) };
        self.slots as *mut Slot<X>
    }
}

/// The block's live paths move to its first threads, in thread order: live path `rank` to thread
/// `rank` (block-collective).
#[inline(always)]
fn compact<X: SpectralState>(block: BlockSlots, lane: &mut Lane<X>) {
    let (slots, thread) = (block.of::<X>(), block.thread);
    let (rank, live) = block_exclusive_count(opaque(lane.active));
    if lane.active {
        // SAFETY: `rank < BLOCK_SIZE` slots.
        unsafe { slots.add(rank as usize).write(lane.slot()) };
    }
    sync_threads();
    lane.active = thread < live;
    if lane.active {
        // SAFETY: written before the barrier by the thread of that rank.
        lane.set_slot(unsafe { slots.add(thread as usize).read() });
    }
    // The slots are read before the next regrouping writes them: the barriers of the next
    // refill's block-wide scan order them.
}

// sorting-sk's collision points and their albedos, one per thread of the block.
core::arch::global_asm!(
    ".shared .align 4 .b8 volpt_sort_points[{n}];",
    ".shared .align 4 .b8 volpt_sort_albedos[{n}];",
    n = const 12 * BLOCK_SIZE as usize,
);

/// One step of the block's live paths with the albedo of their collisions read in Morton order
/// (block-collective).
#[inline(always)]
fn step_with_sorted_albedo_reads<S: Scene>(scene: &S, path: &mut PathOf<S>, active: bool) {
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

/// The persistent loop: refill the idle lanes, leave once the refill's group has no live path,
/// advance the live paths by a step (or advance first: [`Advance::FIRST`]); at the end add the
/// thread's path counts to the launch's.
///
/// # Safety
/// `lp.film` must hold `3 * width * height` `f64`s, `lp.counters` `launch::COUNTERS` `u64`s and
/// `lp.next_path` one zeroed `u64`; the block size a multiple of 32 (of `BLOCK_SIZE` under a
/// block-level refill), and every thread of the block runs the kernel.
#[inline(always)]
unsafe fn persistent<S: Scene, P, R: Refill, A: Advance<L>, L: Lanes<X = SpectralOf<S>>>(
    scene: &S,
    lp: &LaunchParams<P>,
) {
    const {
        assert!(
            R::BLOCK || !A::BLOCK,
            "a block-collective advance needs a block-level refill"
        )
    };
    // SAFETY: the caller's contract.
    let mut pool = unsafe { PathPool::new(scene, lp) };
    let setup = A::setup();
    let mut lanes = L::idle(pool.idle_lane());
    loop {
        if A::FIRST {
            A::advance(setup, &mut pool, &mut lanes);
        }
        R::refill(&mut pool, &mut lanes);
        if !R::any_live(lanes.any_active()) {
            break;
        }
        if !A::FIRST {
            A::advance(setup, &mut pool, &mut lanes);
        }
    }
    pool.flush();
}

/// regenerationSK: a thread advances its path one step at a time, and as soon as the path ends
/// records it and takes the next path index ([`ThreadRefill`]), so that lanes do not idle behind
/// long paths. Path index `k` is sample `k / pixels` of pixel `k % pixels`, so the paths in flight
/// at any time are spread over the image and the film's atomics rarely collide.
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn regeneration_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, ThreadRefill, InPlace, Lane<SpectralOf<S>>>(scene, lp) }
}

/// regenerationSK at warp level: see [`WarpRefill`].
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn regeneration_warp_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, WarpRefill, InPlace, Lane<SpectralOf<S>>>(scene, lp) }
}

/// regenerationSK at block level: see [`BlockRefill`].
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn regeneration_block_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, BlockRefill, InPlace, Lane<SpectralOf<S>>>(scene, lp) }
}

/// regenerationSK with two paths per thread (the thesis's instruction-level-parallelism study):
/// each thread keeps two lanes and steps both in every iteration, so that the latency of one
/// path's memory reads and long arithmetic can overlap the other's, at the price of twice the
/// path state (in local memory: see the `Lanes` impl of arrays). Named lanes in registers, with the
/// step inlined twice, measured slower on five of seven scenes on an H100
/// (`bench/results/2026-11-24-h100-strategies-all/bench-2p-named-slots.txt`).
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn regeneration_2p_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, ThreadRefill, InPlace, [Lane<SpectralOf<S>>; 2]>(scene, lp) }
}

/// streamingSK (the thesis's algorithm 5, with compaction in the block): see [`Compact`].
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn streaming_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, BlockRefill, Compact, Lane<SpectralOf<S>>>(scene, lp) }
}

/// streamingSK with Morton sorting: see [`SortPaths`].
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn streaming_sorted_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, BlockRefill, SortPaths, Lane<SpectralOf<S>>>(scene, lp) }
}

/// sortingSK: see [`SortAlbedoReads`].
///
/// # Safety
/// As [`persistent`].
#[inline(always)]
pub unsafe fn sorting_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    // SAFETY: forwarded.
    unsafe { persistent::<S, P, BlockRefill, SortAlbedoReads, Lane<SpectralOf<S>>>(scene, lp) }
}

/// The multi-kernel strategies, naiveMK and streamingMK (the thesis's; `Regeneration` says how
/// they differ), one kernel whose launches run the stages of an iteration ([`Stage`]): paths live
/// in two queues in device memory;
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
pub unsafe fn multi_kernel<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    let state = lp.wavefront as *mut Wavefront;
    let slot_at = |queue: u32, i: u64| -> *mut Slot<SpectralOf<S>> {
        let index = queue as u64 * lp.capacity as u64 + i;
        (lp.queues + index * SLOT_BYTES as u64) as *mut Slot<SpectralOf<S>>
    };
    // SAFETY: the caller's contract.
    let mut pool = unsafe { PathPool::new(scene, lp) };
    let (parity, regenerate) = match Stage::from_code(lp.stage) {
        Stage::Plan {
            parity,
            regeneration,
        } => {
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
    // The warp's lanes take consecutive items; `base` is the same in every lane of the warp, so
    // the loop and the append's vote stay warp-uniform.
    let stride = grid_threads() as u64;
    let mut base = (global_thread_index() - lane_id()) as u64;
    while base < work {
        let i = base + lane_id() as u64;
        let mut survivor = None;
        if i < work {
            let mut slot = if regenerate {
                pool.start(batch_first + i)
            } else {
                // SAFETY: `i` is below the queue's count, at most its capacity.
                unsafe { slot_at(parity, i).read() }
            };
            step(scene, &mut slot.path);
            if slot.path.alive {
                survivor = Some(slot);
            } else {
                // SAFETY: the path was started by this launch.
                unsafe { pool.record(&slot.path, slot.pixel) };
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
    pool.flush();
}
