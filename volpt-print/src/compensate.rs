//! The scattering compensation loop (Elek et al. 2017, "Scattering-aware texture reproduction for
//! 3D printing", ACM TOG 36(6)): predict the print's appearance, measure each texel's CIEDE2000
//! against the target, correct the colours the layers under each texel aim for, halftone again,
//! and repeat until the error stops falling or the iteration budget ends.
//!
//! **Update** ([`Options::update`]): by default through the print's cross-texel response,
//! fitted from the predictions ([`Update::CrossTalk`], [`crate::crosstalk`]: the aims that
//! minimise the mean CIEDE2000 of a linear model of the print around the best iteration);
//! or per texel ([`Update::PerTexel`]): a fixed-point (Landweber) correction in linear RGB,
//! `aim_{k+1} = clamp(aim_k + step * (target - prediction_k), 0, 1)`, per texel, starting from
//! the naive assignment `aim_0 = target`. It is the per-texel additive correction of the aimed
//! colour by the predicted error that Elek et al. iterate. Why it converges, and monotonically on
//! a blur: where the print responds linearly, `prediction = A aim` with `A` the print's transport
//! (a blur of the inks' mix), the residual obeys `r_{k+1} = (I - step A) r_k`; for a symmetric
//! blur with eigenvalues in (0, 1] and `0 < step <= 1` every eigenmode shrinks by
//! `|1 - step lambda| < 1` at every step, so the residual falls monotonically, and the fixed
//! point is the aim whose prediction is the target (where it is reachable: the clamp to the
//! printable range stops the rest); it is the cross-talk update's special case `K = I`.
//! Halftoning adds at most 1/L of quantisation per ink and texel (see [`crate::halftone`]),
//! which bounds how close the loop gets.
//!
//! **Stopping**: an iteration that does not lower the best mean CIEDE2000 so far (by
//! [`Options::min_improvement`]) is not built on: the next update starts again from the best
//! iteration with half the step (backtracking: parts of a target no print reaches make the
//! update push aims into the printable range's clamp, and a prediction's noise can do the same);
//! after [`Options::backtracks`] such halvings, or [`Options::max_iterations`] predictions, the
//! loop stops. Each iteration's aims, prediction, per-texel CIEDE2000 map, mean and 95th
//! percentile are kept; the result is the print of the iteration with the lowest mean.
//!
//! **Noise** (a rendered prediction is an estimate): each prediction's noise is measured as the
//! mean, over texels, of the CIEDE2000 between the prediction and the prediction moved by one
//! standard error per channel ([`Predictor::standard_error`]). The update moves the aims by
//! `step` times the error, whose size in CIEDE2000 is about `step * mean`; a prediction whose
//! noise is above [`Options::noise_ratio`] times that would let the noise steer the update. Such a
//! prediction is made again with more samples ([`Predictor::more_samples`]: four times as many,
//! half the noise) until its noise is below the bound or the predictor is at its most samples;
//! later iterations keep the samples reached (the error the loop removes only shrinks). So the
//! update follows the signal: its noise is at most `noise_ratio` of the step it takes.
//!
//! **Interruption**: a prediction cut short by its observer (Ctrl-C, [`Predictor::interrupted`])
//! ends the loop with the iterations finished before it ([`Compensation::interrupted`]).
//!
//! The loop is written against [`Predictor`]: the real one renders the print with volpt (an
//! orthographic top view, one pixel per surface texel).

use thiserror::Error;
use volpt::metrics::quantile;

use crate::colour::{ciede2000, Lab, LinearRgb};
use crate::crosstalk::Response;
use crate::halftone::{naive_mix, Halftone};
use crate::print::VoxelPrint;
use volpt_scene::material::MaterialDesc;

/// What predicts a print's appearance.
pub trait Predictor {
    type Error: std::error::Error + Send + Sync + 'static;

    /// The linear RGB colour of each surface texel of `print`, seen from straight above under the
    /// predictor's illumination: `width * height` values, row-major.
    fn predict(&mut self, print: &VoxelPrint) -> Result<Vec<LinearRgb>, Self::Error>;

