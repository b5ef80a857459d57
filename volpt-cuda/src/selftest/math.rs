//! `volpt_core::math` as the kernels compile it, against the CPU.
//!
//! The exact kernels must give the CPU's bits (one source, the same paths). The fast kernels'
//! approximate instructions (`cfg(volpt_fast_math)`) are code that no CPU build compiles, so no
//! CPU test and no CPU-judged mutant reaches it; here they must give the true value (f64) within
//! bounds a few times the errors the PTX ISA documents for them (`sqrt.approx` and `ex2.approx`
//! about 2^-23 and 2^-22.5 relative, `lg2.approx` 2^-22.6 absolute, `rcp.approx` 1 ulp,
//! `div.approx` 2 ulp), plus what rounding the argument costs (`exp(x) = ex2(x log2 e)`: the
//! rounded product moves the result by up to `|x| 2^-24` relative). A wrong constant, operand or
//! instruction misses these bounds by orders of magnitude.

use volpt_device::selftest::{MATH_INPUTS, MATH_OUTPUTS};

/// The functions, in the order the kernel writes them (`volpt_device::selftest::math_functions`).
pub const FUNCTIONS: [&str; MATH_OUTPUTS] = [
    "sqrt(a)",
    "ln(a)",
    "exp(b)",
    "div(a, b)",
    "recip(b)",
    "sin_cos_2pi(u).0",
    "sin_cos_2pi(u).1",
];

/// `(a, b, u)` for `n` threads: the corner cases first (`a = 1`, where `ln` is 0; `b = +-0`,
/// where `exp` is 1 and the reciprocal infinite; `u` on quarter turns and just below a whole
/// one), then `a` log-uniform in [2^-100, 2^100] (so that `a / b` stays a normal number: the fast
/// kernels flush subnormals), `b` uniform in [-80, 80] (`exp(b)` normal) and `u` in [0, 1).
pub fn inputs(n: usize) -> Vec<f32> {
    let corners: [[f32; MATH_INPUTS]; 6] = [
        [1.0, 0.0, 0.0],
        [1.0, -0.0, 0.25],
        [4.0, 1.0, 0.5],
        [0.5, -1.0, 0.75],
        [2.0, 80.0, 1.0 - f32::EPSILON / 2.0],
        [3.0, -80.0, 0.125],
    ];
    let random = (0..n as u64).map(|i| {
        let r = |k: u64| super::unit(MATH_INPUTS as u64 * i + k + 7_000_000);
        [(200.0 * r(0) - 100.0).exp2(), 160.0 * r(1) - 80.0, r(2)]
    });
    corners
        .into_iter()
        .chain(random)
        .take(n)
        .flatten()
        .collect()
}

/// What the host's `volpt_core::math` computes for `(a, b, u)`: the exact kernels' expectation,
/// from the very function the kernel runs.
pub fn host(a: f32, b: f32, u: f32) -> [f32; MATH_OUTPUTS] {
    volpt_device::selftest::math_values(a, b, u)
}

/// The true values, in f64.
fn truth(a: f32, b: f32, u: f32) -> [f64; MATH_OUTPUTS] {
    let (a, b, u) = (f64::from(a), f64::from(b), f64::from(u));
    let turn = 2.0 * std::f64::consts::PI * u;
    [
        a.sqrt(),
        a.ln(),
        b.exp(),
        a / b,
        1.0 / b,
        turn.sin(),
        turn.cos(),
    ]
}

/// The fast kernels' bound on `|got - truth|` for function `k`.
fn fast_bound(k: usize, a: f32, b: f32, truth: f64) -> f64 {
    let rel = 2f64.powi(-21);
    match k {
        // sqrt, a / b, 1 / b: relative.
        0 | 3 | 4 => rel * truth.abs(),
        // ln = lg2.approx * ln 2: absolute near 1, relative beyond.
        1 => rel * (1.0 + f64::from(a).ln().abs()),
        // exp(b) = ex2.approx(b log2 e): relative, and the rounded argument.
        2 => (rel + f64::from(b).abs() * 2f64.powi(-22)) * truth.abs(),
        // sin_cos_2pi's polynomial with fused multiply-adds: absolute.
        _ => rel,
    }
}

