//! The full renderer against results that cannot be tuned: Beer-Lambert transmittance through pure
//! absorbers, and white furnaces in which a non-absorbing medium must return exactly the light it
//! is bathed in.

use volpt_core::path::{step, trace, PathState};
use volpt_core::{Estimator, PathSettings, Roulette};
use volpt_render::{with_scene, Image, SceneVisitor};
use volpt_scene::description::*;
use volpt_tests::compare::{
    absorber_expectation, assert_matches, coverage, relative_bias, Coverage,
};
use volpt_tests::reference::{rough_dielectric_albedo, RefBox, RefCamera, RefMedium};
use volpt_tests::{cube_scene, homogeneous, render_cpu, render_with};

/// Enough for a 1% bias over the medium's pixels to be 4 standard errors.
const BEER_LAMBERT_SPP: u32 = 4096;

/// Every pixel that sees only the medium or only the background within 5 standard errors (plus
/// the quadrature error) of the independent reference `L * mean(exp(-tau))` over the pixel
/// (`volpt_tests::compare::absorber_expectation`: own camera, box and grid in f64), each channel's
/// sum over the medium's pixels within 5 standard errors, and the transmitted light summed over
/// the medium's pixels (not diluted by background) within 1%.
fn assert_matches_transmittance(desc: &SceneDescription, image: &Image) {
    let camera = RefCamera::new(&desc.camera, &desc.film);
    let cover = coverage(&camera, &RefMedium::new(desc).bounds);
    let expected = absorber_expectation(desc, BEER_LAMBERT_SPP, 1000);
    assert_matches("Beer-Lambert", image, &expected, |i| {
        cover[i] != Coverage::Silhouette
    });
    let in_medium = |i: usize| cover[i] == Coverage::Medium;
    assert!(cover.iter().filter(|&&c| c == Coverage::Medium).count() > 100);
    assert_matches("Beer-Lambert in the medium", image, &expected, in_medium);
    // The test must be able to see a 1% bias: 4 of the summed estimate's standard errors.
    let (mean, variance) = (0..expected.len())
        .filter(|&i| in_medium(i))
        .fold((0.0, 0.0), |(m, v), i| {
            (m + expected[i].mean.x, v + expected[i].variance.x)
        });
    let relative_se = variance.sqrt() / mean;
    assert!(
        relative_se < 0.0025,
        "relative standard error {relative_se}"
    );
    let bias = relative_bias(image, &expected, in_medium);
    assert!(bias.abs() < 0.01, "relative bias {bias} over the medium");
}

#[test]
fn homogeneous_absorber_transmits_beer_lambert() {
    let desc = cube_scene(
        32,
        32,
        homogeneous(2.0, 0.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        0.75,
    );
    let (image, _) = render_cpu(&desc, BEER_LAMBERT_SPP, 7);
    assert_matches_transmittance(&desc, &image);
}

fn wavy_density_grid(convention: GridConvention) -> GridDesc {
    let res = [5u32, 4, 6];
    let mut data = Vec::new();
    for z in 0..res[2] {
        for y in 0..res[1] {
            for x in 0..res[0] {
                data.push(0.2 + ((x * 7 + y * 3 + z * 5) % 11) as f32 * 0.3);
            }
        }
    }
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: res,
        channels: 1,
        bounds: Bounds {
            min: [-0.5; 3],
            max: [0.5; 3],
        },
        convention,
        data,
    }
}

#[test]
fn grid_absorber_transmits_beer_lambert_for_both_grid_conventions() {
    for (seed, convention) in [(3, GridConvention::Vertex), (4, GridConvention::Cell)] {
        let medium = MediumDesc {
            density: DensityDesc::Grid(wavy_density_grid(convention)),
            scale: 1.5,
            albedo: AlbedoDesc::Constant([0.0; 3]),
            phase: PhaseDesc::Isotropic,
            lookup: Default::default(),
            storage: Default::default(),
        };
        let desc = cube_scene(32, 32, medium, BsdfDesc::Null, 1.0);
        assert_eq!(
            volpt_render::Variant::of(&desc).medium,
            volpt_render::factory::MediumKind::GridDensityConstantAlbedoDenseTrilinear
        );
        let (image, _) = render_cpu(&desc, BEER_LAMBERT_SPP, seed);
        assert_matches_transmittance(&desc, &image);
    }
}

#[test]
fn max_depth_one_shows_only_unscattered_light() {
    // A path may see the light after at most max_depth - 1 interactions: with max_depth 1 a
    // non-absorbing medium must look exactly like an absorber.
    let mut desc = cube_scene(
        32,
        32,
        homogeneous(2.0, 1.0, PhaseDesc::HenyeyGreenstein { g: 0.3 }),
        BsdfDesc::Null,
        1.0,
    );
    desc.integrator.max_depth = Some(1);
    let (image, _) = render_cpu(&desc, BEER_LAMBERT_SPP, 11);
    assert_matches_transmittance(&desc, &image);
}

