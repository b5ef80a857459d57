//! Absorption tracking (`tracking::absorption_tracking`): its free flights are delta tracking's,
//! and both of its absorption estimates have the analytic expectation
//! `int_0^t_max sigma_a(t) exp(-tau(t)) dt` (the probability that the flight ends absorbed), on a
//! layered medium whose albedo differs per layer, under a loose global majorant.

mod common;

use common::*;
use volpt_core::tracking::{absorption_tracking, FreeFlight};
use volpt_core::{HomogeneousMedium, Medium, Ray, Rng, Spectrum, Vec3};

const N: u32 = 200_000;

/// (start, end, sigma_t, albedo) along x; sigma_t 0 beyond the last layer.
const LAYERS: [(f64, f64, f64, [f32; 3]); 3] = [
    (0.0, 1.0, 1.0, [0.9, 0.5, 1.0]),
    (1.0, 1.5, 3.0, [0.2, 0.8, 0.0]),
    (1.5, 3.0, 0.5, [0.6, 0.6, 0.6]),
];

struct Layered;

impl Layered {
    fn layer(x: f32) -> Option<&'static (f64, f64, f64, [f32; 3])> {
        LAYERS
            .iter()
            .find(|(a, b, _, _)| (x as f64) >= *a && (x as f64) < *b)
    }
}

impl Medium for Layered {
    const HOMOGENEOUS: bool = false;

    fn majorant(&self) -> f32 {
        5.0
    }

    fn sigma_t(&self, p: Vec3) -> f32 {
        Self::layer(p.x).map_or(0.0, |l| l.2 as f32)
    }

    fn albedo(&self, p: Vec3) -> Spectrum {
        Self::layer(p.x).map_or(Spectrum::ONE, |l| Spectrum::from_array(l.3))
    }
}

/// `int_0^t_max sigma_a exp(-tau)` per channel, and `exp(-tau(t_max))`, in closed form.
fn analytic(t_max: f64) -> ([f64; 3], f64) {
    let mut absorbed = [0.0; 3];
    let mut tau = 0.0f64;
    for &(a, b, sigma, albedo) in &LAYERS {
        if a >= t_max {
            break;
        }
        let b = b.min(t_max);
        let collided = (-tau).exp() * (1.0 - (-sigma * (b - a)).exp());
        for (out, alb) in absorbed.iter_mut().zip(albedo) {
            *out += collided * (1.0 - alb as f64);
        }
        tau += sigma * (b - a);
    }
    (absorbed, (-tau).exp())
}

struct Estimates {
    escaped: Moments,
    collision: [Moments; 3],
    expected: [Moments; 3],
}

fn track<M: Medium>(medium: &M, t_max: f32, seed: u32) -> Estimates {
    let mut est = Estimates {
        escaped: Moments::default(),
        collision: Default::default(),
        expected: Default::default(),
    };
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    for i in 0..N {
        let mut rng = Rng::new(seed, 3, i);
        let mut steps = 0;
        let flight = absorption_tracking(medium, &ray, t_max, &mut rng, &mut steps, u32::MAX);
        match flight.flight {
            FreeFlight::Collision(t) => assert!((0.0..t_max).contains(&t), "t = {t}"),
            FreeFlight::Escaped => {
                assert_eq!(flight.collision_absorption, Spectrum::ZERO);
            }
            FreeFlight::OutOfSteps => unreachable!("no step budget"),
        }
        est.escaped
            .push((flight.flight == FreeFlight::Escaped) as u8 as f64);
        for c in 0..3 {
            est.collision[c].push(flight.collision_absorption[c] as f64);
            est.expected[c].push(flight.expected_absorption[c] as f64);
        }
    }
    est
}

/// Both estimates of the absorbed fraction are unbiased, the flights escape with the analytic
/// probability, and the expected-value estimate has a lower variance than the collision estimate
/// (the point of computing it).
#[test]
fn both_absorption_estimates_match_the_analytic_value() {
    for (t_max, seed) in [(0.7, 1), (1.2, 2), (2.5, 3), (4.0, 4)] {
        let (absorbed, transmittance) = analytic(t_max as f64);
        let est = track(&Layered, t_max, seed);
        let z = est.escaped.z_score(transmittance);
        assert!(z.abs() < Z_MAX, "t_max {t_max}: escape z = {z}");
        for c in 0..3 {
            for (name, m) in [("collision", &est.collision[c]), ("expected", &est.expected[c])] {
                let z = m.z_score(absorbed[c]);
                assert!(
                    z.abs() < Z_MAX,
                    "t_max {t_max}, channel {c}, {name}: mean {} vs {} (z = {z})",
                    m.mean(),
                    absorbed[c]
                );
            }
            if absorbed[c] > 0.0 {
                assert!(
                    est.expected[c].variance() < est.collision[c].variance(),
                    "t_max {t_max}, channel {c}: expected-value variance {} not below the collision \
                     estimate's {}",
                    est.expected[c].variance(),
                    est.collision[c].variance()
                );
            }
        }
    }
}

/// A homogeneous medium gets the exact value, `(1 - albedo)(1 - exp(-sigma_t t_max))`, every time.
#[test]
fn homogeneous_absorption_is_exact() {
    let medium = HomogeneousMedium {
        sigma_t: 2.0,
        albedo: Spectrum::new(0.25, 0.5, 1.0),
    };
    let ray = Ray::new(Vec3::ZERO, Vec3::Y);
    let mut rng = Rng::new(9, 0, 0);
    let mut steps = 0;
    for _ in 0..100 {
        let flight = absorption_tracking(&medium, &ray, 0.8, &mut rng, &mut steps, u32::MAX);
        let collided = 1.0 - (-1.6f32).exp();
        let expected = Spectrum::new(0.75, 0.5, 0.0) * collided;
        assert!(
            (flight.expected_absorption - expected).abs().max_element() < 1e-6,
            "{:?} vs {expected:?}",
            flight.expected_absorption
        );
    }
}
