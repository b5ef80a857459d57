//! The counter-based `Rng`: uniformity, range, distinct streams for distinct keys, independence of
//! consecutive dimensions and of neighbouring streams. Also checks the statistics helpers against
//! tabulated values, since every other test's threshold rests on them.

mod common;

use std::collections::HashSet;

use common::*;
use volpt_core::Rng;

#[test]
fn statistics_helpers_match_tables() {
    // Chi-square upper quantiles (Abramowitz & Stegun table 26.8): P(X > x) for (x, dof).
    for (x, dof, p) in [
        (3.841_459, 1, 0.05),
        (6.634_897, 1, 0.01),
        (18.307_04, 10, 0.05),
        (29.588_30, 10, 0.001),
        (124.342_1, 100, 0.05),
        (135.806_7, 100, 0.01),
        // Below the mean: the series branch of the incomplete gamma function.
        (2.558_21, 10, 0.99),
        (70.064_9, 100, 0.99),
    ] {
        let got = chi2_sf(x, dof);
        assert!(
            (got - p).abs() < 1e-3 * p,
            "chi2_sf({x}, {dof}) = {got}, not {p}"
        );
    }
    // Large dof, near the median: Wilson-Hilferty gives 0.494 05 at x = dof = 999.
    assert!((chi2_sf(999.0, 999) - 0.494_05).abs() < 1e-4);
    assert!((gamma_q(1.0, 2.0) - (-2.0f64).exp()).abs() < 1e-14);
    assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    // Kolmogorov distribution: P(K > 1.3581) = 0.05, P(K > 1.9496) = 0.001.
    assert!((kolmogorov_q(1.358_1) - 0.05).abs() < 1e-4);
    assert!((kolmogorov_q(1.949_6) - 0.001).abs() < 1e-5);
}

/// Chi-square of `n` values in 1000 equal bins of [0, 1), with expected n / 1000 each.
fn uniformity(values: impl Iterator<Item = f32>, n: usize) -> Chi2 {
    const BINS: usize = 1000;
    let mut observed = vec![0.0; BINS];
    for x in values {
        assert!((0.0..1.0).contains(&x), "{x} outside [0, 1)");
        observed[(x * BINS as f32) as usize] += 1.0;
    }
    chi2_test(&observed, &vec![n as f64 / BINS as f64; BINS])
}

const KEYS: [(u32, u32, u32); 5] = [
    (0, 0, 0),
    (1, 0, 0),
    (0, 1, 0),
    (0, 0, 1),
    (12_345, 777, 31),
];

#[test]
fn next_f32_is_uniform_along_a_stream() {
    const N: usize = 1_000_000;
    // Bonferroni over the keys and the two cross-stream tests below.
    let threshold = ALPHA / (KEYS.len() + 2) as f64;
    for &(seed, pixel, sample) in &KEYS {
        let mut rng = Rng::new(seed, pixel, sample);
        let chi2 = uniformity((0..N).map(|_| rng.next_f32()), N);
        assert!(
            chi2.p_value > threshold,
            "key {:?}: {chi2:?}",
            (seed, pixel, sample)
        );
        assert_eq!(rng.dimension(), N as u32);
    }
    // Across streams: dimension 0 of 1e6 consecutive pixels, and of 1e6 consecutive samples.
    let chi2 = uniformity((0..N as u32).map(|p| Rng::new(3, p, 0).next_f32()), N);
    assert!(chi2.p_value > threshold, "across pixels: {chi2:?}");
    let chi2 = uniformity((0..N as u32).map(|s| Rng::new(3, 5, s).next_f32()), N);
    assert!(chi2.p_value > threshold, "across samples: {chi2:?}");
}

/// The joint distribution of `next_2d`'s coordinates must be uniform on the unit square (chi-square over 64 x 64 cells), along a stream and across streams.
#[test]
fn next_2d_is_uniform_on_the_square() {
    const N: usize = 2_000_000;
    const SIDE: usize = 64;
    let square = |points: &mut dyn Iterator<Item = volpt_core::Vec2>| {
        let mut observed = vec![0.0; SIDE * SIDE];
        for v in points {
            let (i, j) = ((v.x * SIDE as f32) as usize, (v.y * SIDE as f32) as usize);
            observed[j * SIDE + i] += 1.0;
        }
        chi2_test(
            &observed,
            &vec![N as f64 / (SIDE * SIDE) as f64; SIDE * SIDE],
        )
    };
    let mut rng = Rng::new(8, 9, 10);
    let along = square(&mut (0..N).map(|_| rng.next_2d()));
    assert!(along.p_value > ALPHA / 2.0, "along a stream: {along:?}");
    let across = square(&mut (0..N as u32).map(|p| Rng::new(8, p, 10).next_2d()));
    assert!(across.p_value > ALPHA / 2.0, "across pixels: {across:?}");
    // Power: pairs with a small dependence (y nudged towards x by 2%) fail.
    let mut rng = Rng::new(8, 9, 11);
    let biased = square(&mut (0..N).map(|_| {
        let v = rng.next_2d();
        volpt_core::Vec2::new(v.x, (0.98 * v.y + 0.02 * v.x).min(0.999_999))
    }));
    assert!(
        biased.p_value < ALPHA,
        "a dependent pair passed: {biased:?}"
    );
}

#[test]
fn range_and_determinism() {
    let mut a = Rng::new(9, 8, 7);
    let mut b = Rng::new(9, 8, 7);
    for _ in 0..10_000 {
        let (x, y) = (a.next_f32(), b.next_f32());
        assert_eq!(x, y);
        assert!((0.0..1.0).contains(&x));
    }
    // next_2d is two consecutive numbers.
    let mut c = Rng::new(1, 2, 3);
    let mut d = Rng::new(1, 2, 3);
    let v = c.next_2d();
    assert_eq!((v.x, v.y), (d.next_f32(), d.next_f32()));
    assert_eq!(c.dimension(), 2);
    // The largest value is 1 - 2^-24, strictly below 1.
    assert!(((1u32 << 24) - 1) as f32 / (1u32 << 24) as f32 <= 0.999_999_94);
}

