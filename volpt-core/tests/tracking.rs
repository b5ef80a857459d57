//! Delta (Woodcock) tracking: free-flight distances against the analytic distribution
//! `1 - exp(-tau(t))`, escape probabilities, the tentative-collision counter, and vacuum.
//!
//! Tentative collisions are a Poisson process of rate `majorant` along the ray, stopped at the
//! accepted collision or at `t_max`. The counter counts the points of that process in
//! [0, min(t_collision, t_max)] (the accepted one included), so by Wald's identity for Poisson
//! processes E[steps] = majorant * E[min(t_collision, t_max)] = majorant * int_0^t_max exp(-tau(s)) ds.
//! For a homogeneous medium (majorant = sigma_t, every collision accepted) that is
//! 1 - exp(-sigma_t t_max), the collision probability: one step or none.

mod common;

use common::*;
use volpt_core::math::{exp, ln};
use volpt_core::tracking::{delta_tracking, ratio_tracking, FreeFlight};
use volpt_core::{Aabb, HomogeneousMedium, MajorantGrid, Medium, Ray, Rng, Spectrum, Vec3};

const N: u32 = 100_000;

/// sigma_t = 1 for x < 1, 4 for 1 <= x < 2, 0.5 beyond, with a chosen majorant.
struct Layered {
    majorant: f32,
}

impl Medium for Layered {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;

    fn majorant(&self) -> f32 {
        self.majorant
    }

    fn sigma_t(&self, p: Vec3) -> f32 {
        if p.x < 1.0 {
            1.0
        } else if p.x < 2.0 {
            4.0
        } else {
            0.5
        }
    }

    fn albedo(&self, _p: Vec3) -> Spectrum {
        Spectrum::ONE
    }
}

/// A constant sigma_t that declares itself heterogeneous, so that the rejection step runs.
struct ConstantButTracked {
    sigma_t: f32,
    majorant: f32,
}

impl Medium for ConstantButTracked {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;

    fn majorant(&self) -> f32 {
        self.majorant
    }

    fn sigma_t(&self, _p: Vec3) -> f32 {
        self.sigma_t
    }

    fn albedo(&self, _p: Vec3) -> Spectrum {
        Spectrum::ONE
    }
}

/// Optical depth of `Layered` from x = 0 to x = t.
fn layered_tau(t: f64) -> f64 {
    if t < 1.0 {
        t
    } else if t < 2.0 {
        1.0 + 4.0 * (t - 1.0)
    } else {
        5.0 + 0.5 * (t - 2.0)
    }
}

/// int_0^t_max exp(-tau(s)) ds for `Layered`, segment by segment in closed form.
fn layered_mean_flight(t_max: f64) -> f64 {
    let segments = [(0.0, 1.0, 1.0), (1.0, 2.0, 4.0), (2.0, f64::INFINITY, 0.5)];
    segments
        .iter()
        .filter(|(a, _, _)| *a < t_max)
        .map(|&(a, b, sigma)| {
            let b: f64 = if b < t_max { b } else { t_max };
            (-layered_tau(a)).exp() * (1.0 - (-sigma * (b - a)).exp()) / sigma
        })
        .sum()
}

fn ray() -> Ray {
    Ray::new(Vec3::ZERO, Vec3::X)
}

struct Flights {
    /// Distances of the paths that collided.
    distances: Vec<f64>,
    escaped: usize,
    steps: Moments,
}

fn fly<M: Medium>(medium: &M, t_max: f32, seed: u32) -> Flights {
    let mut flights = Flights {
        distances: Vec::new(),
        escaped: 0,
        steps: Moments::default(),
    };
    for i in 0..N {
        let mut rng = Rng::new(seed, 7, i);
        let mut steps = 0;
        match delta_tracking(medium, &ray(), t_max, &mut rng, &mut steps, u32::MAX) {
            FreeFlight::Collision(t) => {
                assert!(t >= 0.0 && t < t_max, "t = {t}");
                flights.distances.push(t as f64);
            }
            FreeFlight::Escaped => flights.escaped += 1,
            FreeFlight::OutOfSteps => unreachable!("no step budget"),
        }
        flights.steps.push(steps as f64);
    }
    flights
}

