//! `--strategy auto`: the best GPU schedule for this scene on this GPU, chosen by measurement.
//!
//! The thesis's central finding is that the best strategy depends on the scene; so instead of a
//! rule, short calibration renders of the actual scene time the candidates and the fastest wins:
//! the regeneration strategies and streaming-sk ([`TIMED`]) with the compiler's registers, then
//! the fastest of them under two register caps (the caps' effect hardly depends on the strategy,
//! and each candidate costs a JIT compilation). The
//! choice and the measurements behind it are printed, and cached per scene, GPU and math in
//! `$XDG_CACHE_HOME/volpt/auto.json` (or `~/.cache/volpt/`; `VOLPT_CACHE_DIR` overrides), so only
//! the first render of a scene pays for the calibration (a few seconds, most of it JIT compilation).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use serde::{Deserialize, Serialize};
use volpt_core::abi::SceneAbi;
use volpt_cuda::{CudaRenderer, Schedule, Strategy};
use volpt_film::{Film, RenderOptions};

use crate::Error;

/// Register caps tried on the fastest strategy.
const CAPS: [u32; 2] = [96, 64];

/// Paths per calibration render: one full first launch (`FIRST_LAUNCH_PATHS`), as a render of the
/// scene's own size runs. With 2^21 paths (13 spp at 400x400) a launch was mostly its tail (its
/// longest paths, ~25 ms on cgg-logo on an H100), and auto missed the register cap 64 that made
/// cgg-logo and the rough cube 5-6% faster (2026-11-23, `bench/device/auto-check.sh`).
const CALIBRATION_PATHS: u64 = volpt_device::launch::FIRST_LAUNCH_PATHS;

/// Timed renders per candidate; the fastest counts (the first also warms the kernel up).
const TRIALS: usize = 2;

/// The schedule of a render without `--strategy` that is too short to repay a calibration:
/// regeneration-sk, the best fixed strategy on most scenes (docs/strategies.md), with at most 64
/// registers a thread (the JIT's `.maxnreg`; a 128-thread block then needs 8192 of an SM's 65536
/// registers, so 8 blocks fit). Against the compiler's choice on the seven scenes of the Mitsuba
/// comparison (H100, 2026-11-27, `bench/results/2026-11-27-h100-session6/caps.txt`): envmap-cube
/// 1.31x, ad 1.17x, cgg-logo 1.14x, bucky 1.09x, the rough cube 1.07x, the index-matched cube and
/// smoke 0.98x.
pub const DEFAULT: Schedule = Schedule {
    strategy: Strategy::RegenerationSk,
    max_registers: Some(64),
    refill_at: None,
    tiles: None,
};

/// The strategies a calibration times. Not the naive baselines (naive-sk, naive-mk: a batch of
/// one sample per pixel waits for its longest path), and not the sorting, multi-kernel and
/// two-path strategies, each slower than the best of these four on every one of the seven
/// scenes of `docs/strategies.md` (by 1.04x at the least; H100, 2026-11-24): each candidate
/// costs two calibration renders and a JIT compilation.
const TIMED: [Strategy; 4] = [
    Strategy::RegenerationSk,
    Strategy::RegenerationWarpSk,
    Strategy::RegenerationBlockSk,
    Strategy::StreamingSk,
];

/// Candidates a calibration times: the timed strategies, then two register caps.
const CANDIDATES: u64 = TIMED.len() as u64 + CAPS.len() as u64;

/// The most a calibration has saved against regeneration-sk (auto-check.sh on an H100, 2026-11-23:
/// up to 16% with a register cap, on bucky), as a fraction of the render's time. [`DEFAULT`]
/// carries a cap of its own, against which a calibration gained at most 2% on the seven scenes
/// (2026-11-27); the bound is not lowered to that because a calibration is paid once per scene,
/// GPU and math (it is cached) and the seven scenes do not bound what another scene gains.
const LARGEST_SAVING: f64 = 0.16;

/// Whether a render of `paths` paths is long enough to repay a calibration: the calibration
/// renders `TRIALS` x `CALIBRATION_PATHS` per candidate, a render saves at most
/// [`LARGEST_SAVING`] of its own time. So a render without `--strategy` calibrates from about 75
/// calibration renders' worth of paths on (1.26e9 paths: 400x400 at 7900 spp), and below that
/// uses [`DEFAULT`] unless a choice is cached.
pub fn repays_calibration(paths: u64) -> bool {
    let calibration = (TRIALS as u64 * CANDIDATES * CALIBRATION_PATHS) as f64;
    paths as f64 * LARGEST_SAVING >= calibration
}

