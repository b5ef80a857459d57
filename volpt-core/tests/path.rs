//! The path step on a scene built by hand, without the render factory: the white furnace (every
//! estimator and roulette rule must return exactly the environment's radiance on average, also
//! behind a dielectric), where next-event estimation runs, `max_depth`, the albedo's weight, the
//! safety bounds, the random streams of pixels and samples, `sample_pixel`, the path counters, and
//! the split step (`fly` + `scatter`) of the sorting strategy against `step`.
//! Cheap (well under a second): the whole-renderer tests check the same paths against independent
//! references, but only with `max_depth = 2`, where roulette never runs, and they never reach the
//! safety bounds.

mod common;

use common::{Moments, Z_MAX};
use volpt_core::path::{fly, sample_pixel, scatter, step, trace, Truncation, NEGLIGIBLE_WEIGHT};
use volpt_core::{
    Aabb, ConstantEnvironment, Estimator, HenyeyGreenstein, HomogeneousMedium, NullBoundary,
    PathCounters, PathSettings, PathState, PerspectiveCamera, Ray, Rng, Roulette, SmoothDielectric,
    Spectrum, Vec2, Vec3, VolumeScene,
};

type Furnace<B = NullBoundary> =
    VolumeScene<HomogeneousMedium, B, HenyeyGreenstein, ConstantEnvironment>;

/// A camera 4 units in front of the box `[-1, 1]^3`, looking at it along +z; the box fills the
/// central part of the `8 x 6` film, and the rays of its corner pixels miss it.
fn camera() -> PerspectiveCamera {
    PerspectiveCamera {
        origin: Vec3::new(0.0, 0.0, -4.0),
        axis_x: Vec3::new(-1.0, 0.0, 0.0),
        axis_y: Vec3::Y,
        axis_z: Vec3::Z,
        tan_half_fov: Vec2::new(0.6, 0.45),
        width: 8,
        height: 6,
        orthographic: false,
    }
}

/// The furnace's environment radiance: not 1, so that a throughput divided by the light instead of
/// multiplied shows.
const LIGHT: f32 = 2.0;

/// A white furnace: albedo 1 inside an index-matched box under a constant environment of radiance
/// `LIGHT`, so every pixel's value is exactly `LIGHT`. Optical depth 3 across the box, forward
/// scattering.
fn furnace(settings: PathSettings) -> Furnace {
    furnace_behind(NullBoundary, settings)
}

/// The furnace behind `boundary`: a boundary that neither absorbs nor emits keeps every pixel at `LIGHT`.
fn furnace_behind<B>(boundary: B, settings: PathSettings) -> Furnace<B> {
    VolumeScene {
        camera: camera(),
        bounds: Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0)),
        medium: HomogeneousMedium {
            sigma_t: 1.5,
            albedo: Spectrum::ONE,
        },
        boundary,
        phase: HenyeyGreenstein { g: 0.6 },
        environment: ConstantEnvironment(Spectrum::splat(LIGHT)),
        lights: volpt_core::Lights::NONE,
        settings,
    }
}

/// The mean of every pixel's paths, asserted to be `LIGHT` within `Z_MAX` standard errors, and
/// every path's radiance non-negative (MIS weights lie in [0, 1]); the most interactions a path
/// had.
fn assert_furnace_mean_is_the_light<B: volpt_core::Bsdf>(
    scene: &Furnace<B>,
    spp: u32,
    what: &str,
) -> u32 {
    let mut moments = Moments::default();
    let mut longest = 0;
    for py in 0..scene.camera.height {
        for px in 0..scene.camera.width {
            for sample in 0..spp {
                let mut path = PathState::from_camera(scene, px, py, sample, 7);
                trace(scene, &mut path);
                assert_eq!(path.truncated, Truncation::None);
                longest = longest.max(path.depth);
                for value in path.radiance.to_array() {
                    assert_eq!(value, path.radiance.x, "a grey furnace stays grey");
                }
                assert!(path.radiance.x >= 0.0, "{what}: radiance {}", path.radiance);
                moments.push(path.radiance.x as f64);
            }
        }
    }
    // Plus the paths' f32 rounding (products of tens of weights near 1, ~1e-7 each): without
    // roulette every path of a furnace returns the light to within it, with a standard error of 0.
    let (mean, se) = (moments.mean(), moments.std_error());
    let rounding = 1e-5 * LIGHT as f64;
    assert!(
        (mean - LIGHT as f64).abs() <= Z_MAX * se + rounding,
        "{what}: furnace mean {mean} +- {se}"
    );
    longest
}