/// A deliberately wrong tracker that accepts with (sigma_t / majorant)^2: the power check.
fn squared_acceptance_tracking<M: Medium>(medium: &M, ray: &Ray, rng: &mut Rng) -> f32 {
    let majorant = medium.majorant();
    let mut t = 0.0;
    loop {
        t -= ln(1.0 - rng.next_f32()) / majorant;
        let ratio = medium.sigma_t(ray.at(t)) / majorant;
        if rng.next_f32() < ratio * ratio {
            return t;
        }
    }
}

// Every KS test below rejects at ALPHA over the number of KS tests in this file (Bonferroni).
const KS_TESTS: f64 = 7.0;

#[test]
fn homogeneous_free_flights_are_exponential() {
    let sigma = 2.5f64;
    let medium = HomogeneousMedium {
        sigma_t: sigma as f32,
        albedo: Spectrum::ONE,
    };
    for (case, t_max) in [f32::INFINITY, 1e30].into_iter().enumerate() {
        let f = fly(&medium, t_max, 10 + case as u32);
        assert_eq!(f.escaped, 0);
        let ks = ks_test(&f.distances, |t| 1.0 - (-sigma * t).exp());
        assert!(ks.p_value > ALPHA / KS_TESTS, "t_max {t_max}: {ks:?}");
        // Power: the same samples are rejected as exponential with sigma 4% off (D ~ 0.006 vs the
        // 1.9 / sqrt(N) = 0.006 critical value at the Bonferroni level; 2.6 is farther).
        let wrong = ks_test(&f.distances, |t| 1.0 - (-2.6 * t).exp());
        assert!(wrong.p_value < ALPHA / KS_TESTS, "no power: {wrong:?}");
        // A homogeneous medium accepts its first tentative collision: exactly one step.
        assert_eq!(f.steps.mean(), 1.0);
    }
}

#[test]
fn homogeneous_escape_probability_and_steps() {
    let sigma = 2.5f64;
    let t_max = 0.6f64;
    let medium = HomogeneousMedium {
        sigma_t: sigma as f32,
        albedo: Spectrum::ONE,
    };
    let f = fly(&medium, t_max as f32, 20);
    // Escapes are Bernoulli(exp(-sigma t_max)): within 5 standard errors.
    let p = (-sigma * t_max).exp();
    let freq = f.escaped as f64 / N as f64;
    let se = (p * (1.0 - p) / N as f64).sqrt();
    assert!((freq - p).abs() < Z_MAX * se, "escaped {freq} vs {p}");
    // Collided distances follow the exponential truncated at t_max.
    let ks = ks_test(&f.distances, |t| (1.0 - (-sigma * t).exp()) / (1.0 - p));
    assert!(ks.p_value > ALPHA / KS_TESTS, "{ks:?}");
    // One step per collision, none per escape: E[steps] = sigma E[min(t, t_max)] = 1 - p.
    assert!(
        f.steps.z_score(1.0 - p) < Z_MAX,
        "steps {} vs {}",
        f.steps.mean(),
        1.0 - p
    );
    assert!((f.steps.mean() - f.distances.len() as f64 / N as f64).abs() < 1e-9);
}

