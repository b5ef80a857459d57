//! Next-event estimation under a uniform environment (`path::next_flight_in_uniform_light`): path
//! tracing plus a zero-mean control variate, each flight's absorption counted by its expected value.
//! It is exact in a white furnace, path by path, and otherwise gives the same image as path tracing
//! (per pixel, and over the image within a test that sees a 1% bias), with an albedo grid (the
//! absorption then varies along a flight) and a forward phase function, behind an index-matched
//! boundary, with roulette and with a depth limit.

use volpt_core::{Estimator, PathSettings, Rng};
use volpt_scene::description::*;
use volpt_tests::{cube_scene, homogeneous, pixel_statistics_with};

fn settings(estimator: Estimator) -> PathSettings {
    PathSettings {
        majorant_resolution: 8,
        estimator,
        ..PathSettings::default()
    }
}

fn unit_cube_grid(res: [u32; 3], channels: u32, data: Vec<f32>) -> GridDesc {
    GridDesc {
        resolution: res,
        channels,
        bounds: Bounds {
            min: [-0.5; 3],
            max: [0.5; 3],
        },
        convention: GridConvention::Cell,
        data,
    }
}

/// A smoke-like density: random values in [0, 1], a third of the cells empty, scaled by `scale`.
fn smoke_like(rng: &mut Rng, scale: f32, albedo: AlbedoDesc, phase: PhaseDesc) -> MediumDesc {
    let res = [7, 6, 5];
    let data = (0..7 * 6 * 5)
        .map(|_| {
            let v = rng.next_f32();
            if v < 0.33 {
                0.0
            } else {
                v
            }
        })
        .collect();
    MediumDesc {
        density: DensityDesc::Grid(unit_cube_grid(res, 1, data)),
        scale,
        albedo,
        ..homogeneous(1.0, 1.0, phase)
    }
}

/// Albedo 1 under a uniform environment: every path returns the environment's radiance exactly
/// (the control variate cancels path tracing's noise completely), so every pixel has the radiance
/// and no variance. Path tracing, by comparison, is exact too; the earlier NEE (a shadow ray per
/// event weighted by MIS) was not.
#[test]
fn white_furnace_is_exact_path_by_path() {
    let mut rng = Rng::new(11, 0, 0);
    for phase in [PhaseDesc::Isotropic, PhaseDesc::HenyeyGreenstein { g: 0.7 }] {
        let medium = smoke_like(&mut rng, 30.0, AlbedoDesc::Constant([1.0; 3]), phase);
        let desc = cube_scene(16, 16, medium, BsdfDesc::Null, 0.8);
        // Roulette would end some paths early, with zero: not a furnace's exact answer.
        let no_roulette = PathSettings {
            rr_depth: PathSettings::UNLIMITED,
            ..settings(Estimator::NextEvent)
        };
        let stats = pixel_statistics_with(&desc, 16, 3, no_roulette);
        for (i, px) in stats.iter().enumerate() {
            for &(mean, var) in px {
                assert!(
                    (mean - 0.8).abs() < 1e-4 && var < 1e-9,
                    "{phase:?}: pixel {i} mean {mean}, variance of the mean {var}"
                );
            }
        }
    }
}

/// The mean of all pixel channels and the variance of that mean.
fn image_mean(stats: &[[(f64, f64); 3]]) -> (f64, f64) {
    let n = (stats.len() * 3) as f64;
    let mean = stats.iter().flatten().map(|(m, _)| m).sum::<f64>() / n;
    let var = stats.iter().flatten().map(|(_, v)| v).sum::<f64>() / (n * n);
    (mean, var)
}

/// NEE and path tracing agree on a smoke-like grid with a coloured albedo grid, isotropic and
/// forward scattering, without and with roulette and a depth limit: the image means within 5
/// standard errors (which are below 1% of the mean), at most 0.3% of the pixel channels beyond 6.
/// NEE's variance is also below path tracing's over the image (what it is for).
#[test]
fn nee_matches_path_tracing_with_an_albedo_grid() {
    let mut rng = Rng::new(12, 0, 0);
    let albedo_res = [4, 5, 3];
    let albedo_data: Vec<f32> = (0..4 * 5 * 3 * 3)
        .map(|_| 0.5 + 0.5 * rng.next_f32())
        .collect();
    let albedo = AlbedoDesc::Grid(unit_cube_grid(albedo_res, 3, albedo_data));
    let cases = [
        (PhaseDesc::Isotropic, None, None),
        (PhaseDesc::HenyeyGreenstein { g: 0.6 }, Some(2), Some(12)),
    ];
    for (phase, rr_depth, max_depth) in cases {
        let medium = smoke_like(&mut rng, 12.0, albedo.clone(), phase);
        let mut desc = cube_scene(16, 16, medium, BsdfDesc::Null, 1.0);
        desc.integrator = IntegratorDesc {
            max_depth,
            rr_depth,
        };
        let with = |estimator| PathSettings {
            max_depth: max_depth.unwrap_or(PathSettings::UNLIMITED),
            rr_depth: rr_depth.unwrap_or(PathSettings::UNLIMITED),
            ..settings(estimator)
        };
        let pt = pixel_statistics_with(&desc, 512, 1, with(Estimator::PathTracing));
        let nee = pixel_statistics_with(&desc, 512, 2, with(Estimator::NextEvent));
        let (mean_pt, var_pt) = image_mean(&pt);
        let (mean_nee, var_nee) = image_mean(&nee);
        let se = (var_pt + var_nee).sqrt();
        eprintln!(
            "{phase:?}: pt {mean_pt:.5} (variance {var_pt:.3e}), nee {mean_nee:.5} (variance \
             {var_nee:.3e}), difference {:.2} standard errors",
            (mean_pt - mean_nee) / se
        );
        assert!(5.0 * se < 0.01 * mean_pt, "{phase:?}: standard error {se}");
        assert!(
            (mean_pt - mean_nee).abs() < 5.0 * se,
            "{phase:?}: pt {mean_pt} vs nee {mean_nee} (standard error {se})"
        );
        assert!(
            var_nee < var_pt,
            "{phase:?}: nee's variance {var_nee} not below path tracing's {var_pt}"
        );
        let outliers = pt
            .iter()
            .flatten()
            .zip(nee.iter().flatten())
            .filter(|((ma, va), (mb, vb))| (ma - mb).abs() > 6.0 * (va + vb).sqrt() && va + vb > 0.0)
            .count();
        assert!(
            outliers <= pt.len() * 3 / 1000,
            "{phase:?}: {outliers} pixel channels differ by more than 6 standard errors"
        );
    }
}
