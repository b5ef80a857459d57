//! The user's medium renders what its analytic optical depth says: with albedo 0, every camera ray
//! sees the environment times `exp(-tau)`, and `tau` of the smooth ball has a closed form.

use volpt_core::path::PathState;
use volpt_core::{
    Aabb, ConstantEnvironment, Isotropic, NullBoundary, PathSettings, PerspectiveCamera, Ray,
    Scene, Spectrum, Vec2, Vec3, VolumeScene,
};
use volpt_example_smooth_ball::SmoothBall;
use volpt_film::RenderOptions;

#[test]
fn an_absorbing_ball_transmits_its_analytic_transmittance() {
    let scene = VolumeScene {
        camera: PerspectiveCamera {
            origin: Vec3::new(0.3, 0.2, 3.0),
            axis_x: Vec3::new(-1.0, 0.0, 0.0),
            axis_y: Vec3::Y,
            axis_z: Vec3::new(0.0, 0.0, -1.0),
            tan_half_fov: Vec2::splat(0.2),
            width: 16,
            height: 16,
            orthographic: false,
        },
        bounds: Aabb::new(Vec3::splat(-0.5), Vec3::splat(0.5)),
        medium: SmoothBall {
            centre: Vec3::new(0.05, 0.0, 0.0),
            radius: 0.45,
            sigma_max: 4.0,
            albedo: Spectrum::ZERO,
        },
        boundary: NullBoundary,
        phase: Isotropic,
        environment: ConstantEnvironment(Spectrum::ONE),
        lights: volpt_core::Lights::NONE,
        settings: PathSettings::default(),
    };
    let (spp, seed) = (400, 3);
    let options = RenderOptions {
        spp,
        seed,
        threads: None,
    };
    let (image, _) = volpt_render::render(&scene, &options, &|_, _| {}).expect("render");
    let mut inside = 0;
    for y in 0..16 {
        for x in 0..16 {
            // The expected value of this pixel's estimator: the mean transmittance of its own rays.
            let mean: f64 = (0..spp)
                .map(|sample| {
                    let ray = PathState::from_camera(&scene, x, y, sample, seed).ray;
                    transmittance(&scene.medium, scene.bounds(), ray)
                })
                .sum::<f64>()
                / spp as f64;
            // Each sample is 0 or 1: a binomial estimator.
            let sigma = (mean * (1.0 - mean) / spp as f64).sqrt();
            let got = image.pixel(x, y)[0] as f64;
            assert!(
                (got - mean).abs() <= 5.0 * sigma + 1e-6,
                "pixel ({x}, {y}): {got} vs {mean} +- {sigma}"
            );
            inside += (mean < 0.99) as u32;
        }
    }
    assert!(inside > 64, "the ball covers a good part of the image");
}

fn transmittance(ball: &SmoothBall, bounds: Aabb, ray: Ray) -> f64 {
    match bounds.entry(&ray) {
        None => 1.0,
        Some(hit) => {
            let inner = Ray::new(hit.point, ray.dir);
            let exit = bounds.exit(&inner);
            (-ball.optical_depth(inner.origin, inner.dir, 0.0, exit.t)).exp()
        }
    }
}