#[test]
fn piecewise_constant_medium_matches_optical_depth() {
    let cdf = |t: f64| 1.0 - (-layered_tau(t)).exp();
    let mut by_majorant = Vec::new();
    for (case, majorant) in [4.0f32, 40.0].into_iter().enumerate() {
        let medium = Layered { majorant };
        let f = fly(&medium, f32::INFINITY, 30 + case as u32);
        assert_eq!(f.escaped, 0);
        let ks = ks_test(&f.distances, cdf);
        eprintln!("majorant {majorant}: {ks:?}");
        assert!(ks.p_value > ALPHA / KS_TESTS, "majorant {majorant}: {ks:?}");
        // Tentative collisions: E[steps] = majorant * int_0^inf exp(-tau) (see the module doc).
        let expected = majorant as f64 * layered_mean_flight(f64::INFINITY);
        assert!(
            f.steps.z_score(expected) < Z_MAX,
            "majorant {majorant}: steps {} +- {} vs {expected}",
            f.steps.mean(),
            f.steps.std_error()
        );
        by_majorant.push(f.distances);
    }
    // A ten times looser majorant samples the same distribution (only more slowly).
    let ks = ks_test_2(&by_majorant[0], &by_majorant[1]);
    assert!(ks.p_value > ALPHA / KS_TESTS, "majorant 4 vs 40: {ks:?}");

    // Power: accepting with (sigma / majorant)^2 gives a different distribution, and the same test
    // rejects it.
    let medium = Layered { majorant: 4.0 };
    let wrong: Vec<f64> = (0..N)
        .map(|i| squared_acceptance_tracking(&medium, &ray(), &mut Rng::new(39, 7, i)) as f64)
        .collect();
    let ks = ks_test(&wrong, cdf);
    assert!(ks.p_value < ALPHA / KS_TESTS, "no power: {ks:?}");
}

#[test]
fn piecewise_constant_medium_with_finite_t_max() {
    let t_max = 1.5f64;
    for (case, majorant) in [4.0f32, 40.0].into_iter().enumerate() {
        let medium = Layered { majorant };
        let f = fly(&medium, t_max as f32, 40 + case as u32);
        // P(escape) = exp(-tau(t_max)) = exp(-3).
        let p = (-layered_tau(t_max)).exp();
        let freq = f.escaped as f64 / N as f64;
        let se = (p * (1.0 - p) / N as f64).sqrt();
        assert!(
            (freq - p).abs() < Z_MAX * se,
            "majorant {majorant}: escaped {freq} vs {p}"
        );
        let expected = majorant as f64 * layered_mean_flight(t_max);
        assert!(
            f.steps.z_score(expected) < Z_MAX,
            "majorant {majorant}: steps {} vs {expected}",
            f.steps.mean()
        );
    }
}

#[test]
fn rejection_on_a_constant_medium_is_exponential() {
    // sigma_t 2.5 under majorant 4: the thinned process is again exponential with rate 2.5, and the
    // expected number of steps is 4 / 2.5 (geometric number of trials).
    let medium = ConstantButTracked {
        sigma_t: 2.5,
        majorant: 4.0,
    };
    let f = fly(&medium, f32::INFINITY, 50);
    let ks = ks_test(&f.distances, |t| 1.0 - (-2.5 * t).exp());
    assert!(ks.p_value > ALPHA / KS_TESTS, "{ks:?}");
    assert!(
        f.steps.z_score(4.0 / 2.5) < Z_MAX,
        "steps {}",
        f.steps.mean()
    );
}

#[test]
fn vacuum_returns_immediately() {
    let mut rng = Rng::new(1, 2, 3);
    let mut steps = 0;
    let vacuum = HomogeneousMedium {
        sigma_t: 0.0,
        albedo: Spectrum::ONE,
    };
    assert_eq!(
        delta_tracking(&vacuum, &ray(), f32::INFINITY, &mut rng, &mut steps, 0),
        FreeFlight::Escaped
    );
    assert_eq!(
        delta_tracking(
            &Layered { majorant: 0.0 },
            &ray(),
            10.0,
            &mut rng,
            &mut steps,
            0
        ),
        FreeFlight::Escaped
    );
    // No tentative collision, and no random number consumed.
    assert_eq!(steps, 0);
    assert_eq!(rng.dimension(), 0);
    // t_max = 0: nothing can happen before the boundary.
    let medium = HomogeneousMedium {
        sigma_t: 2.5,
        albedo: Spectrum::ONE,
    };
    for i in 0..1000 {
        let mut rng = Rng::new(1, 2, i);
        let hit = delta_tracking(&medium, &ray(), 0.0, &mut rng, &mut steps, u32::MAX);
        assert!(hit == FreeFlight::Escaped || hit == FreeFlight::Collision(0.0));
    }
}

