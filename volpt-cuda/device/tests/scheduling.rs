//! The scheduling arithmetic every strategy's host loop and kernel share: across a render's launches,
//! every `(pixel, sample)` is traced exactly once, for odd image sizes and renders of several launches.

use volpt_core::{Aabb, Vec3};
use volpt_device::launch::{
    next_launch_paths, path_of, pixel_xy, Regeneration, Scheduling, Slot, Stage, Tile, Wavefront,
    BLOCK_SIZE, FIRST_LAUNCH_PATHS, MAX_WAVEFRONT_CAPACITY, SLOT_BYTES, WAVEFRONT_PATHS_PER_THREAD,
};
use volpt_device::order::{morton30, spread_bits, INACTIVE_KEY};
use volpt_device::{LaunchParams, Strategy};

/// How often each `(pixel, sample)` of a `pixels` x `spp` render is traced, as the kernels of
/// `strategy` map their work onto paths, with launch budgets that change from launch to launch as
/// the host's measurements make them.
fn coverage(strategy: Strategy, pixels: u64, spp: u32) -> Vec<u32> {
    let mut seen = vec![0u32; pixels as usize * spp as usize];
    let mut launches = 0;
    let mut budgets = [1, pixels * 2 + 1, 3, FIRST_LAUNCH_PATHS]
        .into_iter()
        .cycle();
    for (first, samples) in strategy.launches(pixels, spp, || budgets.next().unwrap()) {
        launches += 1;
        match strategy.scheduling() {
            // Thread `i` of the launch renders pixel `i`, all of the launch's samples.
            Scheduling::PerPixel => {
                let threads = strategy.blocks(pixels, 0) as u64 * BLOCK_SIZE as u64;
                assert!(threads >= pixels);
                for thread in 0..threads.min(pixels) {
                    for sample in first..first + samples {
                        seen[(sample as u64 * pixels + thread) as usize] += 1;
                    }
                }
            }
            // Persistent threads take path indices 0 .. total_paths from the global counter; the
            // multi-kernel stages start them in batches (`wavefront_stages_start_every_path_once`).
            Scheduling::Persistent | Scheduling::Wavefront(_) => {
                for index in 0..pixels * samples as u64 {
                    let (pixel, sample) = path_of(index, pixels, first);
                    assert!((pixel as u64) < pixels && sample < spp);
                    seen[(sample as u64 * pixels + pixel as u64) as usize] += 1;
                }
            }
        }
    }
    assert!(launches >= 1);
    seen
}

#[test]
fn every_path_is_traced_once_across_launches() {
    for &strategy in Strategy::ALL {
        for pixels in [1, 7, 97 * 61, 1 << 20, (1 << 22) + 3] {
            for spp in [1, 3, 5] {
                let seen = coverage(strategy, pixels, spp);
                assert!(
                    seen.iter().all(|&n| n == 1),
                    "{strategy}: {pixels} pixels x {spp} spp: some path traced {:?} times",
                    seen.iter().find(|&&n| n != 1)
                );
            }
        }
    }
}

#[test]
fn regeneration_traces_a_benchmark_in_one_launch_and_later_launches_by_time() {
    // Every launch pays a tail (its longest path), so 100 spp at 400x400 is one launch.
    let first = || FIRST_LAUNCH_PATHS;
    let launches: Vec<_> = Strategy::RegenerationSk
        .launches(160_000, 100, first)
        .collect();
    assert_eq!(launches, [(0, 100)]);
    // 300 spp: the first launch takes what its budget holds, the rest follows the budgets.
    let mut budgets = [FIRST_LAUNCH_PATHS, 160_000 * 50].into_iter().cycle();
    let launches: Vec<_> = Strategy::RegenerationSk
        .launches(160_000, 300, || budgets.next().unwrap())
        .collect();
    assert_eq!(launches, [(0, 104), (104, 50), (154, 104), (258, 42)]);
    // One path per launch at least, even for films larger than a launch's budget.
    assert_eq!(
        Strategy::RegenerationSk.samples_per_launch(1 << 30, 100, 1 << 24),
        1
    );
    assert_eq!(
        Strategy::RegenerationSk.samples_per_launch(1, 7, 1 << 24),
        7
    );
    assert_eq!(Strategy::NaiveSk.launches(5, 3, first).count(), 3);
    assert_eq!(Strategy::NaiveSk.launches(5, 0, first).count(), 0);
}

