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
    Aabb, ConstantEnvironment, HenyeyGreenstein, HomogeneousMedium, PathSettings, PathState,
    PerspectiveCamera, RoughDielectric, Spectrum, Vec2, Vec3, VolumeScene,
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
