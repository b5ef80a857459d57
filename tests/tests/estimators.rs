//! Estimator against estimator on generated heterogeneous media (`volpt_tests::generated`: a
//! density with holes, an albedo well below 1 that varies per voxel and channel), under a
//! constant and a lat-long environment, with nothing read from beside the checkout: the guards
//! that CI runs (it has no `../shared/data`, so the smoke and bucky comparisons of
//! `heterogeneous.rs` are skipped there).
//!
//! Every test compares an estimator with the plain one on the same scene: path tracing, no
//! roulette, the majorant grid, dense trilinear lookups. Each is unbiased, so the image means agree
//! up to noise; the renders are sized so that a 1% difference is at least 10 standard errors of
//! the difference (`agreement::MARGIN`, asserted), and the window is 5 (`agreement::WINDOW`), so a
//! 0.5% bias fails. Seeds are fixed: the outcome is the same on every run.

use volpt_core::sampling::sample_uniform_sphere;
use volpt_core::tracking::ratio_tracking;
use volpt_core::{Estimator, Medium, PathSettings, Ray, Rng, Roulette, Vec3};
use volpt_render::{with_scene, RenderScene, SceneVisitor};
use volpt_scene::description::*;
use volpt_tests::agreement::{assert_agree, ImageMean, MARGIN, WINDOW};
use volpt_tests::generated::{broad_sun_sky, framed_scene, heterogeneous_medium, LOW_ALBEDO};
use volpt_tests::plain_path_tracing;

/// Pixels per side: every pixel sees the medium.
const SIZE: u32 = 12;

fn nee() -> PathSettings {
    PathSettings {
        estimator: Estimator::NextEvent,
        ..plain_path_tracing()
    }
}

/// Extinction up to 6 per unit length over the unit cube (an optical depth of about 3 across
/// it), forward scattering, albedo in `albedo`.
fn scene(albedo: (f32, f32), environment: EnvironmentDesc) -> SceneDescription {
    framed_scene(SIZE, heterogeneous_medium(6.0, albedo, 0.4), environment)
}

fn constant_sky() -> SceneDescription {
    scene(LOW_ALBEDO, EnvironmentDesc::Constant([1.0, 0.9, 0.8]))
}

fn lat_long_sky() -> SceneDescription {
    scene(LOW_ALBEDO, broad_sun_sky())
}

/// Each candidate (a scene and its settings) against the reference, `spp` samples per pixel for
/// every render, the reference rendered once; all renders with different seeds, so independent.
fn compare(
    spp: u32,
    (desc, settings): (&SceneDescription, PathSettings),
    candidates: &[(&str, &SceneDescription, PathSettings)],
) {
    let start = std::time::Instant::now();
    let a = ImageMean::render(desc, spp, 1, settings);
    for (seed, (name, desc, settings)) in (2..).zip(candidates) {
        let b = ImageMean::render(desc, spp, seed, *settings);
        assert_agree(name, &a, &b);
    }
    eprintln!(
        "{} renders of {spp} spp: {:.1} s",
        1 + candidates.len(),
        start.elapsed().as_secs_f64()
    );
}

/// Next-event estimation (shadow rays by ratio tracking through the holes and the majorant
/// grid, MIS with the phase function) against path tracing, under a constant sky and under a
/// lat-long sky whose sun the environment sampling favours.
#[test]
fn next_event_estimation_matches_path_tracing_on_a_generated_medium() {
    let constant = constant_sky();
    let candidates = [("nee, constant sky", &constant, nee())];
    compare(
        SPP_CONSTANT_NEE,
        (&constant, plain_path_tracing()),
        &candidates,
    );
    let lat_long = lat_long_sky();
    let candidates = [("nee, lat-long sky", &lat_long, nee())];
    compare(
        SPP_LAT_LONG_NEE,
        (&lat_long, plain_path_tracing()),
        &candidates,
    );
}

/// Ratio tracking's error against the transmittance by quadrature, over `rays` shadow rays from
/// uniform points of the box in uniform directions: per ray `R - T`, with `R` the mean of
/// `estimates` independent ratio tracking estimates along it and `T = exp(-tau)`, `tau` by the midpoint rule in 2000 steps of the medium's own
/// extinction (its error, below 1e-5 of `T` for these trilinear grids, is far below the noise).
/// Returns the mean of `R - T`, its standard error (sample variance over the rays) and the mean of
/// `T`.
struct RatioTrackingError {
    rays: u32,
    estimates: u32,
}

impl SceneVisitor for RatioTrackingError {
    type Output = (f64, f64, f64);

    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let bounds = scene.bounds();
        let medium = scene.medium();
        let (mut sum, mut sum2, mut sum_t) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..self.rays {
            let mut rng = Rng::new(23, i, 0);
            let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let origin = bounds.min + bounds.extent() * u;
            let ray = Ray::new(origin, sample_uniform_sphere(rng.next_2d()));
            let t_max = bounds.exit_distance(&ray);
            let mut steps = 0;
            let estimate = (0..self.estimates)
                .map(|_| {
                    ratio_tracking(medium, &ray, t_max, &mut rng, &mut steps, u32::MAX)
                        .expect("no step budget") as f64
                })
                .sum::<f64>()
                / self.estimates as f64;
            let n = 2000;
            let dt = t_max as f64 / n as f64;
            let tau: f64 = (0..n)
                .map(|k| medium.sigma_t(ray.at(((k as f64 + 0.5) * dt) as f32)) as f64 * dt)
                .sum();
            let d = estimate - (-tau).exp();
            sum += d;
            sum2 += d * d;
            sum_t += (-tau).exp();
        }
        let n = self.rays as f64;
        let mean = sum / n;
        let var = (sum2 / n - mean * mean) * n / (n - 1.0);
        (mean, (var / n).sqrt(), sum_t / n)
    }
}