#[test]
fn later_launches_aim_at_half_a_second_within_bounds() {
    // 100 M paths/s: half a second is 50 M paths.
    assert_eq!(next_launch_paths(100_000_000, 1.0), 50_000_000);
    // A slow launch (out-of-core grids) still traces 2^20 paths; a fast one at most 2^28.
    assert_eq!(next_launch_paths(1 << 20, 100.0), 1 << 20);
    assert_eq!(next_launch_paths(1 << 30, 0.1), 1 << 28);
    // A launch too short for the clock does not divide by zero.
    assert_eq!(next_launch_paths(1 << 20, 0.0), 1 << 28);
}

#[test]
fn launch_grids_fit_the_strategy() {
    assert_eq!(Strategy::NaiveSk.blocks(129, 1000), 2);
    assert_eq!(Strategy::NaiveSk.blocks(128, 1000), 1);
    assert_eq!(Strategy::RegenerationSk.blocks(1 << 20, 264), 264);
    assert_eq!(Strategy::RegenerationSk.blocks(1 << 20, 0), 1);
}

#[test]
fn pixels_are_row_major() {
    assert_eq!(pixel_xy(0, 7), (0, 0));
    assert_eq!(pixel_xy(6, 7), (6, 0));
    assert_eq!(pixel_xy(7, 7), (0, 1));
    assert_eq!(pixel_xy(7 * 5 + 3, 7), (3, 5));
}

/// A strategy's kernels are named after it, except where strategies share a kernel function
/// (the multi-kernel ones, told their regeneration by the launch's stage code).
#[test]
fn strategy_names_are_the_kernels_prefixes() {
    assert_eq!(Strategy::NaiveSk.name(), "naive-sk");
    assert_eq!(Strategy::RegenerationSk.entry_prefix(), "regeneration_sk");
    for s in Strategy::ALL {
        match s.scheduling() {
            Scheduling::Wavefront(_) => assert_eq!(s.entry_prefix(), "multi_kernel"),
            _ => assert_eq!(s.name().replace('-', "_"), s.entry_prefix()),
        }
    }
}

/// `path_of`'s 32-bit shortcut gives the 64-bit division's pixel and sample on both sides of 2^32,
/// for indices and for films of 2^32 pixels or more.
#[test]
fn path_indices_divide_the_same_above_and_below_two_to_the_32() {
    let edge = 1u64 << 32;
    for pixels in [1, 3, 160_000, edge - 1, edge, edge + 7] {
        for index in [
            0,
            1,
            pixels - 1,
            pixels,
            edge - 2,
            edge - 1,
            edge,
            edge + 1,
            3 * edge + 5,
        ] {
            let expected = ((index % pixels) as u32, (index / pixels) as u32);
            assert_eq!(
                path_of(index, pixels, 0),
                expected,
                "index {index} of {pixels} pixels"
            );
        }
    }
}

