//! Chromatic extinction on scenes built by hand: the per-channel identity (each channel of a
//! chromatic render equals, in expectation, the grey render made with that channel's coefficients:
//! a test no weight can be tuned to pass), for a homogeneous and a grid medium (with its majorant
//! grid and an albedo grid), path tracing and next-event estimation, behind each boundary kind;
//! that the spectral MIS weights stay finite and bounded on media whose channels are 10^10 apart;
//! that each channel's own majorant leaves a homogeneous medium without null collisions; that it
//! lowers the variance at equal samples against one majorant for all channels, and lets every
//! hero's path live as long as the longest-lived channel's light; and that a density per channel
//! renders as per-channel scales of a grey grid (bit for bit under the global majorant).
//!
//! With `VOLPT_FULL_POWER=1` each comparison has the power to see a 1% bias at 10 standard errors:
//! it asserts that the standard error of the difference is at most 0.1% of the mean (2^23 paths a
//! render, many minutes of CPU a test); by default 2^18 paths see a 6% bias at 10 standard errors
//! (the bound asserted is 0.6%; measured 0.2-0.5%). Three combinations that the others cover (each medium, boundary and
//! estimator appears in a default test) are `#[ignore]`d.

mod common;

use common::{Moments, Z_MAX};
use volpt_core::chromatic::build_channel_majorants;
use volpt_core::grid::DenseTrilinear;
use volpt_core::majorant::{build_majorants, MajorantGrid};
use volpt_core::microfacet::Ggx;
use volpt_core::path::{trace, Truncation};
use volpt_core::rng::Rng;
use volpt_core::tracking::{spectral_delta_tracking, FreeFlight};
use volpt_core::{
    Aabb, Bsdf, ChromaticMedium, ConstantEnvironment, Estimator, GridAlbedo, GridMapping,
    GridMedium, HenyeyGreenstein, HeroChannel, HomogeneousMedium, Medium, NullBoundary,
    PathSettings, PathState, PerspectiveCamera, Ray, RoughDielectric, Scene, SmoothDielectric,
    Spectrum, Vec2, Vec3, VolumeScene,
};
use volpt_core::{Environment, Grid, LatLongEnvironment, LatLongRows};

/// Channels 5x apart, as a cyan resin's (Elek et al. 2017) red and blue.
const SIGMA_T: [f32; 3] = [1.0, 2.5, 5.0];
const ALBEDO: [f32; 3] = [0.95, 0.9, 0.85];
const LIGHT: [f32; 3] = [1.0, 0.9, 0.8];

fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
}

/// A 4 x 4 film whose rays all enter the box `[-1, 1]^3` through its front face.
fn camera() -> PerspectiveCamera {
    PerspectiveCamera {
        origin: Vec3::new(0.0, 0.0, -4.0),
        axis_x: Vec3::new(-1.0, 0.0, 0.0),
        axis_y: Vec3::Y,
        axis_z: Vec3::Z,
        tan_half_fov: Vec2::new(0.15, 0.15),
        width: 4,
        height: 4,
        orthographic: false,
    }
}

fn scene<M: Medium, B: Bsdf>(
    medium: M,
    boundary: B,
    estimator: Estimator,
) -> VolumeScene<M, B, HenyeyGreenstein, ConstantEnvironment> {
    let environment = ConstantEnvironment(Spectrum::from_array(LIGHT));
    scene_under(medium, boundary, environment, estimator)
}

fn scene_under<M: Medium, B: Bsdf, E: Environment>(
    medium: M,
    boundary: B,
    environment: E,
    estimator: Estimator,
) -> VolumeScene<M, B, HenyeyGreenstein, E> {
    VolumeScene {
        camera: camera(),
        bounds: bounds(),
        medium,
        boundary,
        phase: HenyeyGreenstein { g: 0.3 },
        environment,
        lights: volpt_core::Lights::NONE,
        settings: PathSettings {
            estimator,
            ..Default::default()
        },
    }
}

