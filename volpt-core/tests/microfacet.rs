//! GGX: the sampled visible normals against `pdf_visible_normal`, and the normalisations of D and of
//! the visible-normal density.

mod common;

use std::f64::consts::PI;

use common::*;
use volpt_core::microfacet::Ggx;
use volpt_core::Vec3;

const ALPHAS: [f32; 4] = [0.05, 0.1, 0.3, 0.7];
const THETAS_DEG: [f64; 4] = [0.0, 30.0, 60.0, 85.0];
const N: usize = 100_000;
const S_BINS: usize = 10;
const PHI_BINS: usize = 12;

/// The local frame's own axes: the microfacet code works in the frame whose normal is +z.
const LOCAL: (Vec3, Vec3, Vec3) = (Vec3::X, Vec3::Y, Vec3::Z);

/// An incident direction at polar angle `theta_deg` and a non-zero azimuth (so that a rotation error
/// in the sampler shows).
fn incident(theta_deg: f64) -> Vec3 {
    let theta = theta_deg.to_radians();
    let phi: f64 = 0.9;
    Vec3::new(
        (theta.sin() * phi.cos()) as f32,
        (theta.sin() * phi.sin()) as f32,
        theta.cos() as f32,
    )
}

/// cos theta_m at which the GGX slope CDF `s = t / (1 + t)`, `t = tan^2 theta / alpha^2`, reaches `s`.
/// Uniform bins in `s` hold equal projected-area mass of D, so they adapt to alpha: at alpha = 0.05
/// the mass lies within 1e-2 of cos = 1.
fn cos_at_s(alpha: f64, s: f64) -> f64 {
    if s >= 1.0 {
        return 0.0;
    }
    let t = s / (1.0 - s);
    1.0 / (1.0 + alpha * alpha * t).sqrt()
}

/// Ascending cos theta edges from uniform edges in `s`.
fn cos_edges(alpha: f64, bins: usize) -> Vec<f64> {
    let mut edges: Vec<f64> = (0..=bins)
        .map(|k| cos_at_s(alpha, k as f64 / bins as f64))
        .collect();
    edges.reverse();
    edges
}

/// Probability of each (cos theta_m, phi_m) bin under `pdf_visible_normal` (solid-angle density),
/// by nested adaptive Simpson in cos theta and phi; absolute error ~1e-8 per bin.
fn bin_probabilities(ggx: Ggx, wi: Vec3, c_edges: &[f64], phi_edges: &[f64]) -> Vec<f64> {
    let nc = c_edges.len() - 1;
    let nphi = phi_edges.len() - 1;
    let mut p = vec![0.0; nc * nphi];
    for i in 0..nc {
        for j in 0..nphi {
            let density =
                |c: f64, phi: f64| ggx.pdf_visible_normal(wi, from_spherical(LOCAL, c, phi)) as f64;
            p[i * nphi + j] = integrate_2d(
                &density,
                (c_edges[i], c_edges[i + 1]),
                (phi_edges[j], phi_edges[j + 1]),
                1e-8,
            );
        }
    }
    p
}

fn histogram(samples: &[Vec3], c_edges: &[f64], phi_edges: &[f64]) -> Vec<f64> {
    let nphi = phi_edges.len() - 1;
    let mut h = vec![0.0; (c_edges.len() - 1) * nphi];
    for &m in samples {
        let (c, phi) = to_spherical(LOCAL, m);
        h[bin_index(c_edges, c) * nphi + bin_index(phi_edges, phi)] += 1.0;
    }
    h
}

fn sample_normals(ggx: Ggx, wi: Vec3, seed: u64) -> Vec<Vec3> {
    let mut rng = TestRng::new(seed);
    (0..N)
        .map(|_| ggx.sample_visible_normal(wi, rng.vec2()))
        .collect()
}

