//! The update that sees light cross between texels: the print's cross-texel response, fitted
//! from its own predictions, and the aims that minimise the mean CIEDE2000 through it.
//!
//! **Why.** Light entering a print at one texel leaves at others: a texel's colour depends on the
//! aims of its neighbours, up to the millimetre a photon wanders through white resin. The
//! per-texel update (`aim += step * (target - prediction)`, [`crate::compensate`]) reads each
//! texel's error as its own aim's fault. On fine lines on white that is wrong: the white is
//! darkened by the ink of the lines beside it, its aim is already white (the clamp), and the
//! per-texel update can only darken the lines further, which darkens the white more. Undoing a
//! blur needs the blur's adjoint: the error at a texel is sent back to every aim that reaches it.
//!
//! **Response** ([`Response`]). Around an iteration's aims `a_k` and prediction `p_k` the print is
//! modelled as linear in its aims, per channel:
//!
//! `p(a) = p_k + K (a - a_k)`,  `K d = w_0 d + sum_j w_j B_j d`,
//!
//! `B_j` a blur of radius `r_j` = 1, 2, 4, ... texels ([`radii`]: three passes of a box of width
//! `2 r_j + 1` on each axis, a Gaussian of standard deviation `sqrt(r_j (r_j + 1))` to a few
//! percent: Wells 1986, "Efficient synthesis of Gaussian filters by cascaded uniform filters",
//! IEEE PAMI 8(2)), zero outside the print (nothing outside absorbs: a change of aims is an amount of ink, and there
//! is no ink outside). The weights are the print's point-spread function in that basis: `w_0` a
//! texel's own response, `w_j` how far the rest reaches. They are fitted by least squares to the
//! predictions so far, `p_i = c + K (a_i - 1)` over every iteration `i`'s texels (one offset `c`
//! per channel: the colour of an ink-free print), with `w >= 0` (ink only darkens, and more so
//! nearby) and a small ridge towards `K = I` (the per-texel update's model; each weight's in
//! proportion to its feature's variance, so the fit does not depend on scales), which decides what
//! the predictions cannot (a uniform target has no contrast to fit a spread from). So the first
//! update already sees the spread: the naive print of a target with any detail measures it.
//!
//! **Update** ([`Response::update`]). The next aims minimise, over printable aims `a` in
//! `[0, 1]^3`, the mean over texels of the smoothed CIEDE2000 `sqrt(dE00^2 + eps^2)` between the
//! model `p_k + K (a - a_k)` and the target: the loop's own criterion, through the cross-talk.
//! Its gradient is `K^T g` with `g` the per-texel gradient of the smoothed CIEDE2000 with respect
//! to the predicted linear RGB (finite differences), and `K^T = K`: each `B_j` is a symmetric
//! matrix (a box with zero padding is its own transpose). The minimiser is projected gradient
//! descent onto the box with Barzilai-Borwein steps and Armijo backtracking along the projection
//! arc (Birgin, Martinez and Raydan 2000, "Nonmonotone spectral projected gradient methods on
//! convex sets", SIAM J. Optim. 10(4), taken monotone), from `a_k`. With `K = I` and a reachable
//! target the minimum is `a_k + (target - p_k)`, the per-texel update: this update generalises it
//! to the measured spread. The loop moves the aims `step` of the way from `a_k` to the minimiser
//! and backtracks as for the per-texel update; each refit sees the iterations since, so a step
//! the linear model got wrong corrects the model.
//!
//! This is the loop of Elek et al. 2017 (predict the whole print, compare with the target,
//! correct the aims, halftone, repeat) with the correction taken as a gradient step of a
//! deconvolution (the Landweber iteration `a += tau K^T (t - K a)` is its least-squares form;
//! Landweber 1951, Am. J. Math. 73(3)) whose point-spread function is measured from the print's
//! own predictions.

use rayon::prelude::*;

use crate::colour::{ciede2000, Lab, LinearRgb};

/// The blur radii of the response's basis, in texels: powers of two up to this reach.
pub const WIDEST: usize = 32;

