//! Several devices in one render (`--gpus`): every device pulls batches of samples from one
//! shared queue, so a faster or less loaded device takes more of them; each batch is rendered into
//! a film of its own and added to the render's film in batch order.
//!
//! Why batch order: the film is then the same sum, in the same order, whichever device rendered
//! which batch: a render with the same devices gives the same bits every time (unless the observer
//! asks for chunks of a time, [`Observer::check_every`], whose batch sizes follow measured speed).
//! Against one device's uninterrupted render it differs only in the order of the `f64` additions
//! (the batches' partial sums are added instead of every sample one by one).
//!
//! The cost is memory for batches finished ahead of an earlier one still rendering: at most
//! [`window`] batch films exist at once (a device waits rather than take a batch beyond it).
//!
//! Batch sizes are guided self-scheduling: each batch is two thirds of the remaining samples over
//! the device count ([`batch_size`]), at least [`smallest`]: large batches first, small ones at the
//! end, so that devices finish within about one small batch of each other. Every batch costs its
//! kernel's tail (the launch waits for its longest path: 25 ms on `ad`, an H100, 2026-11-26) and a
//! film read back, so there are few: about 6 per device.

use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Condvar, Mutex};
use std::time::Instant;

use volpt_core::PathCounters;
use volpt_film::{Accumulation, Film, RenderStats};

use crate::{Error, Observer};

/// One device: renders samples `samples` into a zeroed film, calling `progress(done, total)` in
/// paths of this batch.
pub(crate) type Device<'a> = Box<
    dyn Fn(&mut Film, Range<u32>, &(dyn Fn(u64, u64) + Sync)) -> Result<RenderStats, Error>
        + Sync
        + 'a,
>;

/// The smallest batch: 1/16 of a device's share of the range. The last batches decide when the
/// slowest device finishes, so they are short; but every batch pays a tail, and in a simulation
/// with the tails measured on two H100s (`bench/multigpu/schedule_sim.py`, `ad`) fewer, larger
/// batches came closer to the ideal time on alike GPUs, the common case: 0.974 with these rules
/// against 0.957 with 1/32 and half of an even share, at the price of 0.912 against 0.930 when one
/// GPU is twice as fast as the other.
fn smallest(samples: u32, devices: u32) -> u32 {
    samples.div_ceil(16 * devices).max(1)
}

/// A batch's size when `remaining` samples are left to `devices`: two thirds of an even share.
fn batch_size(remaining: u32, devices: u32) -> u32 {
    let share = u64::from(remaining) * 2 / (3 * u64::from(devices));
    share.max(1) as u32
}

/// How many batches may be handed out past the oldest one not yet added to the film: two per
/// device and two more, or as many films as fit in 1 GiB, whichever is more.
fn window(devices: u32, film_bytes: u64) -> u64 {
    (2 * u64::from(devices) + 2).max(films_in_a_gib(film_bytes))
}

/// How many films of `film_bytes` fit in 1 GiB, the memory batch films may take before a bound
/// of their count applies.
fn films_in_a_gib(film_bytes: u64) -> u64 {
    (1 << 30) / film_bytes.max(1)
}

/// A zeroed film for a batch, written once: a new allocation's pages are mapped by the first
/// write to each, which on the device machine cost 25 ms for 800x800, more than reading a film
/// back into memory written before.
fn batch_film(width: u32, height: u32, accumulation: Accumulation) -> Film {
    let mut film = Film::new(width, height).with_accumulation(accumulation);
    // Opaque to the optimiser, which knows that a new film's memory is zeroed and would drop the
    // writes.
    std::hint::black_box(film.flat_sums_mut()).fill(0.0);
    film
}

/// The shared queue of batches.
struct Queue {
    state: Mutex<QueueState>,
    /// Signalled when the film has advanced or the queue closed (a device may wait for either).
    advanced: Condvar,
    devices: u32,
    smallest: u32,
    window: u64,
}

struct QueueState {
    next: u32,
    end: u32,
    /// The index the next batch gets; batches are numbered in sample order.
    index: u64,
    /// The index of the oldest batch not yet added to the film.
    merged: u64,
    /// No more batches: cancelled, failed, or every batch handed out.
    closed: bool,
}