/// Per channel, the moments of the radiance of `paths` paths spread over the film; every path's
/// radiance is asserted finite and non-negative.
fn render<S: Scene>(scene: &S, paths: u32, seed: u32) -> [Moments; 3] {
    let mut moments = [Moments::default(); 3];
    let (w, h) = (scene.camera().width, scene.camera().height);
    for sample in 0..paths / (w * h) {
        for py in 0..h {
            for px in 0..w {
                let mut path = PathState::from_camera(scene, px, py, sample, seed);
                trace(scene, &mut path);
                assert_eq!(path.truncated, Truncation::None);
                for (m, r) in moments.iter_mut().zip(path.radiance.to_array()) {
                    assert!(r.is_finite() && r >= 0.0, "radiance {:?}", path.radiance);
                    m.push(r as f64);
                }
            }
        }
    }
    moments
}

/// Asserts channel `c` of `chromatic` equals channel `c` of `grey[c]` within `Z_MAX` standard
/// errors, and that the comparison would see a 1% bias at 10 of them.
fn assert_identity(what: &str, chromatic: [Moments; 3], grey: [[Moments; 3]; 3]) {
    for c in 0..3 {
        let (a, b) = (chromatic[c], grey[c][c]);
        let se = (a.std_error().powi(2) + b.std_error().powi(2)).sqrt();
        let z = (a.mean() - b.mean()).abs() / se;
        eprintln!(
            "{what}, channel {c}: chromatic {:.5} grey {:.5} (se {:.2e}, z {z:.2})",
            a.mean(),
            b.mean(),
            se
        );
        assert!(z < Z_MAX, "{what}, channel {c}: z = {z}");
        let bound = power().1;
        assert!(
            se <= bound * b.mean(),
            "{what}, channel {c}: se {se} cannot see a {}% bias at 10 sigma",
            1000.0 * bound
        );
    }
}

/// Paths per render, and the largest standard error of a difference over the mean asserted: 10
/// of them is the smallest relative bias the comparison is sure to see.
fn power() -> (u32, f64) {
    match std::env::var("VOLPT_FULL_POWER").as_deref() {
        Ok("1") => (1 << 23, 1e-3),
        _ => (1 << 18, 6e-3),
    }
}

fn homogeneous_identity<B: Bsdf + Copy>(boundary: B, estimator: Estimator, what: &str) {
    let chromatic = ChromaticMedium::new(
        Spectrum::from_array(SIGMA_T),
        None,
        Spectrum::from_array(ALBEDO),
        None,
    );
    let chromatic = render(&scene(chromatic, boundary, estimator), power().0, 1);
    let grey = [0, 1, 2].map(|c| {
        let medium = HomogeneousMedium {
            sigma_t: SIGMA_T[c],
            albedo: Spectrum::splat(ALBEDO[c]),
        };
        render(&scene(medium, boundary, estimator), power().0, 2 + c as u32)
    });
    assert_identity(what, chromatic, grey);
}

/// A 4^3 density in [0.25, 1] and an albedo grid that varies across the box.
struct Grids {
    density: Vec<f32>,
    albedo: Vec<f32>,
    majorants: Vec<f32>,
}

const RES: [u32; 3] = [4, 4, 4];

impl Grids {
    fn new() -> Self {
        let n = (RES[0] * RES[1] * RES[2]) as usize;
        let density: Vec<f32> = (0..n)
            .map(|i| 0.25 + 0.75 * ((i * 37 % 11) as f32 / 10.0))
            .collect();
        let albedo = (0..n)
            .flat_map(|i| {
                let t = (i * 13 % 7) as f32 / 6.0;
                [0, 1, 2].map(|c| ALBEDO[c] * (0.8 + 0.2 * t))
            })
            .collect();
        Self {
            density,
            albedo,
            majorants: vec![0.0; 8],
        }
    }

    fn mapping() -> GridMapping {
        GridMapping::cell_centred(bounds(), RES)
    }

    fn density(&self) -> Grid<'_, 1> {
        Grid::new(&self.density, RES, Self::mapping())
    }

    /// The majorant grid (2^3 cells) of the density times `scale`.
    fn build_majorants(&mut self, scale: f32) {
        let mut out = vec![0.0; 8];
        build_majorants(&self.density(), scale, bounds(), [2, 2, 2], &mut out);
        self.majorants = out;
    }

    fn majorant_grid(&self) -> MajorantGrid<'_> {
        MajorantGrid::new(&self.majorants, [2, 2, 2], bounds())
    }
}

