//! What one kernel launch receives, and which paths it traces.
//!
//! The scheduling arithmetic lives here as plain functions so that the host, the kernels and the CPU
//! tests share it: a path is `(pixel, sample)`; a launch traces samples
//! `first_sample .. first_sample + samples` of every pixel; path index `k` of a launch is sample
//! `first_sample + k / pixels` of pixel `k % pixels` ([`path_of`]), so that the paths in flight at any
//! time are spread over the image and the film's atomics rarely collide.

use bytemuck::{Pod, Zeroable};

pub use volpt_core::abi::SceneAbi;

use crate::Strategy;

/// Threads per block. A multiple of the warp size, as the warp-collective code requires.
pub const BLOCK_SIZE: u32 = 128;

/// Number of `u64` counters a launch reduces: paths, segments, tracking steps, truncated paths, and
/// of those the paths cut by the tracking-step bound.
pub const COUNTERS: usize = 5;

/// Paths of a persistent strategy's first launch. Every launch ends in a tail: as its last paths
/// finish, lanes go idle until the longest path in flight ends. On an H100 (2026-11-23,
/// `bench/device/kernel-times.sh`) that tail cost ~25 ms a launch on cgg-logo: 100 spp at 400x400
/// in four launches of 2^22 paths took 182 ms of kernel time where one launch of 16 spp took 41.
/// So a render of up to 2^24 paths (100 spp at 400x400) is one launch; later launches are sized
/// by [`next_launch_paths`].
pub const FIRST_LAUNCH_PATHS: u64 = 1 << 24;

/// Seconds a launch after the first aims at: long enough that the tail is a few percent of it,
/// short enough for progress reports and for an interrupt to be answered within a second.
pub const LAUNCH_SECONDS: f64 = 0.5;

/// The path budget of the launch after one that traced `paths` paths in `seconds`: what that rate
/// traces in [`LAUNCH_SECONDS`], between 2^20 and 2^28 paths.
pub fn next_launch_paths(paths: u64, seconds: f64) -> u64 {
    let rate = paths as f64 / seconds.max(1e-6);
    (rate * LAUNCH_SECONDS).clamp((1u64 << 20) as f64, (1u64 << 28) as f64) as u64
}

/// One launch: the scene's parameters `P` (a [`SceneAbi::Params`]), the sampling, and the device
/// buffers the kernel writes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LaunchParams<P> {
    pub scene: P,
    /// This launch traces samples `first_sample .. first_sample + samples` of every pixel.
    pub first_sample: u32,
    pub samples: u32,
    pub seed: u32,
    /// regeneration-sk refills a warp's idle lanes once at least this many of them are idle (0 and
    /// 1: at once), or when the whole warp is: fewer refills, each for more lanes at once, at the
    /// price of lanes idling in between (the host's default: 8).
    pub refill_at: u32,
    /// A multi-kernel strategy's stage this launch runs ([`Stage::code`]); 0 otherwise.
    pub stage: u32,
    /// A multi-kernel strategy's queue capacity in paths (each of its two queues).
    pub capacity: u32,
    /// `width * height * 3` `f64` sums of the samples' radiance, zeroed before the first launch;
    /// each launch adds its samples.
    pub film: u64,
    /// [`COUNTERS`] `u64` totals (paths, segments, tracking steps, truncated, truncated by
    /// tracking), zeroed before the render.
    pub counters: u64,
    /// One `u64`, zeroed before the launch: the next path index a persistent thread takes.
    pub next_path: u64,
    /// Paths to trace in this launch: `tile.pixels() * samples`.
    pub total_paths: u64,
    /// A multi-kernel strategy's two path queues: `2 * capacity` [`Slot`]s, [`SLOT_BYTES`] apart.
    pub queues: u64,
    /// A multi-kernel strategy's [`Wavefront`] counters, zeroed before the render's first launch
    /// of each launch's path range.
    pub wavefront: u64,
    /// The part of the film this launch covers (`--tiles`; the whole film by default).
    pub tile: Tile,
}