/// Every `(estimator, roulette)` with roulette from the first interaction on: path tracing, and
/// next-event estimation whose two strategies are weighted by the power heuristic (the
/// environment's density `1 / 4 pi` against Henyey-Greenstein's, which differ). The film's corner
/// pixels miss the box: their camera rays see the environment unweighted.
#[test]
fn white_furnace_returns_the_light_with_every_estimator_and_roulette() {
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        for roulette in [Roulette::Mitsuba, Roulette::Throughput] {
            let scene = furnace(PathSettings {
                rr_depth: 0,
                estimator,
                roulette,
                ..PathSettings::default()
            });
            let what = format!("{estimator:?}, {roulette:?}");
            let longest = assert_furnace_mean_is_the_light(&scene, 40, &what);
            assert!(
                longest > 3,
                "{what}: paths scattered at most {longest} times"
            );
        }
    }
}

/// Next-event estimation is valid only behind an index-matched boundary (a dielectric bends or
/// reflects the shadow ray); behind a smooth dielectric the same setting must trace paths only,
/// and the furnace stays at `LIGHT`.
#[test]
fn white_furnace_behind_a_dielectric_returns_the_light_with_next_event_selected() {
    let scene = furnace_behind(
        SmoothDielectric { eta: 1.5 },
        PathSettings {
            estimator: Estimator::NextEvent,
            ..PathSettings::default()
        },
    );
    assert_furnace_mean_is_the_light(&scene, 40, "smooth dielectric, NextEvent");
}

/// Whether a path gathered light at a collision, where only next-event estimation adds any.
fn gathers_at_collisions<B: volpt_core::Bsdf>(scene: &Furnace<B>) -> bool {
    (0..50).any(|sample| {
        let mut path = PathState::from_camera(scene, 4, 3, sample, 2);
        while path.alive {
            let depth = path.depth;
            step(scene, &mut path);
            // A step that ended in a collision counted one more interaction and stayed inside.
            if path.depth > depth && path.inside && path.radiance != Spectrum::ZERO {
                return true;
            }
        }
        false
    })
}

/// Next-event estimation runs where it is selected, behind an index-matched boundary, and nowhere
/// else: path tracing and a dielectric boundary gather light only where a path escapes.
#[test]
fn next_event_estimation_runs_exactly_where_selected() {
    let settings = |estimator| PathSettings {
        estimator,
        ..PathSettings::default()
    };
    assert!(gathers_at_collisions(&furnace(settings(
        Estimator::NextEvent
    ))));
    assert!(!gathers_at_collisions(&furnace(settings(
        Estimator::PathTracing
    ))));
    let dielectric = SmoothDielectric { eta: 1.5 };
    assert!(!gathers_at_collisions(&furnace_behind(
        dielectric,
        settings(Estimator::NextEvent)
    )));
}

/// `sample_pixel`, the CPU renderer's and the naive GPU strategy's loop, adds exactly the radiance
/// of the paths `from_camera` and `trace` give, in `f64`, and records each path.
#[test]
fn sample_pixel_sums_its_paths() {
    let scene = furnace(PathSettings {
        estimator: Estimator::NextEvent,
        ..PathSettings::default()
    });
    let mut expected = [0.0f64; 3];
    let mut expected_counters = PathCounters::default();
    for sample in 3..40 {
        let mut path = PathState::from_camera(&scene, 5, 2, sample, 9);
        trace(&scene, &mut path);
        expected_counters.record(&path);
        for (e, r) in expected.iter_mut().zip(path.radiance.to_array()) {
            *e += r as f64;
        }
    }
    let mut sum = [0.5f64; 3];
    let mut counters = PathCounters::default();
    sample_pixel(&scene, (5, 2), 3..40, 9, &mut sum, &mut counters);
    assert_eq!(sum, expected.map(|e| e + 0.5), "added to what the sum held");
    assert_eq!(counters, expected_counters);
    assert!(expected[0] > 10.0, "the paths gathered light");
}