fn grid_identity<B: Bsdf + Copy>(boundary: B, estimator: Estimator, what: &str) {
    let mut grids = Grids::new();
    let max_density = grids.density.iter().copied().fold(0.0, f32::max);
    grids.build_majorants(SIGMA_T[2]);
    let mut medium = ChromaticMedium::new(
        Spectrum::from_array(SIGMA_T),
        Some(grids.density()),
        Spectrum::ZERO,
        Some(Grid::new(&grids.albedo, RES, Grids::mapping())),
    );
    medium.majorants = Some(grids.majorant_grid());
    let chromatic = render(&scene(medium, boundary, estimator), power().0, 1);
    let grey = [0, 1, 2].map(|c| {
        let mut grey_grids = Grids::new();
        grey_grids.build_majorants(SIGMA_T[c]);
        // Channel c of the albedo in all three.
        let albedo: Vec<f32> = grids.albedo.chunks(3).flat_map(|rgb| [rgb[c]; 3]).collect();
        let medium = GridMedium {
            density: grey_grids.density(),
            scale: SIGMA_T[c],
            majorant: SIGMA_T[c] * max_density,
            majorants: Some(grey_grids.majorant_grid()),
            albedo: GridAlbedo(Grid::new(&albedo, RES, Grids::mapping()), DenseTrilinear),
            reads: DenseTrilinear,
        };
        render(&scene(medium, boundary, estimator), power().0, 2 + c as u32)
    });
    assert_identity(what, chromatic, grey);
}

fn rough() -> RoughDielectric {
    RoughDielectric {
        eta: 1.5,
        distribution: Ggx { alpha: 0.3 },
    }
}

#[test]
fn homogeneous_channels_are_grey_renders_index_matched_path_tracing() {
    homogeneous_identity(NullBoundary, Estimator::PathTracing, "homogeneous, pt");
}

#[test]
fn homogeneous_channels_are_grey_renders_index_matched_next_event() {
    homogeneous_identity(NullBoundary, Estimator::NextEvent, "homogeneous, nee");
}

#[test]
fn homogeneous_channels_are_grey_renders_smooth_dielectric() {
    let boundary = SmoothDielectric { eta: 1.33 };
    homogeneous_identity(boundary, Estimator::PathTracing, "homogeneous, smooth");
}

/// Covered by the other media's tests of this boundary and estimator; run with `--ignored`.
#[test]
#[ignore = "minutes of CPU"]
fn homogeneous_channels_are_grey_renders_rough_dielectric() {
    homogeneous_identity(rough(), Estimator::PathTracing, "homogeneous, rough");
}

/// Covered by the other media's tests of this boundary and estimator; run with `--ignored`.
#[test]
#[ignore = "minutes of CPU"]
fn grid_channels_are_grey_renders_index_matched_path_tracing() {
    grid_identity(NullBoundary, Estimator::PathTracing, "grid, pt");
}

#[test]
fn grid_channels_are_grey_renders_index_matched_next_event() {
    grid_identity(NullBoundary, Estimator::NextEvent, "grid, nee");
}

/// Covered by the other media's tests of this boundary and estimator; run with `--ignored`.
#[test]
#[ignore = "minutes of CPU"]
fn grid_channels_are_grey_renders_smooth_dielectric() {
    let boundary = SmoothDielectric { eta: 1.33 };
    grid_identity(boundary, Estimator::PathTracing, "grid, smooth");
}

#[test]
fn grid_channels_are_grey_renders_rough_dielectric() {
    grid_identity(rough(), Estimator::PathTracing, "grid, rough");
}

/// Next-event estimation at a rough boundary needs an environment that is not constant.
#[test]
fn grid_channels_are_grey_renders_rough_dielectric_next_event_under_a_map() {
    let rgb: Vec<f32> = (0..8 * 4)
        .flat_map(|i| {
            let v = 0.2 + (i % 5) as f32 * 0.4;
            [v, 0.8 * v, 0.6 * v]
        })
        .collect();
    let mut sky = LatLongEnvironment::new(
        &rgb,
        8,
        4,
        LatLongRows::PoleToPole,
        [Vec3::X, Vec3::Y, Vec3::Z],
        1.0,
    );
    let mut distribution = vec![0.0; LatLongEnvironment::distribution_len(8, 4)];
    sky.fill_distribution(&mut distribution);
    sky.distribution = &distribution;
    let with_sky = |medium| scene_under(medium, rough(), sky, Estimator::NextEvent);
    let chromatic = ChromaticMedium::new(
        Spectrum::from_array(SIGMA_T),
        None,
        Spectrum::from_array(ALBEDO),
        None,
    );
    let chromatic = render(&with_sky(chromatic), power().0, 1);
    let grey = [0, 1, 2].map(|c| {
        let medium = HomogeneousMedium {
            sigma_t: SIGMA_T[c],
            albedo: Spectrum::splat(ALBEDO[c]),
        };
        render(
            &scene_under(medium, rough(), sky, Estimator::NextEvent),
            power().0,
            2 + c as u32,
        )
    });
    assert_identity("homogeneous, rough, nee, map", chromatic, grey);
}

