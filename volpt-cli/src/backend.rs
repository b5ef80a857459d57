//! The backend flags (`--backend`, the GPU's `--strategy`, `--math`, ...), parsed by clap and
//! handed to the library's `volpt::Backend::open`, which checks how they combine.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use volpt::{GpuOptions, Math, Observer, StrategyChoice};

use crate::volume::VolumeArgs;

pub use volpt::BackendKind;

/// The flags that only the GPU backend takes: how it schedules and computes.
#[derive(Clone, Copy, Debug, Default, clap::Args)]
pub struct GpuArgs {
    /// GPU scheduling strategy; `auto` picks the fastest for the scene by calibration renders,
    /// cached per scene and GPU (default: auto's cached choice, a calibration for a render long
    /// enough to repay it, else regeneration-sk).
    #[arg(long, value_parser = crate::named::<StrategyChoice>())]
    pub strategy: Option<StrategyChoice>,
    /// GPU arithmetic: `fast` (default) uses the GPU's approximate instructions, statistically
    /// equal to `exact`, which is bit-identical to the CPU (with naive-sk).
    #[arg(long, value_parser = crate::named::<Math>())]
    pub math: Option<Math>,
    /// Cap the GPU kernel's registers per thread (the JIT spills the rest): more threads resident
    /// per multiprocessor, at the price of spills.
    #[arg(long, value_name = "N")]
    pub max_registers: Option<u32>,
    /// regeneration-sk: refill a warp's idle lanes with new paths once at least N of them are
    /// idle (default 8; 1 refills at once, 32 waits for the whole warp): fewer, fuller refills
    /// against lanes idling in between.
    #[arg(long, value_name = "N")]
    pub refill_at: Option<u32>,
    /// Cut the image into COLUMNS x ROWS tiles, each rendered by its own launches one after the
    /// other (the thesis's tiling study: smaller launches, more tails; docs/strategies.md).
    #[arg(long, value_name = "COLUMNS,ROWS")]
    pub tiles: Option<Tiles>,
    /// Render on several GPUs at once: `all`, or GPU numbers separated by commas (`0,1`). Each GPU
    /// pulls batches of samples from one queue (a faster GPU takes more) into a film of its own;
    /// the films are added in batch order (default: GPU 0 alone).
    #[arg(long, value_name = "all|0,1,...")]
    pub gpus: Option<volpt::Gpus>,
}

/// `--tiles COLUMNS,ROWS` (their bounds are the library's, `volpt::TILES`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiles(pub [u32; 2]);

impl std::str::FromStr for Tiles {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let parse = |v: &str| -> Result<u32, String> {
            (v.trim().parse::<u32>())
                .map_err(|_| format!("expected COLUMNS,ROWS (e.g. 4,4), found {s:?}"))
        };
        match s.split_once(',') {
            Some((c, r)) => Ok(Tiles([parse(c)?, parse(r)?])),
            None => Err(format!("expected COLUMNS,ROWS (e.g. 4,4), found {s:?}")),
        }
    }
}

impl GpuArgs {
    /// The library's GPU options: these flags and the volume flags.
    pub fn options(&self, volumes: &VolumeArgs) -> GpuOptions {
        GpuOptions {
            strategy: self.strategy,
            math: self.math,
            max_registers: self.max_registers,
            refill_at: self.refill_at,
            tiles: self.tiles.map(|t| t.0),
            volume_memory: volumes.volume_memory,
            device_memory_budget: volumes.device_memory_budget,
            bricked: volumes.bricked,
            gpus: self.gpus.unwrap_or_default(),
        }
    }
}

/// What `volpt render` shows while it renders: a progress bar, auto's notes, and Ctrl-C.
pub struct Terminal {
    bar: ProgressBar,
    interrupted: Option<Arc<AtomicBool>>,
}

impl Terminal {
    /// A progress bar if `show`, else nothing.
    pub fn new(show: bool) -> Self {
        let bar = if show {
            let bar = ProgressBar::new(0);
            bar.set_style(
                ProgressStyle::with_template(
                    "{spinner} [{elapsed_precise}] {wide_bar} {percent}% eta {eta}",
                )
                .expect("static template"),
            );
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        } else {
            ProgressBar::hidden()
        };
        Self {
            bar,
            interrupted: None,
        }
    }

    /// Stops the render between chunks on Ctrl-C, saying `message` (a second Ctrl-C ends the
    /// process at once).
    pub fn interruptible(mut self, message: &'static str) -> anyhow::Result<Self> {
        let interrupted = Arc::new(AtomicBool::new(false));
        let flag = interrupted.clone();
        ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
            eprintln!("{message}");
        })
        .map_err(|e| anyhow::anyhow!("installing the Ctrl-C handler: {e}"))?;
        self.interrupted = Some(interrupted);
        Ok(self)
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Observer for Terminal {
    fn progress(&self, done: u64, total: u64) {
        self.bar.set_length(total);
        self.bar.set_position(done);
    }

    fn note(&self, text: &str) {
        self.bar.suspend(|| eprint!("{text}"));
    }

    fn cancelled(&self) -> bool {
        self.interrupted
            .as_ref()
            .is_some_and(|f| f.load(Ordering::SeqCst))
    }

    /// An interruptible terminal looks at Ctrl-C twice a second (a render's samples are the
    /// same however they are chunked).
    fn check_every(&self) -> Option<Duration> {
        self.interrupted
            .as_ref()
            .map(|_| Duration::from_millis(500))
    }
}

/// The name reports give a math build.
pub fn math_name(math: Option<Math>) -> Option<String> {
    math.map(|m| m.name().to_owned())
}

/// The strategy a report names: `auto` or a strategy's name.
pub fn strategy_name(strategy: Option<StrategyChoice>) -> Option<String> {
    strategy.map(|s| s.to_string())
}