fn assert_furnace(image: &Image, radiance: f32, tolerance: f32) {
    for (i, px) in image.pixels.iter().enumerate() {
        for c in px {
            assert!(
                (c - radiance).abs() <= tolerance,
                "pixel {i}: {c} in a furnace of radiance {radiance}"
            );
        }
    }
}

/// Albedo 1 inside an index-matched boundary: every path-traced path escapes with throughput exactly
/// 1, so every pixel must be exactly the environment's radiance, whatever the density and phase
/// function. (With NEE the MIS weights make single paths differ; its furnace is in heterogeneous.rs.)
#[test]
fn white_furnace_index_matched() {
    for (sigma_t, phase) in [
        (0.5, PhaseDesc::Isotropic),
        (30.0, PhaseDesc::Isotropic),
        (30.0, PhaseDesc::HenyeyGreenstein { g: 0.9 }),
        (30.0, PhaseDesc::HenyeyGreenstein { g: -0.6 }),
    ] {
        let desc = cube_scene(
            16,
            16,
            homogeneous(sigma_t, 1.0, phase),
            BsdfDesc::Null,
            0.8,
        );
        let settings = PathSettings {
            estimator: Estimator::PathTracing,
            ..volpt_render::path_settings(&desc)
        };
        let (image, stats) = render_with(&desc, 16, 1, settings);
        assert_eq!(stats.counters.truncated, 0);
        assert_furnace(&image, 0.8, 1e-6);
    }
}

/// A smooth dielectric only redirects light: refraction scales radiance by `1 / eta^2` going in and
/// `eta^2` coming out, so every escaping path carries exactly the environment's radiance.
#[test]
fn white_furnace_smooth_dielectric() {
    let bsdf = BsdfDesc::Dielectric {
        int_ior: 1.5,
        ext_ior: 1.0,
    };
    let desc = cube_scene(
        16,
        16,
        homogeneous(10.0, 1.0, PhaseDesc::Isotropic),
        bsdf,
        0.8,
    );
    let (image, stats) = render_cpu(&desc, 16, 1);
    assert_eq!(stats.counters.truncated, 0);
    assert_furnace(&image, 0.8, 1e-4);
}

/// `rho(mu)` of the boundary for light arriving from outside or inside, tabulated at `N` cosines,
/// with the difference between two quadrature orders as its error.
struct AlbedoTable {
    from_outside: Vec<(f64, f64)>,
    from_inside: Vec<(f64, f64)>,
}

impl AlbedoTable {
    const N: usize = 1000;

    fn new(alpha: f64, eta: f64) -> Self {
        let table = |eta: f64| {
            (0..Self::N)
                .map(|i| {
                    let mu = (i as f64 + 0.5) / Self::N as f64;
                    let fine = rough_dielectric_albedo(alpha, eta, mu, (64, 64));
                    let coarse = rough_dielectric_albedo(alpha, eta, mu, (32, 32));
                    (fine, (fine - coarse).abs())
                })
                .collect()
        };
        Self {
            from_outside: table(eta),
            from_inside: table(1.0 / eta),
        }
    }

    fn at(&self, inside: bool, mu: f64) -> (f64, f64) {
        let table = if inside {
            &self.from_inside
        } else {
            &self.from_outside
        };
        let x = (mu * Self::N as f64 - 0.5).clamp(0.0, (Self::N - 1) as f64);
        let i = (x.floor() as usize).min(Self::N - 2);
        let f = x - i as f64;
        let (a, b) = (table[i], table[i + 1]);
        (a.0 + (b.0 - a.0) * f, a.1.max(b.1))
    }
}

/// The renderer's furnace paths, stepped one event at a time. At each boundary interaction `k` the
/// energy-normalised weight `w_k` (the throughput's change times `eta^2` on refraction, zero if the
/// path dies there) has conditional mean `rho(mu_k)` given the path so far, so with `W_<k` the
/// product of the earlier weights the path's value obeys, exactly,
/// `E[value] = 1 - E[sum_k W_<k (1 - rho(mu_k))]`: the furnace loses precisely the known
/// single-scattering loss of the microfacet model, accumulated along its own paths. Per path
/// `value - 1 + loss` has mean zero; returns its mean, standard error, the mean value and loss,
/// and the bound on the loss's quadrature error.
struct FurnaceLoss<'a> {
    table: &'a AlbedoTable,
    spp: u32,
}