/// `--tiles`: the tiles of a film cover it exactly once, whatever the film's size and the tiles
/// asked for, and every strategy's launches over the tiles trace every `(pixel, sample)` once.
#[test]
fn tiles_cover_the_film_once_and_every_path_is_traced_once() {
    for (width, height) in [(1, 1), (7, 5), (97, 61), (33, 1), (1, 40)] {
        for (columns, rows) in [(1, 1), (2, 3), (4, 4), (64, 64), (3, 1)] {
            let tiles: Vec<Tile> = Tile::grid(width, height, columns, rows).collect();
            assert!(tiles.iter().all(|t| t.pixels() > 0), "an empty tile");
            assert!(tiles.len() as u32 <= columns * rows);
            let spp = 3;
            for &strategy in Strategy::ALL {
                let mut seen = vec![0u32; (width * height * spp) as usize];
                for tile in &tiles {
                    let pixels = tile.pixels();
                    for (first, samples) in strategy.launches(pixels, spp, || 2 * pixels + 1) {
                        for index in 0..pixels * samples as u64 {
                            let (p, sample) = path_of(index, pixels, first);
                            let (x, y, film) = tile.film_pixel(p, width);
                            assert!(x < width && y < height && film == y * width + x);
                            seen[(sample * width * height + film) as usize] += 1;
                        }
                    }
                }
                assert!(
                    seen.iter().all(|&n| n == 1),
                    "{strategy}: {width}x{height} in {columns}x{rows} tiles"
                );
            }
        }
    }
    // The whole film is one tile.
    let whole: Vec<Tile> = Tile::grid(400, 300, 1, 1).collect();
    assert_eq!(whole, [Tile::whole(400, 300)]);
}

/// A multi-kernel launch of `total` paths run as the host and the stages run it, on the CPU:
/// path index `k` lives `lengths(k)` segments (the regeneration stage traces the first). Returns
/// how often each index was started and how many iterations the launch took, and checks on the
/// way that no queue overflows, that naive-mk starts a batch only into an empty queue, and that
/// the counters say "done" exactly when every path has ended.
fn run_wavefront(
    regeneration: Regeneration,
    capacity: u64,
    total: u64,
    lengths: impl Fn(u64) -> u32,
) -> (Vec<u32>, u64) {
    let mut state = Wavefront::default();
    // The queues: (path index, segments left).
    let mut queues: [Vec<(u64, u32)>; 2] = [Vec::new(), Vec::new()];
    let mut started = vec![0u32; total as usize];
    let mut iteration = 0;
    while !state.done(total) {
        for stage in Stage::iteration(iteration, regeneration) {
            assert_eq!(Stage::from_code(stage.code()), stage);
            match stage {
                Stage::Extend { parity } => {
                    let (p, o) = (parity as usize, 1 - parity as usize);
                    assert_eq!(queues[p].len() as u64, state.count[p]);
                    for (k, left) in std::mem::take(&mut queues[p]) {
                        if left > 1 {
                            queues[o].push((k, left - 1));
                        }
                    }
                    state.count[o] = queues[o].len() as u64;
                    // The input is consumed; `plan` zeroes its count.
                }
                Stage::Plan {
                    parity,
                    regeneration: planned,
                } => {
                    assert_eq!(planned, regeneration);
                    let live = state.count[1 - parity as usize];
                    state.plan(parity, capacity, total, planned);
                    if regeneration == Regeneration::WhenEmpty && live > 0 {
                        assert_eq!(
                            state.batch_len, 0,
                            "naive-mk started paths into a busy queue"
                        );
                    }
                    assert_eq!(state.count[parity as usize], 0);
                }
                Stage::Regenerate { parity } => {
                    let o = 1 - parity as usize;
                    for k in state.batch_first..state.batch_first + state.batch_len {
                        started[k as usize] += 1;
                        let left = lengths(k);
                        if left > 1 {
                            queues[o].push((k, left - 1));
                        }
                    }
                    state.count[o] = queues[o].len() as u64;
                    assert!(state.count[o] <= capacity, "queue {o} overflows");
                }
            }
        }
        iteration += 1;
        let live = queues[0].len() + queues[1].len();
        assert_eq!(state.done(total), live == 0 && state.issued == total);
        assert!(iteration < 100 * total + 100, "the launch does not end");
    }
    (started, iteration)
}

#[test]
fn wavefront_stages_start_every_path_once_and_end() {
    for regeneration in [Regeneration::WhenEmpty, Regeneration::Continuous] {
        for capacity in [1, 7, 64] {
            for total in [0, 1, 63, 200] {
                let lengths = |k: u64| (k * 2654435761 % 13) as u32 + 1;
                let (started, _) = run_wavefront(regeneration, capacity, total, lengths);
                assert!(
                    started.iter().all(|&n| n == 1),
                    "{regeneration:?}, capacity {capacity}, {total} paths"
                );
            }
        }
    }
}

