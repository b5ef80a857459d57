//! The strategies' collective building blocks on the GPU against plain CPU implementations, on
//! random inputs with the corner cases (every, no, one and only the last thread of a block
//! active): the block-wide exclusive count of streaming's compaction, the block-wide radix sort of
//! the sorting strategies (Morton keys, ended paths as the largest key, ties) and the warp and
//! block index takers of regeneration (`volpt_device::selftest`); grid lookups through textures against
//! the CPU's reproduction of the texture unit's filter; and `volpt_core::math` as the loaded kernels
//! compile it ([`math`]: the CPU's bits, or the fast kernels' documented accuracy); and the
//! viewer's tone mapping against the CPU's frames ([`tone`]).

pub mod math;
pub mod tone;

use cudarc::driver::{CudaSlice, LaunchConfig, PushKernelArg};
use volpt_core::abi::GridParams;
use volpt_core::{Aabb, Grid, GridMapping, GridPlacement, TexelFormat, Vec3};
use volpt_device::launch::BLOCK_SIZE;
use volpt_gpu_mem::{VolumePlacer, VolumePolicy};

use crate::error::{CudaError, Doing};
use crate::CudaRenderer;

/// Blocks per test launch.
const BLOCKS: usize = 96;

/// `BLOCKS` blocks of `BLOCK_SIZE` threads: the launch of the collective building blocks' tests.
fn test_blocks() -> LaunchConfig {
    LaunchConfig {
        grid_dim: (BLOCKS as u32, 1, 1),
        block_dim: (BLOCK_SIZE, 1, 1),
        shared_mem_bytes: 0,
    }
}

/// One thread per item of `n`, in blocks of `BLOCK_SIZE`.
fn one_thread_each(n: usize) -> LaunchConfig {
    LaunchConfig {
        grid_dim: ((n as u32).div_ceil(BLOCK_SIZE), 1, 1),
        block_dim: (BLOCK_SIZE, 1, 1),
        shared_mem_bytes: 0,
    }
}

/// One building block's result: how many inputs, what differed from the CPU, and what was
/// measured on the way (empty if nothing).
#[derive(Debug)]
pub struct SelfTest {
    pub name: &'static str,
    pub threads: usize,
    pub failures: Vec<String>,
    pub measured: String,
}

/// One flag per thread: block `b` is all set, none, one at random, only the last thread, or random
/// at a density that varies with `b`.
pub fn patterns(seed: u64) -> Vec<bool> {
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as u32
    };
    let n = BLOCK_SIZE as usize;
    let mut flags = Vec::with_capacity(BLOCKS * n);
    for b in 0..BLOCKS {
        let one = next() as usize % n;
        let density = (b % 7) as u32;
        flags.extend((0..n).map(|t| match b % 8 {
            0 => true,
            1 => false,
            2 => t == one,
            3 => t == n - 1,
            _ => next() % 7 < density,
        }));
    }
    flags
}

/// What the block-wide exclusive count must give thread `i`: the set flags before it in its block,
/// and the block's total.
pub fn expected_counts(flags: &[bool]) -> Vec<(u32, u32)> {
    flags
        .chunks(BLOCK_SIZE as usize)
        .flat_map(|block| {
            let total = block.iter().filter(|&&f| f).count() as u32;
            let mut before = 0;
            block.iter().map(move |&f| {
                let r = (before, total);
                before += f as u32;
                r
            })
        })
        .collect()
}

