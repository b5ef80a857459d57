//! The scattering compensation loop (Elek et al. 2017, "Scattering-aware texture reproduction for
//! 3D printing", ACM TOG 36(6)): predict the print's appearance, measure each texel's CIEDE2000
//! against the target, correct the colours the layers under each texel aim for, halftone again,
//! and repeat until the error stops falling or the iteration budget ends.
//!
//! **Update**: a fixed-point (Landweber) correction in linear RGB,
//! `aim_{k+1} = clamp(aim_k + step * (target - prediction_k), 0, 1)`, per texel, starting from
//! the naive assignment `aim_0 = target`. It is the per-texel additive correction of the aimed
//! colour by the predicted error that Elek et al. iterate. Why it converges, and monotonically on
//! a blur: where the print responds linearly, `prediction = A aim` with `A` the print's transport
//! (a blur of the inks' mix), the residual obeys `r_{k+1} = (I - step A) r_k`; for a symmetric
//! blur with eigenvalues in (0, 1] and `0 < step <= 1` every eigenmode shrinks by
//! `|1 - step lambda| < 1` at every step, so the residual falls monotonically, and the fixed
//! point is the aim whose prediction is the target (where it is reachable: the clamp to the
//! printable range stops the rest). Halftoning adds at most 1/L of quantisation per ink and
//! texel (see [`crate::halftone`]), which bounds how close the loop gets.
//!
//! **Stopping**: an iteration that does not lower the best mean CIEDE2000 so far (by
//! [`Options::min_improvement`]) is not built on: the next update starts again from the best
//! iteration with half the step (backtracking: parts of a target no print reaches make the
//! update push aims into the printable range's clamp, and a prediction's noise can do the same);
//! after [`Options::backtracks`] such halvings, or [`Options::max_iterations`] predictions, the
//! loop stops. Each iteration's aims, prediction, per-texel CIEDE2000 map, mean and 95th
//! percentile are kept; the result is the print of the iteration with the lowest mean.
//!
//! The loop is written against [`Predictor`]: the real one renders the print with volpt (an
//! orthographic top view, one pixel per surface texel).

use thiserror::Error;
use volpt::metrics::quantile;

use crate::colour::{ciede2000, Lab, LinearRgb};
use crate::halftone::{naive_mix, Halftone};
use crate::material::Material;
use crate::print::VoxelPrint;

/// What predicts a print's appearance.
pub trait Predictor {
    type Error: std::error::Error + Send + Sync + 'static;

    /// The linear RGB colour of each surface texel of `print`, seen from straight above under the
    /// predictor's illumination: `width * height` values, row-major.
    fn predict(&mut self, print: &VoxelPrint) -> Result<Vec<LinearRgb>, Self::Error>;
}

/// The print the loop builds: its materials and voxel size, and the halftone of its inks.
#[derive(Clone, Debug)]
pub struct Setup {
    pub materials: Vec<Material>,
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
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_iterations: 10,
            step: 1.0,
            min_improvement: 1e-3,
            backtracks: 2,
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
}

/// The loop's record and its result.
#[derive(Clone, Debug)]
pub struct Compensation {
    pub iterations: Vec<Iteration>,
    /// The iteration whose print is `print` (the lowest mean CIEDE2000).
    pub best: usize,
    pub print: VoxelPrint,
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
    if !(options.step > 0.0 && options.step <= 1.0) || options.max_iterations == 0 {
        return Err(invalid(
            "options",
            "a step in (0, 1] and at least one iteration".into(),
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
    while iterations.len() < options.max_iterations {
        let print = print_for(setup, &aims, width, height)
            .map_err(|(field, expected, found)| invalid(field, expected, found))?;
        let prediction = predictor
            .predict(&print)
            .map_err(CompensateError::Predictor)?;
        let not_finite = prediction
            .iter()
            .filter(|c| !c.0.iter().all(|v| v.is_finite()))
            .count();
        if prediction.len() != texels || not_finite > 0 {
            return Err(invalid(
                "prediction",
                format!("{texels} finite colours"),
                format!("{} values, {not_finite} not finite", prediction.len()),
            ));
        }
        let delta_e: Vec<f64> = prediction
            .iter()
            .zip(&target_lab)
            .map(|(p, t)| ciede2000(p.to_lab(), *t))
            .collect();
        let mean = delta_e.iter().sum::<f64>() / texels as f64;
        let iteration = Iteration {
            aims: std::mem::take(&mut aims),
            prediction,
            p95: quantile(&delta_e, 0.95),
            delta_e,
            mean,
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
        aims = update(&from.aims, target, &from.prediction, step);
    }
    let (best, print) = best.expect("at least one iteration ran");
    Ok(Compensation {
        iterations,
        best,
        print,
    })
}