/// A rectangle of the film: its first column and row, and its size in pixels. A launch traces the
/// paths of one tile's pixels (the thesis's image tiling: one launch per tile).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl Tile {
    /// The whole `width` x `height` film.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }

    /// The film position of the tile's pixel `pixel` (row by row within the tile) and its index
    /// in a film `film_width` pixels wide.
    #[inline(always)]
    pub fn film_pixel(&self, pixel: u32, film_width: u32) -> (u32, u32, u32) {
        let (x, y) = pixel_xy(pixel, self.width);
        let (x, y) = (self.x + x, self.y + y);
        (x, y, y * film_width + x)
    }

    /// A `width` x `height` film cut into `columns` x `rows` tiles, row by row; the tiles' sizes
    /// differ by one pixel at most, and a film narrower than `columns` has fewer (none empty).
    pub fn grid(width: u32, height: u32, columns: u32, rows: u32) -> impl Iterator<Item = Tile> {
        let (columns, rows) = (columns.clamp(1, width.max(1)), rows.clamp(1, height.max(1)));
        let edge = |i: u32, n: u32, len: u32| (i as u64 * len as u64 / n as u64) as u32;
        (0..rows).flat_map(move |r| {
            (0..columns).map(move |c| {
                let (x, y) = (edge(c, columns, width), edge(r, rows, height));
                Tile {
                    x,
                    y,
                    width: edge(c + 1, columns, width) - x,
                    height: edge(r + 1, rows, height) - y,
                }
            })
        })
    }
}

impl<P: Pod> LaunchParams<P> {
    /// The scene parameters are a multiple of 8 bytes (see `volpt_core::abi`), so the 88 bytes that
    /// follow them need no padding.
    pub const LAYOUT: () = assert!(
        core::mem::size_of::<P>().is_multiple_of(8)
            && core::mem::size_of::<Self>() == core::mem::size_of::<P>() + 88
    );

    /// The parameters, once `LAYOUT` has been checked: the host ships only values built by this.
    pub fn checked(self) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::LAYOUT;
        self
    }
}

// SAFETY: `repr(C)` of `Pod` fields; `LAYOUT` (evaluated by `checked`, the only way the host ships
// the struct) proves that there is no padding.
unsafe impl<P: Pod> Zeroable for LaunchParams<P> {}
// SAFETY: as above.
unsafe impl<P: Pod> Pod for LaunchParams<P> {}

/// The pixel and sample of path index `index` of a launch over `pixels` pixels from `first_sample`.
///
/// A launch's indices stay below 2^32 unless the film has 2^32 pixels or more; then 32-bit
/// division gives the same quotient and remainder, and on a GPU it is a few instructions where a
/// 64-bit one is a software routine paid once per path.
#[inline(always)]
pub fn path_of(index: u64, pixels: u64, first_sample: u32) -> (u32, u32) {
    if let (Ok(index), Ok(pixels)) = (u32::try_from(index), u32::try_from(pixels)) {
        return (index % pixels, first_sample + index / pixels);
    }
    (
        (index % pixels) as u32,
        first_sample + (index / pixels) as u32,
    )
}

/// The film position of pixel `pixel` of an image `width` pixels wide.
#[inline(always)]
pub fn pixel_xy(pixel: u32, width: u32) -> (u32, u32) {
    (pixel % width, pixel / width)
}

/// How a strategy maps its work onto threads and launches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheduling {
    /// One thread per pixel, one launch per sample (naive-sk).
    PerPixel,
    /// Persistent threads take path indices from a global counter until the launch's paths are
    /// done (regeneration and streaming, single kernel).
    Persistent,
    /// Multi-kernel: paths live in device memory between launches, and each iteration is three
    /// launches of the strategy's kernel ([`Stage`]): extend every queued path by one segment and
    /// compact the survivors into the other queue, plan the next batch of new paths, regenerate
    /// (start them and trace their first segment).
    Wavefront(Regeneration),
}

