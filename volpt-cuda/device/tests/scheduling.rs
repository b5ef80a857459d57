//! The scheduling arithmetic every strategy's host loop and kernel share: across a render's launches,
//! every `(pixel, sample)` is traced exactly once, for odd image sizes and renders of several launches.

use volpt_device::launch::{
    next_launch_paths, path_of, pixel_xy, Tile, BLOCK_SIZE, FIRST_LAUNCH_PATHS,
};
use volpt_device::Strategy;

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
        match strategy {
            // Thread `i` of the launch renders pixel `i`, all of the launch's samples.
            Strategy::NaiveSk => {
                let threads = strategy.blocks(pixels, 0) as u64 * BLOCK_SIZE as u64;
                assert!(threads >= pixels);
                for thread in 0..threads.min(pixels) {
                    for sample in first..first + samples {
                        seen[(sample as u64 * pixels + thread) as usize] += 1;
                    }
                }
            }
            // Persistent threads take path indices 0 .. total_paths from the global counter.
            _ => {
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

#[test]
fn strategy_names_are_the_kernels_prefixes() {
    assert_eq!(Strategy::NaiveSk.name(), "naive-sk");
    assert_eq!(Strategy::RegenerationSk.entry_prefix(), "regeneration_sk");
    for s in Strategy::ALL {
        assert_eq!(s.name().replace('-', "_"), s.entry_prefix());
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