/// Mitsuba's `max_depth`: a path may see the light after at most `max_depth - 1` interactions, and
/// `max_depth = 0` renders nothing. In the furnace (path tracing), a path of `max_depth = d`
/// returns `LIGHT` if it escapes after fewer than `d` collisions and 0 if its `d`-th collision ends
/// it.
#[test]
fn max_depth_counts_interactions() {
    for max_depth in [0, 1, 2, 3] {
        let scene = furnace(PathSettings {
            max_depth,
            ..PathSettings::default()
        });
        let (mut lit, mut cut) = (0, 0);
        for sample in 0..400 {
            let mut path = PathState::from_camera(&scene, 4, 3, sample, 5);
            trace(&scene, &mut path);
            if path.radiance == Spectrum::splat(LIGHT) {
                assert!(
                    path.depth < max_depth,
                    "lit after {} collisions",
                    path.depth
                );
                lit += 1;
            } else {
                assert_eq!(path.radiance, Spectrum::ZERO);
                assert_eq!(path.depth, max_depth, "a path ended early");
                cut += 1;
            }
        }
        if max_depth == 0 {
            assert_eq!(lit, 0, "max_depth 0 is black");
        } else {
            assert!(
                lit > 0 && cut > 0,
                "max_depth {max_depth}: {lit} lit, {cut} cut"
            );
        }
    }
}

/// With path tracing and no roulette, a path that escapes after `k` collisions returns exactly
/// `albedo^k` times the light: the collision estimator's weight is the albedo.
#[test]
fn each_collision_weighs_the_throughput_by_the_albedo() {
    let mut scene = furnace(PathSettings {
        rr_depth: PathSettings::UNLIMITED,
        ..PathSettings::default()
    });
    let albedo = Spectrum::new(0.9, 0.7, 0.5);
    scene.medium.albedo = albedo;
    let mut deepest = 0;
    for sample in 0..200 {
        let mut path = PathState::from_camera(&scene, 4, 3, sample, 8);
        trace(&scene, &mut path);
        let expected = albedo.powf(path.depth as f32) * LIGHT;
        let error = (path.radiance - expected).abs().max_element();
        assert!(
            error <= 1e-5 * LIGHT,
            "after {} collisions: {} instead of {expected}",
            path.depth,
            path.radiance
        );
        deepest = deepest.max(path.depth);
    }
    assert!(deepest >= 3, "paths collided at most {deepest} times");
}

/// Asserts that of `paths` paths that `advance` takes through one interaction, each of weight
/// `max(throughput) * eta^2 = q * NEGLIGIBLE_WEIGHT` before it, a binomial count of probability
/// `q` survives roulette (within `Z_MAX` sigma), each survivor with the weight of the bound, and
/// that the mean weight after it (0 for a path that died) is the weight before (within `Z_MAX`
/// standard errors).
fn assert_negligible_roulette(what: &str, paths: u32, q: f32, advance: impl Fn(u32) -> PathState) {
    let (mut survived, mut weights) = (0u32, Moments::default());
    for sample in 0..paths {
        let path = advance(sample);
        let weight = if path.alive {
            survived += 1;
            let weight = path.throughput.max_element() * path.eta_scale * path.eta_scale;
            assert!(
                (weight / NEGLIGIBLE_WEIGHT - 1.0).abs() < 1e-6,
                "{what}: a survivor carries {weight}, not {NEGLIGIBLE_WEIGHT}"
            );
            weight
        } else {
            0.0
        };
        weights.push(weight as f64);
    }
    let expected = paths as f64 * q as f64;
    let sd = (expected * (1.0 - q as f64)).sqrt();
    assert!(
        (survived as f64 - expected).abs() <= Z_MAX * sd,
        "{what}: {survived} of {paths} survived, expected {expected} +- {sd}"
    );
    let before = (q * NEGLIGIBLE_WEIGHT) as f64;
    assert!(
        weights.z_score(before).abs() <= Z_MAX,
        "{what}: mean weight after roulette {} +- {}, before {before}",
        weights.mean(),
        weights.std_error()
    );
}

