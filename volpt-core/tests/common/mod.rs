//! Shared statistics for the statistical tests: a test-only random generator (independent of the
//! crate's `Rng`, so that a bug there cannot hide a bug elsewhere), the chi-square and Kolmogorov
//! distributions, adaptive quadrature and a few geometric helpers. Everything is f64 and
//! deterministic.
//!
//! Conventions used by every test:
//! - chi-square tests pool bins whose expected count is below `MIN_EXPECTED` (the usual validity
//!   condition of the chi-square approximation) and reject at p < 1e-3 divided by the number of cases
//!   in the test (Bonferroni), so one run of a correct implementation fails with probability < 1e-3;
//! - Kolmogorov-Smirnov tests do the same with the asymptotic Kolmogorov distribution;
//! - means are compared within 5 standard errors (two-sided normal tail 5.7e-7 per comparison).

#![allow(dead_code)]

use std::f64::consts::PI;

use volpt_core::{Vec2, Vec3};

/// Family-wise false-rejection probability of one statistical test function.
pub const ALPHA: f64 = 1e-3;

/// Bins with a smaller expected count are pooled (Cochran's rule for the chi-square approximation).
pub const MIN_EXPECTED: f64 = 5.0;

/// Standard errors allowed for a sample mean: a two-sided normal tail of 5.7e-7.
pub const Z_MAX: f64 = 5.0;

/// xoshiro256++ seeded through SplitMix64 (Blackman & Vigna 2018).
pub struct TestRng {
    s: [u64; 4],
}

impl TestRng {
    pub fn new(seed: u64) -> Self {
        let mut z = seed;
        let mut next = || {
            z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut x = z;
            x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            x ^ (x >> 31)
        };
        Self {
            s: [next(), next(), next(), next()],
        }
    }

    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform in [0, 1) with 24 bits, like the renderer's numbers.
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    pub fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }

    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }

    /// Uniform direction on the sphere, computed in f64.
    pub fn unit_vector(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.f64();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * self.f64();
        Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32).normalize()
    }
}

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, n = 9; relative error ~1e-15).
pub fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection formula.
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised upper incomplete gamma function Q(a, x) (Numerical Recipes 6.2: series below
/// a + 1, Lentz's continued fraction above).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "gamma_q({a}, {x})");
    if x == 0.0 {
        return 1.0;
    }
    let log_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        let mut ap = a;
        let mut del = 1.0 / a;
        let mut sum = del;
        for _ in 0..100_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * log_prefactor.exp()).max(0.0)
    } else {
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        log_prefactor.exp() * h
    }
}

/// P(X >= x) for X chi-square distributed with `dof` degrees of freedom.
pub fn chi2_sf(x: f64, dof: usize) -> f64 {
    gamma_q(0.5 * dof as f64, 0.5 * x)
}