/// When a multi-kernel strategy starts new paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Regeneration {
    /// Only when the queue is empty: a batch of `capacity` paths (one sample of every pixel) is
    /// traced to its end before the next starts (the thesis's naiveMK).
    WhenEmpty,
    /// After every extension, into the room the finished paths left (the thesis's streamingMK).
    Continuous,
}

/// The stages of a multi-kernel strategy's iteration, each one launch. `parity` says which
/// queue the iteration consumes: extension reads queue `parity` and writes its survivors to queue
/// `1 - parity`, to which regeneration adds the new paths; the next iteration has the other
/// parity. Both multi-kernel strategies run one kernel, whose plan stage is told the strategy's
/// [`Regeneration`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    Extend {
        parity: u32,
    },
    /// One thread: [`Wavefront::plan`].
    Plan {
        parity: u32,
        regeneration: Regeneration,
    },
    Regenerate {
        parity: u32,
    },
}

impl Stage {
    /// The stage as [`LaunchParams::stage`] carries it: bit 0 the parity, bits 1-2 the stage,
    /// bit 3 a plan's [`Regeneration::Continuous`].
    pub fn code(self) -> u32 {
        match self {
            Stage::Extend { parity } => parity & 1,
            Stage::Plan {
                parity,
                regeneration,
            } => {
                let continuous = match regeneration {
                    Regeneration::WhenEmpty => 0,
                    Regeneration::Continuous => 8,
                };
                continuous | 2 | (parity & 1)
            }
            Stage::Regenerate { parity } => 4 | (parity & 1),
        }
    }

    #[inline(always)]
    pub fn from_code(code: u32) -> Self {
        let parity = code & 1;
        match (code >> 1) & 3 {
            0 => Stage::Extend { parity },
            1 => Stage::Plan {
                parity,
                regeneration: if code & 8 != 0 {
                    Regeneration::Continuous
                } else {
                    Regeneration::WhenEmpty
                },
            },
            _ => Stage::Regenerate { parity },
        }
    }

    /// The three launches of iteration `iteration` of a strategy that regenerates as
    /// `regeneration`, in order.
    pub fn iteration(iteration: u64, regeneration: Regeneration) -> [Stage; 3] {
        let parity = (iteration & 1) as u32;
        [
            Stage::Extend { parity },
            Stage::Plan {
                parity,
                regeneration,
            },
            Stage::Regenerate { parity },
        ]
    }
}

/// The counters of a multi-kernel strategy's queues in device memory, shared by its stages.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct Wavefront {
    /// Paths in each queue.
    pub count: [u64; 2],
    /// Path indices handed out so far: `0 ..= total_paths`.
    pub issued: u64,
    /// The paths the next regeneration starts: indices `batch_first .. batch_first + batch_len`.
    pub batch_first: u64,
    pub batch_len: u64,
}

impl Wavefront {
    /// The plan stage, after extension has compacted the survivors of queue `parity` into the
    /// other: the next batch of new paths fills the room left in that queue (all of it, and only
    /// once it is empty, for [`Regeneration::WhenEmpty`]), and queue `parity`, consumed, is
    /// emptied for the next iteration's survivors.
    #[inline(always)]
    pub fn plan(
        &mut self,
        parity: u32,
        capacity: u64,
        total_paths: u64,
        regeneration: Regeneration,
    ) {
        let live = self.count[(1 - (parity & 1)) as usize];
        let room = match regeneration {
            Regeneration::WhenEmpty if live > 0 => 0,
            _ => capacity.saturating_sub(live),
        };
        let len = room.min(total_paths.saturating_sub(self.issued));
        self.batch_first = self.issued;
        self.batch_len = len;
        self.issued += len;
        self.count[(parity & 1) as usize] = 0;
    }

    /// Whether every path of a launch of `total_paths` paths has been started and has ended.
    pub fn done(&self, total_paths: u64) -> bool {
        self.issued >= total_paths && self.count == [0, 0]
    }
}

/// Bytes from one queued path to the next: a [`Slot`] padded to a cache line, on the host and on
/// the device alike (their layouts of `PathState` need not agree; this bound must).
pub const SLOT_BYTES: usize = 128;

