//! The path step behind a rough dielectric, on a scene built by hand: the boundary's weight
//! multiplies the throughput. A smooth dielectric's weight is exactly 1 on reflection and cancels
//! between entering (`1 / eta^2`) and leaving (`eta^2`), so `path.rs`'s furnace behind one cannot
//! tell multiplying from dividing (mutation testing, shard 2/8: `throughput /= weight` in
//! `interact_with_boundary` passed every test volpt-core has and every whole-renderer test but
//! `analytic.rs`'s rough furnace, which no mutation stage runs).

mod common;

use common::{Moments, Z_MAX};
use volpt_core::microfacet::Ggx;
use volpt_core::path::{trace, Truncation};
use volpt_core::{
    Aabb, ConstantEnvironment, Environment, Estimator, HenyeyGreenstein, HomogeneousMedium,
    LatLongEnvironment, LatLongRows, PathSettings, PathState, PerspectiveCamera, RoughDielectric,
    Spectrum, Vec2, Vec3, VolumeScene,
};

const LIGHT: f32 = 2.0;

/// A white furnace (albedo 1, optical depth 3 across the box) behind a rough dielectric, seen by a
/// camera whose film the box fills but for its corners; roulette off, so that every path's
/// throughput on escape is exactly the product of the boundary's weights.
fn rough_furnace(
) -> VolumeScene<HomogeneousMedium, RoughDielectric, HenyeyGreenstein, ConstantEnvironment> {
    VolumeScene {
        camera: PerspectiveCamera {
            origin: Vec3::new(0.0, 0.0, -4.0),
            axis_x: Vec3::new(-1.0, 0.0, 0.0),
            axis_y: Vec3::Y,
            axis_z: Vec3::Z,
            tan_half_fov: Vec2::new(0.6, 0.45),
            width: 8,
            height: 6,
            orthographic: false,
        },
        bounds: Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0)),
        medium: HomogeneousMedium {
            sigma_t: 1.5,
            albedo: Spectrum::ONE,
        },
        boundary: RoughDielectric {
            eta: 1.5,
            distribution: Ggx { alpha: 0.6 },
        },
        phase: HenyeyGreenstein { g: 0.6 },
        environment: ConstantEnvironment(Spectrum::splat(LIGHT)),
        lights: volpt_core::Lights::NONE,
        settings: PathSettings {
            rr_depth: PathSettings::UNLIMITED,
            ..PathSettings::default()
        },
    }
}

/// Each interaction with the boundary weighs the path by the masking `G1 <= 1` of its outgoing
/// direction (times `1 / eta^2` entering and `eta^2` leaving, which cancel on the way out), so no
/// path returns more than the light, and the paths together lose some of it (the single-scattering
/// loss of a rough interface): the mean lies below the light by many standard errors.
#[test]
fn behind_a_rough_dielectric_no_path_returns_more_than_the_light() {
    let scene = rough_furnace();
    let mut moments = Moments::default();
    let mut crossed = 0;
    for py in 0..scene.camera.height {
        for px in 0..scene.camera.width {
            for sample in 0..50 {
                let mut path = PathState::from_camera(&scene, px, py, sample, 5);
                trace(&scene, &mut path);
                assert_eq!(path.truncated, Truncation::None);
                let radiance = path.radiance.x;
                // Plus the f32 rounding of a product of tens of weights.
                assert!(
                    (0.0..=LIGHT * (1.0 + 1e-5)).contains(&radiance),
                    "pixel ({px}, {py}), sample {sample}: radiance {radiance} after {} interactions",
                    path.depth
                );
                crossed += (path.depth >= 2) as u32;
                moments.push(radiance as f64);
            }
        }
    }
    assert!(crossed > 500, "only {crossed} paths met the boundary twice");
    let (mean, se) = (moments.mean(), moments.std_error());
    assert!(
        mean < LIGHT as f64 - Z_MAX * se,
        "no light lost at a rough interface: mean {mean} +- {se}"
    );
}

/// A 16 x 8 lat-long sky of radiance 0.5 with a sun of radiance 8-12 in one texel, 45 degrees above
/// the horizon (row 2 of 8, pole to pole) and off to one side of the camera's view.
fn sunlit_sky() -> Vec<f32> {
    let (w, h) = (16, 8);
    let mut rgb = vec![0.5f32; 3 * w * h];
    let sun = 3 * (2 * w + 5);
    rgb[sun..sun + 3].copy_from_slice(&[12.0, 10.0, 8.0]);
    rgb
}