/// Channels 10^10 apart, an absorbing one and a subnormal one: (sigma_t, albedo).
const EXTREME_MEDIA: [([f32; 3], [f32; 3]); 3] = [
    ([1e-5, 1.0, 1e5], [1.0, 0.5, 0.0]),
    ([1e-40, 3.0, 30.0], [0.99, 1.0, 0.9]),
    ([0.0, 0.0, 8.0], [1.0, 1.0, 1.0]),
];

/// Traces `samples` paths of `scene` and asserts after every step that the path densities are
/// finite and in [0, 3] (the balance heuristic bounds the weight of each channel by 3 times its
/// own estimator's), with mean 1 where `mean_one`, and that every path's light is finite and
/// non-negative.
fn assert_spectral_weights_bounded<S>(scene: &S, samples: u32, mean_one: bool)
where
    S: Scene,
    S::Medium: Medium<Spectral = HeroChannel>,
{
    for sample in 0..samples {
        let mut path = PathState::from_camera(scene, 1, 2, sample, 9);
        while path.alive {
            volpt_core::path::step(scene, &mut path);
            let r = path.spectral.r_u;
            assert!(
                r.is_finite() && r.min_element() >= 0.0 && r.max_element() <= 3.0001,
                "r_u {r:?}"
            );
            let mean = (r.x + r.y + r.z) / 3.0;
            assert!(
                !mean_one || r == Spectrum::ZERO || (mean - 1.0).abs() < 1e-4,
                "r_u {r:?}"
            );
        }
        assert!(path.radiance.is_finite() && path.radiance.min_element() >= 0.0);
    }
}

/// The [`EXTREME_MEDIA`] homogeneous: every path's light is finite, and its path densities stay
/// in [0, 3] with mean 1.
#[test]
fn spectral_weights_are_finite_and_bounded_on_extreme_media() {
    for (sigma_t, albedo) in EXTREME_MEDIA {
        for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
            let medium = ChromaticMedium::new(
                Spectrum::from_array(sigma_t),
                None,
                Spectrum::from_array(albedo),
                None,
            );
            assert_spectral_weights_bounded(&scene(medium, NullBoundary, estimator), 4096, true);
        }
    }
}

/// The [`EXTREME_MEDIA`] as density grids with empty voxels, tracked through a majorant grid
/// whose cells scale each channel's bound (empty cells included): every step's path densities
/// finite in [0, 3], every path's light finite and non-negative.
#[test]
fn spectral_weights_are_finite_and_bounded_in_grids_with_empty_cells() {
    let mut grids = Grids::new();
    for (i, d) in grids.density.iter_mut().enumerate() {
        if i % 3 == 0 || i < 16 {
            *d = 0.0;
        }
    }
    for (sigma_t, albedo) in EXTREME_MEDIA {
        let extinction = Spectrum::from_array(sigma_t);
        grids.build_majorants(extinction.max_element());
        for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
            let mut medium = ChromaticMedium::new(
                extinction,
                Some(grids.density()),
                Spectrum::from_array(albedo),
                None,
            );
            medium.majorants = Some(grids.majorant_grid());
            assert_spectral_weights_bounded(&scene(medium, NullBoundary, estimator), 512, false);
        }
    }
}