/// A path in flight with the film pixel it belongs to (parked in shared or device memory by the
/// strategies that move paths between threads); `X` is the path's spectral state (nothing for a
/// grey medium).
#[derive(Clone, Copy)]
#[repr(C)]
pub struct Slot<X = ()> {
    pub path: volpt_core::path::PathState<X>,
    pub pixel: u32,
}

const _: () = assert!(core::mem::size_of::<Slot<volpt_core::HeroChannel>>() <= SLOT_BYTES);

/// Queued paths per resident thread of streaming-mk: each thread extends several paths per
/// launch, so that the launches' fixed cost is shared by more segments.
pub const WAVEFRONT_PATHS_PER_THREAD: u64 = 8;

/// The most paths a multi-kernel strategy queues (each queue; 2^22 slots are 512 MiB).
pub const MAX_WAVEFRONT_CAPACITY: u64 = 1 << 22;

impl Strategy {
    /// How this strategy maps its work onto threads and launches.
    pub fn scheduling(self) -> Scheduling {
        match self {
            Strategy::NaiveSk => Scheduling::PerPixel,
            Strategy::NaiveMk => Scheduling::Wavefront(Regeneration::WhenEmpty),
            Strategy::StreamingMk => Scheduling::Wavefront(Regeneration::Continuous),
            _ => Scheduling::Persistent,
        }
    }

    /// A multi-kernel strategy's queue capacity for a tile of `pixels` pixels on a GPU that
    /// keeps `resident_threads` of its kernel: naive-mk queues one sample of every pixel (the
    /// thesis's naiveMK: a launch per sample), streaming-mk [`WAVEFRONT_PATHS_PER_THREAD`] per
    /// resident thread; at most [`MAX_WAVEFRONT_CAPACITY`], at least one path.
    pub fn wavefront_capacity(self, pixels: u64, resident_threads: u64) -> u64 {
        let wanted = match self.scheduling() {
            Scheduling::Wavefront(Regeneration::WhenEmpty) => pixels,
            _ => resident_threads * WAVEFRONT_PATHS_PER_THREAD,
        };
        wanted.clamp(1, MAX_WAVEFRONT_CAPACITY)
    }

    /// Samples per pixel that one launch traces, out of the `remaining` samples of a render over
    /// `pixels` pixels, for a persistent strategy within a budget of `paths` paths (one sample at
    /// least).
    pub fn samples_per_launch(self, pixels: u64, remaining: u32, paths: u64) -> u32 {
        match self.scheduling() {
            // One thread per pixel: several samples per launch would only lengthen the warp's
            // longest path, so each launch is one sample, and progress is reported per sample.
            Scheduling::PerPixel => remaining.min(1),
            _ => {
                let fit = (paths / pixels.max(1)).max(1);
                remaining.min(u32::try_from(fit).unwrap_or(u32::MAX))
            }
        }
    }

    /// The launches of a render of `spp` samples over `pixels` pixels, as
    /// `(first_sample, samples)`, in order, each within the path budget `budgets` yields for it.
    pub fn launches(
        self,
        pixels: u64,
        spp: u32,
        mut budgets: impl FnMut() -> u64,
    ) -> impl Iterator<Item = (u32, u32)> {
        let mut first = 0;
        core::iter::from_fn(move || {
            let samples = self.samples_per_launch(pixels, spp - first, budgets());
            (samples > 0).then(|| {
                let launch = (first, samples);
                first += samples;
                launch
            })
        })
    }

    /// Blocks of [`BLOCK_SIZE`] threads one launch needs; `resident_blocks` is how many the GPU
    /// keeps resident at once for the kernel.
    pub fn blocks(self, pixels: u64, resident_blocks: u32) -> u32 {
        match self.scheduling() {
            Scheduling::PerPixel => pixels.div_ceil(BLOCK_SIZE as u64) as u32,
            // Persistent threads (and the multi-kernel stages, which loop over their queue):
            // exactly as many blocks as the GPU keeps resident.
            _ => resident_blocks.max(1),
        }
    }
}