/// Ratio tracking, the transmittance estimator of NEE's shadow rays, is unbiased on the generated
/// medium (holes, where the majorant grid has cells of bound 0) with the majorant grid and with
/// the global majorant: its mean error within 5 standard errors of 0, at a ray count where 1% of
/// the mean transmittance is at least 10 of them. The image-level NEE test sees such an error only
/// through the share of the light that NEE carries (about half).
#[test]
fn ratio_tracking_matches_quadrature_on_a_generated_medium() {
    let desc = constant_sky();
    for resolution in [16, 1] {
        let settings = PathSettings {
            majorant_resolution: resolution,
            ..nee()
        };
        let (error, se, transmittance) = with_scene(
            &desc,
            settings,
            // One estimate per ray gave 1% = 3.0 standard errors: 24 give about 15.
            RatioTrackingError {
                rays: 20_000,
                estimates: 24,
            },
        );
        eprintln!(
            "majorant resolution {resolution}: mean transmittance {transmittance:.4}, ratio \
             tracking's error {error:.2e} +- {se:.1e} (z = {:.2}); 1% is {:.1} standard errors",
            error / se,
            0.01 * transmittance / se
        );
        assert!(
            MARGIN * se <= 0.01 * transmittance,
            "{resolution}: standard error {se} too large to see 1% of {transmittance}"
        );
        assert!(
            error.abs() < WINDOW * se,
            "majorant resolution {resolution}: ratio tracking's mean error {error} is {:.1} \
             standard errors from 0",
            error / se
        );
    }
}

/// The global majorant against the majorant grid, for free flights (delta tracking) and shadow
/// rays (ratio tracking) alike: under NEE both walk the grid.
#[test]
fn global_majorant_matches_the_majorant_grid_on_a_generated_medium() {
    let global = PathSettings {
        majorant_resolution: 1,
        ..nee()
    };
    let desc = lat_long_sky();
    let candidates = [("global majorant, nee, lat-long sky", &desc, global)];
    compare(SPP_GLOBAL, (&desc, nee()), &candidates);
}

/// Each roulette rule from the first interaction on against no roulette, in a medium of albedo
/// 0.5 to 0.98: the throughput falls at every collision, so both rules end paths from the first
/// one, and where the albedo is above 0.95 Mitsuba's rule caps the survival probability (and its
/// paths' throughput grows) while the thesis's keeps every path whose throughput has not fallen.
#[test]
fn each_roulette_rule_matches_no_roulette_on_a_generated_medium() {
    let rule = |roulette| PathSettings {
        rr_depth: 0,
        roulette,
        ..plain_path_tracing()
    };
    let desc = scene((0.5, 0.98), EnvironmentDesc::Constant([1.0, 0.9, 0.8]));
    let candidates = [
        ("Mitsuba's roulette", &desc, rule(Roulette::Mitsuba)),
        (
            "the thesis's throughput roulette",
            &desc,
            rule(Roulette::Throughput),
        ),
    ];
    compare(SPP_ROULETTE, (&desc, plain_path_tracing()), &candidates);
}

/// Every grid lookup against dense trilinear reads of the same grids: the any-layout reads
/// (bricked storage) compute the same trilinear function, the texture filter approximates it
/// (weights of 8 fractional bits), half-precision texels hold the samples to 2^-10; none may move
/// the image by as much as 0.5%.
#[test]
fn every_grid_lookup_matches_dense_trilinear_on_a_generated_medium() {
    let desc = constant_sky();
    let with = |lookup, storage| {
        let mut d = desc.clone();
        d.medium.lookup = lookup;
        d.medium.storage = storage;
        d
    };
    let bricked = with(GridLookup::Trilinear, GridStorage::Bricked);
    let texture = with(GridLookup::Texture, GridStorage::Dense);
    let half = with(GridLookup::TextureHalf, GridStorage::Dense);
    let candidates = [
        ("any-layout reads (bricked)", &bricked, plain_path_tracing()),
        ("texture filter", &texture, plain_path_tracing()),
        ("half-precision texture", &half, plain_path_tracing()),
    ];
    compare(SPP_LOOKUP, (&desc, plain_path_tracing()), &candidates);
}

// Samples per pixel, sized from pilot renders of 256 spp: the factor by which those fell short
// of 1% = 10 standard errors in the worst channel (in brackets), times 1.3 to spare.
/// (x23.7)
const SPP_CONSTANT_NEE: u32 = 8192;
/// (x76.4: path tracing rarely finds the sun)
const SPP_LAT_LONG_NEE: u32 = 25600;
/// (x34.8)
const SPP_GLOBAL: u32 = 11520;
/// (x18.2)
const SPP_ROULETTE: u32 = 6144;
/// (x25.0)
const SPP_LOOKUP: u32 = 8320;