/// Before `rr_depth` (unlimited, or not yet reached) a path still faces roulette once its weight
/// `max(throughput) * eta^2` is below `NEGLIGIBLE_WEIGHT`: it survives with probability
/// `weight / NEGLIGIBLE_WEIGHT` and then carries that weight, so the throughput's mean is
/// unchanged; at the bound or above it a path draws no number for roulette. Both places that run
/// roulette are checked: after a collision in a denser medium, and after a refraction or
/// reflection at a smooth dielectric. A rule without `eta^2`, a survivor's throughput left
/// undivided, roulette at or above the bound, the rule gated on an unlimited `rr_depth`, or the
/// rule missing at the boundary each fail one of the assertions.
#[test]
fn a_negligible_weight_faces_roulette_without_bias() {
    // A weight a quarter of the bound: q = 1/4.
    let q = 0.25f32;
    let eta = 1.5f32;
    for rr_depth in [PathSettings::UNLIMITED, 1000] {
        let scene = furnace(PathSettings {
            rr_depth,
            estimator: Estimator::PathTracing,
            ..PathSettings::default()
        });
        // A collision inside a denser medium (eta 1.5), the albedo 1.
        let collide = |sample: u32, throughput: Spectrum| {
            let mut path = PathState::from_camera(&scene, 4, 3, sample, 5);
            path.inside = true;
            path.eta_scale = eta;
            path.throughput = throughput;
            let drawn = path.rng.dimension();
            scatter(&scene, &mut path, Vec3::ZERO, None);
            (path, path.rng.dimension() - drawn)
        };
        let throughput = Spectrum::new(1.0, 0.5, 0.25) * (q * NEGLIGIBLE_WEIGHT / (eta * eta));
        let what = format!("collision, rr_depth {rr_depth}");
        assert_negligible_roulette(&what, 100_000, q, |sample| {
            let (path, drawn) = collide(sample, throughput);
            assert_eq!(
                drawn, 3,
                "the phase sample's two numbers and roulette's one"
            );
            // Every component divided by q, not only the largest.
            if path.alive {
                let ratio = path.throughput / throughput;
                assert!((ratio.max_element() / ratio.min_element() - 1.0).abs() < 1e-6);
            }
            path
        });
        // At the bound and at twice it: no roulette, no number drawn for it, the throughput only
        // weighted by the albedo (1).
        for at in [throughput / q, throughput * (2.0 / q)] {
            for sample in 0..1000 {
                let (path, drawn) = collide(sample, at);
                assert!(path.alive && path.throughput == at && drawn == 2, "{what}");
            }
        }
    }
    // The camera ray meets a smooth dielectric of relative IOR 1.5: a reflection keeps the
    // throughput and `eta_scale`, a refraction scales the throughput by 1/eta^2 and `eta_scale` by
    // eta, so the weight after either is the weight before.
    let scene = furnace_behind(
        SmoothDielectric { eta },
        PathSettings {
            rr_depth: PathSettings::UNLIMITED,
            estimator: Estimator::PathTracing,
            ..PathSettings::default()
        },
    );
    assert_negligible_roulette("boundary", 40_000, q, |sample| {
        let mut path = PathState::from_camera(&scene, 4, 3, sample, 6);
        path.throughput = Spectrum::splat(q * NEGLIGIBLE_WEIGHT);
        step(&scene, &mut path);
        assert_eq!(path.depth, 1, "the camera ray meets the boundary");
        path
    });
}

/// `fly` up to a real collision and `scatter` there, with the albedo read by `scatter` or handed
/// in (as sorting-sk does after reading its block's albedos in Morton order), trace the same path
/// as `step`, bit for bit and state by state: with and without next-event estimation, behind an
/// index-matched and a refracting boundary. Only the GPU's sorting-sk runs this split, so the
/// CPU's images never see it.
#[test]
fn fly_then_scatter_is_the_step() {
    fn compare<B: volpt_core::Bsdf>(scene: &Furnace<B>) -> u32 {
        use volpt_core::Medium;
        let mut collisions = 0;
        for handed_in in [false, true] {
            for sample in 0..128 {
                // The central pixels, whose rays enter the box.
                let (px, py) = (2 + sample % 4, 1 + (sample / 4) % 4);
                let mut whole = PathState::from_camera(scene, px, py, sample, 5);
                let mut split = whole;
                while whole.alive {
                    step(scene, &mut whole);
                    if let Some(p) = fly(scene, &mut split) {
                        let albedo = handed_in.then(|| scene.medium.albedo(p));
                        scatter(scene, &mut split, p, albedo);
                        collisions += 1;
                    }
                    assert_eq!(
                        format!("{whole:?}"),
                        format!("{split:?}"),
                        "sample {sample}"
                    );
                }
                assert!(!split.alive);
            }
        }
        collisions
    }
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        let settings = PathSettings {
            estimator,
            ..PathSettings::default()
        };
        let mut scene = furnace(settings);
        scene.medium.albedo = Spectrum::new(0.9, 0.7, 0.5);
        assert!(compare(&scene) > 300, "{estimator:?}: too few collisions");
        let mut behind = furnace_behind(SmoothDielectric { eta: 1.3 }, settings);
        behind.medium.albedo = Spectrum::new(0.9, 0.7, 0.5);
        assert!(
            compare(&behind) > 300,
            "{estimator:?} behind a dielectric: too few collisions"
        );
    }
}