/// A majorant that delta tracking can never get past: infinite (`t` stays 0, every tentative
/// collision is rejected), NaN, or finite but enormous over a long flight. Each must stop at the
/// budget, having counted exactly the budget's steps, never more.
#[test]
fn step_budget_bounds_hopeless_majorants() {
    for majorant in [f32::INFINITY, f32::NAN, 1e30] {
        let medium = Layered { majorant };
        let mut rng = Rng::new(4, 5, 6);
        let mut steps = 0;
        let flight = delta_tracking(&medium, &ray(), 10.0, &mut rng, &mut steps, 1000);
        assert_eq!(flight, FreeFlight::OutOfSteps, "majorant {majorant}");
        assert_eq!(steps, 1000, "majorant {majorant}");
        // A budget already spent stops the next flight before its first step.
        let flight = delta_tracking(&medium, &ray(), 10.0, &mut rng, &mut steps, 1000);
        assert_eq!(flight, FreeFlight::OutOfSteps);
        assert_eq!(steps, 1000);
    }
}

/// Under the budget the budget changes nothing: the same random numbers give the same flights.
#[test]
fn step_budget_does_not_change_flights_under_it() {
    let medium = Layered { majorant: 8.0 };
    for i in 0..10_000 {
        let (mut a, mut b) = (Rng::new(3, 1, i), Rng::new(3, 1, i));
        let (mut sa, mut sb) = (0, 0);
        let unbounded = delta_tracking(&medium, &ray(), 3.0, &mut a, &mut sa, u32::MAX);
        let bounded = delta_tracking(&medium, &ray(), 3.0, &mut b, &mut sb, 1000);
        assert_eq!(unbounded, bounded);
        assert_eq!(sa, sb);
    }
}

/// `Layered` under a majorant grid of four cells along x (bounds 1.5, 4, 0.5, 1: loose, tight,
/// tight, loose), so that tracking walks the cells.
struct LayeredOnGrid<'a> {
    majorants: MajorantGrid<'a>,
}

impl Medium for LayeredOnGrid<'_> {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;

    fn majorant(&self) -> f32 {
        4.0
    }

    fn majorant_grid(&self) -> Option<&MajorantGrid<'_>> {
        Some(&self.majorants)
    }

    fn sigma_t(&self, p: Vec3) -> f32 {
        Layered { majorant: 4.0 }.sigma_t(p)
    }

    fn albedo(&self, _p: Vec3) -> Spectrum {
        Spectrum::ONE
    }
}

const GRID_MAJORANTS: [f32; 4] = [1.5, 4.0, 0.5, 1.0];

fn layered_on_grid() -> LayeredOnGrid<'static> {
    let bounds = Aabb::new(Vec3::new(0.0, -1.0, -1.0), Vec3::new(4.0, 1.0, 1.0));
    LayeredOnGrid {
        majorants: MajorantGrid::new(&GRID_MAJORANTS, [4, 1, 1], bounds),
    }
}

/// Delta tracking through the majorant grid escapes with probability `exp(-tau(t_max))` (5
/// binomial sigma) and collides where the analytic distribution says (KS).
#[test]
fn delta_tracking_through_a_majorant_grid_matches_optical_depth() {
    let medium = layered_on_grid();
    let t_max = 2.5;
    let f = fly(&medium, t_max, 11);
    let p = (-layered_tau(t_max as f64)).exp();
    let n = N as f64;
    let escaped = f.escaped as f64 / n;
    let se = (p * (1.0 - p) / n).sqrt();
    assert!(
        (escaped - p).abs() < 5.0 * se,
        "escaped {escaped} vs {p} +- {se}"
    );
    let cdf = |t: f64| (1.0 - (-layered_tau(t)).exp()) / (1.0 - p);
    let ks = ks_test(&f.distances, cdf);
    assert!(ks.p_value > ALPHA, "{ks:?}");
}

