//! Statistical tests of the phase functions: moments, the distribution of sampled directions against
//! the integrated `eval`, normalisation, and `sample().pdf == eval()`.
//!
//! Directions are propagation directions: `wi` before scattering, `wo` after, `g > 0` forward. So
//! E[wi . wo] = g and E[P2(wi . wo)] = g^2 for Henyey-Greenstein (its Legendre moments are g^l).

mod common;

use std::f64::consts::PI;

use common::*;
use volpt_core::{HenyeyGreenstein, Isotropic, PhaseFunction, Vec3};

const GS: [f32; 6] = [-0.9, -0.3, 0.0, 1e-6, 0.5, 0.99];
const N: usize = 200_000;

/// HG in f64, written from the definition, independent of the crate.
fn hg_reference(g: f64, c: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * c).powf(1.5))
}

/// P(cos <= c) of HG, from integrating the definition in closed form.
fn hg_cdf(g: f64, c: f64) -> f64 {
    if g == 0.0 {
        return 0.5 * (c + 1.0);
    }
    (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 + g * g - 2.0 * g * c).sqrt() - 1.0 / (1.0 + g))
}

/// Bin edges in cos theta at the analytic quantiles k / n (bisection on the closed-form CDF), so that
/// even g = 0.99, whose mass sits within 1e-4 of cos = 1, fills every bin.
fn quantile_edges(g: f64, n: usize) -> Vec<f64> {
    let mut edges = vec![-1.0];
    for k in 1..n {
        let target = k as f64 / n as f64;
        let (mut lo, mut hi) = (-1.0f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if hg_cdf(g, mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        edges.push(0.5 * (lo + hi));
    }
    edges.push(1.0);
    edges
}

/// A fixed incident direction along no axis.
fn incident(seed: u64) -> Vec3 {
    let mut rng = TestRng::new(seed);
    loop {
        let w = rng.unit_vector();
        if w.abs().max_element() < 0.9 && w.abs().min_element() > 0.1 {
            return w;
        }
    }
}

/// Samples `N` directions and returns their (cos theta, phi) about `wi` in the test's own frame.
fn sample_directions(phase: &impl PhaseFunction, wi: Vec3, seed: u64) -> Vec<(f64, f64)> {
    let frame = test_frame(wi);
    let mut rng = TestRng::new(seed);
    (0..N)
        .map(|_| to_spherical(frame, phase.sample(wi, rng.vec2()).wo))
        .collect()
}

/// Chi-square of sampled directions against `eval` integrated over bins in (cos theta, phi about wi).
/// The density depends on cos theta only, so the phi integral is exact (bin width times the value);
/// the cos theta integral is adaptive Simpson of `eval` at directions built from (cos theta, phi).
fn direction_chi2(
    samples: &[(f64, f64)],
    eval_phase: &impl PhaseFunction,
    wi: Vec3,
    cos_edges: &[f64],
) -> Chi2 {
    const PHI_BINS: usize = 8;
    let frame = test_frame(wi);
    let phi_edges = uniform_edges(0.0, 2.0 * PI, PHI_BINS);
    let nc = cos_edges.len() - 1;
    let mut observed = vec![0.0; nc * PHI_BINS];
    for &(c, phi) in samples {
        observed[bin_index(cos_edges, c) * PHI_BINS + bin_index(&phi_edges, phi)] += 1.0;
    }
    let mut expected = vec![0.0; nc * PHI_BINS];
    for i in 0..nc {
        for j in 0..PHI_BINS {
            let phi = 0.5 * (phi_edges[j] + phi_edges[j + 1]);
            let density = |c: f64| eval_phase.eval(wi, from_spherical(frame, c, phi)) as f64;
            let p = (phi_edges[j + 1] - phi_edges[j])
                * integrate(&density, cos_edges[i], cos_edges[i + 1], 1e-8);
            expected[i * PHI_BINS + j] = p * samples.len() as f64;
        }
    }
    chi2_test(&observed, &expected)
}

#[test]
fn hg_mean_cosine_is_g() {
    let wi = incident(1);
    for (case, &g) in GS.iter().enumerate() {
        let hg = HenyeyGreenstein { g };
        let mut rng = TestRng::new(100 + case as u64);
        let mut cos = Moments::default();
        let mut p2 = Moments::default();
        for _ in 0..N {
            let wo = hg.sample(wi, rng.vec2()).wo;
            let c = wi.dot(wo) as f64;
            cos.push(c);
            p2.push(1.5 * c * c - 0.5);
        }
        let g = g as f64;
        // The mean of N iid cosines is within Z_MAX of its standard errors of g = E[cos].
        assert!(
            cos.z_score(g) < Z_MAX,
            "g = {g}: mean cos {} +- {}",
            cos.mean(),
            cos.std_error()
        );
        // The second Legendre moment of HG is g^2: checks the shape, not just the mean.
        assert!(
            p2.z_score(g * g) < Z_MAX,
            "g = {g}: mean P2 {} +- {}, expected {}",
            p2.mean(),
            p2.std_error(),
            g * g
        );
        // Power: the same test rejects the mirrored lobe whenever it is distinguishable.
        if g.abs() >= 0.3 {
            assert!(cos.z_score(-g) > Z_MAX, "g = {g}: cannot tell g from -g");
        }
    }
}

#[test]
fn hg_directions_match_eval() {
    // Bonferroni over the HG cases and the isotropic one.
    let threshold = ALPHA / (GS.len() + 1) as f64;
    let wi = incident(2);
    for (case, &g) in GS.iter().enumerate() {
        let hg = HenyeyGreenstein { g };
        let samples = sample_directions(&hg, wi, 200 + case as u64);
        let edges = quantile_edges(g as f64, 16);
        let chi2 = direction_chi2(&samples, &hg, wi, &edges);
        eprintln!("HG g = {g}: {chi2:?}");
        assert!(chi2.p_value > threshold, "HG g = {g}: {chi2:?}");
        // Power: the density of a slightly different g (10%), or of the mirrored lobe, is rejected.
        if g == 0.5 {
            for wrong in [0.45, -0.5] {
                let chi2 = direction_chi2(&samples, &HenyeyGreenstein { g: wrong }, wi, &edges);
                eprintln!("HG g = 0.5 against g = {wrong}: {chi2:?}");
                assert!(
                    chi2.p_value < threshold,
                    "g = 0.5 passes as g = {wrong}: {chi2:?}"
                );
            }
        }
    }
    let samples = sample_directions(&Isotropic, wi, 299);
    let chi2 = direction_chi2(&samples, &Isotropic, wi, &uniform_edges(-1.0, 1.0, 16));
    eprintln!("isotropic: {chi2:?}");
    assert!(chi2.p_value > threshold, "isotropic: {chi2:?}");
    // Power: isotropic samples are not HG with g = 0.1.
    let chi2 = direction_chi2(
        &samples,
        &HenyeyGreenstein { g: 0.1 },
        wi,
        &uniform_edges(-1.0, 1.0, 16),
    );
    assert!(chi2.p_value < threshold, "isotropic passes as g = 0.1");
}

#[test]
fn isotropic_mean_cosine_is_zero() {
    let wi = incident(3);
    let mut rng = TestRng::new(300);
    let mut cos = Moments::default();
    for _ in 0..N {
        cos.push(wi.dot(Isotropic.sample(wi, rng.vec2()).wo) as f64);
    }
    assert!(cos.z_score(0.0) < Z_MAX, "mean cos {}", cos.mean());
    // The variance of a uniform cosine on [-1, 1] is 1/3; its sample estimate has a relative
    // standard error of about sqrt(0.8 / N) = 0.2%, so 2% is > 5 standard errors.
    assert!((cos.variance() - 1.0 / 3.0).abs() < 0.02 / 3.0);
}

#[test]
fn eval_integrates_to_one_and_matches_definition() {
    let wi = incident(4);
    let frame = test_frame(wi);
    for &g in &GS {
        let hg = HenyeyGreenstein { g };
        // Integrate over cos theta on the quantile edges (each piece holds 1/32 of the mass, so the
        // forward peak of g = 0.99 is resolved), times 2 pi for the azimuth. f32 evaluation and
        // direction rounding leave ~1e-5 relative; 1e-4 still catches any wrong constant or power.
        let edges = quantile_edges(g as f64, 32);
        let density = |c: f64| hg.eval(wi, from_spherical(frame, c, 0.3)) as f64;
        let total: f64 = edges
            .windows(2)
            .map(|e| 2.0 * PI * integrate(&density, e[0], e[1], 1e-9))
            .sum();
        assert!((total - 1.0).abs() < 1e-4, "g = {g}: integral {total}");
        // Point values against the definition: sign convention (forward for g > 0) and constants.
        // The reference is evaluated at the same f32 inputs; f32 evaluation of the base
        // 1 + g^2 - 2 g cos cancels near the peak and carries an absolute error of a few 1e-7, which
        // the power 3/2 turns into a relative error of 1.5 * 6e-7 / base.
        for c in [-1.0f32, -0.5, 0.0, 0.3, 0.9, 0.999, 1.0] {
            let (g64, c64) = (g as f64, c as f64);
            let expected = hg_reference(g64, c64);
            let got = hg.eval_cos(c) as f64;
            let base = 1.0 + g64 * g64 - 2.0 * g64 * c64;
            assert!(
                (got - expected).abs() <= (1e-5 + 1.5 * 6e-7 / base) * expected,
                "g = {g}, cos = {c}: {got} vs {expected}"
            );
        }
    }
    let total = 4.0 * PI * Isotropic.eval(wi, -wi) as f64;
    assert!((total - 1.0).abs() < 1e-6);
}

#[test]
fn sample_pdf_equals_eval() {
    let mut rng = TestRng::new(5);
    for &g in &GS {
        let hg = HenyeyGreenstein { g };
        for _ in 0..20_000 {
            let wi = rng.unit_vector();
            let s = hg.sample(wi, rng.vec2());
            assert!(
                (s.wo.length() - 1.0).abs() < 1e-5,
                "|wo| = {}",
                s.wo.length()
            );
            let eval = hg.eval(wi, s.wo);
            // `pdf` is the density at the sampled cosine; `eval` recomputes the cosine as wi . wo,
            // which f32 rounding moves by ~1e-7. d ln p / d cos = 3 g / (1 + g^2 - 2 g cos), so the
            // allowed relative difference is that slope times a 1e-6 cosine error, plus 1e-5.
            let c = wi.dot(s.wo).clamp(-1.0, 1.0);
            let slope = 3.0 * g.abs() / (1.0 + g * g - 2.0 * g * c);
            let tolerance = (1e-5 + slope * 1e-6) * eval;
            assert!(
                (s.pdf - eval).abs() <= tolerance,
                "g = {g}: pdf {} vs eval {eval} at cos {c}",
                s.pdf
            );
        }
    }
    for _ in 0..1000 {
        let wi = rng.unit_vector();
        let s = Isotropic.sample(wi, rng.vec2());
        assert!((s.wo.length() - 1.0).abs() < 1e-5);
        assert_eq!(s.pdf, Isotropic.eval(wi, s.wo));
    }
}
