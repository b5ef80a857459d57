//! Hard cases stay numerically stable (issue 11, part 3; `docs/stability.md` lists every case).
//!
//! Each case renders (or traces) a scene at a limit of its parameters and asserts that no pixel is
//! NaN or infinite, that the work is bounded (paths cut by a safety bound are counted, never a
//! hang), that a white furnace returns exactly its light where one applies, and the analytic value
//! where there is one: Beer-Lambert transmittance through absorbers, which the renderer must match
//! per pixel within its binomial noise.

use volpt_core::path::{trace, PathState};
use volpt_core::{PathSettings, Ray, Vec3};
use volpt_render::{with_scene, Image, RenderStats, SceneVisitor};
use volpt_scene::description::*;
use volpt_scene::numerics::{check_position_resolution, MIN_FREE_PATH_SPACINGS};
use volpt_scene::{Config, SceneAssembler, SceneBuilder, SceneError};
use volpt_tests::{assert_matches_transmittance, cube_scene, homogeneous, look_at, render_with};

/// Path tracing, whose furnaces are exact per path; NEE's furnaces hold in expectation
/// (heterogeneous.rs).
fn settings(desc: &SceneDescription) -> PathSettings {
    PathSettings {
        estimator: volpt_core::Estimator::PathTracing,
        ..volpt_render::path_settings(desc)
    }
}

fn render(desc: &SceneDescription, spp: u32, seed: u32) -> (Image, RenderStats) {
    render_with(desc, spp, seed, settings(desc))
}

fn assert_finite(image: &Image, case: &str) {
    for (i, px) in image.pixels.iter().enumerate() {
        assert!(
            px.iter().all(|c| c.is_finite() && *c >= 0.0),
            "{case}: pixel {i} is {px:?}"
        );
    }
}

/// A white furnace (albedo 1, index-matched or smooth boundary): every path escapes with its
/// throughput intact, so every pixel is the environment's radiance.
fn assert_furnace(desc: &SceneDescription, spp: u32, tolerance: f32, case: &str) -> RenderStats {
    let (image, stats) = render(desc, spp, 1);
    assert_finite(&image, case);
    assert_eq!(stats.counters.truncated, 0, "{case}: truncated paths");
    let EnvironmentDesc::Constant([env, ..]) = desc.environment else {
        unreachable!("furnaces use a constant environment")
    };
    for (i, px) in image.pixels.iter().enumerate() {
        for c in px {
            assert!(
                (c - env).abs() <= tolerance,
                "{case}: pixel {i} is {c} in a furnace of {env}"
            );
        }
    }
    stats
}

/// Renders an absorber and checks it against Beer-Lambert per pixel.
fn assert_absorber(desc: &SceneDescription, spp: u32, seed: u32, case: &str) -> RenderStats {
    let (image, stats) = render(desc, spp, seed);
    assert_finite(&image, case);
    assert_eq!(stats.counters.truncated, 0, "{case}: truncated paths");
    let EnvironmentDesc::Constant([env, ..]) = desc.environment else {
        unreachable!("absorbers use a constant environment")
    };
    assert_matches_transmittance(desc, &image, env, spp, seed);
    stats
}

fn with_albedo(mut desc: SceneDescription, albedo: f32) -> SceneDescription {
    desc.medium.albedo = AlbedoDesc::Constant([albedo; 3]);
    desc
}

fn unit_bounds() -> Bounds {
    Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    }
}

fn grid(resolution: [u32; 3], data: Vec<f32>) -> GridDesc {
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution,
        channels: 1,
        bounds: unit_bounds(),
        convention: GridConvention::Cell,
        data,
    }
}

fn grid_medium(grid: GridDesc, albedo: f32) -> MediumDesc {
    MediumDesc {
        density: DensityDesc::Grid(grid),
        scale: 1.0,
        albedo: AlbedoDesc::Constant([albedo; 3]),
        phase: PhaseDesc::Isotropic,
        lookup: Default::default(),
        storage: Default::default(),
    }
}