/// Past `max_segments` free flights a path ends, contributes nothing (even light it had gathered)
/// and is counted as truncated; up to it, it runs.
#[test]
fn a_path_past_max_segments_is_dropped() {
    let scene = furnace(PathSettings {
        max_segments: 2,
        ..PathSettings::default()
    });
    for sample in 0..20 {
        let mut path = PathState::from_camera(&scene, 4, 3, sample, 1);
        assert!(!path.inside && path.alive);
        step(&scene, &mut path);
        assert!(path.alive && path.inside, "the first flight enters the box");
        // The second flight ends at a collision or at the far face, and the path goes on either way.
        step(&scene, &mut path);
        assert!(
            path.alive,
            "sample {sample}: the second flight is within the bound"
        );
        assert_eq!(path.truncated, Truncation::None);
        path.radiance = Spectrum::ONE;
        step(&scene, &mut path);
        assert!(
            !path.alive,
            "sample {sample}: the third flight is past the bound"
        );
        assert_eq!(path.segments, 3);
        assert_eq!(path.truncated, Truncation::Segments);
        assert_eq!(
            path.radiance,
            Spectrum::ZERO,
            "a truncated path contributes nothing"
        );
    }
}

/// `max_tracking_steps` cuts a path that would track for too long, and it contributes nothing.
#[test]
fn a_path_out_of_tracking_steps_is_dropped() {
    // From the centre of a box 1e4 mean free paths across, without absorption or roulette: a
    // random walk far longer than 50 flights.
    let mut scene = furnace(PathSettings {
        max_tracking_steps: 50,
        rr_depth: PathSettings::UNLIMITED,
        ..PathSettings::default()
    });
    scene.medium.sigma_t = 1e4;
    scene.camera.origin = Vec3::ZERO;
    let mut path = PathState::from_camera(&scene, 4, 3, 0, 1);
    path.radiance = Spectrum::ONE;
    trace(&scene, &mut path);
    assert_eq!(path.truncated, Truncation::TrackingSteps);
    assert_eq!(path.tracking_steps, 50);
    assert_eq!(path.radiance, Spectrum::ZERO);
    assert!(!path.alive);
}

/// Every pixel and sample gets a stream of its own: no two `(pixel, sample)` of a film start
/// with the same random numbers (shared streams make neighbouring pixels' noise identical).
#[test]
fn every_pixel_and_sample_has_its_own_stream() {
    let scene = furnace(PathSettings::default());
    let cam = scene.camera;
    let mut firsts = Vec::new();
    for py in 0..cam.height {
        for px in 0..cam.width {
            for sample in 0..4 {
                let mut path = PathState::from_camera(&scene, px, py, sample, 3);
                assert_eq!(
                    path.rng.dimension(),
                    2,
                    "the film position takes two numbers"
                );
                firsts.push((path.rng.next_u64(), (px, py, sample)));
            }
        }
    }
    firsts.sort();
    for pair in firsts.windows(2) {
        assert_ne!(
            pair[0].0, pair[1].0,
            "{:?} and {:?} share a stream",
            pair[0].1, pair[1].1
        );
    }
}

fn finished(segments: u32, tracking_steps: u32, truncated: Truncation) -> PathState {
    PathState {
        ray: Ray::new(Vec3::ZERO, Vec3::Z),
        throughput: Spectrum::ONE,
        radiance: Spectrum::ZERO,
        rng: Rng::new(0, 0, 0),
        depth: 0,
        eta_scale: 1.0,
        segments,
        tracking_steps,
        inside: false,
        alive: false,
        truncated,
        mis_pdf: 0.0,
        spectral: (),
    }
}

#[test]
fn counters_record_and_merge_every_path() {
    let mut a = PathCounters::default();
    a.record(&finished(3, 40, Truncation::None));
    a.record(&finished(5, 7, Truncation::Segments));
    let mut b = PathCounters::default();
    b.record(&finished(2, 1000, Truncation::TrackingSteps));
    let expected_a = PathCounters {
        paths: 2,
        segments: 8,
        tracking_steps: 47,
        truncated: 1,
        truncated_tracking: 0,
    };
    let expected_b = PathCounters {
        paths: 1,
        segments: 2,
        tracking_steps: 1000,
        truncated: 1,
        truncated_tracking: 1,
    };
    assert_eq!(a, expected_a);
    assert_eq!(b, expected_b);
    let total = PathCounters {
        paths: 3,
        segments: 10,
        tracking_steps: 1047,
        truncated: 2,
        truncated_tracking: 1,
    };
    assert_eq!(a.merge(b), total);
    assert_eq!(b.merge(a), total);
}