fn vndf_case(alpha: f32, case: u64) {
    let threshold = ALPHA / (ALPHAS.len() * THETAS_DEG.len()) as f64;
    let phi_edges = uniform_edges(0.0, 2.0 * PI, PHI_BINS);
    let c_edges = cos_edges(alpha as f64, S_BINS);
    let ggx = Ggx { alpha };
    for (k, &theta) in THETAS_DEG.iter().enumerate() {
        let wi = incident(theta);
        let samples = sample_normals(ggx, wi, 1000 * case + k as u64);
        for &m in &samples {
            assert!(
                m.is_finite() && (m.length() - 1.0).abs() < 1e-5,
                "m = {m:?}"
            );
            // Visible normals face up and face the viewer (up to rounding).
            assert!(
                m.z > 0.0 && wi.dot(m) > -1e-6,
                "alpha {alpha}, {theta} deg: m = {m:?}"
            );
        }
        let observed = histogram(&samples, &c_edges, &phi_edges);
        let probabilities = bin_probabilities(ggx, wi, &c_edges, &phi_edges);
        // The visible-normal density integrates to 1 over the hemisphere. The quadrature is good to
        // ~1e-6 in total; f32 evaluation of the density adds less.
        let total: f64 = probabilities.iter().sum();
        assert!(
            (total - 1.0).abs() < 1e-4,
            "alpha {alpha}, {theta} deg: pdf_visible_normal integrates to {total}"
        );
        let expected: Vec<f64> = probabilities.iter().map(|p| p * N as f64).collect();
        let chi2 = chi2_test(&observed, &expected);
        eprintln!("alpha {alpha}, theta {theta}: {chi2:?}");
        assert!(
            chi2.p_value > threshold,
            "alpha {alpha}, {theta} deg: {chi2:?}"
        );
        // Power: the same samples are rejected against alpha 10% larger, and against the density
        // for the viewer mirrored about the normal (a sign error in the stretch or the rotation).
        if alpha == 0.3 && theta == 60.0 {
            let wrong_alpha = bin_probabilities(Ggx { alpha: 0.33 }, wi, &c_edges, &phi_edges);
            let mirrored = Vec3::new(-wi.x, -wi.y, wi.z);
            let wrong_side = bin_probabilities(ggx, mirrored, &c_edges, &phi_edges);
            for wrong in [wrong_alpha, wrong_side] {
                let expected: Vec<f64> = wrong.iter().map(|p| p * N as f64).collect();
                let chi2 = chi2_test(&observed, &expected);
                assert!(chi2.p_value < threshold, "test has no power: {chi2:?}");
            }
        }
    }
}

#[test]
fn vndf_alpha_0_05() {
    vndf_case(0.05, 1);
}

#[test]
fn vndf_alpha_0_1() {
    vndf_case(0.1, 2);
}

#[test]
fn vndf_alpha_0_3() {
    vndf_case(0.3, 3);
}

#[test]
fn vndf_alpha_0_7() {
    vndf_case(0.7, 4);
}

#[test]
fn ndf_projected_area_is_one() {
    // int D(m) cos theta_m dw = 1: the microsurface projects onto the macrosurface's unit area.
    // Integrated over cos theta in 64 pieces of equal projected mass (resolving the peak at small
    // alpha), times 2 pi; 1e-5 is far below any wrong constant (a missing pi or alpha^2).
    for &alpha in &ALPHAS {
        let ggx = Ggx { alpha };
        let edges = cos_edges(alpha as f64, 64);
        let density = |c: f64| ggx.d(from_spherical(LOCAL, c, 1.1)) as f64 * c;
        let total: f64 = edges
            .windows(2)
            .map(|e| 2.0 * PI * integrate(&density, e[0], e[1], 1e-10))
            .sum();
        assert!((total - 1.0).abs() < 1e-5, "alpha {alpha}: {total}");
    }
}

#[test]
fn d_and_g1_match_definitions() {
    // Walter et al. 2007 eqs. 33 and 34, in f64, at angles where f32 is accurate to ~1e-6.
    for &alpha in &ALPHAS {
        let ggx = Ggx { alpha };
        let a = alpha as f64;
        for theta_deg in [0.0f64, 5.0, 20.0, 45.0, 70.0, 85.0] {
            let t = theta_deg.to_radians();
            let m = from_spherical(LOCAL, t.cos(), 2.0);
            let tan2 = t.tan().powi(2);
            let d_ref = 1.0 / (PI * a * a * t.cos().powi(4) * (1.0 + tan2 / (a * a)).powi(2));
            let d = ggx.d(m) as f64;
            assert!(
                (d - d_ref).abs() <= 1e-4 * d_ref,
                "alpha {alpha}, {theta_deg}: D {d} vs {d_ref}"
            );
            let g1_ref = 2.0 / (1.0 + (1.0 + a * a * tan2).sqrt());
            let g1 = ggx.g1(m, Vec3::Z) as f64;
            assert!(
                (g1 - g1_ref).abs() <= 1e-5,
                "alpha {alpha}, {theta_deg}: G1 {g1} vs {g1_ref}"
            );
        }
        // Below the horizon D vanishes; G1 vanishes when v sees the back of m.
        assert_eq!(ggx.d(Vec3::new(0.6, 0.0, -0.8)), 0.0);
        assert_eq!(
            ggx.g1(Vec3::new(0.8, 0.0, 0.6), Vec3::new(-0.8, 0.0, -0.6)),
            0.0
        );
        assert_eq!(
            ggx.pdf_visible_normal(Vec3::new(0.0, 0.0, -1.0), Vec3::Z),
            0.0
        );
    }
}
