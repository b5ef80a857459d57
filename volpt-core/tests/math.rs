//! The scalar math every backend shares: accuracy against f64 references.

use volpt_core::math::sin_cos_2pi;

/// `sin_cos_2pi` against f64 `sin`/`cos` over a dense sweep of one turn, including the quadrant
/// boundaries and values just below 1, where the reduction wraps.
#[test]
fn sin_cos_2pi_is_accurate_over_a_turn() {
    let mut worst = 0.0f64;
    let n = 1 << 20;
    let special = [
        0.0,
        0.125,
        0.25,
        0.375,
        0.5,
        0.625,
        0.75,
        0.875,
        1.0 - f32::EPSILON / 2.0,
    ];
    let sweep = (0..n).map(|i| i as f32 / n as f32);
    for u in special.into_iter().chain(sweep) {
        let (s, c) = sin_cos_2pi(u);
        let angle = 2.0 * std::f64::consts::PI * u as f64;
        worst = worst
            .max((s as f64 - angle.sin()).abs())
            .max((c as f64 - angle.cos()).abs());
    }
    // A few f32 ulps of a unit-magnitude result (libm's sincosf(2 pi u) is off by ~1e-7 too,
    // mostly from rounding 2 pi u).
    assert!(worst < 2.5e-7, "max abs error {worst:e}");
}

#[test]
fn sin_cos_2pi_is_exact_on_the_axes() {
    assert_eq!(sin_cos_2pi(0.0), (0.0, 1.0));
    assert_eq!(sin_cos_2pi(0.25), (1.0, 0.0));
    assert_eq!(sin_cos_2pi(0.5), (0.0, -1.0));
    assert_eq!(sin_cos_2pi(0.75), (-1.0, 0.0));
}

/// Outside [0, 1) the argument is wrapped first (a whole turn changes nothing); negative turns are
/// where a wrong wrap shows (mutation testing: `u + floor(u)` passed the tests of one turn).
#[test]
fn sin_cos_2pi_wraps_whole_turns() {
    for u in [-0.25f32, -0.1, -1.3, 1.25, 2.6] {
        let (s, c) = sin_cos_2pi(u);
        let angle = 2.0 * std::f64::consts::PI * u as f64;
        assert!(
            (s as f64 - angle.sin()).abs() < 1e-6 && (c as f64 - angle.cos()).abs() < 1e-6,
            "sin_cos_2pi({u}) = ({s}, {c})"
        );
    }
}

/// A quarter turn more rotates the pair exactly: for `u` on a grid of 2^-20 (where `u + j/4`, `4u`
/// and the reduced angle are exact, so the polynomial sees the same argument), the pair at
/// `u + j/4` is the pair at `u` turned by `j` quadrants, bit for bit: (cos, -sin), (-sin, -cos),
/// (-cos, sin). This pins the quadrant's swap and signs (done with selects and sign-bit masks).
#[test]
fn sin_cos_2pi_turns_exactly_by_quarter_turns() {
    let turn = |(s, c): (f32, f32)| (c, -s);
    for i in 0..1u32 << 18 {
        let u = i as f32 / (1u32 << 20) as f32;
        let mut expected = sin_cos_2pi(u);
        for j in 1..4 {
            expected = turn(expected);
            let got = sin_cos_2pi(u + j as f32 / 4.0);
            assert_eq!(
                (got.0.to_bits(), got.1.to_bits()),
                (expected.0.to_bits(), expected.1.to_bits()),
                "u = {u}, {j} quarter turns"
            );
        }
    }
}
