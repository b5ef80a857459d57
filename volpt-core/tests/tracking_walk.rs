//! The walk over the majorants step by step, where the statistical tests of `tracking.rs` see only
//! distributions and means (mutation testing, shard 2/8): a closure passed to `walk_majorants`
//! sees every tentative collision (the closure impl replaced by `true` left every judge green:
//! only `tests/tests/heterogeneous.rs`, which no mutation stage runs, walks with a closure), and
//! ratio tracking's estimate is exactly the product of `1 - sigma_t / majorant`, with its roulette
//! starting once the product falls below 1/8, not at 1/8. Under a majorant grid the walk counts
//! every step too (shard 2/8 of 2026-11-25: the grid loop's `*steps += 1` as `*= 1` left every
//! judge green), and its budget ends a walk that would not end.

use volpt_core::majorant::MajorantGrid;
use volpt_core::tracking::{ratio_tracking, walk_majorants, FreeFlight};
use volpt_core::{Aabb, Medium, Ray, Rng, Spectrum, Vec3};

/// Extinction exactly half the majorant everywhere, declared heterogeneous so that the walk's
/// rejection and ratio steps run: each tentative collision halves ratio tracking's product, exactly.
/// With a majorant grid (four cells of majorant 2 along x over the box the test ray crosses) the
/// walk takes the grid's loop, cell by cell, instead of the global one.
struct HalfOfMajorant(Option<MajorantGrid<'static>>);

const HALF_OF_MAJORANT: HalfOfMajorant = HalfOfMajorant(None);

const GRID_CELLS: [f32; 4] = [2.0; 4];

impl HalfOfMajorant {
    fn with_grid() -> Self {
        let bounds = Aabb::new(Vec3::new(0.0, -2.0, 0.0), Vec3::new(4.0, 0.0, 6.0));
        Self(Some(MajorantGrid::new(&GRID_CELLS, [4, 1, 1], bounds)))
    }
}

impl Medium for HalfOfMajorant {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;

    fn majorant(&self) -> f32 {
        2.0
    }

    fn majorant_grid(&self) -> Option<&MajorantGrid<'_>> {
        self.0.as_ref()
    }

    fn sigma_t(&self, _p: Vec3) -> f32 {
        1.0
    }

    fn albedo(&self, _p: Vec3) -> Spectrum {
        Spectrum::ONE
    }
}

fn ray() -> Ray {
    Ray::new(Vec3::new(0.5, -1.0, 2.0), Vec3::new(0.6, 0.0, 0.8))
}

/// A closure that never stops the walk is called at every tentative collision, one step counted
/// for each, in order along the ray and under the medium's majorant, and the walk escapes; one
/// that stops at the third gets a collision at the distance it was given. Under the global
/// majorant and through a majorant grid's cells.
#[test]
fn a_closure_sees_every_tentative_collision() {
    for medium in [HALF_OF_MAJORANT, HalfOfMajorant::with_grid()] {
        closure_sees_every_tentative_collision(&medium);
    }
}

fn closure_sees_every_tentative_collision(medium: &HalfOfMajorant) {
    let ray = ray();
    let mut total = 0;
    for seed in 0..50 {
        let mut seen = Vec::new();
        let mut steps = 0;
        let flight = walk_majorants(
            medium,
            &ray,
            4.0,
            &mut Rng::new(seed, 1, 2),
            &mut steps,
            1000,
            |_: &mut Rng, t: f32, majorant: f32| {
                seen.push(t);
                assert_eq!(majorant, 2.0);
                false
            },
        );
        assert_eq!(flight, FreeFlight::Escaped, "seed {seed}");
        assert_eq!(seen.len(), steps as usize, "seed {seed}: one call a step");
        assert!(seen.windows(2).all(|w| w[0] < w[1]) && seen.iter().all(|&t| t < 4.0));
        total += seen.len();

        let mut calls = 0;
        let mut third = None;
        let mut steps = 0;
        let flight = walk_majorants(
            medium,
            &ray,
            f32::INFINITY,
            &mut Rng::new(seed, 1, 2),
            &mut steps,
            1000,
            |_: &mut Rng, t: f32, _: f32| {
                calls += 1;
                if calls == 3 {
                    third = Some(t);
                }
                calls == 3
            },
        );
        assert_eq!(flight, FreeFlight::Collision(third.unwrap()), "seed {seed}");
        assert_eq!((calls, steps), (3, 3), "seed {seed}");
    }
    // Optical depth 8 under the majorant: about 8 steps a walk.
    assert!(total > 200, "only {total} tentative collisions in 50 walks");
}

/// With an endless `t_max` (a majorant grid's last cell ends at infinity too) the walk stops at
/// exactly `max_steps`, out of steps.
#[test]
fn the_step_budget_ends_an_endless_walk() {
    let ray = ray();
    for medium in [HALF_OF_MAJORANT, HalfOfMajorant::with_grid()] {
        for seed in 0..50 {
            let mut steps = 0;
            let flight = walk_majorants(
                &medium,
                &ray,
                f32::INFINITY,
                &mut Rng::new(seed, 1, 2),
                &mut steps,
                25,
                |_: &mut Rng, _: f32, _: f32| false,
            );
            assert_eq!((flight, steps), (FreeFlight::OutOfSteps, 25), "seed {seed}");
        }
    }
}

/// Each tentative collision halves ratio tracking's product: a walk of `k` steps estimates `2^-k`
/// while that stays at or above 1/8 (k <= 3). From the fourth step on the product is below 1/8 and
/// each step's roulette either ends the walk (estimate 0) or doubles the halved product back to
/// 1/8. So every estimate is exactly 1, 1/2, 1/4, 1/8 or 0, each where its step count says.
#[test]
fn ratio_tracking_multiplies_exact_ratios_and_roulettes_below_an_eighth() {
    let (medium, ray) = (HALF_OF_MAJORANT, ray());
    let mut counts = [0u32; 5];
    for seed in 0..2000 {
        let mut steps = 0;
        let estimate = ratio_tracking(
            &medium,
            &ray,
            1.5,
            &mut Rng::new(seed, 3, 4),
            &mut steps,
            1000,
        )
        .expect("within the step budget");
        let expected: &[f32] = match steps {
            0 => &[1.0],
            1 => &[0.5],
            2 => &[0.25],
            3 => &[0.125],
            _ => &[0.125, 0.0],
        };
        assert!(
            expected.contains(&estimate),
            "seed {seed}: {steps} steps, estimate {estimate}, expected one of {expected:?}"
        );
        counts[(steps as usize).min(4)] += 1;
    }
    // Optical depth 3 under the majorant: every step count is common.
    assert!(counts.iter().all(|&c| c > 50), "step counts {counts:?}");
}