/// Whether `taken` (an index per flagged thread, `u64::MAX` elsewhere) is what an index taker
/// over groups of `group` threads must hand out: within a group, consecutive indices in thread
/// order; over all groups, each of `0..flagged` exactly once.
pub fn check_taken(flags: &[bool], taken: &[u64], group: usize) -> Vec<String> {
    let mut failures = Vec::new();
    let mut seen = vec![false; flags.iter().filter(|&&f| f).count()];
    for (g, (fs, ts)) in flags.chunks(group).zip(taken.chunks(group)).enumerate() {
        let mut expect = None;
        for (t, (&f, &index)) in fs.iter().zip(ts).enumerate() {
            if !f {
                if index != u64::MAX {
                    failures.push(format!("group {g} thread {t}: took {index} without need"));
                }
                continue;
            }
            if let Some(e) = expect {
                if index != e {
                    failures.push(format!("group {g} thread {t}: took {index}, expected {e}"));
                }
            }
            expect = Some(index.wrapping_add(1));
            match seen.get_mut(index as usize) {
                Some(s) if !*s => *s = true,
                Some(_) => failures.push(format!("index {index} taken twice")),
                None => failures.push(format!("group {g} thread {t}: index {index} out of range")),
            }
        }
    }
    failures
}

/// Sort keys for every thread: per block, the flags of [`patterns`] say which threads hold a key
/// (the others hold `order::INACTIVE_KEY`, as ended paths do); held keys are random Morton codes,
/// drawn from few values in every other block so that ties are common.
pub fn sort_keys(seed: u64) -> Vec<u32> {
    let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as u32
    };
    patterns(seed)
        .chunks(BLOCK_SIZE as usize)
        .enumerate()
        .flat_map(|(b, block)| {
            block
                .iter()
                .map(|&held| match held {
                    false => volpt_device::order::INACTIVE_KEY,
                    true if b % 2 == 0 => next() % 4,
                    true => next() & ((1 << 30) - 1),
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// What the block-wide sort must give each thread: its block's keys sorted stably, as (key, the
/// thread of the block that held it).
pub fn expected_sort(keys: &[u32]) -> Vec<(u32, u32)> {
    keys.chunks(BLOCK_SIZE as usize)
        .flat_map(|block| {
            let mut order: Vec<u32> = (0..block.len() as u32).collect();
            order.sort_by_key(|&t| block[t as usize]);
            order.into_iter().map(|t| (block[t as usize], t))
        })
        .collect()
}

impl CudaRenderer {
    /// Runs every building block on the GPU and compares with the CPU.
    pub fn selftest(&self) -> Result<Vec<SelfTest>, CudaError> {
        let stream = self.stream();
        let threads = BLOCKS * BLOCK_SIZE as usize;
        let config = test_blocks();
        let mut results = Vec::new();
        for seed in 1..=4u64 {
            let flags = patterns(seed);
            let input: Vec<u32> = flags.iter().map(|&f| f as u32).collect();
            let input = stream.clone_htod(&input).doing("copying test input")?;

            results.push(self.pair_per_thread(
                "block exclusive count",
                "selftest__block_exclusive_count",
                &input,
                expected_counts(&flags),
            )?);
            let keys = sort_keys(seed);
            let input_keys = stream.clone_htod(&keys).doing("copying test input")?;
            results.push(self.pair_per_thread(
                "block radix sort",
                "selftest__block_sort",
                &input_keys,
                expected_sort(&keys),
            )?);

            for (name, entry, group) in [
                ("warp index taker", "selftest__warp_take_indices", 32),
                (
                    "block index taker",
                    "selftest__block_take_indices",
                    BLOCK_SIZE as usize,
                ),
            ] {
                let kernel = self.kernel(entry, None)?;
                let mut next: CudaSlice<u64> =
                    stream.alloc_zeros(1).doing("allocating a counter")?;
                let mut out: CudaSlice<u64> = stream
                    .alloc_zeros(threads)
                    .doing("allocating test output")?;
                // SAFETY: one flag and one output per thread of the launch, one counter.
                unsafe {
                    stream
                        .launch_builder(&kernel)
                        .arg(&input)
                        .arg(&mut next)
                        .arg(&mut out)
                        .launch(config)
                }
                .doing("launching a selftest")?;
                let taken = stream.clone_dtoh(&out).doing("reading test output")?;
                let counter = stream.clone_dtoh(&next).doing("reading the counter")?;
                let mut failures = check_taken(&flags, &taken, group);
                let flagged = flags.iter().filter(|&&f| f).count() as u64;
                if counter[0] != flagged {
                    failures.push(format!("counter {}, expected {flagged}", counter[0]));
                }
                results.push(SelfTest {
                    name,
                    threads,
                    failures,
                    measured: String::new(),
                });
            }
        }
        for texel in [TexelFormat::F32, TexelFormat::F16] {
            results.push(self.texture_lookups::<1>(texel, Samples::Random)?);
            results.push(self.texture_lookups::<3>(texel, Samples::Random)?);
            results.push(self.texture_lookups::<1>(texel, Samples::Constant)?);
        }
        results.push(self.math_functions()?);
        results.push(self.tone_mapping()?);
        Ok(results)
    }

    /// Tone maps [`tone::film`] on the GPU at each of [`tone::EXPOSURES`] and compares with the
    /// CPU's frames ([`tone::check`]).
    pub fn tone_mapping(&self) -> Result<SelfTest, CudaError> {
        const PIXELS: u32 = 1 << 16;
        const SPP: u32 = 7;
        let stream = self.stream();
        let film = tone::film(PIXELS, SPP);
        let device_film = stream
            .clone_htod(film.flat_sums())
            .doing("copying test input")?;
        let mut frame: CudaSlice<u8> = stream
            .alloc_zeros(3 * PIXELS as usize)
            .doing("allocating test output")?;
        let (mut failures, mut measured) = (Vec::new(), Vec::new());
        for exposure in tone::EXPOSURES {
            self.launch_tone_map(&device_film, &mut frame, PIXELS, SPP, exposure)?;
            let got = stream.clone_dtoh(&frame).doing("reading test output")?;
            let expected = tone::cpu_frame(&film, SPP, exposure);
            let (f, m) = tone::check(&expected, &got, &format!("exposure {exposure}"));
            failures.extend(f);
            measured.push(m);
        }
        Ok(SelfTest {
            name: "tone mapping",
            threads: PIXELS as usize,
            failures,
            measured: measured.join("; "),
        })
    }

    /// Runs `volpt_core::math`'s functions on the GPU ([`math`]) and compares with the CPU's bits
    /// or, if the kernels say they are the fast build, with the true values.
    fn math_functions(&self) -> Result<SelfTest, CudaError> {
        use volpt_device::selftest::MATH_OUTPUTS;
        const N: usize = 1 << 16;
        let stream = self.stream();
        let inputs = math::inputs(N);
        let input = stream.clone_htod(&inputs).doing("copying test input")?;
        let mut out: CudaSlice<f32> = stream
            .alloc_zeros(MATH_OUTPUTS * N)
            .doing("allocating test output")?;
        let mut fast: CudaSlice<u32> = stream.alloc_zeros(1).doing("allocating a flag")?;
        let kernel = self.kernel("selftest__math_functions", None)?;
        let config = one_thread_each(N);
        // SAFETY: three inputs and seven outputs per thread below N, one flag.
        unsafe {
            stream
                .launch_builder(&kernel)
                .arg(&input)
                .arg(&mut out)
                .arg(&mut fast)
                .arg(&(N as u32))
                .launch(config)
        }
        .doing("launching a selftest")?;
        let got = stream.clone_dtoh(&out).doing("reading test output")?;
        let fast = stream.clone_dtoh(&fast).doing("reading the flag")?[0] != 0;
        let (failures, measured) = math::check(&inputs, &got, fast);
        Ok(SelfTest {
            name: if fast {
                "math functions (fast kernels)"
            } else {
                "math functions (exact kernels)"
            },
            threads: N,
            failures,
            measured,
        })
    }

    /// Runs the selftest kernel `entry`, which reads one `u32` of `input` per thread and writes two,
    /// on `BLOCKS` blocks, and compares each thread's pair with `expected`.
    fn pair_per_thread(
        &self,
        name: &'static str,
        entry: &str,
        input: &CudaSlice<u32>,
        expected: Vec<(u32, u32)>,
    ) -> Result<SelfTest, CudaError> {
        let stream = self.stream();
        let threads = BLOCKS * BLOCK_SIZE as usize;
        let kernel = self.kernel(entry, None)?;
        let mut out: CudaSlice<u32> = stream
            .alloc_zeros(2 * threads)
            .doing("allocating test output")?;
        // SAFETY: one input and two outputs per thread of the launch.
        unsafe {
            stream
                .launch_builder(&kernel)
                .arg(input)
                .arg(&mut out)
                .launch(test_blocks())
        }
        .doing("launching a selftest")?;
        let got = stream.clone_dtoh(&out).doing("reading test output")?;
        let failures = got
            .chunks(2)
            .zip(expected)
            .enumerate()
            .filter(|(_, (g, e))| (g[0], g[1]) != *e)
            .map(|(i, (g, e))| format!("thread {i}: ({}, {}), expected {e:?}", g[0], g[1]))
            .collect();
        Ok(SelfTest {
            name,
            threads,
            failures,
            measured: String::new(),
        })
    }

    /// Looks up a `C`-channel grid in a texture of `texel`s at random points (inside the box, on
    /// its faces and outside) on the GPU and compares with the CPU's filter
    /// (`Grid::lookup_texture_filter`).
    ///
    /// Random samples: the texture unit does not round its weights exactly as the CPU does (on an
    /// H100, 2026-11-24, some lookups differ by slightly more than one weight step, 1/256 of the
    /// samples' range), so up to two steps pass; a mapping off by half a texel or a channel out
    /// of place differs by far more. No lookup may exceed the largest texel. Constant samples:
    /// every lookup inside the box must be that constant exactly, i.e. the unit's weights sum to
    /// 1 and a density at its majorant never reads above it.
    fn texture_lookups<const C: usize>(
        &self,
        texel: TexelFormat,
        samples: Samples,
    ) -> Result<SelfTest, CudaError> {
        const POINTS: usize = 1 << 16;
        let stream = self.stream();
        let res = [7, 5, 6];
        let data: Vec<f32> = (0..res.iter().product::<u32>() * C as u32)
            .map(|i| match samples {
                Samples::Random => 4.0 * unit(u64::from(i) + 1000),
                Samples::Constant => 1.7,
            })
            .collect();
        let bounds = Aabb::new(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(3.0, 1.5, 2.5));
        let grid: Grid<'_, C> =
            Grid::new(&data, res, GridMapping::cell_centred(bounds, res)).with_texel(texel);
        let points: Vec<f32> = (0..3 * POINTS as u64)
            .map(|i| {
                let axis = (i % 3) as usize;
                let u = 1.2 * unit(i) - 0.1;
                bounds.min[axis] + u * (bounds.max[axis] - bounds.min[axis])
            })
            .collect();
        // SAFETY: `data` outlives the placer, which is dropped at the end of this function.
        let mut placer = unsafe { VolumePlacer::new(stream.clone(), VolumePolicy::default()) }?;
        let params = GridParams::new(&grid, &mut placer, GridPlacement::Texture);
        placer.check()?;
        let params = stream
            .clone_htod(bytemuck::bytes_of(&params))
            .doing("copying test input")?;
        let points_device = stream.clone_htod(&points).doing("copying test input")?;
        let mut out: CudaSlice<f32> = stream
            .alloc_zeros(C * POINTS)
            .doing("allocating test output")?;
        let entry = if C == 1 {
            "selftest__texture_lookups_1"
        } else {
            "selftest__texture_lookups_3"
        };
        let kernel = self.kernel(entry, None)?;
        let config = one_thread_each(POINTS);
        // SAFETY: one grid's parameters, 3 coordinates and C outputs per point, for the launch.
        unsafe {
            stream
                .launch_builder(&kernel)
                .arg(&params)
                .arg(&points_device)
                .arg(&mut out)
                .arg(&(POINTS as u32))
                .launch(config)
        }
        .doing("launching a selftest")?;
        let got = stream.clone_dtoh(&out).doing("reading test output")?;
        let texels: Vec<f32> = data.iter().map(|&v| texel.texel(v)).collect();
        let largest = texels.iter().copied().fold(0.0, f32::max);
        let smallest = texels.iter().copied().fold(f32::INFINITY, f32::min);
        let step = (largest - smallest).max(largest) / 256.0;
        let tolerance = match samples {
            Samples::Random => 2.0 * step,
            Samples::Constant => 0.0,
        };
        let (mut failures, mut worst, mut identical, mut within_step) = (Vec::new(), 0.0f32, 0, 0);
        for (i, got) in got.chunks(C).enumerate() {
            let p = Vec3::new(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
            let expected = grid.lookup_texture_filter(p);
            for c in 0..C {
                let error = (got[c] - expected[c]).abs();
                worst = worst.max(error);
                identical += usize::from(got[c].to_bits() == expected[c].to_bits());
                within_step += usize::from(error <= step);
                if error > tolerance || got[c] > largest {
                    failures.push(format!(
                        "{p:?} channel {c}: {}, the CPU's filter {}",
                        got[c], expected[c]
                    ));
                }
            }
        }
        let values = (C * POINTS) as f64;
        Ok(SelfTest {
            name: match (texel, C, samples) {
                (TexelFormat::F32, _, Samples::Constant) => "texture lookup (f32, constant)",
                (TexelFormat::F16, _, Samples::Constant) => "texture lookup (f16, constant)",
                (TexelFormat::F32, 1, _) => "texture lookup (f32, 1 channel)",
                (TexelFormat::F32, _, _) => "texture lookup (f32, 3 channels)",
                (TexelFormat::F16, 1, _) => "texture lookup (f16, 1 channel)",
                (TexelFormat::F16, _, _) => "texture lookup (f16, 3 channels)",
            },
            threads: POINTS,
            failures,
            measured: format!(
                "largest difference from the CPU's filter {:.3e} ({:.3} weight steps), \
                 {:.2}% bit-identical, {:.3}% within one step",
                worst,
                worst / step,
                100.0 * identical as f64 / values,
                100.0 * within_step as f64 / values
            ),
        })
    }
}

/// The samples of a texture selftest's grid.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Samples {
    Random,
    Constant,
}

/// A uniform number in [0, 1) from a counter (SplitMix64's finaliser).
fn unit(i: u64) -> f32 {
    let mut z = i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_patterns_hold_the_corner_cases() {
        let flags = patterns(1);
        let n = BLOCK_SIZE as usize;
        let count = |b: usize| flags[b * n..(b + 1) * n].iter().filter(|&&f| f).count();
        assert_eq!((count(0), count(1), count(2), count(3)), (n, 0, 1, 1));
        assert!(flags[4 * n - 1]);
    }

    #[test]
    fn the_reference_count_is_an_exclusive_scan_per_block() {
        let flags = [true, false, true, true].repeat(BLOCK_SIZE as usize / 4);
        let counts = expected_counts(&flags);
        assert_eq!(&counts[..5], &[(0, 96), (1, 96), (1, 96), (2, 96), (3, 96)]);
    }

    #[test]
    fn the_taken_check_catches_gaps_repeats_and_order() {
        let flags = [true, false, true, true];
        assert!(check_taken(&flags, &[0, u64::MAX, 1, 2], 4).is_empty());
        // Another group order is fine: the second group took first.
        assert!(check_taken(&flags, &[2, u64::MAX, 0, 1], 2).is_empty());
        assert!(!check_taken(&flags, &[0, u64::MAX, 2, 1], 4).is_empty());
        assert!(!check_taken(&flags, &[0, u64::MAX, 1, 1], 4).is_empty());
        assert!(!check_taken(&flags, &[0, 3, 1, 2], 4).is_empty());
        assert!(!check_taken(&flags, &[0, u64::MAX, 1, 7], 4).is_empty());
    }
}