impl SceneVisitor for FurnaceLoss<'_> {
    type Output = [f64; 5];

    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> [f64; 5] {
        let camera = scene.camera();
        let unit = RefBox::new(&Bounds {
            min: [-0.5; 3],
            max: [0.5; 3],
        });
        let (mut sum, mut sum2, mut values, mut losses, mut quadrature) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let mut n = 0.0;
        for (x, y) in (0..camera.height).flat_map(|y| (0..camera.width).map(move |x| (x, y))) {
            for s in 0..self.spp {
                let mut path = PathState::from_camera(scene, x, y, s, 5);
                let (mut weight, mut loss, mut error) = (1.0f64, 0.0, 0.0);
                while path.alive {
                    let before = path;
                    step(scene, &mut path);
                    let o = before.ray.origin.as_dvec3();
                    let d = before.ray.dir.as_dvec3();
                    let (t_near, t_far) = unit.interval(o, d).unwrap_or((f64::INFINITY, 0.0));
                    let t_boundary = if before.inside { t_far } else { t_near };
                    let at_boundary = path.depth > before.depth
                        && (!path.alive
                            || (path.ray.origin.as_dvec3() - (o + d * t_boundary)).length() < 1e-4);
                    if !at_boundary {
                        continue;
                    }
                    let hit = o + d * t_boundary;
                    let axis = (0..3)
                        .max_by(|&a, &b| hit[a].abs().total_cmp(&hit[b].abs()))
                        .unwrap();
                    let (rho, rho_error) = self.table.at(before.inside, d[axis].abs());
                    loss += weight * (1.0 - rho);
                    error += weight * rho_error;
                    weight *= if path.alive {
                        let eta = (path.eta_scale / before.eta_scale) as f64;
                        (path.throughput.x / before.throughput.x) as f64 * eta * eta
                    } else {
                        0.0
                    };
                }
                let value = path.radiance.x as f64;
                assert!(
                    (value - weight).abs() <= 1e-4 * weight.max(1.0),
                    "value {value}, weights {weight}"
                );
                let z = value - 1.0 + loss;
                sum += z;
                sum2 += z * z;
                values += value;
                losses += loss;
                quadrature += error;
                n += 1.0;
            }
        }
        let mean = sum / n;
        [
            mean,
            ((sum2 / n - mean * mean) / (n - 1.0)).sqrt(),
            values / n,
            losses / n,
            quadrature / n,
        ]
    }
}

fn rough_furnace(alpha: f32) -> [f64; 5] {
    let (int_ior, ext_ior) = (1.05, 1.01);
    let bsdf = BsdfDesc::RoughDielectric {
        alpha,
        int_ior,
        ext_ior,
    };
    let desc = cube_scene(
        32,
        32,
        homogeneous(10.0, 1.0, PhaseDesc::Isotropic),
        bsdf,
        1.0,
    );
    let table = AlbedoTable::new(alpha as f64, (int_ior / ext_ior) as f64);
    with_scene(
        &desc,
        volpt_render::path_settings(&desc),
        FurnaceLoss {
            table: &table,
            spp: 64,
        },
    )
}

/// Walter's microfacet BSDF with Smith masking models single scattering on the microsurface only:
/// light masked after one microfacet bounce is lost (Heitz et al. 2016), so a rough white furnace
/// returns less than the environment by exactly the loss of the model's directional albedo,
/// integrated independently (`reference::rough_dielectric_albedo`) along the furnace's own paths.
/// The window is the estimator's standard error (5 sigma) plus the albedo's quadrature error and
/// f32 rounding; a
/// missing or doubled G1, an extra Fresnel factor or a wrong eta^2 moves the mean by many of them.
#[test]
fn white_furnace_rough_dielectric_loses_exactly_the_single_scattering_loss() {
    for alpha in [1e-3, 0.1, 0.4] {
        let [mean, se, value, loss, quadrature] = rough_furnace(alpha);
        eprintln!(
            "alpha {alpha}: furnace {value:.5}, known loss {loss:.5}, difference {mean:.2e} +- {se:.1e}, quadrature {quadrature:.1e}"
        );
        // f32 throughput over ~100 interactions rounds by a few 1e-6.
        assert!(
            mean.abs() <= 5.0 * se + quadrature + 1e-5,
            "alpha {alpha}: furnace {value} but 1 - loss = {} (difference {mean} +- {se})",
            1.0 - loss
        );
        assert!(
            value <= 1.0 + 5.0 * se,
            "alpha {alpha} created energy: {value}"
        );
    }
}

/// Russian roulette is unbiased: with roulette from the first interaction on, a white furnace's paths
/// carry random weights, but their mean is still the environment's radiance.
struct FurnaceSampleMean {
    paths: u32,
}