/// A homogeneous chromatic medium's channels each have their exact extinction as majorant: the
/// hero samples its own free flights, so every tentative collision is real (at most one step a
/// free flight), whichever channel is the hero. One majorant for all channels (the largest)
/// would give a weak hero null collisions (the test fails with that majorant).
#[test]
fn a_homogeneous_medium_has_no_null_collisions() {
    let medium = ChromaticMedium::new(
        Spectrum::from_array(SIGMA_T),
        None,
        Spectrum::from_array(ALBEDO),
        None,
    );
    let ray = Ray::new(Vec3::new(0.1, 0.2, -1.0), Vec3::Z);
    for hero in 0..3u8 {
        let mut collisions = 0;
        for i in 0..20_000 {
            let mut rng = Rng::new(5, i, hero as u32);
            let (mut r_u, mut steps) = (Spectrum::ONE, 0);
            let flight = spectral_delta_tracking(
                &medium, &ray, 2.0, &mut rng, hero, &mut r_u, &mut steps, 64,
            );
            let collided = matches!(flight, FreeFlight::Collision(_));
            assert_eq!(
                steps, collided as u32,
                "hero {hero}: {flight:?} in {steps} steps"
            );
            collisions += collided as u32;
        }
        // The hero's own collision probability over 2 units, 1 - exp(-2 sigma_t).
        let expected = 20_000.0 * (1.0 - (-2.0 * SIGMA_T[hero as usize] as f64).exp());
        assert!(
            (collisions as f64 - expected).abs() < 5.0 * expected.sqrt(),
            "hero {hero}: {collisions} collisions, expected {expected:.0}"
        );
    }
}

/// Spectral MIS with each channel's own majorant (the hero samples its own extinction, Mitsuba 3's
/// `volpathmis`) against one majorant for all channels (the largest; the same estimator with
/// every channel's majorant raised to it, whose weak heroes meet null collisions that rescale the
/// other channels): on a homogeneous cube behind a rough dielectric, the per-path variance of
/// every channel is lower, by more than 5 standard errors of the difference (batches of paths'
/// variances), and so is the number of tracking steps.
#[test]
fn own_channel_majorants_lower_the_variance_at_equal_samples() {
    let exact = ChromaticMedium::new(
        Spectrum::from_array(SIGMA_T),
        None,
        Spectrum::from_array(ALBEDO),
        None,
    );
    let shared = ChromaticMedium {
        channel_majorant: Spectrum::splat(exact.majorant),
        ..exact
    };
    const BATCHES: usize = 64;
    const BATCH: u32 = 4096;
    let variances = |medium: ChromaticMedium<'static>| {
        let scene = scene(medium, rough(), Estimator::PathTracing);
        let (mut batches, mut steps) = (vec![[0.0f64; 3]; BATCHES], 0u64);
        for (b, v) in batches.iter_mut().enumerate() {
            let mut m = [Moments::default(); 3];
            for i in 0..BATCH {
                let sample = b as u32 * BATCH + i;
                let mut path =
                    PathState::from_camera(&scene, sample % 4, (sample / 4) % 4, sample / 16, 1);
                trace(&scene, &mut path);
                steps += path.tracking_steps as u64;
                for (m, r) in m.iter_mut().zip(path.radiance.to_array()) {
                    m.push(r as f64);
                }
            }
            *v = [0, 1, 2].map(|c| m[c].variance());
        }
        (batches, steps)
    };
    let (own, own_steps) = variances(exact);
    let (one, one_steps) = variances(shared);
    for c in 0..3 {
        let d: Vec<f64> = own.iter().zip(&one).map(|(a, b)| a[c] - b[c]).collect();
        let mean = d.iter().sum::<f64>() / BATCHES as f64;
        let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (BATCHES - 1) as f64;
        let z = mean / (var / BATCHES as f64).sqrt();
        let (a, b) = (
            own.iter().map(|v| v[c]).sum::<f64>() / BATCHES as f64,
            one.iter().map(|v| v[c]).sum::<f64>() / BATCHES as f64,
        );
        eprintln!(
            "channel {c}: variance own {a:.5} one {b:.5} (ratio {:.3}, z {z:.1})",
            a / b
        );
        assert!(z < -5.0, "channel {c}: z = {z}");
    }
    eprintln!("tracking steps: own {own_steps}, one {one_steps}");
    assert!(own_steps < one_steps);
}

