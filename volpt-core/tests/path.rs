//! The path step on a scene built by hand, without the render factory: the white furnace (every
//! estimator and roulette rule must return exactly 1 on average), the safety bounds, the random
//! streams of pixels and samples, and the path counters. Cheap (well under a second): the
//! whole-renderer tests check the same paths against independent references, but only with
//! `max_depth = 2`, where roulette never runs, and they never reach the safety bounds.

mod common;

use common::{Moments, Z_MAX};
use volpt_core::path::{step, trace, Truncation};
use volpt_core::{
    Aabb, ConstantEnvironment, Estimator, HenyeyGreenstein, HomogeneousMedium, NullBoundary,
    PathCounters, PathSettings, PathState, PerspectiveCamera, Ray, Rng, Roulette, Spectrum, Vec2,
    Vec3, VolumeScene,
};

type Furnace = VolumeScene<HomogeneousMedium, NullBoundary, HenyeyGreenstein, ConstantEnvironment>;

/// A camera 4 units in front of the box `[-1, 1]^3`, looking at it along +z; the box fills the
/// central part of the `8 x 6` film.
fn camera() -> PerspectiveCamera {
    PerspectiveCamera {
        origin: Vec3::new(0.0, 0.0, -4.0),
        axis_x: Vec3::new(-1.0, 0.0, 0.0),
        axis_y: Vec3::Y,
        axis_z: Vec3::Z,
        tan_half_fov: Vec2::new(0.3, 0.225),
        width: 8,
        height: 6,
    }
}

/// A white furnace: albedo 1 inside an index-matched box under a constant environment of radiance
/// 1, so every pixel's value is exactly 1. Optical depth 3 across the box, forward scattering.
fn furnace(settings: PathSettings) -> Furnace {
    VolumeScene {
        camera: camera(),
        bounds: Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0)),
        medium: HomogeneousMedium {
            sigma_t: 1.5,
            albedo: Spectrum::ONE,
        },
        boundary: NullBoundary,
        phase: HenyeyGreenstein { g: 0.6 },
        environment: ConstantEnvironment(Spectrum::ONE),
        settings,
    }
}

/// Every `(estimator, roulette)` with roulette from the first interaction on: path tracing, and
/// next-event estimation whose two strategies are weighted by the power heuristic (the
/// environment's density `1 / 4 pi` against Henyey-Greenstein's, which differ).
#[test]
fn white_furnace_returns_one_with_every_estimator_and_roulette() {
    const SPP: u32 = 600;
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        for roulette in [Roulette::Mitsuba, Roulette::Throughput] {
            let scene = furnace(PathSettings {
                rr_depth: 0,
                estimator,
                roulette,
                ..PathSettings::default()
            });
            let mut moments = Moments::default();
            let mut longest = 0;
            // Pixel (4, 3) looks at the box's centre.
            for (px, py) in [(4, 3), (3, 2), (5, 3)] {
                for sample in 0..SPP {
                    let mut path = PathState::from_camera(&scene, px, py, sample, 7);
                    trace(&scene, &mut path);
                    assert_eq!(path.truncated, Truncation::None);
                    longest = longest.max(path.depth);
                    for value in path.radiance.to_array() {
                        assert_eq!(value, path.radiance.x, "a grey furnace stays grey");
                    }
                    moments.push(path.radiance.x as f64);
                }
            }
            let z = moments.z_score(1.0);
            assert!(
                z.abs() <= Z_MAX,
                "{estimator:?}, {roulette:?}: furnace mean {} +- {} (z = {z:.1})",
                moments.mean(),
                moments.std_error()
            );
            assert!(longest > 3, "paths scattered at most {longest} times");
        }
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
