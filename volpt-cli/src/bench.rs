//! `volpt bench`: the thesis' testing mode. One warm-up trial is discarded; the rest give the mean
//! and standard deviation of the render time and the throughputs derived from it.

use serde::Serialize;
use volpt::RenderStats;

#[derive(Debug, Serialize)]
pub struct BenchReport {
    pub scene: String,
    pub backend: String,
    pub strategy: Option<String>,
    /// The GPU's arithmetic (`exact` or `fast`).
    pub math: Option<String>,
    pub device: String,
    pub variant: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub trials: usize,
    pub time_mean_s: f64,
    pub time_std_s: f64,
    pub time_median_s: f64,
    pub paths: u64,
    pub segments: u64,
    pub tracking_steps: u64,
    /// Paths cut by a safety bound (free flights or tracking steps per path).
    pub truncated_paths: u64,
    /// Of those, the paths cut by the tracking-step bound.
    pub truncated_tracking_paths: u64,
    /// Throughputs over the mean time.
    pub paths_per_s: f64,
    pub segments_per_s: f64,
    pub tracking_steps_per_s: f64,
    pub image_mean: [f64; 3],
}

pub struct TimeStats {
    pub mean: f64,
    pub std: f64,
    pub median: f64,
}

/// Mean, sample standard deviation and median of the trials' times in seconds.
pub fn time_stats(trials: &[RenderStats]) -> TimeStats {
    let mut times: Vec<f64> = trials.iter().map(|t| t.elapsed.as_secs_f64()).collect();
    let n = times.len() as f64;
    let mean = times.iter().sum::<f64>() / n;
    let std = if times.len() > 1 {
        (times.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    times.sort_by(f64::total_cmp);
    let median = if times.len() % 2 == 1 {
        times[times.len() / 2]
    } else {
        0.5 * (times[times.len() / 2 - 1] + times[times.len() / 2])
    };
    TimeStats { mean, std, median }
}

impl BenchReport {
    pub fn table_row(&self) -> String {
        format!(
            "{:<28} {:<6} {:<16} {:>9.4} s +- {:<8.4} {:>10.3} M paths/s {:>10.3} M segments/s {:>10.3} M steps/s",
            self.scene,
            self.backend,
            self.strategy.as_deref().unwrap_or("-"),
            self.time_mean_s,
            self.time_std_s,
            self.paths_per_s * 1e-6,
            self.segments_per_s * 1e-6,
            self.tracking_steps_per_s * 1e-6
        )
    }
}