/// The furnace box (rough dielectric, alpha 0.2) with an amber medium of albedo < 1 under the sunlit
/// sky; roulette from the fifth interaction.
fn sunlit<'a>(
    sky: LatLongEnvironment<'a>,
    estimator: Estimator,
) -> VolumeScene<HomogeneousMedium, RoughDielectric, HenyeyGreenstein, LatLongEnvironment<'a>> {
    let furnace = rough_furnace();
    VolumeScene {
        medium: HomogeneousMedium {
            sigma_t: 1.5,
            albedo: Spectrum::new(0.95, 0.8, 0.5),
        },
        boundary: RoughDielectric {
            eta: 1.5,
            distribution: Ggx { alpha: 0.2 },
        },
        environment: sky,
        lights: volpt_core::Lights::NONE,
        settings: PathSettings {
            rr_depth: 5,
            estimator,
            ..PathSettings::default()
        },
        camera: furnace.camera,
        bounds: furnace.bounds,
        phase: furnace.phase,
    }
}

/// Per channel: the mean and standard error of every path's radiance over the film, and whether
/// some path gathered light at an interaction with the boundary (it did if its radiance grew in a
/// step that did not escape).
fn film_moments<E: Environment>(
    scene: &VolumeScene<HomogeneousMedium, RoughDielectric, HenyeyGreenstein, E>,
    spp: u32,
    seed: u32,
) -> ([Moments; 3], bool) {
    let mut moments: [Moments; 3] = Default::default();
    let mut gathered_at_boundary = false;
    for py in 0..scene.camera.height {
        for px in 0..scene.camera.width {
            for sample in 0..spp {
                let mut path = PathState::from_camera(scene, px, py, sample, seed);
                while path.alive {
                    let before = path.radiance;
                    volpt_core::path::step(scene, &mut path);
                    gathered_at_boundary |= path.alive && path.radiance != before;
                }
                assert_eq!(path.truncated, Truncation::None);
                for (m, r) in moments.iter_mut().zip(path.radiance.to_array()) {
                    assert!(r >= 0.0 && r.is_finite(), "radiance {r}");
                    m.push(r as f64);
                }
            }
        }
    }
    (moments, gathered_at_boundary)
}

/// Next-event estimation at a rough boundary (the environment sampled where a path meets the
/// boundary, MIS against the BSDF's sample) has the expectation of path tracing, on a sky with a
/// sun that path tracing finds rarely: the film's means agree within 5 standard errors per channel
/// (independent seeds), where 5 standard errors are below 1% of the mean. It gathers light at the
/// boundary and path tracing does not; and it is the less noisy of the two.
#[test]
fn next_event_at_a_rough_boundary_has_the_expectation_of_path_tracing() {
    let rgb = sunlit_sky();
    let mut sky = LatLongEnvironment::new(
        &rgb,
        16,
        8,
        LatLongRows::PoleToPole,
        [Vec3::X, Vec3::Y, Vec3::Z],
        1.0,
    );
    let mut distribution = vec![0.0; LatLongEnvironment::distribution_len(16, 8)];
    sky.fill_distribution(&mut distribution);
    sky.distribution = &distribution;
    // The sun lights the box: a direction towards it from the box's centre.
    let (pt, pt_gathered) = film_moments(&sunlit(sky, Estimator::PathTracing), 16000, 1);
    let (nee, nee_gathered) = film_moments(&sunlit(sky, Estimator::NextEvent), 8000, 2);
    assert!(
        !pt_gathered,
        "path tracing gathered light before a path escaped"
    );
    assert!(
        nee_gathered,
        "next-event estimation never gathered light at the boundary"
    );
    for c in 0..3 {
        let (a, b) = (&pt[c], &nee[c]);
        let se = (a.std_error().powi(2) + b.std_error().powi(2)).sqrt();
        let z = (a.mean() - b.mean()) / se;
        eprintln!(
            "channel {c}: pt {} +- {}, nee {} +- {} (z {z:.2}); variance per path pt {}, nee {}",
            a.mean(),
            a.std_error(),
            b.mean(),
            b.std_error(),
            a.variance(),
            b.variance()
        );
        assert!(
            5.0 * se < 0.01 * a.mean(),
            "channel {c}: too noisy to see a 1% bias"
        );
        assert!(
            z.abs() < Z_MAX,
            "channel {c}: pt {} vs nee {} (z {z})",
            a.mean(),
            b.mean()
        );
        assert!(
            b.variance() < a.variance(),
            "channel {c}: nee is the noisier"
        );
    }
}
