//! The dielectric boundaries: Fresnel lobe selection, weights, Snell's law, the rough dielectric's
//! sampled estimator against Walter et al.'s BSDF integrated numerically, and robustness.
//!
//! Conventions (bsdf.rs): `n` is the outward normal, `d` the propagation direction arriving at the
//! boundary, `wo` the new propagation direction, `eta = n_inside / n_outside`; the weight is
//! `f |cos| / pdf` including the radiance scaling `1 / eta_rel^2` on refraction.

mod common;

use std::f64::consts::PI;

use common::*;
use glam::DVec3;
use volpt_core::microfacet::Ggx;
use volpt_core::{
    Bsdf, BsdfEval, BsdfSample, NullBoundary, RoughDielectric, SmoothDielectric, Vec2, Vec3,
};

const ETA: f32 = 1.5;

/// A non-axis outward normal, so that the crate's `Frame` is exercised off its axes.
fn normal() -> Vec3 {
    Vec3::new(0.3, -0.5, 0.81).normalize()
}

/// The propagation direction of light arriving at polar angle `theta_deg` (about the normal on the
/// incident side) and azimuth `phi`, from outside (`d . n < 0`) or from inside (`d . n > 0`).
fn arriving(n: Vec3, theta_deg: f64, phi: f64, outside: bool) -> Vec3 {
    let frame = test_frame(n);
    let c = theta_deg.to_radians().cos();
    let towards_light = from_spherical(frame, if outside { c } else { -c }, phi);
    -towards_light
}

fn to_f64(v: Vec3) -> DVec3 {
    DVec3::new(v.x as f64, v.y as f64, v.z as f64)
}

/// `eta_t / eta_i` for a path arriving from `outside` or not.
fn relative_eta(outside: bool) -> f64 {
    if outside {
        ETA as f64
    } else {
        1.0 / ETA as f64
    }
}

#[test]
fn smooth_dielectric_fresnel_weights_and_snell() {
    const N: usize = 50_000;
    let n = normal();
    let bsdf = SmoothDielectric { eta: ETA };
    let mut rng = TestRng::new(11);
    for outside in [true, false] {
        for theta in [0.0, 20.0, 40.0, 60.0, 80.0, 89.0] {
            let d = arriving(n, theta, 0.7, outside);
            let eta = relative_eta(outside);
            let f = fresnel_reference(theta.to_radians(), eta);
            let mut reflected = 0usize;
            let mut weight_eta2 = Moments::default();
            let mut weight = Moments::default();
            for _ in 0..N {
                let s = bsdf
                    .sample(n, d, rng.f32(), rng.vec2())
                    .expect("a smooth dielectric always scatters");
                check_smooth_geometry(n, d, &s, eta, theta);
                if !s.transmitted {
                    reflected += 1;
                }
                weight.push(s.weight as f64);
                weight_eta2.push(s.weight as f64 * (s.eta as f64).powi(2));
            }
            let freq = reflected as f64 / N as f64;
            // Reflections are Bernoulli(F): the frequency lies within 5 standard errors of F. Under
            // total internal reflection F = 1 and every sample must reflect.
            let se = (f * (1.0 - f) / N as f64).sqrt();
            assert!(
                (freq - f).abs() <= Z_MAX * se,
                "outside {outside}, {theta} deg: reflected {freq}, Fresnel {f} (+- {se})"
            );
            // weight * eta_rel^2 is exactly 1 for every sample (no masking on a smooth interface),
            // so the expected weight is R + T / eta_rel^2.
            assert!(
                (weight_eta2.mean() - 1.0).abs() < 1e-6 && weight_eta2.variance() < 1e-12,
                "outside {outside}, {theta} deg: weight * eta^2 = {} (var {})",
                weight_eta2.mean(),
                weight_eta2.variance()
            );
            let expected = f + (1.0 - f) / (eta * eta);
            let w_se = ((1.0 - 1.0 / (eta * eta)).powi(2) * f * (1.0 - f) / N as f64).sqrt();
            assert!(
                (weight.mean() - expected).abs() <= Z_MAX * w_se + 1e-6,
                "outside {outside}, {theta} deg: mean weight {} vs {expected}",
                weight.mean()
            );
        }
    }
}