    /// The last prediction's standard error per texel and channel, if the predictor estimates
    /// it (an exact predictor has none: no noise to control).
    fn standard_error(&self) -> Option<&[LinearRgb]> {
        None
    }

    /// Makes later predictions with four times the samples; `false` (and no change) when the
    /// predictor is at its most samples or has no samples to add.
    fn more_samples(&mut self) -> bool {
        false
    }

    /// The samples per texel the next prediction takes, if the predictor samples (for the
    /// record).
    fn samples(&self) -> Option<u32> {
        None
    }

    /// Whether the last prediction was cut short by its observer (Ctrl-C): not a whole
    /// prediction, so the loop ends without it.
    fn interrupted(&self) -> bool {
        false
    }
}

/// The print the loop builds: its materials and voxel size, and the halftone of its inks.
#[derive(Clone, Debug)]
pub struct Setup {
    pub materials: Vec<MaterialDesc>,
    pub voxel_size: [f64; 3],
    pub halftone: Halftone,
}

/// When the loop stops, and how far each update steps.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// The most predictions made (the naive assignment's included).
    pub max_iterations: usize,
    /// The update's step, in (0, 1].
    pub step: f64,
    /// An iteration improves when its mean CIEDE2000 is below the best so far by this fraction
    /// of it.
    pub min_improvement: f64,
    /// How often an iteration that does not improve halves the step and retries from the best
    /// iteration before the loop stops.
    pub backtracks: u32,
    /// A prediction's noise (see the module docs) may be at most this fraction of the update's
    /// step, `step * mean`; `None` takes every prediction as it comes.
    pub noise_ratio: Option<f64>,
    /// How the aims are corrected.
    pub update: Update,
}

/// The update's model of the print.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Update {
    /// Each texel's aim corrected by its own error (the module docs).
    PerTexel,
    /// The aims corrected through the print's cross-texel response, fitted from the predictions
    /// ([`crate::crosstalk`]).
    #[default]
    CrossTalk,
}

impl Update {
    /// Every update, by the name the front ends take ([`Update::name`]).
    pub const ALL: [Update; 2] = [Update::CrossTalk, Update::PerTexel];

    /// The update's name on the command line and in Python.
    pub fn name(self) -> &'static str {
        match self {
            Update::PerTexel => "per-texel",
            Update::CrossTalk => "cross-talk",
        }
    }
}

impl std::str::FromStr for Update {
    type Err = String;

    fn from_str(name: &str) -> Result<Update, String> {
        Update::ALL
            .into_iter()
            .find(|u| u.name() == name)
            .ok_or_else(|| {
                let names: Vec<_> = Update::ALL
                    .iter()
                    .map(|u| format!("{:?}", u.name()))
                    .collect();
                format!("expected {}, found {name:?}", names.join(" or "))
            })
    }
}

/// Projected-gradient steps of one cross-talk update ([`Response::update`]).
const CROSS_TALK_STEPS: usize = 200;

impl Default for Options {
    fn default() -> Self {
        Options {
            max_iterations: 10,
            step: 1.0,
            min_improvement: 1e-3,
            backtracks: 2,
            noise_ratio: Some(0.25),
            update: Update::default(),
        }
    }
}

/// One iteration: what the layers aimed for, what the predictor saw, and the error.
#[derive(Clone, Debug)]
pub struct Iteration {
    pub aims: Vec<LinearRgb>,
    pub prediction: Vec<LinearRgb>,
    /// CIEDE2000 of each texel's prediction against the target.
    pub delta_e: Vec<f64>,
    pub mean: f64,
    /// 95th percentile of `delta_e` ([`volpt::metrics::quantile`]: linear between order
    /// statistics, as NumPy's default).
    pub p95: f64,
    /// The prediction's noise: the mean CIEDE2000 of one standard error (0 where the predictor
    /// estimates none).
    pub noise: f64,
    /// The samples per texel the prediction took, if the predictor samples.
    pub samples: Option<u32>,
}