#[test]
fn distinct_keys_give_distinct_streams() {
    // 4 seeds x 64 pixels x 64 samples = 16384 streams, 4 numbers each: 65536 64-bit values. A
    // collision among independent values has probability ~1e-10, while two equal streams, or a
    // stream that is another one shifted by up to 3 dimensions, would collide surely.
    let mut seen = HashSet::new();
    for seed in [0u32, 1, 2, 0xFFFF_FFFF] {
        for pixel in 0..64u32 {
            for sample in 0..64u32 {
                let mut rng = Rng::new(seed, pixel, sample);
                for _ in 0..4 {
                    assert!(
                        seen.insert(rng.next_u64()),
                        "repeat at {:?}",
                        (seed, pixel, sample)
                    );
                }
            }
        }
    }
    // Keys that differ only in where the pixel ends and the sample begins.
    let mut a = Rng::new(0, 1, 0);
    let mut b = Rng::new(0, 0, 1);
    assert_ne!(a.next_u64(), b.next_u64());
    // Large indices too.
    let mut a = Rng::new(0, u32::MAX, u32::MAX);
    let mut b = Rng::new(0, u32::MAX - 1, u32::MAX);
    assert_ne!(a.next_u64(), b.next_u64());
}

/// Pearson correlation of pairs; for independent uniforms it is ~N(0, 1/n).
fn correlation(pairs: impl Iterator<Item = (f32, f32)>) -> (f64, usize) {
    let (mut n, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0usize, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (x, y) in pairs {
        let (x, y) = (x as f64, y as f64);
        n += 1;
        sx += x;
        sy += y;
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
    }
    let nf = n as f64;
    let cov = sxy / nf - sx / nf * sy / nf;
    let vx = sxx / nf - (sx / nf).powi(2);
    let vy = syy / nf - (sy / nf).powi(2);
    (cov / (vx * vy).sqrt(), n)
}

#[test]
fn consecutive_dimensions_and_neighbouring_streams_are_uncorrelated() {
    const N: u32 = 500_000;
    // |r| within 5 standard errors (1 / sqrt(n)) of 0.
    let check = |(r, n): (f64, usize), what: &str| {
        assert!(r.abs() < Z_MAX / (n as f64).sqrt(), "{what}: r = {r}");
    };
    let mut rng = Rng::new(4, 4, 4);
    let mut prev = rng.next_f32();
    check(
        correlation((0..N).map(|_| {
            let x = rng.next_f32();
            let pair = (prev, x);
            prev = x;
            pair
        })),
        "consecutive dimensions",
    );
    // The two coordinates of next_2d.
    let mut rng = Rng::new(4, 4, 5);
    check(
        correlation((0..N).map(|_| {
            let v = rng.next_2d();
            (v.x, v.y)
        })),
        "next_2d",
    );
    // Same dimension of neighbouring pixels, samples and seeds (dimension 3, an arbitrary one).
    let nth = |mut rng: Rng| {
        for _ in 0..3 {
            rng.next_f32();
        }
        rng.next_f32()
    };
    check(
        correlation((0..N).map(|p| (nth(Rng::new(6, p, 9)), nth(Rng::new(6, p + 1, 9))))),
        "neighbouring pixels",
    );
    check(
        correlation((0..N).map(|s| (nth(Rng::new(6, 9, s)), nth(Rng::new(6, 9, s + 1))))),
        "neighbouring samples",
    );
    check(
        correlation((0..N).map(|s| (nth(Rng::new(s, 9, 9)), nth(Rng::new(s + 1, 9, 9))))),
        "neighbouring seeds",
    );
    // Power: a sequence with a small serial dependence (x_{k+1} = 0.98 u + 0.02 x_k, r ~ 0.02) fails.
    let mut rng = Rng::new(4, 4, 6);
    let mut prev = rng.next_f32();
    let (r, n) = correlation((0..N).map(|_| {
        let x = 0.98 * rng.next_f32() + 0.02 * prev;
        let pair = (prev, x);
        prev = x;
        pair
    }));
    assert!(r.abs() > Z_MAX / (n as f64).sqrt(), "no power: r = {r}");
}

/// SplitMix64's finaliser, as published (Steele, Lea & Flood 2014).
fn splitmix64_mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Known answers: the statistical tests above pass for many a weaker mixer (mutation testing:
/// `z << 30` for `z >> 30` passed them), but the streams are documented as SplitMix64's finaliser
/// of `key + (i + 1) * golden`, keyed by the finaliser too, and every backend must reproduce them.
#[test]
fn streams_are_splitmix64() {
    const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;
    // SplitMix64 seeded with 0: its first output, the published reference value.
    assert_eq!(splitmix64_mix(GOLDEN), 0xE220_A839_7B1D_CDAF);
    for &(seed, pixel, sample) in &KEYS {
        let seed_key = splitmix64_mix((seed as u64).wrapping_add(GOLDEN));
        let key = splitmix64_mix((((pixel as u64) << 32) | sample as u64) ^ seed_key);
        let mut rng = Rng::new(seed, pixel, sample);
        for i in 1..=4u64 {
            let want = splitmix64_mix(key.wrapping_add(i.wrapping_mul(GOLDEN)));
            assert_eq!(
                rng.next_u64(),
                want,
                "key {seed},{pixel},{sample}, number {i}"
            );
        }
    }
}