/// Mirror reflection, or refraction obeying Snell's law in the plane of incidence, with the right
/// `eta` and weight; reflections stay on the incident side, refractions cross.
fn check_smooth_geometry(n: Vec3, d: Vec3, s: &BsdfSample, eta: f64, theta: f64) {
    let (n, d, wo) = (to_f64(n), to_f64(d), to_f64(s.wo));
    assert!((wo.length() - 1.0).abs() < 1e-5);
    let incident_side = d.dot(n).signum();
    if s.transmitted {
        assert_eq!(wo.dot(n).signum(), incident_side, "refraction must cross");
        assert!((s.eta as f64 - eta).abs() < 1e-6, "eta {} vs {eta}", s.eta);
        assert!((s.weight as f64 * eta * eta - 1.0).abs() < 1e-6);
        // n_i sin_i = n_t sin_t, i.e. sin_i = eta_rel sin_t, to f32 accuracy.
        let sin_i = d.cross(n).length();
        let sin_t = wo.cross(n).length();
        assert!(
            (sin_i - eta * sin_t).abs() < 1e-5,
            "{theta} deg: sin_i {sin_i} vs eta sin_t {}",
            eta * sin_t
        );
        // In the plane of incidence, on the far side of the normal from where the light came.
        assert!(d.cross(n).dot(wo).abs() < 1e-5);
        let (dt, ot) = (d - n * d.dot(n), wo - n * wo.dot(n));
        assert!(dt.dot(ot) >= -1e-7);
    } else {
        assert!(wo.dot(n) * incident_side <= 0.0, "reflection must stay");
        assert_eq!(s.eta, 1.0);
        assert_eq!(s.weight, 1.0);
        let mirror = d - n * (2.0 * d.dot(n));
        assert!((wo - mirror).length() < 1e-5, "{wo:?} vs mirror {mirror:?}");
    }
}

#[test]
fn rough_dielectric_approaches_smooth_at_small_alpha() {
    const N: usize = 50_000;
    let alpha = 0.001;
    let n = normal();
    let smooth = SmoothDielectric { eta: ETA };
    let rough = RoughDielectric {
        eta: ETA,
        distribution: Ggx { alpha },
    };
    let mut rng = TestRng::new(12);
    for outside in [true, false] {
        for theta in [0.0, 30.0, 60.0, 80.0] {
            let d = arriving(n, theta, 1.9, outside);
            let eta = relative_eta(outside);
            let f = fresnel_reference(theta.to_radians(), eta);
            let mut reflected = 0usize;
            let mut g1 = Moments::default();
            let mut deviations = Vec::with_capacity(N);
            for _ in 0..N {
                let (u_lobe, u) = (rng.f32(), rng.vec2());
                let Some(s) = rough.sample(n, d, u_lobe, u) else {
                    g1.push(0.0);
                    continue;
                };
                assert_eq!(s.transmitted, d.dot(n).signum() == s.wo.dot(n).signum());
                if !s.transmitted {
                    reflected += 1;
                }
                g1.push(s.weight as f64 * (s.eta as f64).powi(2));
                // The smooth interface's direction for the same lobe.
                let lobe = if s.transmitted { 0.999_999 } else { 0.0 };
                let reference = smooth.sample(n, d, lobe, Vec2::ZERO).unwrap();
                if reference.transmitted == s.transmitted {
                    deviations.push(to_f64(s.wo).angle_between(to_f64(reference.wo)));
                }
            }
            let freq = reflected as f64 / N as f64;
            // Bernoulli(F) within 5 standard errors, plus 1e-3 for the microfacet spread: GGX slopes
            // have P(tan theta_m > x) ~ alpha^2 / x^2, so facets tilted enough to change F by a
            // visible amount are rarer than 1e-3 at alpha = 1e-3.
            let se = (f * (1.0 - f) / N as f64).sqrt();
            assert!(
                (freq - f).abs() <= Z_MAX * se + 1e-3,
                "outside {outside}, {theta} deg: reflected {freq}, Fresnel {f}"
            );
            // weight * eta^2 = G1(wo, m) is 1 - O(alpha^2 tan^2) for a nearly smooth surface (and
            // at most 1 up to the f32 rounding of weight and eta).
            assert!(
                g1.mean() > 1.0 - 1e-3 && g1.mean() <= 1.0 + 1e-6,
                "outside {outside}, {theta} deg: weight * eta^2 = {}",
                g1.mean()
            );
            // Directions stay within 50 alpha of the specular ones for 95% of samples (the half
            // vector deviates beyond 25 alpha with probability ~1 / 625).
            deviations.sort_by(f64::total_cmp);
            let q95 = deviations[deviations.len() * 95 / 100];
            assert!(
                q95 < 50.0 * alpha as f64,
                "outside {outside}, {theta} deg: 95% deviation {q95}"
            );
        }
    }
}