#[derive(Clone, Copy, Debug)]
pub struct Chi2 {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Pearson's chi-square test of observed counts against expected counts. Bins with expected counts
/// below `MIN_EXPECTED` are pooled, smallest first, into one bin that is closed once it reaches
/// `MIN_EXPECTED` (as in Mitsuba's and pbrt's chi2 tests); a sample in a bin of zero expectation is an
/// immediate failure (p = 0). Expected counts are *not* rescaled to the observed total, so a
/// wrongly normalised density fails as well.
pub fn chi2_test(observed: &[f64], expected: &[f64]) -> Chi2 {
    assert_eq!(observed.len(), expected.len());
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut statistic = 0.0;
    let mut cells = 0usize;
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    for &i in &order {
        if expected[i] <= 0.0 && observed[i] > 0.0 {
            return Chi2 {
                statistic: f64::INFINITY,
                dof: 0,
                p_value: 0.0,
            };
        }
        if expected[i] < MIN_EXPECTED {
            pool_obs += observed[i];
            pool_exp += expected[i];
            if pool_exp >= MIN_EXPECTED {
                statistic += (pool_obs - pool_exp).powi(2) / pool_exp;
                cells += 1;
                pool_obs = 0.0;
                pool_exp = 0.0;
            }
        } else {
            statistic += (observed[i] - expected[i]).powi(2) / expected[i];
            cells += 1;
        }
    }
    if pool_exp > 0.0 {
        // A remainder smaller than MIN_EXPECTED: still counted, it only makes the test stricter.
        statistic += (pool_obs - pool_exp).powi(2) / pool_exp;
        cells += 1;
    } else if pool_obs > 0.0 {
        return Chi2 {
            statistic: f64::INFINITY,
            dof: 0,
            p_value: 0.0,
        };
    }
    let dof = cells.saturating_sub(1).max(1);
    Chi2 {
        statistic,
        dof,
        p_value: chi2_sf(statistic, dof),
    }
}

/// The Kolmogorov distribution's tail P(K > lambda) = 2 sum (-1)^(k-1) exp(-2 k^2 lambda^2).
pub fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda < 0.2 {
        return 1.0;
    }
    let mut sum = 0.0;
    for k in 1..=100 {
        let k = k as f64;
        let term = (-2.0 * k * k * lambda * lambda).exp();
        sum += if k as u64 % 2 == 1 { term } else { -term };
        if term < 1e-17 {
            break;
        }
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

#[derive(Clone, Copy, Debug)]
pub struct Ks {
    pub statistic: f64,
    pub n: usize,
    pub p_value: f64,
}

/// One-sample Kolmogorov-Smirnov test against a continuous CDF, with Stephens' finite-n correction
/// of the asymptotic distribution (Numerical Recipes 14.3).
pub fn ks_test(samples: &[f64], cdf: impl Fn(f64) -> f64) -> Ks {
    let mut x = samples.to_vec();
    x.sort_by(f64::total_cmp);
    let n = x.len();
    let nf = n as f64;
    let mut d: f64 = 0.0;
    for (i, &xi) in x.iter().enumerate() {
        let f = cdf(xi);
        d = d.max(f - i as f64 / nf).max((i + 1) as f64 / nf - f);
    }
    let sqrt_n = nf.sqrt();
    Ks {
        statistic: d,
        n,
        p_value: kolmogorov_q((sqrt_n + 0.12 + 0.11 / sqrt_n) * d),
    }
}

/// Two-sample Kolmogorov-Smirnov test.
pub fn ks_test_2(a: &[f64], b: &[f64]) -> Ks {
    let mut a = a.to_vec();
    let mut b = b.to_vec();
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j) = (0, 0);
    let mut d: f64 = 0.0;
    while i < a.len() && j < b.len() {
        let x = a[i].min(b[j]);
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
        d = d.max((i as f64 / na - j as f64 / nb).abs());
    }
    let ne = (na * nb / (na + nb)).sqrt();
    Ks {
        statistic: d,
        n: (na * nb / (na + nb)) as usize,
        p_value: kolmogorov_q((ne + 0.12 + 0.11 / ne) * d),
    }
}

/// Mean and variance of a stream of values (Welford).
#[derive(Clone, Copy, Debug, Default)]
pub struct Moments {
    pub n: u64,
    mean: f64,
    m2: f64,
}

impl Moments {
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    pub fn mean(&self) -> f64 {
        self.mean
    }

    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    /// Standard error of the mean.
    pub fn std_error(&self) -> f64 {
        (self.variance() / self.n as f64).sqrt()
    }

    /// How many standard errors the mean lies from `expected` (a tiny floor keeps a sample of
    /// constant values comparable).
    pub fn z_score(&self, expected: f64) -> f64 {
        (self.mean - expected).abs() / self.std_error().max(1e-300)
    }
}

fn simpson_rec(
    f: &dyn Fn(f64) -> f64,
    (a, fa): (f64, f64),
    (m, fm): (f64, f64),
    (b, fb): (f64, f64),
    whole: f64,
    eps: f64,
    depth: u32,
) -> f64 {
    let lm = 0.5 * (a + m);
    let rm = 0.5 * (m + b);
    let flm = f(lm);
    let frm = f(rm);
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth == 0 || delta.abs() <= 15.0 * eps {
        return left + right + delta / 15.0;
    }
    simpson_rec(f, (a, fa), (lm, flm), (m, fm), left, 0.5 * eps, depth - 1)
        + simpson_rec(f, (m, fm), (rm, frm), (b, fb), right, 0.5 * eps, depth - 1)
}

/// Adaptive Simpson quadrature of `f` over [a, b] to an absolute error of about `eps`. The interval is
/// first cut into 8 pieces so that a narrow peak cannot hide between the first five nodes.
pub fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, eps: f64) -> f64 {
    const PIECES: usize = 8;
    if a == b {
        return 0.0;
    }
    let h = (b - a) / PIECES as f64;
    let mut total = 0.0;
    for i in 0..PIECES {
        let x0 = a + h * i as f64;
        let x1 = if i + 1 == PIECES { b } else { x0 + h };
        let xm = 0.5 * (x0 + x1);
        let (f0, fm, f1) = (f(x0), f(xm), f(x1));
        let whole = (x1 - x0) / 6.0 * (f0 + 4.0 * fm + f1);
        total += simpson_rec(
            f,
            (x0, f0),
            (xm, fm),
            (x1, f1),
            whole,
            eps / PIECES as f64,
            14,
        );
    }
    total
}