/// The radii of a `width` x `height` print's basis: `1, 2, 4, ...` up to [`WIDEST`] and to a
/// quarter of the print's shorter side (a blur much wider than that is nearly a constant on the
/// print, which the fit's offset already is: the two could not be told apart).
pub fn radii([width, height]: [u32; 2]) -> impl Iterator<Item = usize> {
    let reach = WIDEST.min(width.min(height) as usize / 4).max(1);
    (0..).map(|k| 1usize << k).take_while(move |&r| r <= reach)
}

/// The number of kernels of a response for a print of `size`: the texel itself and one blur
/// per radius.
pub fn kernels(size: [u32; 2]) -> usize {
    1 + radii(size).count()
}

/// The smoothing of the CIEDE2000 minimised (`sqrt(dE00^2 + eps^2)`): far below a just
/// noticeable difference, it only makes the minimum differentiable.
const EPS: f64 = 0.25;

/// The ridge towards `K = I`, relative to each feature's variance.
const RIDGE: f64 = 1e-3;

/// The print's cross-texel response per channel (see the module docs): `weights[c][0]` the
/// texel's own, `weights[c][1 + j]` the blur of radius `radii(size)[j]`'s.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    pub weights: [Vec<f64>; 3],
}

/// An image of `width` x `height` texels, one value a texel, row-major.
#[derive(Clone, Copy, Debug)]
struct Plane {
    width: usize,
    height: usize,
}

impl Plane {
    /// Three passes of a box of width `2 r + 1` along x, then along y, zero outside: a symmetric
    /// linear map (its own adjoint).
    fn blur(self, values: &[f64], r: usize) -> Vec<f64> {
        let mut out = values.to_vec();
        let mut line = Vec::new();
        let mut sums = Vec::new();
        for (n, count, stride, lines, line_stride) in [
            (self.width, self.width, 1, self.height, self.width),
            (self.height, self.height, self.width, self.width, 1),
        ] {
            for l in 0..lines {
                line.clear();
                line.extend((0..count).map(|i| out[l * line_stride + i * stride]));
                for _ in 0..3 {
                    sums.clear();
                    sums.push(0.0);
                    let mut s = 0.0;
                    for v in &line {
                        s += v;
                        sums.push(s);
                    }
                    let scale = 1.0 / (2 * r + 1) as f64;
                    for (i, v) in line.iter_mut().enumerate() {
                        let (lo, hi) = (i.saturating_sub(r), (i + r + 1).min(n));
                        *v = (sums[hi] - sums[lo]) * scale;
                    }
                }
                for (i, v) in line.iter().enumerate() {
                    out[l * line_stride + i * stride] = *v;
                }
            }
        }
        out
    }

    fn size(self) -> [u32; 2] {
        [self.width as u32, self.height as u32]
    }

    /// The response's kernels applied to one channel: the values themselves, then each blur.
    fn features(self, values: &[f64]) -> Vec<Vec<f64>> {
        std::iter::once(values.to_vec())
            .chain(radii(self.size()).map(|r| self.blur(values, r)))
            .collect()
    }
}

fn channel(image: &[LinearRgb], c: usize) -> Vec<f64> {
    image.iter().map(|t| t.0[c]).collect()
}

impl Response {
    /// `K = I` for a print of `size`: each texel responds to its own aim alone (the per-texel
    /// update's model).
    pub fn identity(size: [u32; 2]) -> Response {
        let mut w = vec![0.0; kernels(size)];
        w[0] = 1.0;
        Response {
            weights: [w.clone(), w.clone(), w],
        }
    }