/// One candidate's calibration time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    pub strategy: String,
    pub max_registers: Option<u32>,
    /// Seconds per million paths (the fastest trial).
    pub seconds_per_mpath: f64,
}

/// A choice and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Choice {
    pub strategy: String,
    pub max_registers: Option<u32>,
    pub measurements: Vec<Measurement>,
}

impl Choice {
    pub fn schedule(&self) -> Option<Schedule> {
        let strategy = Strategy::ALL
            .iter()
            .copied()
            .find(|s| s.name() == self.strategy)?;
        Some(Schedule {
            strategy,
            max_registers: self.max_registers,
            refill_at: None,
            tiles: None,
        })
    }

    /// The measurements as a table, fastest first, and the choice.
    pub fn report(&self) -> String {
        let mut rows = self.measurements.clone();
        rows.sort_by(|a, b| a.seconds_per_mpath.total_cmp(&b.seconds_per_mpath));
        let best = rows.first().map_or(f64::NAN, |m| m.seconds_per_mpath);
        let mut out = format!(
            "auto: {} with {} (calibration, ms per million paths):\n",
            self.strategy,
            registers(self.max_registers)
        );
        for m in &rows {
            out.push_str(&format!(
                "  {:<24} {:<16} {:>9.3} ms  {:>6.2}x\n",
                m.strategy,
                registers(m.max_registers),
                1e3 * m.seconds_per_mpath,
                m.seconds_per_mpath / best
            ));
        }
        out
    }
}

/// A register cap as the reports name it: `<= N registers`, or the compiler's choice.
pub fn registers(cap: Option<u32>) -> String {
    cap.map_or_else(
        || "compiler's registers".to_owned(),
        |n| format!("<= {n} registers"),
    )
}

/// Times every candidate on `scene` and returns the fastest.
pub fn calibrate<S: SceneAbi>(
    renderer: &CudaRenderer,
    scene: &S,
    options: &RenderOptions,
) -> Result<Choice, Error> {
    let (width, height) = (scene.camera().width, scene.camera().height);
    let pixels = width as u64 * height as u64;
    let spp = CALIBRATION_PATHS.div_ceil(pixels.max(1)).clamp(1, 64) as u32;
    let time = |schedule: Schedule| -> Result<Measurement, Error> {
        let mut best = Duration::MAX;
        for _ in 0..TRIALS {
            let mut film = Film::new(width, height);
            let stats =
                renderer.render_samples(scene, schedule, &mut film, 0..spp, options, &|_, _| {})?;
            best = best.min(stats.elapsed);
        }
        Ok(Measurement {
            strategy: schedule.strategy.name().to_owned(),
            max_registers: schedule.max_registers,
            seconds_per_mpath: best.as_secs_f64() / (pixels * spp as u64) as f64 * 1e6,
        })
    };
    // A scene with a light on or a mesh boundary has kernels for its set's strategies only.
    let set = volpt_device::KernelSet::of_scene(scene);
    let timed = TIMED
        .into_iter()
        .filter(|s| set.is_none_or(|set| set.strategies().contains(s)));
    let mut measurements = Vec::new();
    for strategy in timed {
        measurements.push(time(strategy.into())?);
    }
    let winner = fastest(&measurements).strategy.clone();
    let strategy = Strategy::ALL
        .iter()
        .copied()
        .find(|s| s.name() == winner)
        .expect("measured strategies are strategies");
    for cap in CAPS {
        measurements.push(time(Schedule {
            strategy,
            max_registers: Some(cap),
            refill_at: None,
            tiles: None,
        })?);
    }
    let best = fastest(&measurements);
    Ok(Choice {
        strategy: best.strategy.clone(),
        max_registers: best.max_registers,
        measurements,
    })
}

fn fastest(measurements: &[Measurement]) -> &Measurement {
    measurements
        .iter()
        .min_by(|a, b| a.seconds_per_mpath.total_cmp(&b.seconds_per_mpath))
        .expect("at least one candidate")
}

/// Choices by key (scene fingerprint, GPU and math), kept in memory and in a JSON file.
pub struct AutoCache {
    path: Option<PathBuf>,
    entries: Mutex<BTreeMap<String, Choice>>,
}