/// Nested adaptive quadrature over the rectangle [x0, x1] x [y0, y1].
pub fn integrate_2d(
    f: &dyn Fn(f64, f64) -> f64,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    eps: f64,
) -> f64 {
    let inner_eps = 0.5 * eps / (x1 - x0).abs().max(1e-300);
    integrate(&|x| integrate(&|y| f(x, y), y0, y1, inner_eps), x0, x1, eps)
}

/// An orthonormal frame around `w` built by Gram-Schmidt against a fixed helper axis: independent
/// of the crate's `Frame`, so that tests of code that uses `Frame` do not reuse it.
pub fn test_frame(w: Vec3) -> (Vec3, Vec3, Vec3) {
    let w = w.normalize();
    let helper = if w.x.abs() < 0.6 { Vec3::X } else { Vec3::Y };
    let u = (helper - w * helper.dot(w)).normalize();
    let v = w.cross(u);
    (u, v, w)
}

/// The direction with polar cosine `cos_theta` and azimuth `phi` in the frame (u, v, w).
pub fn from_spherical(frame: (Vec3, Vec3, Vec3), cos_theta: f64, phi: f64) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (u, v, w) = frame;
    let x = sin_theta * phi.cos();
    let y = sin_theta * phi.sin();
    // Sum in f64 so that the only rounding is the final conversion.
    let c = |k: usize| (x * u[k] as f64 + y * v[k] as f64 + cos_theta * w[k] as f64) as f32;
    Vec3::new(c(0), c(1), c(2))
}

/// (cos theta, phi in [0, 2 pi)) of `d` in the frame (u, v, w), in f64.
pub fn to_spherical(frame: (Vec3, Vec3, Vec3), d: Vec3) -> (f64, f64) {
    let (u, v, w) = frame;
    let dot = |a: Vec3, b: Vec3| {
        a.x as f64 * b.x as f64 + a.y as f64 * b.y as f64 + a.z as f64 * b.z as f64
    };
    let len = dot(d, d).sqrt();
    let cos_theta = (dot(d, w) / len).clamp(-1.0, 1.0);
    let mut phi = dot(d, v).atan2(dot(d, u));
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    (cos_theta, phi.min(2.0 * PI))
}

/// The index of the bin of `x` among sorted `edges` (len = bins + 1); values outside are clamped.
pub fn bin_index(edges: &[f64], x: f64) -> usize {
    let bins = edges.len() - 1;
    let i = edges.partition_point(|&e| e <= x);
    i.saturating_sub(1).min(bins - 1)
}

/// `n + 1` uniformly spaced edges over [a, b].
pub fn uniform_edges(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| {
            if i == n {
                b
            } else {
                a + (b - a) * i as f64 / n as f64
            }
        })
        .collect()
}

/// Fresnel reflectances (s, p) of a dielectric interface with relative index `eta = n_t / n_i` at
/// incidence angle `theta_i` (radians), from Fresnel's sine and tangent laws, in f64. Independent of
/// the crate's cosine form; 1 under total internal reflection.
pub fn fresnel_sp_reference(theta_i: f64, eta: f64) -> (f64, f64) {
    let sin_t = theta_i.sin() / eta;
    if sin_t >= 1.0 {
        return (1.0, 1.0);
    }
    if theta_i == 0.0 {
        let r = ((eta - 1.0) / (eta + 1.0)).powi(2);
        return (r, r);
    }
    let theta_t = sin_t.asin();
    let rs = ((theta_i - theta_t).sin() / (theta_i + theta_t).sin()).powi(2);
    let rp = ((theta_i - theta_t).tan() / (theta_i + theta_t).tan()).powi(2);
    (rs, rp)
}

/// Unpolarised reflectance from [`fresnel_sp_reference`].
pub fn fresnel_reference(theta_i: f64, eta: f64) -> f64 {
    let (rs, rp) = fresnel_sp_reference(theta_i, eta);
    0.5 * (rs + rp)
}

pub fn assert_finite_vec(v: Vec3, what: &str) {
    assert!(v.is_finite(), "{what} is not finite: {v:?}");
}