impl SceneVisitor for FurnaceSampleMean {
    type Output = (f64, f64, u64);
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        let (mut sum, mut sum2, mut killed) = (0.0, 0.0, 0);
        for s in 0..self.paths {
            let mut path = PathState::from_camera(scene, 8, 8, s, 9);
            trace(scene, &mut path);
            let v = path.radiance.x as f64;
            sum += v;
            sum2 += v * v;
            killed += (v == 0.0) as u64;
        }
        let n = self.paths as f64;
        let mean = sum / n;
        (mean, ((sum2 / n - mean * mean) / n).sqrt(), killed)
    }
}

#[test]
fn russian_roulette_is_unbiased() {
    let desc = cube_scene(
        16,
        16,
        homogeneous(5.0, 0.7, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    // Path tracing, so that a path killed by roulette is one with zero radiance (NEE gathers
    // light before roulette); NEE's unbiasedness is tested in heterogeneous.rs.
    let no_rr = PathSettings {
        rr_depth: PathSettings::UNLIMITED,
        estimator: Estimator::PathTracing,
        ..PathSettings::default()
    };
    let (reference, ref_se, _) = with_scene(&desc, no_rr, FurnaceSampleMean { paths: 200_000 });
    // Both survival rules: any probability in (0, 1] with the throughput divided by it.
    for roulette in [Roulette::Mitsuba, Roulette::Throughput] {
        let rr = PathSettings {
            rr_depth: 1,
            roulette,
            ..no_rr
        };
        let (mean, se, killed) = with_scene(&desc, rr, FurnaceSampleMean { paths: 200_000 });
        assert!(killed > 10_000, "{roulette:?}: roulette never ran");
        let z = (mean - reference) / (se * se + ref_se * ref_se).sqrt();
        assert!(
            z.abs() < 5.0,
            "{roulette:?} roulette {mean} vs none {reference}: z = {z}"
        );
    }
}

/// The thesis's rule never raises a throughput: in an albedo-1 medium (throughput 1 at every
/// bounce) no path is killed and every path returns exactly the environment, where Mitsuba's
/// 0.95 cap kills some paths and multiplies the survivors by 1/0.95 per bounce.
#[test]
fn the_throughput_roulette_leaves_a_white_furnace_exact() {
    // 16x16, so that `FurnaceSampleMean`'s pixel (8, 8) sees the medium.
    let desc = cube_scene(
        16,
        16,
        homogeneous(5.0, 1.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    let settings = |roulette| PathSettings {
        rr_depth: 0,
        estimator: Estimator::PathTracing,
        roulette,
        ..PathSettings::default()
    };
    let (_, se, killed) = with_scene(
        &desc,
        settings(Roulette::Throughput),
        FurnaceSampleMean { paths: 20_000 },
    );
    assert_eq!((killed, se), (0, 0.0));
    let (_, se, killed) = with_scene(
        &desc,
        settings(Roulette::Mitsuba),
        FurnaceSampleMean { paths: 20_000 },
    );
    assert!(
        killed > 0 && se > 0.0,
        "Mitsuba's rule: {killed} killed, se {se}"
    );
}

/// The same behind a smooth dielectric boundary into a denser medium: the radiance's `1/eta^2` at
/// the refraction in is not a loss of throughput (the refraction out restores it), so the
/// thesis's rule kills no path there either and every path returns the environment.
#[test]
fn the_throughput_roulette_kills_no_path_for_entering_a_denser_medium() {
    let desc = cube_scene(
        16,
        16,
        homogeneous(5.0, 1.0, PhaseDesc::Isotropic),
        BsdfDesc::Dielectric {
            int_ior: 1.5,
            ext_ior: 1.0,
        },
        1.0,
    );
    let settings = PathSettings {
        rr_depth: 0,
        estimator: Estimator::PathTracing,
        roulette: Roulette::Throughput,
        ..PathSettings::default()
    };
    let (mean, se, killed) = with_scene(&desc, settings, FurnaceSampleMean { paths: 20_000 });
    assert_eq!(killed, 0, "mean {mean}, se {se}");
    // `1/eta^2` and `eta^2` in f32: exact up to rounding.
    assert!(
        (mean - 1.0).abs() < 1e-5 && se < 1e-6,
        "mean {mean}, se {se}"
    );
}

#[test]
fn same_seed_same_image_and_different_seed_different_image() {
    let desc = cube_scene(
        8,
        8,
        homogeneous(3.0, 0.9, PhaseDesc::HenyeyGreenstein { g: 0.5 }),
        BsdfDesc::RoughDielectric {
            alpha: 0.1,
            int_ior: 1.33,
            ext_ior: 1.0,
        },
        1.0,
    );
    let settings = volpt_render::path_settings(&desc);
    let (a, _) = render_with(&desc, 8, 1, settings);
    let (b, _) = render_with(&desc, 8, 1, settings);
    let (c, _) = render_with(&desc, 8, 2, settings);
    assert_eq!(a, b);
    assert_ne!(a, c);
}