#[test]
fn naive_mk_waits_for_its_batch_and_streaming_mk_does_not() {
    // One path of 50 segments among short ones: naive-mk's batches each wait for their longest
    // path (regeneration traces its first segment, 49 extensions the rest, and the next batch
    // starts in the iteration of its last); streaming-mk refills around it.
    let lengths = |k: u64| if k.is_multiple_of(16) { 50 } else { 2 };
    let (_, naive) = run_wavefront(Regeneration::WhenEmpty, 16, 160, lengths);
    let (_, streaming) = run_wavefront(Regeneration::Continuous, 16, 160, lengths);
    assert_eq!(naive, 10 * 49 + 1);
    assert!(streaming < 150, "streaming-mk took {streaming} iterations");
}

#[test]
fn wavefront_queues_hold_a_sample_for_naive_mk_and_several_paths_per_thread_for_streaming_mk() {
    assert_eq!(
        Strategy::NaiveMk.wavefront_capacity(160_000, 60_000),
        160_000
    );
    assert_eq!(
        Strategy::StreamingMk.wavefront_capacity(160_000, 60_000),
        60_000 * WAVEFRONT_PATHS_PER_THREAD
    );
    assert_eq!(
        Strategy::NaiveMk.wavefront_capacity(1 << 30, 1),
        MAX_WAVEFRONT_CAPACITY
    );
    assert_eq!(Strategy::StreamingMk.wavefront_capacity(5, 0), 1);
    for &s in Strategy::ALL {
        let wavefront = matches!(s.scheduling(), Scheduling::Wavefront(_));
        assert_eq!(
            wavefront,
            matches!(s, Strategy::NaiveMk | Strategy::StreamingMk),
            "{s}"
        );
    }
}

#[test]
fn morton_codes_interleave_the_cells_of_the_three_axes() {
    assert_eq!(spread_bits(0b1011), 0b001_000_001_001);
    assert_eq!(spread_bits(0x3ff), 0x0924_9249);
    assert_eq!(spread_bits(0x400), 0, "only ten bits");
    let bounds = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 4.0, 3.0));
    let code = |x, y, z| morton30(Vec3::new(x, y, z), &bounds);
    assert_eq!(code(-1.0, 0.0, 2.0), 0);
    assert_eq!(code(1.0, 4.0, 3.0), (1 << 30) - 1, "the far corner's cell");
    // One cell step along x, y and z sets bits 0, 1 and 2.
    let step = |axis: f32| axis / 1024.0 * 1.5;
    assert_eq!(code(-1.0 + 2.0 * step(1.0), 0.0, 2.0), 0b001);
    assert_eq!(code(-1.0, 4.0 * step(1.0), 2.0), 0b010);
    assert_eq!(code(-1.0, 0.0, 2.0 + step(1.0)), 0b100);
    // Outside the box and not a number: clamped to a cell, never above 30 bits.
    for p in [
        Vec3::splat(-1e30),
        Vec3::splat(1e30),
        Vec3::splat(f32::NAN),
        Vec3::splat(f32::INFINITY),
    ] {
        assert!(morton30(p, &bounds) < 1 << 30);
        assert!(morton30(p, &bounds) < INACTIVE_KEY);
    }
    // A flat box (zero extent on an axis) still codes.
    let flat = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0));
    assert!(morton30(Vec3::splat(0.5), &flat) < 1 << 30);
}

#[test]
fn the_launch_parameters_keep_their_layout_with_the_queue_fields() {
    #[allow(clippy::let_unit_value)]
    let () = LaunchParams::<[u64; 3]>::LAYOUT;
    assert_eq!(size_of::<LaunchParams<[u64; 3]>>(), 24 + 88);
    assert!(size_of::<Slot>() <= SLOT_BYTES);
    assert!(size_of::<Slot<volpt_core::HeroChannel>>() <= SLOT_BYTES);
}