/// The incident side's normal `ns`, `wi` (towards where the light came from) and `eta_rel`.
struct Incidence {
    ns: DVec3,
    wi: DVec3,
    eta: f64,
}

fn ggx_d(alpha: f64, ns: DVec3, h: DVec3) -> f64 {
    let c = h.dot(ns);
    if c <= 0.0 {
        return 0.0;
    }
    let c2 = c * c;
    let t2 = (1.0 - c2) / c2;
    1.0 / (PI * alpha * alpha * c2 * c2 * (1.0 + t2 / (alpha * alpha)).powi(2))
}

fn smith_g1(alpha: f64, ns: DVec3, v: DVec3, h: DVec3) -> f64 {
    let c = v.dot(ns);
    if v.dot(h) * c <= 0.0 {
        return 0.0;
    }
    let t2 = (1.0 - c * c).max(0.0) / (c * c);
    2.0 / (1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

/// Walter et al. 2007's rough dielectric BSDF times |cos theta_o|, written from the paper in f64 for
/// the camera-path (radiance) convention: the light travels from `wo`'s side to `wi`'s side, so
/// Walter's `i` is our `wo` (index `eta`) and his `o` our `wi` (index 1), giving eq. 21 as
/// `|i.h||o.h| / (|i.n||o.n|) (1 - F) D G / (eta wo.h + wi.h)^2` with no eta^2 in the numerator.
/// `with_g1_wo = false` drops the outgoing masking: a deliberately wrong BSDF for the power check.
fn walter_f_cos(inc: &Incidence, wo: DVec3, alpha: f64, with_g1_wo: bool) -> f64 {
    let (ns, wi, eta) = (inc.ns, inc.wi, inc.eta);
    let ci = wi.dot(ns);
    let co = wo.dot(ns);
    let masking = |h: DVec3| {
        smith_g1(alpha, ns, wi, h)
            * if with_g1_wo {
                smith_g1(alpha, ns, wo, h)
            } else {
                (wo.dot(h) * co > 0.0) as u8 as f64
            }
    };
    if co > 0.0 {
        let h = (wi + wo).normalize();
        let f = fresnel_reference(wi.dot(h).clamp(-1.0, 1.0).acos(), eta);
        f * ggx_d(alpha, ns, h) * masking(h) / (4.0 * ci * co) * co
    } else if co < 0.0 {
        // The generalised half vector, oriented to the incident side: m is proportional to
        // -(wi + eta wo) when eta > 1 and to +(wi + eta wo) when eta < 1.
        let mut h = wi + wo * eta;
        if eta > 1.0 {
            h = -h;
        }
        let h = h.normalize();
        let (ih, oh) = (wi.dot(h), wo.dot(h));
        if h.dot(ns) <= 0.0 || ih <= 0.0 || oh >= 0.0 {
            return 0.0;
        }
        let f = fresnel_reference(ih.clamp(-1.0, 1.0).acos(), eta);
        ih * oh.abs() / (ci * co.abs()) * (1.0 - f) * ggx_d(alpha, ns, h) * masking(h)
            / (ih + eta * oh).powi(2)
            * co.abs()
    } else {
        0.0
    }
}

/// The rough dielectric's cases, which its sampler and its `eval` are checked on: roughness 0.1, 0.3
/// and 0.7, light arriving from outside and from inside at 30 and 70 degrees to `normal()`, and the
/// sphere of `wo` in `C_BINS` x `PHI_BINS` bins of cos theta and azimuth about the normal.
struct RoughCases {
    n: Vec3,
    frame: (Vec3, Vec3, Vec3),
    frame64: (DVec3, DVec3, DVec3),
    c_edges: Vec<f64>,
    phi_edges: Vec<f64>,
}

const C_BINS: usize = 16;
const PHI_BINS: usize = 12;
const BINS: usize = C_BINS * PHI_BINS;

/// One of `RoughCases`: the boundary, the propagation direction `d` arriving at it and the same
/// incidence in f64 for `walter_f_cos`.
struct RoughCase {
    alpha: f32,
    outside: bool,
    theta: f64,
    bsdf: RoughDielectric,
    d: Vec3,
    inc: Incidence,
    label: String,
}

impl RoughCases {
    fn new() -> Self {
        let n = normal();
        let frame = test_frame(n);
        RoughCases {
            n,
            frame,
            frame64: (to_f64(frame.0), to_f64(frame.1), to_f64(frame.2)),
            c_edges: uniform_edges(-1.0, 1.0, C_BINS),
            phi_edges: uniform_edges(0.0, 2.0 * PI, PHI_BINS),
        }
    }

    /// The direction of polar cosine `c` and azimuth `phi` about the normal, in f64.
    fn direction(&self, c: f64, phi: f64) -> DVec3 {
        let s = (1.0 - c * c).max(0.0).sqrt();
        self.frame64.0 * (s * phi.cos()) + self.frame64.1 * (s * phi.sin()) + self.frame64.2 * c
    }

    /// The bin of `wo`, `i * PHI_BINS + j` for the `i`th cosine and `j`th azimuth range.
    fn bin(&self, wo: Vec3) -> usize {
        let (c, phi) = to_spherical(self.frame, wo);
        bin_index(&self.c_edges, c) * PHI_BINS + bin_index(&self.phi_edges, phi)
    }

    /// The integral of `f(c, phi)` over each bin, indexed as `bin`'s.
    fn integrate_bins(&self, f: &dyn Fn(f64, f64) -> f64, eps: f64) -> Vec<f64> {
        let mut r = vec![0.0; BINS];
        for i in 0..C_BINS {
            for j in 0..PHI_BINS {
                r[i * PHI_BINS + j] = integrate_2d(
                    f,
                    (self.c_edges[i], self.c_edges[i + 1]),
                    (self.phi_edges[j], self.phi_edges[j + 1]),
                    eps,
                );
            }
        }
        r
    }

    fn cases(&self) -> impl Iterator<Item = RoughCase> {
        let n = self.n;
        [0.1f32, 0.3, 0.7].into_iter().flat_map(move |alpha| {
            [true, false].into_iter().flat_map(move |outside| {
                [30.0, 70.0].into_iter().map(move |theta| {
                    let d = arriving(n, theta, 0.4, outside);
                    let n64 = to_f64(n);
                    RoughCase {
                        alpha,
                        outside,
                        theta,
                        bsdf: RoughDielectric {
                            eta: ETA,
                            distribution: Ggx { alpha },
                        },
                        d,
                        inc: Incidence {
                            ns: if outside { n64 } else { -n64 },
                            wi: -to_f64(d),
                            eta: relative_eta(outside),
                        },
                        label: format!("alpha {alpha}, outside {outside}, {theta} deg"),
                    }
                })
            })
        })
    }
}

/// Sampled estimator vs numerically integrated BSDF, bin by bin: with `m` from the visible normals
/// and the lobe chosen by F, E[weight 1{wo in B}] = int_B f |cos theta_o| dw for every bin B.
#[test]
fn rough_dielectric_matches_walter_bsdf() {
    const N: usize = 200_000;
    let sphere = RoughCases::new();
    let n = sphere.n;
    let mut rng = TestRng::new(13);
    let mut power_checked = false;
    for case in sphere.cases() {
        let RoughCase {
            alpha,
            outside,
            theta,
            bsdf,
            d,
            inc,
            label,
        } = case;
        let mut sum_w = vec![0.0; BINS];
        let mut sum_w2 = vec![0.0; BINS];
        let (mut refl, mut trans) = (Moments::default(), Moments::default());
        for _ in 0..N {
            let s = bsdf.sample(n, d, rng.f32(), rng.vec2());
            let (w_r, w_t) = match s {
                Some(s) => {
                    let b = sphere.bin(s.wo);
                    let w = s.weight as f64;
                    sum_w[b] += w;
                    sum_w2[b] += w * w;
                    if s.transmitted {
                        (0.0, w)
                    } else {
                        (w, 0.0)
                    }
                }
                None => (0.0, 0.0),
            };
            refl.push(w_r);
            trans.push(w_t);
        }
        let reference = |with_g1_wo: bool| -> Vec<f64> {
            let f = |c: f64, phi: f64| {
                walter_f_cos(&inc, sphere.direction(c, phi), alpha as f64, with_g1_wo)
            };
            sphere.integrate_bins(&f, 1e-8)
        };
        let expected = reference(true);
        // A bin of the incident hemisphere holds reflections (weight <= 1), the other refractions
        // (weight <= 1 / eta^2).
        let incident_hemisphere = |b: usize| {
            let c = 0.5 * (sphere.c_edges[b / PHI_BINS] + sphere.c_edges[b / PHI_BINS + 1]);
            (c > 0.0) == outside
        };
        let max_weight = |b: usize| {
            if incident_hemisphere(b) {
                1.0
            } else {
                1.0 / inc.eta.powi(2)
            }
        };
        let mismatch = |expected: &[f64]| -> Option<String> {
            for b in 0..BINS {
                let est = sum_w[b] / N as f64;
                // Var(w 1_B) <= E[w^2 1_B] <= w_max E[w 1_B]: the larger of the sampled second
                // moment and that bound under the null hypothesis gives a conservative standard
                // error; 1e-4 relative and 1e-7 absolute cover the quadrature.
                let m2 = (sum_w2[b] / N as f64).max(max_weight(b) * expected[b]);
                let se = (m2 / N as f64).sqrt();
                if (est - expected[b]).abs() > Z_MAX * se + 1e-4 * expected[b] + 1e-7 {
                    return Some(format!(
                        "bin {b}: estimate {est} vs integral {} (se {se})",
                        expected[b]
                    ));
                }
            }
            None
        };
        if let Some(m) = mismatch(&expected) {
            panic!("{label}: {m}");
        }
        // Total reflectance and transmittance (the albedo of each lobe) within 5 s.e.
        let (r_ref, t_ref) = (0..BINS).fold((0.0, 0.0), |(r, t), b| {
            if incident_hemisphere(b) {
                (r + expected[b], t)
            } else {
                (r, t + expected[b])
            }
        });
        eprintln!(
            "{label}: R {} vs {r_ref}, T {} vs {t_ref}",
            refl.mean(),
            trans.mean()
        );
        assert!(
            refl.z_score(r_ref) < Z_MAX,
            "{label}: R {} vs {r_ref}",
            refl.mean()
        );
        assert!(
            trans.z_score(t_ref) < Z_MAX,
            "{label}: T {} vs {t_ref}",
            trans.mean()
        );
        // Power: a BSDF without the outgoing masking term is rejected by the same test.
        if alpha == 0.7 && theta == 70.0 && outside {
            let wrong = reference(false);
            assert!(
                mismatch(&wrong).is_some(),
                "{label}: cannot tell G1(wo) from 1"
            );
            power_checked = true;
        }
    }
    assert!(power_checked);
}

/// `RoughDielectric::eval`, which next-event estimation through the boundary uses: its value is
/// Walter et al.'s `f |cos theta_o|` written independently above (at directions over both
/// hemispheres), and its density is the sampler's (the fraction of samples landing in each bin of
/// the sphere against the density integrated over the bin). A `SmoothDielectric` and the
/// index-matched boundary have no density anywhere.
#[test]
fn rough_dielectric_eval_is_walter_bsdf_and_the_samplers_density() {
    const N: usize = 200_000;
    let sphere = RoughCases::new();
    let n = sphere.n;
    let to_f32 = |v: DVec3| Vec3::new(v.x as f32, v.y as f32, v.z as f32);
    let mut rng = TestRng::new(29);
    let cases = sphere.cases().count();
    for case in sphere.cases() {
        let RoughCase {
            alpha,
            bsdf,
            d,
            inc,
            label,
            ..
        } = case;
        // The value, direction by direction.
        let mut nonzero = 0;
        for _ in 0..4000 {
            let (c, phi) = (2.0 * rng.f64() - 1.0, 2.0 * PI * rng.f64());
            let wo = sphere.direction(c, phi);
            let expected = walter_f_cos(&inc, wo, alpha as f64, true);
            let got = bsdf.eval(n, d, to_f32(wo));
            assert!(
                got.value >= 0.0 && got.pdf >= 0.0 && got.pdf.is_finite(),
                "{label}: {got:?}"
            );
            // f32 against f64: relative 1e-3, and 1e-5 absolute (the mean of f |cos| over the
            // sphere is ~0.1) for the far tails near total internal reflection, where `1 - F`
            // cancels in f32 (sampling uses the very same F).
            assert!(
                (got.value as f64 - expected).abs() <= 1e-3 * expected + 1e-5,
                "{label}, wo {wo}: value {} vs Walter {expected}",
                got.value
            );
            nonzero += (expected > 0.0) as u32;
        }
        assert!(
            nonzero > 1000,
            "{label}: only {nonzero} directions with f > 0"
        );
        // The density: sampled fractions per bin against the integrated pdf. The integral is 0
        // where no bin is reached, so a z-test with the binomial error of the expected fraction
        // (floored at one sample) and a quadrature tolerance.
        if alpha == 0.1 {
            // Too narrow a lobe for the bins' quadrature; its pdf is the same formula.
            continue;
        }
        let mut counts = vec![0.0f64; BINS];
        for _ in 0..N {
            if let Some(s) = bsdf.sample(n, d, rng.f32(), rng.vec2()) {
                counts[sphere.bin(s.wo)] += 1.0;
            }
        }
        let pdf = |c: f64, phi: f64| bsdf.eval(n, d, to_f32(sphere.direction(c, phi))).pdf as f64;
        let integrated = sphere.integrate_bins(&pdf, 1e-7);
        let mut total = 0.0;
        for (b, &p) in integrated.iter().enumerate() {
            total += p;
            let observed = counts[b] / N as f64;
            let se = (p.max(1.0 / N as f64) * (1.0 - p).max(0.0) / N as f64).sqrt();
            assert!(
                (observed - p).abs() <= Z_MAX * se + 1e-3 * p + 1e-6,
                "{label}, bin ({}, {}) of {cases} cases: sampled {observed} vs integrated pdf {p} \
                 (se {se})",
                b / PHI_BINS,
                b % PHI_BINS
            );
        }
        // The density integrates to the fraction of samples not rejected (a reflection below the
        // surface or a refraction that does not cross).
        let accepted = counts.iter().sum::<f64>() / N as f64;
        let se = (accepted * (1.0 - accepted) / N as f64).sqrt();
        eprintln!("{label}: pdf integrates to {total}, {accepted} of the samples accepted");
        assert!(
            total > 0.5 && (total - accepted).abs() <= Z_MAX * se + 1e-3,
            "{label}: pdf integrates to {total}, {accepted} of the samples accepted"
        );
    }
    let d = arriving(n, 30.0, 0.4, true);
    let wo = -d;
    assert_eq!(
        SmoothDielectric { eta: ETA }.eval(n, d, wo),
        BsdfEval::default()
    );
    assert_eq!(NullBoundary.eval(n, d, wo), BsdfEval::default());
}

#[test]
fn no_nan_or_inf_at_extreme_directions() {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
    let mut directions: Vec<Vec3> = axes.to_vec();
    // Axis directions with negative zeros, and near-grazing and grazing directions to each normal.
    directions.extend([
        Vec3::new(-0.0, 1.0, -0.0),
        Vec3::new(0.0, -0.0, -1.0),
        Vec3::new(1.0, 1e-7, 0.0).normalize(),
        Vec3::new(1.0, -1e-7, 0.0).normalize(),
        Vec3::new(1e-7, 0.0, 1.0).normalize(),
        Vec3::new(1.0, 0.0, 1.0).normalize(),
        Vec3::new(0.3, -0.5, 0.81).normalize(),
    ]);
    let mut rng = TestRng::new(14);
    let mut u_values = vec![
        Vec2::ZERO,
        Vec2::new(0.999_999_94, 0.999_999_94),
        Vec2::new(0.0, 0.999_999_94),
    ];
    u_values.extend((0..20).map(|_| rng.vec2()));
    let lobes = [0.0, 0.5, 0.999_999_94];
    let mut some = 0usize;
    for alpha in [1e-4f32, 0.1, 1.0] {
        for eta in [ETA, 1.0 / ETA, 1.0] {
            let rough = RoughDielectric {
                eta,
                distribution: Ggx { alpha },
            };
            let smooth = SmoothDielectric { eta };
            for &n in &axes {
                for &d in &directions {
                    for &u in &u_values {
                        for &u_lobe in &lobes {
                            for s in [
                                rough.sample(n, d, u_lobe, u),
                                smooth.sample(n, d, u_lobe, u),
                            ] {
                                let Some(s) = s else { continue };
                                some += 1;
                                let ctx =
                                    format!("alpha {alpha}, eta {eta}, n {n:?}, d {d:?}, u {u:?}");
                                assert_finite_vec(s.wo, &ctx);
                                assert!((s.wo.length() - 1.0).abs() < 1e-4, "{ctx}: {s:?}");
                                assert!(s.weight.is_finite() && s.weight > 0.0, "{ctx}: {s:?}");
                                // weight * eta^2 = G1 <= 1.
                                assert!(s.weight * s.eta * s.eta <= 1.0 + 1e-6, "{ctx}: {s:?}");
                                assert!(s.eta.is_finite() && s.eta > 0.0, "{ctx}: {s:?}");
                                // Reflections stay on the side the light came from, refractions cross
                                // (grazing outputs may sit exactly in the plane).
                                let side = d.dot(n) * s.wo.dot(n);
                                assert!(
                                    if s.transmitted {
                                        side >= 0.0
                                    } else {
                                        side <= 0.0
                                    },
                                    "{ctx}: {s:?}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(some > 1000, "almost every sample was None: {some}");
}

/// The index-matched boundary passes every direction through unweighted. The path step never asks
/// it (`Bsdf::IS_NULL` short-circuits the interaction), so only this test holds it to the contract
/// (mutation testing: `sample` returning `None` left every other test green).
#[test]
fn null_boundary_passes_light_through() {
    let d = Vec3::new(0.6, -0.8, 0.0);
    let s = NullBoundary
        .sample(Vec3::Z, d, 0.3, Vec2::new(0.1, 0.9))
        .expect("an index-matched boundary always transmits");
    assert_eq!((s.wo, s.weight, s.transmitted, s.eta), (d, 1.0, true, 1.0));
}
