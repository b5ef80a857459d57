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

use volpt_core::path::{sample_pixel, step, PathCounters, PathState};
use volpt_core::Scene;

use crate::launch::{path_of, pixel_xy, LaunchParams};
use crate::nvptx::{
    atomic_add_u64, ballot, global_thread_index, lane_id, lanemask_lt, red_add_f64, red_add_u64,
    shfl_idx_u64, warp_sum_u64,
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

/// naiveSK: thread `i` renders pixel `i`, adding this launch's samples to its `f64` sum with the
/// CPU's own per-pixel loop, so the sums are the CPU's bit for bit.
///
/// # Safety
/// `lp.film` must hold `3 * width * height` `f64`s and `lp.counters` `launch::COUNTERS` `u64`s.
#[inline(always)]
pub unsafe fn naive_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    let width = scene.camera().width;
    let pixels = width * scene.camera().height;
    let i = global_thread_index();
    let mut counters = PathCounters::default();
    if i < pixels {
        // SAFETY: pixel `i` is inside the film, and no other thread touches it.
        let sum = unsafe { &mut *(lp.film as *mut [f64; 3]).add(i as usize) };
        let samples = lp.first_sample..lp.first_sample + lp.samples;
        sample_pixel(
            scene,
            pixel_xy(i, width),
            samples,
            lp.seed,
            sum,
            &mut counters,
        );
    }
    // SAFETY: forwarded.
    unsafe { add_counters(&counters, lp) };
}

/// regenerationSK: persistent threads step their paths and refill finished lanes from a global
/// path counter. Path index `k` is sample `k / pixels` of pixel `k % pixels`, so the paths in flight
/// at any time are spread over the image and the film's atomics rarely collide.
///
/// # Safety
/// As [`naive_sk`]; and `lp.next_path` must be one zeroed `u64`, and the block size a multiple of 32.
#[inline(always)]
pub unsafe fn regeneration_sk<S: Scene, P>(scene: &S, lp: &LaunchParams<P>) {
    let width = scene.camera().width;
    let pixels = (width * scene.camera().height) as u64;
    let film = lp.film as *mut f64;
    let next_path = lp.next_path as *mut u64;
    let lane = lane_id();
    let below = lanemask_lt();
    let mut counters = PathCounters::default();
    // A placeholder until the first refill; `active` says whether `path` is a live path.
    let mut path = PathState::from_camera(scene, 0, 0, 0, lp.seed);
    let mut pixel = 0u32;
    let mut active = false;
    let mut exhausted = false;
    loop {
        // Refill: the lanes without a path take consecutive indices with one atomic per warp.
        let need = !active && !exhausted;
        let wanting = ballot(need);
        if wanting != 0 {
            let leader = wanting.trailing_zeros();
            let mut base = 0;
            if lane == leader {
                // SAFETY: `next_path` is one `u64` (the caller's contract).
                base = unsafe { atomic_add_u64(next_path, wanting.count_ones() as u64) };
            }
            let base = shfl_idx_u64(base, leader);
            if need {
                let index = base + (wanting & below).count_ones() as u64;
                if index < lp.total_paths {
                    let sample;
                    (pixel, sample) = path_of(index, pixels, lp.first_sample);
                    let (px, py) = pixel_xy(pixel, width);
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
                counters.record(&path);
                for c in 0..3 {
                    let value = path.radiance[c];
                    if value != 0.0 {
                        // SAFETY: `pixel` is inside the film.
                        unsafe { red_add_f64(film.add(3 * pixel as usize + c), value as f64) };
                    }
                }
                active = false;
            }
        }
    }
    // SAFETY: forwarded.
    unsafe { add_counters(&counters, lp) };
}