/// Ratio tracking's estimate has mean `exp(-tau(t_max))` (5 standard errors), with one global
/// majorant and through the grid, and is exact for a homogeneous medium. With these optical depths
/// (3 and 5.25) the product falls below 1/8 on most rays, so the roulette is exercised too.
#[test]
fn ratio_tracking_is_unbiased() {
    let homogeneous = HomogeneousMedium {
        sigma_t: 2.0,
        albedo: Spectrum::ONE,
    };
    let mut rng = Rng::new(3, 0, 0);
    let mut steps = 0;
    let t = ratio_tracking(&homogeneous, &ray(), 0.7, &mut rng, &mut steps, u32::MAX);
    assert_eq!(t, Some(exp(-1.4)));

    for t_max in [1.5f32, 2.5] {
        let expected = (-layered_tau(t_max as f64)).exp();
        let global = Layered { majorant: 4.0 };
        let grid = layered_on_grid();
        let estimates = |medium: &dyn Fn(&mut Rng, &mut u32) -> Option<f32>| {
            let mut m = Moments::default();
            for i in 0..N {
                let mut rng = Rng::new(5, 1, i);
                let mut steps = 0;
                m.push(medium(&mut rng, &mut steps).expect("no step budget") as f64);
            }
            m
        };
        let cases = [
            (
                "global majorant",
                estimates(&|rng, steps| {
                    ratio_tracking(&global, &ray(), t_max, rng, steps, u32::MAX)
                }),
            ),
            (
                "majorant grid",
                estimates(&|rng, steps| ratio_tracking(&grid, &ray(), t_max, rng, steps, u32::MAX)),
            ),
        ];
        for (name, m) in cases {
            assert!(
                (m.mean() - expected).abs() < 5.0 * m.std_error(),
                "{name}, t_max {t_max}: transmittance {} +- {} vs {expected}",
                m.mean(),
                m.std_error()
            );
        }
    }
}

/// A medium of subnormal extinction (smoke's grid has such voxels), tracked under its own
/// subnormal majorant, globally or through a grid of four cells.
struct Faint<'a> {
    majorants: Option<MajorantGrid<'a>>,
}

const FAINT: f32 = 2.2e-42;
const FAINT_CELLS: [f32; 4] = [FAINT; 4];

impl Medium for Faint<'_> {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;

    fn majorant(&self) -> f32 {
        FAINT
    }

    fn majorant_grid(&self) -> Option<&MajorantGrid<'_>> {
        self.majorants.as_ref()
    }

    fn sigma_t(&self, _p: Vec3) -> f32 {
        FAINT
    }

    fn albedo(&self, _p: Vec3) -> Spectrum {
        Spectrum::ONE
    }
}

/// The stream of (seed 0, pixel 0, sample 34962537) starts with exactly 0 (found by search; a
/// 2^-24 event per draw). Under a subnormal majorant the first step was `-ln(1 - 0) * (1 /
/// majorant)` = `0 * inf`: a NaN distance that never reached the cell's end, so tracking spun
/// until the step budget and the path was dropped (one smoke path in ~80 million). The walk must
/// end after at most one step, without touching the budget.
#[test]
fn a_subnormal_majorant_and_a_zero_draw_do_not_spin() {
    let zero_first = || Rng::new(0, 0, 34_962_537);
    assert_eq!(zero_first().next_f32(), 0.0);
    let bounds = Aabb::new(Vec3::new(0.0, -1.0, -1.0), Vec3::new(4.0, 1.0, 1.0));
    for majorants in [
        None,
        Some(MajorantGrid::new(&FAINT_CELLS, [4, 1, 1], bounds)),
    ] {
        let gridded = majorants.is_some();
        let medium = Faint { majorants };
        let mut steps = 0;
        let flight = delta_tracking(&medium, &ray(), 4.0, &mut zero_first(), &mut steps, 1000);
        match flight {
            FreeFlight::Escaped => {}
            FreeFlight::Collision(t) => assert!((0.0..4.0).contains(&t), "grid {gridded}: {t}"),
            FreeFlight::OutOfSteps => panic!("grid {gridded}: out of steps"),
        }
        assert!(steps <= 1, "grid {gridded}: {steps} steps");
        let mut steps = 0;
        let transmittance =
            ratio_tracking(&medium, &ray(), 4.0, &mut zero_first(), &mut steps, 1000);
        // One tentative collision at most, weighted by 1 - sigma_t / majorant (near 1).
        let t = transmittance.expect("within the budget");
        assert!(t > 0.999 && t <= 1.0, "grid {gridded}: transmittance {t}");
        assert!(steps <= 1, "grid {gridded}: {steps} steps");
    }
}