/// A density per channel (Mitsuba's RGB `sigma_t` grid times its scale,
/// [`ChromaticMedium::per_channel`]) renders as the same medium given as per-channel scales of a
/// grey grid ([`ChromaticMedium::new`]): bit for bit, path by path, under the global majorant,
/// with channels a power of two apart (so that the grid of `d * 2^c` interpolates to exactly
/// `2^c` times `d`'s interpolation: the same arithmetic, the same paths); and in expectation with each medium's majorant grid (the per-channel one's
/// bounds come from each channel's samples, [`build_channel_majorants`], and bound each channel's
/// extinction in every cell, checked at 100,000 points).
#[test]
fn a_density_per_channel_renders_as_per_channel_scales_of_its_grey_grid() {
    const SCALE: f32 = 1.25;
    const CHANNELS: [f32; 3] = [1.0, 2.0, 4.0];
    const SCALES: [f32; 3] = [
        SCALE * CHANNELS[0],
        SCALE * CHANNELS[1],
        SCALE * CHANNELS[2],
    ];
    let grids = Grids::new();
    let rgb: Vec<f32> = grids
        .density
        .iter()
        .flat_map(|d| CHANNELS.map(|e| d * e))
        .collect();
    let albedo = Grid::new(&grids.albedo, RES, Grids::mapping());
    let scaled = ChromaticMedium::new(
        Spectrum::from_array(SCALES),
        Some(grids.density()),
        Spectrum::ZERO,
        Some(albedo),
    );
    let per_channel = ChromaticMedium::per_channel(
        Spectrum::splat(SCALE),
        Grid::new(&rgb, RES, Grids::mapping()),
        Spectrum::ZERO,
        Some(albedo),
    );
    assert_eq!(per_channel.majorant, scaled.majorant);
    assert_eq!(per_channel.channel_majorant, scaled.channel_majorant);
    same_paths(scaled, per_channel, rough(), Estimator::PathTracing);
    same_paths(scaled, per_channel, NullBoundary, Estimator::NextEvent);

    // Each medium with its majorant grid (2^3 cells).
    let mut grey_grids = Grids::new();
    grey_grids.build_majorants(SCALES[2]);
    let mut scaled = scaled;
    scaled.majorants = Some(grey_grids.majorant_grid());
    let (mut plane, mut channels, mut cells) = (vec![0.0; 64], vec![0.0; 24], vec![0.0; 8]);
    let rgb_grid = per_channel.density_rgb.unwrap();
    build_channel_majorants(
        &rgb_grid,
        Spectrum::splat(SCALE),
        bounds(),
        [2, 2, 2],
        &mut plane,
        &mut channels,
        &mut cells,
    );
    let mut per_channel = per_channel;
    per_channel.majorants = Some(MajorantGrid::new(&cells, [2, 2, 2], bounds()));
    per_channel.channel_majorants = Some(&channels);
    let mut rng = Rng::new(9, 0, 0);
    for _ in 0..100_000 {
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        let cell = [p.x, p.y, p.z].map(|v| ((v + 1.0) as usize).min(1));
        let k = cell[0] + 2 * cell[1] + 4 * cell[2];
        let sigma = per_channel.sigma_t_rgb(p);
        for c in 0..3 {
            assert!(
                sigma[c] <= channels[3 * k + c],
                "{p:?}: channel {c} {sigma:?}"
            );
        }
        assert_eq!(
            cells[k],
            channels[3 * k..3 * k + 3]
                .iter()
                .copied()
                .fold(0.0, f32::max)
        );
    }
    let grey = render(
        &scene(scaled, rough(), Estimator::PathTracing),
        power().0,
        1,
    );
    let rgb = render(
        &scene(per_channel, rough(), Estimator::PathTracing),
        power().0,
        2,
    );
    assert_identity("density per channel, rough, PT", rgb, [grey; 3]);
    let grey = render(
        &scene(scaled, NullBoundary, Estimator::NextEvent),
        power().0,
        1,
    );
    let rgb = render(
        &scene(per_channel, NullBoundary, Estimator::NextEvent),
        power().0,
        2,
    );
    assert_identity("density per channel, null, NEE", rgb, [grey; 3]);
}

/// Asserts that `a` and `b` trace the same paths to the same light, bit for bit.
fn same_paths<B: Bsdf + Copy>(
    a: ChromaticMedium<'_>,
    b: ChromaticMedium<'_>,
    boundary: B,
    estimator: Estimator,
) {
    let (a, b) = (scene(a, boundary, estimator), scene(b, boundary, estimator));
    for sample in 0..4096 {
        let mut p = PathState::from_camera(&a, sample % 4, (sample / 4) % 4, sample / 16, 5);
        let mut q = PathState::from_camera(&b, sample % 4, (sample / 4) % 4, sample / 16, 5);
        trace(&a, &mut p);
        trace(&b, &mut q);
        assert_eq!(
            (p.radiance, p.segments, p.tracking_steps),
            (q.radiance, q.segments, q.tracking_steps),
            "{estimator:?}, sample {sample}"
        );
    }
}