    /// The response fitted to `samples` (each iteration's aims and prediction, `width` x
    /// `height`), as the module docs say.
    pub fn fit(samples: &[(&[LinearRgb], &[LinearRgb])], [width, height]: [u32; 2]) -> Response {
        let plane = Plane {
            width: width as usize,
            height: height as usize,
        };
        let n = kernels([width, height]);
        let prior = Response::identity([width, height]);
        let weights = [0, 1, 2].map(|c| {
            // Normal equations of (offset, w_0, ..., w_J).
            let m = n + 1;
            let mut h = vec![vec![0.0; m]; m];
            let mut b = vec![0.0; m];
            let mut count = 0.0;
            for (aims, prediction) in samples {
                let ink: Vec<f64> = aims.iter().map(|a| a.0[c] - 1.0).collect();
                let features = plane.features(&ink);
                let p = channel(prediction, c);
                for t in 0..p.len() {
                    let x = |i: usize| if i == 0 { 1.0 } else { features[i - 1][t] };
                    for i in 0..m {
                        let xi = x(i);
                        b[i] += xi * p[t];
                        for (k, hik) in h[i].iter_mut().enumerate() {
                            *hik += xi * x(k);
                        }
                    }
                }
                count += p.len() as f64;
            }
            for row in h.iter_mut() {
                row.iter_mut().for_each(|v| *v /= count);
            }
            b.iter_mut().for_each(|v| *v /= count);
            // Each weight's ridge in proportion to its feature's variance (centred): the fit
            // does not depend on the features' scales.
            let ridge: Vec<f64> = (0..m)
                .map(|i| match i {
                    0 => 0.0,
                    _ => RIDGE * (h[i][i] - h[0][i] * h[0][i]).max(0.0) + 1e-12,
                })
                .collect();
            let target = |i: usize| if i == 0 { 0.0 } else { prior.weights[c][i - 1] };
            // Projected coordinate descent on the convex quadratic (offset free, weights >= 0).
            let mut x: Vec<f64> = (0..m).map(target).collect();
            for _ in 0..5000 {
                let mut change: f64 = 0.0;
                for i in 0..m {
                    let ridge = ridge[i];
                    let rest: f64 = (0..m).filter(|&k| k != i).map(|k| h[i][k] * x[k]).sum();
                    let mut v = (b[i] - rest + ridge * target(i)) / (h[i][i] + ridge);
                    if i > 0 {
                        v = v.max(0.0);
                    }
                    change = change.max((v - x[i]).abs());
                    x[i] = v;
                }
                if change < 1e-12 {
                    break;
                }
            }
            x[1..].to_vec()
        });
        Response { weights }
    }

    /// `K d` for a change `d` of the aims (zero outside the print); also `K^T d` (see the
    /// module docs).
    pub fn apply(&self, d: &[LinearRgb], [width, height]: [u32; 2]) -> Vec<LinearRgb> {
        let plane = Plane {
            width: width as usize,
            height: height as usize,
        };
        let radii: Vec<usize> = std::iter::once(0).chain(radii(plane.size())).collect();
        // Every (channel, kernel) of a weight, blurred on its own core.
        let terms: Vec<(usize, usize)> = (0..3)
            .flat_map(|c| (0..radii.len()).map(move |k| (c, k)))
            .filter(|&(c, k)| self.weights[c][k] != 0.0)
            .collect();
        let blurred: Vec<(usize, f64, Vec<f64>)> = terms
            .into_par_iter()
            .map(|(c, k)| {
                let values = channel(d, c);
                let values = match radii[k] {
                    0 => values,
                    r => plane.blur(&values, r),
                };
                (c, self.weights[c][k], values)
            })
            .collect();
        let mut out = vec![LinearRgb([0.0; 3]); d.len()];
        for (c, w, values) in blurred {
            for (o, v) in out.iter_mut().zip(values) {
                o.0[c] += w * v;
            }
        }
        out
    }