#[test]
fn henyey_greenstein_at_its_limits_conserves_energy() {
    for g in [-0.999999, -1e-7, 0.0, 1e-7, 0.999999] {
        let desc = cube_scene(
            8,
            8,
            homogeneous(20.0, 1.0, PhaseDesc::HenyeyGreenstein { g }),
            BsdfDesc::Null,
            0.8,
        );
        assert_furnace(&desc, 8, 1e-6, &format!("HG g = {g}"));
        let smooth = cube_scene(
            8,
            8,
            homogeneous(20.0, 1.0, PhaseDesc::HenyeyGreenstein { g }),
            BsdfDesc::Dielectric {
                int_ior: 1.33,
                ext_ior: 1.0,
            },
            0.8,
        );
        assert_furnace(&smooth, 4, 1e-4, &format!("HG g = {g}, smooth boundary"));
    }
}

#[test]
fn density_zero_and_tiny_transmit_everything() {
    let env = 0.7;
    let zero = cube_scene(
        8,
        8,
        homogeneous(0.0, 0.5, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        env,
    );
    let stats = assert_furnace(&zero, 4, 0.0, "density 0");
    assert_eq!(stats.counters.tracking_steps, 0);
    let zero_grid = cube_scene(
        8,
        8,
        grid_medium(grid([4, 4, 4], vec![0.0; 64]), 0.5),
        BsdfDesc::Null,
        env,
    );
    assert_furnace(&zero_grid, 4, 0.0, "grid of zeros");
    let tiny = cube_scene(
        8,
        8,
        homogeneous(1e-8, 0.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        env,
    );
    assert_absorber(&tiny, 16, 2, "density 1e-8");
}

#[test]
fn dense_absorber_is_black_where_rays_cross_it() {
    let desc = cube_scene(
        8,
        8,
        homogeneous(1e6, 0.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    assert_absorber(&desc, 16, 3, "density 1e6");
}

/// A grid with empty holes: every other voxel of a 6^3 grid is zero.
fn holes() -> GridDesc {
    let data = (0..216)
        .map(|i| {
            let (x, y, z) = (i % 6, (i / 6) % 6, i / 36);
            if (x + y + z) % 2 == 0 {
                0.0
            } else {
                4.0
            }
        })
        .collect();
    grid([6, 6, 6], data)
}

/// A 5^3 grid, empty but for its centre voxel.
fn one_dense_voxel(density: f32) -> GridDesc {
    let mut data = vec![0.0; 125];
    data[62] = density;
    grid([5, 5, 5], data)
}

#[test]
fn grids_with_holes_and_a_lone_dense_voxel() {
    let absorber = |g| cube_scene(8, 8, grid_medium(g, 0.0), BsdfDesc::Null, 1.0);
    let furnace = |g| cube_scene(8, 8, grid_medium(g, 1.0), BsdfDesc::Null, 1.0);
    assert_absorber(&absorber(holes()), 16, 4, "zero-density holes");
    assert_furnace(&furnace(holes()), 4, 1e-6, "zero-density holes");
    // 1e6 in one voxel: ~1e6 tentative collisions per crossing of the box, far below the budget.
    let stats = assert_absorber(&absorber(one_dense_voxel(1e6)), 2, 5, "one voxel of 1e6");
    assert!(stats.counters.tracking_steps > 1_000_000);
    assert_furnace(&furnace(one_dense_voxel(1e3)), 2, 1e-6, "one voxel of 1e3");
}

/// Albedo 1 inside a smooth dielectric that traps light by total internal reflection: without
/// roulette or a depth limit a path scatters up to ~(sigma_t L)^2 times (the escape times of a
/// random walk are heavy-tailed); the free-flight bound (here 100) cuts the longest, counts them, and the image is dark but finite. With roulette from the first
/// interaction the furnace is unbiased and no path is cut.
#[test]
fn albedo_one_work_is_bounded_with_and_without_roulette() {
    let mut desc = cube_scene(
        8,
        8,
        homogeneous(200.0, 1.0, PhaseDesc::Isotropic),
        BsdfDesc::Dielectric {
            int_ior: 1.5,
            ext_ior: 1.0,
        },
        1.0,
    );
    let bounded = PathSettings {
        max_segments: 100,
        ..settings(&desc)
    };
    let (image, stats) = render_with(&desc, 4, 6, bounded);
    assert_finite(&image, "albedo 1, no roulette");
    let c = stats.counters;
    assert!(c.truncated > 0, "no path reached the free-flight bound");
    assert_eq!(c.truncated_tracking, 0);
    assert!(c.segments <= c.paths * 100);
    assert!(image.pixels.iter().all(|p| p[0] <= 1.0 + 1e-4));

    desc.integrator.rr_depth = Some(1);
    let (image, stats) = render(&desc, 16, 7);
    assert_finite(&image, "albedo 1, roulette");
    assert_eq!(stats.counters.truncated, 0);
    let (mean, se) = mean_and_standard_error(&image);
    assert!(
        (mean - 1.0).abs() < 5.0 * se,
        "roulette furnace {mean} +- {se}"
    );
}

fn mean_and_standard_error(image: &Image) -> (f64, f64) {
    let values: Vec<f64> = image.pixels.iter().map(|p| p[0] as f64).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn rough(alpha: f32, int_ior: f32, ext_ior: f32) -> BsdfDesc {
    BsdfDesc::RoughDielectric {
        alpha,
        int_ior,
        ext_ior,
    }
}

/// The rough furnace loses the energy of single-scattering microfacets (never creates any): exact
/// as alpha -> 0, a loss at alpha 1.
fn rough_furnace(bsdf: BsdfDesc, case: &str) -> (f64, f64) {
    let desc = cube_scene(
        16,
        16,
        homogeneous(10.0, 1.0, PhaseDesc::Isotropic),
        bsdf,
        1.0,
    );
    let (image, stats) = render(&desc, 16, 8);
    assert_finite(&image, case);
    assert_eq!(stats.counters.truncated, 0, "{case}");
    let (mean, se) = mean_and_standard_error(&image);
    assert!(
        mean <= 1.0 + 4.0 * se,
        "{case} created energy: {mean} +- {se}"
    );
    (mean, se)
}

#[test]
fn ggx_roughness_at_its_limits() {
    let (mean, se) = rough_furnace(rough(1e-6, 1.05, 1.01), "alpha 1e-6");
    assert!(
        (mean - 1.0).abs() <= 4.0 * se + 1e-4,
        "alpha 1e-6: {mean} +- {se}"
    );
    let (mean, se) = rough_furnace(rough(1.0, 1.05, 1.01), "alpha 1");
    assert!(mean > 0.5, "alpha 1 lost too much: {mean} +- {se}");
}

#[test]
fn index_of_refraction_one_and_next_to_one() {
    for int_ior in [1.0, 1.0 + 1e-7] {
        let smooth = BsdfDesc::Dielectric {
            int_ior,
            ext_ior: 1.0,
        };
        let furnace = cube_scene(
            8,
            8,
            homogeneous(10.0, 1.0, PhaseDesc::Isotropic),
            smooth,
            1.0,
        );
        assert_furnace(&furnace, 4, 1e-4, &format!("smooth IOR {int_ior}"));
        // Nothing reflects or bends: an absorber behind it is Beer-Lambert, as if index-matched.
        let absorber = cube_scene(
            8,
            8,
            homogeneous(2.0, 0.0, PhaseDesc::Isotropic),
            smooth,
            1.0,
        );
        assert_absorber(&absorber, 64, 9, &format!("smooth IOR {int_ior} absorber"));
        let (mean, se) = rough_furnace(rough(0.1, int_ior, 1.0), "rough IOR 1");
        assert!(mean >= 0.98, "rough IOR {int_ior}: {mean} +- {se}");
    }
}

/// Traces `paths` paths along one given ray (each with its own random numbers) and returns the
/// mean radiance and its standard error, checking every path is finite and ends.
struct AlongRay {
    ray: Ray,
    inside: bool,
    paths: u32,
}

impl SceneVisitor for AlongRay {
    type Output = (f64, f64);

    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for s in 0..self.paths {
            let mut path = PathState::from_camera(scene, 0, 0, s, 12);
            path.ray = self.ray;
            path.inside = self.inside;
            trace(scene, &mut path);
            assert!(
                path.radiance.is_finite(),
                "{:?}: {}",
                self.ray,
                path.radiance
            );
            assert!(
                path.segments < 1000,
                "{:?}: {} segments",
                self.ray,
                path.segments
            );
            let v = path.radiance.x as f64;
            sum += v;
            sum2 += v * v;
        }
        let n = self.paths as f64;
        let mean = sum / n;
        (mean, ((sum2 / n - mean * mean).max(0.0) / n).sqrt())
    }
}

/// Rays through edges and corners, in the plane of a face, touching only a corner, and starting on
/// the boundary: an absorber of sigma_t 2 transmits exp(-2 L) along the chord L the closed box
/// cuts from each, and a white furnace returns exactly 1.
#[test]
fn rays_through_edges_corners_faces_and_from_the_boundary() {
    let diagonal = Vec3::ONE.normalize();
    let cases = [
        (
            "along an edge",
            Vec3::new(-2.0, 0.5, 0.5),
            Vec3::X,
            false,
            1.0,
        ),
        (
            "in a face's plane",
            Vec3::new(-2.0, 0.1, 0.5),
            Vec3::X,
            false,
            1.0,
        ),
        (
            "corner to corner",
            Vec3::splat(-1.0),
            diagonal,
            false,
            3f32.sqrt(),
        ),
        (
            "touching one corner",
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, -1.0).normalize(),
            false,
            0.0,
        ),
        (
            "on a face, leaving",
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::X,
            true,
            0.0,
        ),
        (
            "on a face, entering",
            Vec3::new(-0.5, 0.1, 0.2),
            Vec3::X,
            true,
            1.0,
        ),
        (
            "on a corner, entering",
            Vec3::splat(-0.5),
            diagonal,
            true,
            3f32.sqrt(),
        ),
        (
            "on an edge, along it",
            Vec3::new(-0.5, 0.5, 0.5),
            Vec3::X,
            true,
            1.0,
        ),
    ];
    for (case, origin, dir, inside, chord) in cases {
        let along = || AlongRay {
            ray: Ray::new(origin, dir),
            inside,
            paths: 20_000,
        };
        let absorber = cube_scene(
            1,
            1,
            homogeneous(2.0, 0.0, PhaseDesc::Isotropic),
            BsdfDesc::Null,
            1.0,
        );
        let (mean, se) = with_scene(&absorber, settings(&absorber), along());
        let expected = (-2.0 * chord as f64).exp();
        assert!(
            (mean - expected).abs() <= 5.0 * se + 1e-6,
            "{case}: {mean} +- {se}, expected {expected}"
        );
        let furnace = with_albedo(absorber.clone(), 1.0);
        let (mean, _) = with_scene(&furnace, settings(&furnace), along());
        assert_eq!(mean, 1.0, "{case}: furnace");
        let rough_furnace = SceneDescription {
            lights: Default::default(),
            boundary: BoundaryDesc {
                bounds: unit_bounds(),
                bsdf: rough(0.1, 1.05, 1.01),
                mesh: None,
            },
            ..furnace
        };
        let (mean, se) = with_scene(&rough_furnace, settings(&rough_furnace), along());
        // Radiance inside a medium of relative index eta is eta^2 that outside.
        let light = if inside {
            (1.05f64 / 1.01).powi(2)
        } else {
            1.0
        };
        assert!(
            mean <= light * (1.0 + 1e-6) + 5.0 * se,
            "{case}: rough furnace {mean} +- {se}, at most {light}"
        );
    }
}

/// Per pixel, the mean over the camera's own rays of `exp(-sigma_t t_exit)`: a camera inside a
/// homogeneous absorber sees the environment through the chord to the exit face.
struct InsideTransmittance {
    sigma_t: f32,
    spp: u32,
    seed: u32,
}

impl SceneVisitor for InsideTransmittance {
    type Output = Vec<(f64, f64)>;

    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        let camera = scene.camera();
        let mut out = Vec::new();
        for y in 0..camera.height {
            for x in 0..camera.width {
                let (mut m, mut v) = (0.0, 0.0);
                for s in 0..self.spp {
                    let path = PathState::from_camera(scene, x, y, s, self.seed);
                    assert!(path.inside);
                    let t = scene.bounds().exit(&path.ray).t;
                    let tr = (-(self.sigma_t as f64) * t as f64).exp();
                    m += tr;
                    v += tr * (1.0 - tr);
                }
                let n = self.spp as f64;
                out.push((m / n, v / (n * n)));
            }
        }
        out
    }
}

#[test]
fn camera_inside_the_medium() {
    let mut desc = cube_scene(
        8,
        8,
        homogeneous(3.0, 0.0, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    desc.camera.to_world = look_at([0.1, 0.2, 0.3]);
    let (spp, seed) = (64, 13);
    let (image, stats) = render(&desc, spp, seed);
    assert_finite(&image, "camera inside");
    assert_eq!(stats.counters.truncated, 0);
    let expected = with_scene(
        &desc,
        settings(&desc),
        InsideTransmittance {
            sigma_t: 3.0,
            spp,
            seed,
        },
    );
    for (px, (mean, var)) in image.pixels.iter().zip(expected) {
        let bound = 5.0 * var.sqrt() + 1.0 / spp as f64 + 1e-5;
        assert!((px[0] as f64 - mean).abs() <= bound, "{} vs {mean}", px[0]);
    }
    assert_furnace(&with_albedo(desc, 1.0), 4, 1e-6, "camera inside, furnace");
}

#[test]
fn grids_of_one_voxel_and_of_2048_by_1_by_1() {
    let one = grid([1, 1, 1], vec![2.5]);
    let long = grid(
        [2048, 1, 1],
        (0..2048).map(|i| ((i * 7) % 17) as f32 * 0.25).collect(),
    );
    for (case, g) in [("1x1x1", one), ("2048x1x1", long)] {
        let absorber = cube_scene(8, 8, grid_medium(g.clone(), 0.0), BsdfDesc::Null, 1.0);
        assert_absorber(&absorber, 32, 14, case);
        let furnace = cube_scene(8, 8, grid_medium(g, 1.0), BsdfDesc::Null, 1.0);
        assert_furnace(&furnace, 4, 1e-6, case);
    }
}

/// The cube scene moved by `offset` along x, camera and all.
fn moved(mut desc: SceneDescription, offset: f32) -> SceneDescription {
    desc.camera.to_world[0][3] += offset;
    desc.boundary.bounds.min[0] += offset;
    desc.boundary.bounds.max[0] += offset;
    desc
}

/// At world coordinates of 1e5, f32 positions are 0.0078 apart: a unit box of extinction 4 (mean
/// free path 32 spacings) still renders right, an absorber as Beer-Lambert, a scattering medium as
/// it does at the origin; an extinction of 100 there is refused.
#[test]
fn world_coordinates_of_1e5() {
    let absorber = moved(
        cube_scene(
            8,
            8,
            homogeneous(4.0, 0.0, PhaseDesc::Isotropic),
            BsdfDesc::Null,
            1.0,
        ),
        1e5,
    );
    assert!(check_position_resolution(&absorber, "moved".as_ref()).is_ok());
    assert_absorber(&absorber, 32, 15, "at 1e5");
    assert_furnace(
        &with_albedo(absorber.clone(), 1.0),
        4,
        1e-6,
        "at 1e5, furnace",
    );

    let scattering = |offset| {
        moved(
            cube_scene(
                8,
                8,
                homogeneous(4.0, 0.8, PhaseDesc::Isotropic),
                BsdfDesc::Null,
                1.0,
            ),
            offset,
        )
    };
    let (far, _) = render(&scattering(1e5), 256, 16);
    let (near, _) = render(&scattering(0.0), 256, 17);
    let (mf, sf) = mean_and_standard_error(&far);
    let (mn, sn) = mean_and_standard_error(&near);
    assert!(
        (mf - mn).abs() <= 5.0 * (sf * sf + sn * sn).sqrt(),
        "at 1e5 {mf} +- {sf}, at the origin {mn} +- {sn}"
    );

    let dense = moved(
        cube_scene(
            8,
            8,
            homogeneous(100.0, 0.8, PhaseDesc::Isotropic),
            BsdfDesc::Null,
            1.0,
        ),
        1e5,
    );
    assert!(check_position_resolution(&dense, "moved".as_ref()).is_err());
}

fn stability_scene(params: &[(&str, &str)]) -> Result<SceneDescription, SceneError> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/stability/cube.xml");
    let config = Config {
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        ..Config::default()
    };
    SceneAssembler::new(config).assemble(volpt_scene::builder_for(&path)?.as_ref())
}

/// The scene file of the suite (`scenes/stability/cube.xml`, for the GPU script) loads at the
/// origin and at 1e5 (where the loader once took a unit box for a flat one), and refuses 1e8.
#[test]
fn the_stability_scene_file_loads_where_the_suite_renders() {
    let at_origin = stability_scene(&[]).expect("at the origin");
    assert_eq!(at_origin.boundary.bounds, unit_bounds());
    let far = stability_scene(&[
        ("offset", "1e5"),
        ("origin", "100002, 1.5, 2.5"),
        ("target", "1e5, 0, 0"),
        ("sigma_t", "4"),
    ])
    .expect("at 1e5");
    assert_eq!(far.boundary.bounds.min[0], 1e5 - 0.5);
    let message = stability_scene(&[("sigma_t", "1e8")])
        .expect_err("too dense")
        .to_string();
    assert!(
        message.contains("cube.xml") && message.contains("extinction"),
        "{message}"
    );
}

/// A builder that hands the assembler a ready description.
struct Given(SceneDescription);

impl SceneBuilder for Given {
    fn source(&self) -> String {
        "thick.xml".into()
    }
    fn build(&self, _params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        Ok(self.0.clone())
    }
}

fn thick(sigma_t: f32) -> SceneDescription {
    let mut desc = cube_scene(
        8,
        8,
        homogeneous(sigma_t, 0.9, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    // Without roulette a path wanders ~(sigma_t L)^2 steps with a throughput of 0.9^steps.
    desc.integrator.rr_depth = Some(5);
    desc.camera.to_world = look_at([0.0, 0.0, 100.0]);
    desc.camera.fov_degrees = 0.2;
    desc
}

/// A thick albedo-0.9 cube seen face-on reflects the same light at any extinction (the scene is
/// optically semi-infinite, so only the optical depth scale changes): at 1e2 and 1e6 it does; at
/// 1e8 and 1e10, where free flights fall below the spacing of f32 positions and used to give 0.64
/// and 0.82, the scene is refused with an error that names the field and the way out.
#[test]
fn extreme_extinction_renders_right_or_is_refused() {
    let (a, _) = render(&thick(1e2), 256, 18);
    let (b, stats) = render(&thick(1e6), 256, 19);
    assert_eq!(stats.counters.truncated, 0);
    let (ma, sa) = mean_and_standard_error(&a);
    let (mb, sb) = mean_and_standard_error(&b);
    assert!((0.35..0.5).contains(&ma), "thick cube at 1e2: {ma}");
    assert!(
        (ma - mb).abs() <= 5.0 * (sa * sa + sb * sb).sqrt(),
        "1e2: {ma} +- {sa}, 1e6: {mb} +- {sb}"
    );
    let assemble =
        |sigma_t| SceneAssembler::new(Config::default()).assemble(&Given(thick(sigma_t)));
    assert!(assemble(1e2).is_ok());
    assert!(assemble(1e6).is_ok());
    for sigma_t in [1e8, 1e10, f32::INFINITY, f32::NAN] {
        let message = assemble(sigma_t).expect_err("refused").to_string();
        assert!(
            message.contains("thick.xml")
                && message.contains("extinction")
                && message.contains("rescale"),
            "{message}"
        );
    }
    let limit = 1.0 / (MIN_FREE_PATH_SPACINGS * f32::EPSILON * 0.5);
    assert!(assemble(0.9 * limit).is_ok() && assemble(1.1 * limit).is_err());
}

/// A majorant that delta tracking cannot get past (a grid scale overflowing to infinity, a voxel of
/// 1e30 among zeros), reaching the renderer without the loader's checks: every path stops at the
/// tracking-step budget, is counted as cut by it, and the image is finite (the cut paths are
/// black), quickly.
#[test]
fn hopeless_majorants_hit_the_step_budget() {
    // Two different voxels: a one-valued grid would be specialised to a homogeneous medium
    // (`volpt_render::factory::Simplification`), which tracks without the budget's loop.
    let overflowing = MediumDesc {
        scale: 1e38,
        ..grid_medium(grid([2, 1, 1], vec![10.0, 5.0]), 0.9)
    };
    for (case, medium) in [
        ("infinite majorant", overflowing),
        ("one voxel of 1e30", grid_medium(one_dense_voxel(1e30), 0.9)),
    ] {
        let desc = cube_scene(4, 4, medium, BsdfDesc::Null, 1.0);
        let budget = PathSettings {
            max_tracking_steps: 10_000,
            ..settings(&desc)
        };
        let (image, stats) = render_with(&desc, 2, 20, budget);
        assert_finite(&image, case);
        let c = stats.counters;
        assert!(c.truncated_tracking > 0, "{case}: no path hit the budget");
        assert_eq!(c.truncated, c.truncated_tracking, "{case}");
        assert!(c.tracking_steps <= c.paths * 10_000, "{case}");
        assert!(SceneAssembler::new(Config::default())
            .assemble(&Given(desc))
            .is_err());
    }
}