/// The loop's record and its result.
#[derive(Clone, Debug)]
pub struct Compensation {
    pub iterations: Vec<Iteration>,
    /// The iteration whose print is `print` (the lowest mean CIEDE2000).
    pub best: usize,
    pub print: VoxelPrint,
    /// The loop was stopped by its predictor's observer (Ctrl-C) before it ended by itself.
    pub interrupted: bool,
}

#[derive(Debug, Error)]
pub enum CompensateError<E: std::error::Error + 'static> {
    #[error("the predictor failed: {0}")]
    Predictor(#[source] E),
    #[error("{field}: expected {expected}, found {found}")]
    Invalid {
        field: &'static str,
        expected: String,
        found: String,
    },
    #[error("interrupted before the first prediction finished")]
    Interrupted,
}

/// The print whose surface texels aim for `aims` (`width` x `height`).
pub fn print_for(
    setup: &Setup,
    aims: &[LinearRgb],
    width: u32,
    height: u32,
) -> Result<VoxelPrint, (&'static str, String, String)> {
    let mixes: Vec<_> = aims.iter().map(|&a| naive_mix(a)).collect();
    let indices = setup.halftone.indices(&mixes, width, height);
    VoxelPrint::new(
        setup.materials.clone(),
        setup.voxel_size,
        [width, height, setup.halftone.depth],
        indices,
    )
}

/// The update: each texel's aim moved by `step` times the prediction's error, within [0, 1].
fn update(
    aims: &[LinearRgb],
    target: &[LinearRgb],
    prediction: &[LinearRgb],
    step: f64,
) -> Vec<LinearRgb> {
    aims.iter()
        .zip(target.iter().zip(prediction))
        .map(|(a, (t, p))| {
            LinearRgb([0, 1, 2].map(|c| (a.0[c] + step * (t.0[c] - p.0[c])).clamp(0.0, 1.0)))
        })
        .collect()
}

/// The mean CIEDE2000 between each texel's prediction and the prediction moved by one standard
/// error in every channel: how far the noise alone moves a texel's colour.
pub fn noise(prediction: &[LinearRgb], standard_error: &[LinearRgb]) -> f64 {
    if prediction.is_empty() {
        return 0.0;
    }
    let sum: f64 = prediction
        .iter()
        .zip(standard_error)
        .map(|(p, e)| {
            let moved = LinearRgb([0, 1, 2].map(|c| p.0[c] + e.0[c]));
            ciede2000(p.to_lab(), moved.to_lab())
        })
        .sum();
    sum / prediction.len() as f64
}

/// One prediction of a print, made again with more samples while its noise would steer an update
/// of `step` (see the module docs); `None` when the predictor was interrupted.
struct Predicted {
    prediction: Vec<LinearRgb>,
    delta_e: Vec<f64>,
    mean: f64,
    noise: f64,
    samples: Option<u32>,
}

fn predict<P: Predictor>(
    predictor: &mut P,
    print: &VoxelPrint,
    target_lab: &[Lab],
    step: f64,
    options: &Options,
) -> Result<Option<Predicted>, CompensateError<P::Error>> {
    loop {
        let prediction = predictor
            .predict(print)
            .map_err(CompensateError::Predictor)?;
        if predictor.interrupted() {
            return Ok(None);
        }
        let not_finite = prediction
            .iter()
            .filter(|c| !c.0.iter().all(|v| v.is_finite()))
            .count();
        if prediction.len() != target_lab.len() || not_finite > 0 {
            return Err(CompensateError::Invalid {
                field: "prediction",
                expected: format!("{} finite colours", target_lab.len()),
                found: format!("{} values, {not_finite} not finite", prediction.len()),
            });
        }
        let delta_e: Vec<f64> = prediction
            .iter()
            .zip(target_lab)
            .map(|(p, t)| ciede2000(p.to_lab(), *t))
            .collect();
        let mean = delta_e.iter().sum::<f64>() / delta_e.len() as f64;
        let noise = predictor
            .standard_error()
            .map_or(0.0, |e| self::noise(&prediction, e));
        let too_noisy = options
            .noise_ratio
            .is_some_and(|ratio| noise > ratio * step * mean);
        if !(too_noisy && predictor.more_samples()) {
            return Ok(Some(Predicted {
                prediction,
                delta_e,
                mean,
                noise,
                samples: predictor.samples(),
            }));
        }
    }
}