/// Compares the kernel's outputs `got` (`MATH_OUTPUTS` per input triple) with the host's bits
/// (`fast = false`) or with the true values within [`fast_bound`] (`fast = true`). Returns the
/// failures and a line of what was measured.
pub fn check(inputs: &[f32], got: &[f32], fast: bool) -> (Vec<String>, String) {
    let mut failures = Vec::new();
    let mut identical = 0usize;
    // The largest error of each function, as a fraction of its bound.
    let mut worst = [0f64; MATH_OUTPUTS];
    for (x, got) in inputs.chunks(MATH_INPUTS).zip(got.chunks(MATH_OUTPUTS)) {
        let (a, b, u) = (x[0], x[1], x[2]);
        let expected = host(a, b, u);
        let truth = truth(a, b, u);
        for k in 0..MATH_OUTPUTS {
            let bits_equal = got[k].to_bits() == expected[k].to_bits();
            identical += usize::from(bits_equal);
            let ok = if !fast {
                bits_equal
            } else if truth[k].is_infinite() {
                f64::from(got[k]) == truth[k]
            } else {
                let ratio = (f64::from(got[k]) - truth[k]).abs() / fast_bound(k, a, b, truth[k]);
                worst[k] = worst[k].max(ratio);
                ratio <= 1.0
            };
            if !ok {
                failures.push(format!(
                    "{} at (a, b, u) = ({a:e}, {b:e}, {u:e}): {:e}, {} {:e}",
                    FUNCTIONS[k],
                    got[k],
                    if fast { "true value" } else { "the CPU's" },
                    if fast {
                        truth[k]
                    } else {
                        f64::from(expected[k])
                    },
                ));
            }
        }
    }
    let values = inputs.len() / MATH_INPUTS * MATH_OUTPUTS;
    let mut measured = format!(
        "{:.2}% bit-identical to the CPU",
        100.0 * identical as f64 / values.max(1) as f64
    );
    if fast {
        measured += "; largest error as a fraction of its bound:";
        for (name, w) in FUNCTIONS.iter().zip(worst) {
            measured += &format!(" {name} {w:.3}");
        }
    }
    (failures, measured)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn host_outputs(inputs: &[f32]) -> Vec<f32> {
        inputs
            .chunks(MATH_INPUTS)
            .flat_map(|x| host(x[0], x[1], x[2]))
            .collect()
    }

    #[test]
    fn the_inputs_keep_every_result_normal_or_exactly_infinite() {
        let inputs = inputs(4096);
        assert_eq!(inputs.len(), 4096 * MATH_INPUTS);
        for x in inputs.chunks(MATH_INPUTS) {
            let (a, b, u) = (x[0], x[1], x[2]);
            assert!((2f32.powi(-100)..=2f32.powi(100)).contains(&a), "a = {a}");
            assert!((-80.0..=80.0).contains(&b) && (0.0..1.0).contains(&u));
            for (k, t) in truth(a, b, u).into_iter().enumerate() {
                let t = t.abs();
                let normal =
                    t == 0.0 || t >= f64::from(f32::MIN_POSITIVE) && t < f64::from(f32::MAX);
                assert!(normal || t.is_infinite(), "{} = {t:e}", FUNCTIONS[k]);
            }
        }
    }

    #[test]
    fn the_cpus_own_results_pass_both_checks() {
        let inputs = inputs(4096);
        let got = host_outputs(&inputs);
        let (failures, _) = check(&inputs, &got, false);
        assert!(failures.is_empty(), "{failures:?}");
        let (failures, measured) = check(&inputs, &got, true);
        assert!(failures.is_empty(), "{failures:?}");
        assert!(measured.starts_with("100.00% bit-identical"), "{measured}");
    }

    #[test]
    fn the_exact_check_fails_on_one_ulp() {
        let inputs = inputs(64);
        let mut got = host_outputs(&inputs);
        got[9 * MATH_OUTPUTS + 1] = f32::from_bits(got[9 * MATH_OUTPUTS + 1].to_bits() + 1);
        let (failures, _) = check(&inputs, &got, false);
        assert_eq!(failures.len(), 1, "{failures:?}");
        assert!(failures[0].starts_with("ln(a)"), "{failures:?}");
    }

    /// The fast kernels' mutants of `volpt_core::math` (the argument's scaling of `exp` and
    /// `ln`, `approx::div` replaced by a constant), computed on the host, each fail the check.
    #[test]
    fn the_fast_check_fails_on_the_fast_kernels_mutants() {
        use std::f32::consts::{LN_2, LOG2_E};
        let inputs = inputs(1024);
        type Mutant<'a> = (usize, &'a dyn Fn(f32, f32) -> f32);
        let mutants: [Mutant; 7] = [
            (1, &|a, _| a.log2() + LN_2),
            (1, &|a, _| a.log2() / LN_2),
            (2, &|_, b| (b + LOG2_E).exp2()),
            (2, &|_, b| (b / LOG2_E).exp2()),
            (3, &|_, _| 0.0),
            (3, &|_, _| 1.0),
            (3, &|_, _| -1.0),
        ];
        for (m, (k, mutant)) in mutants.into_iter().enumerate() {
            let mut got = host_outputs(&inputs);
            for (x, out) in inputs.chunks(MATH_INPUTS).zip(got.chunks_mut(MATH_OUTPUTS)) {
                out[k] = mutant(x[0], x[1]);
            }
            let (failures, _) = check(&inputs, &got, true);
            assert!(
                failures.len() > inputs.len() / MATH_INPUTS / 2,
                "mutant {m} of {}: {} failures",
                FUNCTIONS[k],
                failures.len()
            );
        }
    }

    #[test]
    fn the_fast_check_fails_on_a_wrong_sign_and_a_wrong_quadrant() {
        let inputs = inputs(1024);
        let mut got = host_outputs(&inputs);
        for (x, out) in inputs.chunks(MATH_INPUTS).zip(got.chunks_mut(MATH_OUTPUTS)) {
            out[6] = volpt_core::math::sin_cos_2pi(x[2] + 0.25).1;
        }
        assert!(!check(&inputs, &got, true).0.is_empty());
        let mut got = host_outputs(&inputs);
        got[10 * MATH_OUTPUTS] = -got[10 * MATH_OUTPUTS];
        assert_eq!(check(&inputs, &got, true).0.len(), 1);
    }
}