    /// The aims that minimise the mean smoothed CIEDE2000 of the model around `aims`
    /// (`prediction` seen) against `target`, within `[0, 1]`, after at most `iterations` steps
    /// of the projected gradient (see the module docs).
    pub fn update(
        &self,
        aims: &[LinearRgb],
        prediction: &[LinearRgb],
        target: &[Lab],
        size: [u32; 2],
        iterations: usize,
    ) -> Vec<LinearRgb> {
        let texels = aims.len() as f64;
        let zip3 =
            |a: &[LinearRgb], b: &[LinearRgb], f: &dyn Fn(f64, f64) -> f64| -> Vec<LinearRgb> {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| LinearRgb([0, 1, 2].map(|c| f(x.0[c], y.0[c]))))
                    .collect()
            };
        let dot = |a: &[LinearRgb], b: &[LinearRgb]| -> f64 {
            a.iter()
                .zip(b)
                .map(|(x, y)| (0..3).map(|c| x.0[c] * y.0[c]).sum::<f64>())
                .sum()
        };
        // The model's prediction at aims `a`.
        let model = |a: &[LinearRgb]| -> Vec<LinearRgb> {
            let k = self.apply(&zip3(a, aims, &|x, y| x - y), size);
            zip3(prediction, &k, &|p, k| p + k)
        };
        let smoothed = |p: LinearRgb, t: Lab| {
            // A physical prediction is not negative; the model's may be.
            let p = LinearRgb(p.0.map(|v| v.max(0.0)));
            ciede2000(p.to_lab(), t).hypot(EPS)
        };
        let objective = |m: &[LinearRgb]| -> f64 {
            m.par_iter()
                .zip(target)
                .map(|(p, t)| smoothed(*p, *t))
                .sum::<f64>()
                / texels
        };
        // Each texel's gradient of its smoothed CIEDE2000 with respect to its predicted linear
        // RGB: per channel the one-sided difference of the smaller size, since CIEDE2000 is not
        // continuous everywhere (its mean hue jumps where the two hues straddle a half turn:
        // Sharma, Wu and Dalal 2005, section 3), and a difference across a jump is no slope.
        let terms = |m: &[LinearRgb]| -> Vec<LinearRgb> {
            let h = 1e-6;
            m.par_iter()
                .zip(target)
                .map(|(p, t)| {
                    let at = smoothed(*p, *t);
                    LinearRgb([0, 1, 2].map(|c| {
                        let mut q = *p;
                        q.0[c] = p.0[c] + h;
                        let forward = (smoothed(q, *t) - at) / h;
                        q.0[c] = p.0[c] - h;
                        let backward = (at - smoothed(q, *t)) / h;
                        if forward.abs() < backward.abs() {
                            forward
                        } else {
                            backward
                        }
                    }))
                })
                .collect()
        };
        // The objective's gradient with respect to the aims: K^T (= K) of the per-texel
        // gradients, over the texels' count.
        let gradient = |m: &[LinearRgb]| -> Vec<LinearRgb> {
            self.apply(&terms(m), size)
                .into_iter()
                .map(|g| LinearRgb(g.0.map(|v| v / texels)))
                .collect()
        };
        let mut x: Vec<LinearRgb> = aims
            .iter()
            .map(|a| LinearRgb(a.0.map(|v| v.clamp(0.0, 1.0))))
            .collect();
        let m = model(&x);
        let mut f = objective(&m);
        let mut g = gradient(&m);
        // The first step moves most aims (all but the 1% of the largest gradients) by at most
        // 0.05; Barzilai-Borwein then finds the scale.
        let sizes: Vec<f64> = g.iter().flat_map(|v| v.0).map(f64::abs).collect();
        let large = volpt::metrics::quantile(&sizes, 0.99);
        if large.is_nan() || large <= 0.0 {
            return x;
        }
        let mut tau = 0.05 / large;
        let mut history = vec![f];
        for _ in 0..iterations {
            // Armijo backtracking along the projection arc.
            let mut accepted = None;
            let mut t = tau;
            for _ in 0..30 {
                let y = zip3(&x, &g, &|x, g| (x - t * g).clamp(0.0, 1.0));
                let step = zip3(&y, &x, &|a, b| a - b);
                let my = model(&y);
                let fy = objective(&my);
                if fy <= f + 1e-4 * dot(&g, &step) {
                    accepted = Some((y, step, my, fy));
                    break;
                }
                t *= 0.5;
            }
            let Some((y, step, my, fy)) = accepted else {
                break;
            };
            let gy = gradient(&my);
            let sy = dot(&step, &zip3(&gy, &g, &|a, b| a - b));
            let ss = dot(&step, &step);
            (x, f, g) = (y, fy, gy);
            history.push(f);
            // Converged: the last ten steps lowered the objective by less than 10^-4 of it.
            let stalled = history.len() > 10 && history[history.len() - 11] - f <= 1e-4 * f;
            if stalled || ss == 0.0 {
                break;
            }
            // Barzilai-Borwein: the step of the secant's curvature, bounded.
            tau = if sy > 0.0 {
                (ss / sy).clamp(1e-3 * t, 1e3 * t)
            } else {
                4.0 * t
            };
        }
        x
    }
}