/// Runs the loop for a `target` image (linear RGB, `width` x `height`, row-major); `observe` sees
/// each iteration as it ends (progress).
pub fn compensate<P: Predictor>(
    target: &[LinearRgb],
    [width, height]: [u32; 2],
    setup: &Setup,
    options: &Options,
    predictor: &mut P,
    mut observe: impl FnMut(&Iteration),
) -> Result<Compensation, CompensateError<P::Error>> {
    let texels = width as usize * height as usize;
    let invalid = |field, expected: String, found: String| CompensateError::Invalid {
        field,
        expected,
        found,
    };
    if target.len() != texels || texels == 0 {
        return Err(invalid(
            "target",
            format!("{width} x {height} texels, at least one"),
            format!("{} values", target.len()),
        ));
    }
    let ratio_ok = options.noise_ratio.is_none_or(|r| r > 0.0);
    if !(options.step > 0.0 && options.step <= 1.0) || options.max_iterations == 0 || !ratio_ok {
        return Err(invalid(
            "options",
            "a step in (0, 1], at least one iteration and a noise ratio above 0".into(),
            format!("{options:?}"),
        ));
    }
    let target_lab: Vec<Lab> = target.iter().map(|c| c.to_lab()).collect();
    let mut aims: Vec<LinearRgb> = target
        .iter()
        .map(|c| LinearRgb(c.0.map(|v| v.clamp(0.0, 1.0))))
        .collect();
    let mut iterations: Vec<Iteration> = Vec::new();
    let mut best: Option<(usize, VoxelPrint)> = None;
    let mut step = options.step;
    let mut backtracks = 0;
    let mut interrupted = false;
    while iterations.len() < options.max_iterations {
        let print = print_for(setup, &aims, width, height)
            .map_err(|(field, expected, found)| invalid(field, expected, found))?;
        let Some(predicted) = predict(predictor, &print, &target_lab, step, options)? else {
            interrupted = true;
            break;
        };
        let Predicted {
            prediction,
            delta_e,
            mean,
            noise,
            samples,
        } = predicted;
        let iteration = Iteration {
            aims: std::mem::take(&mut aims),
            prediction,
            p95: quantile(&delta_e, 0.95),
            delta_e,
            mean,
            noise,
            samples,
        };
        observe(&iteration);
        let k = iterations.len();
        iterations.push(iteration);
        let best_mean = best.as_ref().map(|(b, _)| iterations[*b].mean);
        if best_mean.is_none_or(|b| mean < b) {
            best = Some((k, print));
        }
        if best_mean.is_some_and(|b| mean >= b * (1.0 - options.min_improvement)) {
            // No improvement: retry from the best with half the step, or stop.
            if backtracks == options.backtracks {
                break;
            }
            backtracks += 1;
            step *= 0.5;
        }
        let from = &iterations[best.as_ref().expect("set above").0];
        aims = match options.update {
            Update::PerTexel => update(&from.aims, target, &from.prediction, step),
            Update::CrossTalk => {
                let samples: Vec<_> = iterations
                    .iter()
                    .map(|i| (&i.aims[..], &i.prediction[..]))
                    .collect();
                let response = Response::fit(&samples, [width, height]);
                let minimum = response.update(
                    &from.aims,
                    &from.prediction,
                    &target_lab,
                    [width, height],
                    CROSS_TALK_STEPS,
                );
                from.aims
                    .iter()
                    .zip(minimum)
                    .map(|(a, m)| LinearRgb([0, 1, 2].map(|c| a.0[c] + step * (m.0[c] - a.0[c]))))
                    .collect()
            }
        };
    }
    let (best, print) = best.ok_or(CompensateError::Interrupted)?;
    Ok(Compensation {
        iterations,
        best,
        print,
        interrupted,
    })
}