impl Queue {
    /// The next batch, at most `cap` samples when given; `None` once there is none to take.
    fn take(&self, cap: Option<u32>) -> Option<(u64, Range<u32>)> {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        while !s.closed && s.next < s.end && s.index >= s.merged + self.window {
            s = self.advanced.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        if s.closed || s.next >= s.end {
            return None;
        }
        let remaining = s.end - s.next;
        let mut size = batch_size(remaining, self.devices)
            .max(self.smallest)
            .min(remaining);
        if let Some(cap) = cap {
            size = size.min(cap.max(1));
        }
        let batch = s.next..s.next + size;
        s.next += size;
        s.index += 1;
        Some((s.index - 1, batch))
    }

    fn close(&self) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).closed = true;
        self.advanced.notify_all();
    }

    fn merged_up_to(&self, index: u64) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).merged = index;
        self.advanced.notify_all();
    }
}

/// What a device sends back.
enum Finished {
    Batch {
        index: u64,
        samples: Range<u32>,
        film: Film,
        stats: RenderStats,
    },
    Failed(Error),
}

/// Renders samples `samples` on `devices` into `film` (which holds the samples before them), as
/// [`crate::Backend::render_chunks`]: `after_chunk(film, end)` whenever the film has grown to
/// samples `..end`, the observer's progress over all devices, and cancellation between batches.
/// Returns the stats (`elapsed`: the wall time of the whole, so that throughput is the devices'
/// together) and the end of the samples the film holds.
pub(crate) fn render_shared(
    devices: &[Device<'_>],
    film: &mut Film,
    samples: Range<u32>,
    observer: &dyn Observer,
    after_chunk: &mut dyn FnMut(&Film, u32) -> Result<(), Error>,
) -> Result<(RenderStats, u32), Error> {
    let n = devices.len() as u32;
    let (width, height) = (film.width, film.height);
    let pixels = u64::from(width) * u64::from(height);
    let total = pixels * u64::from(samples.end - samples.start);
    let film_bytes = pixels * size_of::<[f64; 3]>() as u64;
    let queue = Queue {
        state: Mutex::new(QueueState {
            next: samples.start,
            end: samples.end,
            index: 0,
            merged: 0,
            closed: false,
        }),
        advanced: Condvar::new(),
        devices: n,
        smallest: smallest(samples.end - samples.start, n),
        window: window(n, film_bytes),
    };
    // Films for batches: made before the clock, as one device's render gets its film from the
    // caller ([`batch_film`]). Films added to the render's film are zeroed by the thread that
    // added them and come back here; a batch finds one unless more than these are pending. Two
    // per device, as many as fit in 1 GiB if fewer (at least one): the others are made when a
    // batch needs them.
    let accumulation = film.accumulation;
    let premade = (2 * u64::from(n)).min(films_in_a_gib(film_bytes).max(1));
    let spare: Mutex<Vec<Film>> = Mutex::new(std::thread::scope(|threads| {
        let makers: Vec<_> = (0..premade)
            .map(|_| threads.spawn(|| batch_film(width, height, accumulation)))
            .collect();
        makers
            .into_iter()
            .map(|maker| {
                maker
                    .join()
                    .unwrap_or_else(|p| std::panic::resume_unwind(p))
            })
            .collect()
    }));
    // Paths of finished batches, and of each device's batch in flight.
    let finished = AtomicU64::new(0);
    let in_flight: Vec<AtomicU64> = devices.iter().map(|_| AtomicU64::new(0)).collect();
    let report = || {
        let done = finished.load(Ordering::Relaxed)
            + in_flight
                .iter()
                .map(|a| a.load(Ordering::Relaxed))
                .sum::<u64>();
        observer.progress(done.min(total), total);
    };
    let started = Instant::now();
    let mut counters = PathCounters::default();
    let mut done = samples.start;
    let mut error = None;
    std::thread::scope(|scope| {
        let (send, receive) = mpsc::channel();
        for (d, device) in devices.iter().enumerate() {
            let send = send.clone();
            let (queue, finished, in_flight, report, spare) =
                (&queue, &finished, &in_flight, &report, &spare);
            scope.spawn(move || {
                let mut cap = observer.check_every().map(|_| 1u32);
                let mut first = true;
                loop {
                    // Between batches, as one device looks between chunks.
                    if !first && observer.cancelled() {
                        queue.close();
                        break;
                    }
                    first = false;
                    let Some((index, batch)) = queue.take(cap) else {
                        break;
                    };
                    let batch_paths = pixels * u64::from(batch.end - batch.start);
                    let progress = |p: u64, t: u64| {
                        let part = (p * batch_paths).checked_div(t).unwrap_or(0);
                        in_flight[d].store(part, Ordering::Relaxed);
                        report();
                    };
                    let reused = spare.lock().unwrap_or_else(|e| e.into_inner()).pop();
                    let mut batch_film =
                        reused.unwrap_or_else(|| batch_film(width, height, accumulation));
                    let batch_started = Instant::now();
                    match device(&mut batch_film, batch.clone(), &progress) {
                        Ok(stats) => {
                            // The schedule's timeline (`RUST_LOG=volpt=debug`): where the time
                            // between batches goes.
                            tracing::debug!(
                                device = d,
                                samples = ?batch,
                                from_s = (batch_started - started).as_secs_f64(),
                                took_s = batch_started.elapsed().as_secs_f64(),
                                kernels_s = stats.elapsed.as_secs_f64(),
                                "batch"
                            );
                            finished.fetch_add(batch_paths, Ordering::Relaxed);
                            in_flight[d].store(0, Ordering::Relaxed);
                            // Batches grow towards one `check_every` of this device's work, at
                            // most fourfold each time (as one device's chunks do).
                            if let (Some(every), Some(c)) = (observer.check_every(), cap) {
                                let per_sample = batch_started.elapsed().as_secs_f64()
                                    / f64::from(batch.end - batch.start);
                                let fit = every.as_secs_f64() / per_sample.max(1e-9);
                                cap = Some((fit as u32).clamp(1, c.saturating_mul(4)));
                            }
                            let message = Finished::Batch {
                                index,
                                samples: batch,
                                film: batch_film,
                                stats,
                            };
                            if send.send(message).is_err() {
                                break;
                            }
                        }
                        Err(e) => {
                            queue.close();
                            let _ = send.send(Finished::Failed(e));
                            break;
                        }
                    }
                }
            });
        }
        drop(send);
        // Batches finished ahead of an earlier one, by index.
        let mut pending: BTreeMap<u64, (Range<u32>, Film)> = BTreeMap::new();
        let mut next_index = 0;
        for message in receive {
            match message {
                Finished::Failed(e) => {
                    error.get_or_insert(e);
                }
                Finished::Batch {
                    index,
                    samples: batch,
                    film: batch_film,
                    stats,
                } => {
                    counters = counters.merge(stats.counters);
                    pending.insert(index, (batch, batch_film));
                    let before = next_index;
                    while let Some((batch, mut batch_film)) = pending.remove(&next_index) {
                        debug_assert_eq!(batch.start, done, "batches are numbered in sample order");
                        film.add(&batch_film);
                        done = batch.end;
                        next_index += 1;
                        batch_film.flat_sums_mut().fill(0.0);
                        spare
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .push(batch_film);
                    }
                    if next_index > before {
                        queue.merged_up_to(next_index);
                        if error.is_none() {
                            if let Err(e) = after_chunk(film, done) {
                                error = Some(e);
                                queue.close();
                            }
                        }
                    }
                }
            }
        }
        // Batches past a gap left by cancellation or failure are dropped: the film holds only
        // samples `..done`, contiguous, as a checkpoint must.
    });
    if let Some(e) = error {
        return Err(e);
    }
    Ok((
        RenderStats {
            elapsed: started.elapsed(),
            counters,
        },
        done,
    ))
}

/// Parses `--gpus`: `all`, or device ordinals separated by commas (`0,1,3`).
pub fn parse_gpus(text: &str) -> Result<crate::Gpus, String> {
    let text = text.trim();
    if text.eq_ignore_ascii_case("all") {
        return Ok(crate::Gpus::All);
    }
    let mut mask = 0u64;
    for part in text.split(',') {
        let ordinal: u32 = part.trim().parse().map_err(|_| {
            format!("expected `all` or GPU numbers separated by commas (0,1), found {text:?}")
        })?;
        if ordinal >= 64 {
            return Err(format!(
                "GPU {ordinal}: expected GPU numbers from 0 to 63, found {ordinal}"
            ));
        }
        if mask & (1 << ordinal) != 0 {
            return Err(format!("GPU {ordinal} is named twice in {text:?}"));
        }
        mask |= 1 << ordinal;
    }
    Ok(crate::Gpus::List(mask))
}
