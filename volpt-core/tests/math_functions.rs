//! The scalar wrappers every backend calls (`volpt_core::math`) against f64 `std`: each is the
//! correctly rounded function or within a few f32 ulps of it over its domain in the renderer.
//! Mutation testing found `sin_cos` and `tan` replaced by constants unseen by volpt-core's tests.

use volpt_core::math::{clamp, exp, lerp, ln, safe_sqrt, sin_cos, sqr, sqrt, tan};

/// `|got - want| <= ulps` f32 ulps of `want` (absolute near zero, where f32 is denser).
fn assert_close(name: &str, x: f32, got: f32, want: f64, ulps: f64) {
    let scale = (want.abs() as f32).max(f32::MIN_POSITIVE);
    let ulp = (scale.next_up() - scale) as f64;
    let tolerance = ulps * ulp.max(f32::EPSILON as f64 * 1e-3);
    assert!(
        (got as f64 - want).abs() <= tolerance,
        "{name}({x}) = {got}, expected {want} (within {ulps} ulps)"
    );
}

fn sweep(lo: f32, hi: f32) -> impl Iterator<Item = f32> {
    let n = 20_000;
    (0..=n).map(move |i| lo + (hi - lo) * i as f32 / n as f32)
}

#[test]
fn elementary_functions_match_f64() {
    for x in sweep(-20.0, 20.0) {
        let (s, c) = sin_cos(x);
        assert_close("sin", x, s, (x as f64).sin(), 2.0);
        assert_close("cos", x, c, (x as f64).cos(), 2.0);
        assert_close("exp", x, exp(x), (x as f64).exp(), 2.0);
    }
    // tan on the half-angles of fields of view (0 to 179 degrees).
    for x in sweep(0.0, 1.56) {
        assert_close("tan", x, tan(x), (x as f64).tan(), 2.0);
    }
    for x in sweep(1e-6, 1e3) {
        assert_close("ln", x, ln(x), (x as f64).ln(), 2.0);
        assert_close("sqrt", x, sqrt(x), (x as f64).sqrt(), 0.5);
        assert_close("safe_sqrt", x, safe_sqrt(x), (x as f64).sqrt(), 0.5);
    }
    assert_eq!(
        safe_sqrt(-1e-7),
        0.0,
        "rounding below zero is clamped, not NaN"
    );
}

#[test]
fn small_helpers_do_what_they_say() {
    assert_eq!(sqr(-3.0), 9.0);
    assert_eq!(lerp(0.25, 2.0, 6.0), 3.0);
    assert_eq!(lerp(0.0, 2.0, 6.0), 2.0);
    assert_eq!(lerp(1.0, 2.0, 6.0), 6.0);
    assert_eq!(clamp(-1.0, 0.0, 1.0), 0.0);
    assert_eq!(clamp(2.0, 0.0, 1.0), 1.0);
    assert_eq!(clamp(0.5, 0.0, 1.0), 0.5);
}