/// Why a chromatic slab's paths are longer with each channel's own majorant than with one for all
/// (`bench/peers/mitsuba3`'s chromatic-slab: 104.5 against 81.6 segments per path): both count a
/// segment per free flight (a real collision or a boundary interaction; null collisions are
/// tracking steps, not segments), and the free flights of a hero are its own medium's either way.
/// What differs is when a path ends: in the slab (no roulette) only by leaving it or by the
/// negligible-weight roulette, which watches `max_c(throughput_c r_c)`. Under one majorant (the
/// red's 100) a red hero's every collision is real and multiplies `r_c / r_red` by
/// `sigma_c / 100` (0.93, 0.96): `r` drifts to the red, whose albedo is 0.8, and the path's weight
/// falls as `(0.99 x 0.96)^k`, so no red-hero path outlives about 570 collisions. With own
/// majorants `r_c / r_h` changes by `(sigma_c / sigma_h) exp(-(sigma_c - sigma_h) t)`, whose
/// logarithm has mean `ln(0.96) + 0.04 ~ -0.0008` per collision: `r` stays flat, every hero's path
/// lives as long as the blue's light (albedo 0.99: about 2,750 collisions), and the three heroes'
/// paths are alike. The added segments carry the blue's light of long walks, which one majorant
/// left to the roulette (its variance; both are unbiased, the identity tests).
#[test]
fn own_majorants_let_every_hero_live_as_long_as_the_longest_lived_channel() {
    let exact = ChromaticMedium::new(
        Spectrum::new(100.0, 93.0, 96.0),
        None,
        Spectrum::new(0.8, 0.9677419, 0.9895833),
        None,
    );
    let shared = ChromaticMedium {
        channel_majorant: Spectrum::splat(exact.majorant),
        ..exact
    };
    // Per hero: paths, segments, and paths of more than 1,000 segments.
    let lengths = |medium: ChromaticMedium<'static>| {
        // The slab's box, boundary and settings (no roulette but the negligible weight's).
        let boundary = RoughDielectric {
            eta: 1.05 / 1.01,
            distribution: Ggx { alpha: 0.1 },
        };
        let scene = VolumeScene {
            bounds: Aabb::new(Vec3::new(-1.6, -1.6, -0.5), Vec3::new(1.6, 1.6, 0.5)),
            settings: PathSettings {
                rr_depth: u32::MAX,
                ..Default::default()
            },
            ..scene(medium, boundary, Estimator::PathTracing)
        };
        let mut by_hero = [[0u64; 3]; 3];
        for sample in 0..30_000 {
            let mut path =
                PathState::from_camera(&scene, sample % 4, (sample / 4) % 4, sample / 16, 7);
            trace(&scene, &mut path);
            let h = &mut by_hero[path.spectral.hero as usize];
            h[0] += 1;
            h[1] += path.segments as u64;
            h[2] += (path.segments > 1000) as u64;
        }
        by_hero
    };
    let (own, one) = (lengths(exact), lengths(shared));
    for (name, l) in [("own", own), ("one", one)] {
        for (h, [n, segments, long]) in l.iter().enumerate() {
            eprintln!(
                "{name} majorants, hero {h}: {:.1} segments a path, {:.2}% of more than 1,000",
                *segments as f64 / *n as f64,
                100.0 * *long as f64 / *n as f64
            );
        }
    }
    let mean = |l: [u64; 3]| l[1] as f64 / l[0] as f64;
    for h in 0..3 {
        assert!((mean(own[h]) / mean(own[2]) - 1.0).abs() < 0.1, "{own:?}");
        assert!(own[h][2] * 50 > own[h][0], "{own:?}");
    }
    // One majorant: the red hero's paths end within ~570 collisions, the blue's live long.
    assert_eq!(one[0][2], 0, "{one:?}");
    assert!(one[2][2] * 50 > one[2][0], "{one:?}");
    assert!(mean(one[0]) < 0.6 * mean(own[0]), "{one:?} {own:?}");
}
