//! The cross-talk update's parts: the fitted response recovers a spread it can represent, it is
//! its own adjoint, and with no spread its update is the per-texel one.

mod common;

use common::Rng;
use volpt_print::colour::LinearRgb;
use volpt_print::crosstalk::{kernels, Response};

const SIZE: [u32; 2] = [40, 28];

fn texels() -> usize {
    (SIZE[0] * SIZE[1]) as usize
}

fn random_image(rng: &mut Rng) -> Vec<LinearRgb> {
    (0..texels())
        .map(|_| LinearRgb([0, 1, 2].map(|_| rng.unit())))
        .collect()
}

fn dot(a: &[LinearRgb], b: &[LinearRgb]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| x.0[c] * y.0[c]).sum::<f64>())
        .sum()
}

/// A spread in the response's basis: a texel's own share and a long tail, per channel.
fn spread() -> Response {
    let mut weights = [0, 1, 2].map(|_| vec![0.0; kernels(SIZE)]);
    for (c, w) in weights.iter_mut().enumerate() {
        w[0] = 0.3 + 0.1 * c as f64;
        w[2] = 0.2;
        w[kernels(SIZE) - 1] = 0.25 - 0.05 * c as f64;
    }
    Response { weights }
}

#[test]
fn the_response_is_its_own_adjoint() {
    // <K x, y> = <x, K y> for random images: the update's gradient K^T g is K g.
    let mut rng = Rng(7);
    let k = spread();
    for _ in 0..5 {
        let (x, y) = (random_image(&mut rng), random_image(&mut rng));
        let (kx, ky) = (k.apply(&x, SIZE), k.apply(&y, SIZE));
        let (a, b) = (dot(&kx, &y), dot(&x, &ky));
        assert!((a - b).abs() <= 1e-12 * a.abs(), "{a} vs {b}");
    }
}

#[test]
fn the_fit_recovers_a_spread_its_basis_holds() {
    // Predictions made by an offset plus a known spread of the aims' ink (aims minus white):
    // the fit gives that spread back, from one print and from three.
    let truth = spread();
    let mut rng = Rng(3);
    let offset = [0.9, 0.85, 0.8];
    let samples: Vec<(Vec<LinearRgb>, Vec<LinearRgb>)> = (0..3)
        .map(|_| {
            let aims = random_image(&mut rng);
            let ink: Vec<LinearRgb> = aims
                .iter()
                .map(|a| LinearRgb(a.0.map(|v| v - 1.0)))
                .collect();
            let p = truth
                .apply(&ink, SIZE)
                .into_iter()
                .map(|k| LinearRgb([0, 1, 2].map(|c| offset[c] + k.0[c])))
                .collect();
            (aims, p)
        })
        .collect();
    // What the update uses is the response's action: on an image it was not fitted to, the
    // fitted spread gives the true one's (weights of nearly parallel features, such as the widest
    // blur and the offset on a small print, may trade places without changing it much).
    let probe = random_image(&mut rng);
    let expected = truth.apply(&probe, SIZE);
    for n in [1, 3] {
        let pairs: Vec<_> = samples[..n].iter().map(|(a, p)| (&a[..], &p[..])).collect();
        let fitted = Response::fit(&pairs, SIZE);
        let got = fitted.apply(&probe, SIZE);
        let error: f64 = got
            .iter()
            .zip(&expected)
            .map(|(g, e)| (0..3).map(|c| (g.0[c] - e.0[c]).powi(2)).sum::<f64>())
            .sum();
        let relative = (error / dot(&expected, &expected)).sqrt();
        eprintln!(
            "{n} print(s): fitted {:?}, relative error {relative:.2e}",
            fitted.weights
        );
        assert!(relative < 0.01, "{n} print(s): relative error {relative}");
        // The texel's own share and the near spread are identified one by one.
        for c in 0..3 {
            for k in 0..3 {
                let (f, t) = (fitted.weights[c][k], truth.weights[c][k]);
                assert!(
                    (f - t).abs() < 0.01,
                    "{n} print(s), channel {c}, kernel {k}: {f} vs {t}"
                );
            }
        }
    }
}

#[test]
fn with_no_spread_the_update_is_the_per_texel_one() {
    // K = I and a target every texel reaches: the minimiser is aims + (target - prediction).
    let mut rng = Rng(5);
    let aims: Vec<LinearRgb> = (0..texels())
        .map(|_| LinearRgb([0, 1, 2].map(|_| 0.3 + 0.4 * rng.unit())))
        .collect();
    let prediction: Vec<LinearRgb> = aims
        .iter()
        .map(|a| LinearRgb(a.0.map(|v| 0.8 * v)))
        .collect();
    let target: Vec<LinearRgb> = aims
        .iter()
        .map(|a| LinearRgb(a.0.map(|v| 0.8 * v + 0.1 * (rng.unit() - 0.5))))
        .collect();
    let target_lab: Vec<_> = target.iter().map(|t| t.to_lab()).collect();
    let updated = Response::identity(SIZE).update(&aims, &prediction, &target_lab, SIZE, 200);
    let mut worst: f64 = 0.0;
    for ((u, a), (t, p)) in updated
        .iter()
        .zip(&aims)
        .zip(target.iter().zip(&prediction))
    {
        for c in 0..3 {
            worst = worst.max((u.0[c] - (a.0[c] + t.0[c] - p.0[c])).abs());
        }
    }
    // Within what the minimiser's stopping rule leaves (10^-4 of the objective over ten steps).
    assert!(
        worst < 5e-3,
        "largest difference from the per-texel update {worst}"
    );
}