/// The bytes of the regular file at `path` (anything else is refused before it is opened).
fn read_regular(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let (file, len) = volpt_film::regular::open_regular(path)?;
    let mut bytes = Vec::new();
    file.take(len).read_to_end(&mut bytes)?;
    Ok(bytes)
}

impl AutoCache {
    /// The user's cache file, read if it exists; an unreadable cache is ignored with a warning
    /// (it only saves calibration time).
    pub fn open() -> Self {
        Self::at(cache_dir().map(|d| d.join("auto.json")))
    }

    /// The cache in file `path` (none: in memory only).
    fn at(path: Option<PathBuf>) -> Self {
        let entries = path
            .as_ref()
            .filter(|p| p.exists())
            // A regular file only: a FIFO in its place would block the read for ever.
            .and_then(|p| match read_regular(p) {
                Ok(bytes) => serde_json::from_slice(&bytes)
                    .map_err(|e| tracing::warn!("ignoring the auto cache {}: {e}", p.display()))
                    .ok(),
                Err(e) => {
                    tracing::warn!("ignoring the auto cache {}: {e}", p.display());
                    None
                }
            })
            .unwrap_or_default();
        Self {
            path,
            entries: Mutex::new(entries),
        }
    }

    pub fn get(&self, key: &str) -> Option<Choice> {
        self.lock().get(key).cloned()
    }

    /// Records `choice` and writes the cache file (a failure to write only warns).
    pub fn insert(&self, key: String, choice: Choice) {
        let mut entries = self.lock();
        entries.insert(key, choice);
        let Some(path) = &self.path else { return };
        let written = path
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .and_then(|()| {
                let json = serde_json::to_vec_pretty(&*entries).map_err(std::io::Error::other)?;
                // Written beside and renamed, so that a concurrent reader never sees half a file.
                let tmp = path.with_extension(format!("json.{}", std::process::id()));
                std::fs::write(&tmp, json)?;
                std::fs::rename(&tmp, path)
            });
        if let Err(e) = written {
            tracing::warn!("could not write the auto cache {}: {e}", path.display());
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, BTreeMap<String, Choice>> {
        self.entries.lock().unwrap_or_else(|e| e.into_inner())
    }
}

fn cache_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("VOLPT_CACHE_DIR") {
        return Some(dir.into());
    }
    std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .map(|d| d.join("volpt"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn choice() -> Choice {
        Choice {
            strategy: "regeneration-sk".to_owned(),
            max_registers: Some(96),
            measurements: vec![
                Measurement {
                    strategy: "regeneration-sk".to_owned(),
                    max_registers: Some(96),
                    seconds_per_mpath: 0.001,
                },
                Measurement {
                    strategy: "streaming-sk".to_owned(),
                    max_registers: None,
                    seconds_per_mpath: 0.003,
                },
            ],
        }
    }

    #[test]
    fn only_long_renders_repay_a_calibration() {
        // 400x400 at 100 spp: a calibration of 12 renders of 2^24 paths would cost 10x the render.
        assert!(!repays_calibration(400 * 400 * 100));
        assert!(!repays_calibration(400 * 400 * 7000));
        assert!(repays_calibration(400 * 400 * 8000));
        assert!(repays_calibration(1920 * 1080 * 1024));
    }

    #[test]
    fn a_choice_names_a_schedule_and_reports_its_measurements() {
        let c = choice();
        assert_eq!(
            c.schedule(),
            Some(Schedule {
                strategy: Strategy::RegenerationSk,
                max_registers: Some(96),
                refill_at: None,
                tiles: None,
            })
        );
        let report = c.report();
        assert!(
            report.contains("auto: regeneration-sk with <= 96 registers"),
            "{report}"
        );
        assert!(report.contains("3.00x"), "{report}");
        let unknown = Choice {
            strategy: "warp-drive".to_owned(),
            ..c
        };
        assert_eq!(unknown.schedule(), None);
    }

    #[test]
    fn the_cache_survives_a_restart_and_ignores_a_broken_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("auto.json");
        let cache = AutoCache::at(Some(path.clone()));
        cache.insert("gpu|exact|1234".to_owned(), choice());
        let again: BTreeMap<String, Choice> =
            serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        assert_eq!(again.get("gpu|exact|1234"), Some(&choice()));
        assert_eq!(
            AutoCache::at(Some(path.clone())).get("gpu|exact|1234"),
            Some(choice())
        );
        std::fs::write(&path, b"{ not json").unwrap();
        assert_eq!(AutoCache::at(Some(path)).get("gpu|exact|1234"), None);
    }
}
