//! The lights besides the environment (a sun with or without extent, a point or spot light)
//! against integrals computed here, independently of the renderer's sampling:
//! - a sun disc seen through a purely absorbing slab is its radiance times Beer-Lambert's
//!   transmittance (the disc's normalisation and the escape test);
//! - a sun over a scattering slab seen from below with one scattering event allowed
//!   (`max_depth` 2) gives the single-scattering integral, in closed form for a delta sun and by
//!   quadrature over the disc for one with extent, where next-event estimation and the phase
//!   function's escapes share the light by MIS;
//! - a point or spot light inside a homogeneous medium, grey or chromatic, gives the
//!   single-scattering integral along the camera ray (inverse-square law, falloff, phase,
//!   transmittance on both legs).
//!
//! Each compares a sample mean with the integral within `Z_MAX` standard errors and a relative
//! band that the planted defects tried during development leave (a wrong disc normalisation, an
//! unweighted escape, a transmittance or `1/r^2` dropped).

mod common;

use std::f64::consts::PI;

use common::{from_spherical, integrate, integrate_2d, test_frame, Moments, Z_MAX};
use volpt_core::path::trace;
use volpt_core::{
    Aabb, ChromaticMedium, ConstantEnvironment, DirectionalLight, Estimator, HenyeyGreenstein,
    HomogeneousMedium, Lights, NullBoundary, PathSettings, PathState, PerspectiveCamera, Ray,
    Scene, Spectrum, SpotLight, Vec2, Vec3, VolumeScene,
};

type LitScene<M> = VolumeScene<M, NullBoundary, HenyeyGreenstein, ConstantEnvironment>;

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

/// `medium` in `bounds` under a black environment, lit by `lights`, one scattering event at most
/// (`max_depth` 2: a path sees the light after at most one interaction).
fn scene<M>(medium: M, bounds: Aabb, g: f32, lights: Lights, estimator: Estimator) -> LitScene<M> {
    VolumeScene {
        camera: camera(),
        bounds,
        medium,
        boundary: NullBoundary,
        phase: HenyeyGreenstein { g },
        environment: ConstantEnvironment(Spectrum::ZERO),
        lights,
        settings: PathSettings {
            max_depth: 2,
            estimator,
            ..PathSettings::default()
        },
    }
}

/// The moments of each channel of `paths` paths along `ray` (inside the medium or not).
fn moments<S: Scene>(scene: &S, ray: Ray, inside: bool, paths: u32) -> [Moments; 3] {
    let mut m = [Moments::default(); 3];
    for sample in 0..paths {
        let mut path = PathState::from_camera(scene, 0, 0, sample, 11);
        path.ray = ray;
        path.inside = inside;
        trace(scene, &mut path);
        for (m, v) in m.iter_mut().zip(path.radiance.to_array()) {
            assert!(v >= 0.0 && v.is_finite(), "radiance {v}");
            m.push(v as f64);
        }
    }
    m
}

fn assert_mean(m: &Moments, expected: f64, what: &str) {
    let (mean, se) = (m.mean(), m.std_error());
    assert!(
        m.z_score(expected) <= Z_MAX && (mean - expected).abs() <= 0.02 * expected,
        "{what}: mean {mean} +- {se}, expected {expected}"
    );
}

fn hg(g: f64, cos: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a.x as f64 * b.x as f64 + a.y as f64 * b.y as f64 + a.z as f64 * b.z as f64
}

/// A slab `[-1000, 1000]^2 x [0, depth]`: wide enough that no light considered here leaves it
/// sideways.
fn slab(depth: f32) -> Aabb {
    Aabb::new(
        Vec3::new(-1000.0, -1000.0, 0.0),
        Vec3::new(1000.0, 1000.0, depth),
    )
}

/// The unit direction `zenith` degrees from +z towards +x.
fn from_zenith(zenith: f64) -> Vec3 {
    let t = zenith.to_radians();
    Vec3::new(t.sin() as f32, 0.0, t.cos() as f32)
}

#[test]
fn a_sun_disc_seen_through_an_absorbing_slab_is_its_radiance_times_the_transmittance() {
    let (sigma_t, depth, irradiance, radius) = (2.0f64, 0.5f32, 3.0f64, 30.0f64);
    let to_sun = from_zenith(25.0);
    let sun = DirectionalLight::new(-to_sun, radius.to_radians() as f32, Spectrum::splat(3.0));
    let lights = Lights {
        sun,
        ..Lights::NONE
    };
    let absorber = HomogeneousMedium {
        sigma_t: sigma_t as f32,
        albedo: Spectrum::ZERO,
    };
    let scene = scene(absorber, slab(depth), 0.0, lights, Estimator::NextEvent);
    // The disc's radiance: its irradiance over its solid angle.
    let radiance = irradiance / (2.0 * PI * (1.0 - radius.to_radians().cos()));
    // Rays from below the slab: one 20 degrees off the sun's centre (inside the disc), one 35
    // degrees off (outside it).
    for (zenith, seen) in [(5.0, true), (60.0, false)] {
        let dir = from_zenith(zenith);
        let ray = Ray::new(Vec3::new(0.0, 0.0, -1.0), dir);
        let m = moments(&scene, ray, false, 100_000);
        let transmittance = (-sigma_t * depth as f64 / dir.z as f64).exp();
        let expected = if seen { radiance * transmittance } else { 0.0 };
        if seen {
            assert_mean(&m[0], expected, "the disc through the slab");
        } else {
            assert_eq!(m[0].mean(), 0.0, "a ray outside the disc sees no sun");
        }
    }
    // A delta sun is never seen by a ray, even one along its direction.
    let delta = Lights {
        sun: DirectionalLight::new(-to_sun, 0.0, Spectrum::splat(3.0)),
        ..Lights::NONE
    };
    let scene = LitScene {
        lights: delta,
        ..scene
    };
    let m = moments(
        &scene,
        Ray::new(Vec3::new(0.0, 0.0, -1.0), to_sun),
        false,
        1000,
    );
    assert_eq!(m[0].mean(), 0.0);
}

/// The single-scattering radiance seen looking along `view` (up, from below) into the slab
/// `[0, depth]` lit from `dir` (a unit direction towards the light) with radiance `radiance`:
/// `int_0^{depth/v_z} sigma_s e^{-sigma_t s} p(view . dir) L e^{-sigma_t (depth - z(s)) / dir_z} ds`,
/// the inner integral over the depth in closed form.
fn single_scattering_from(
    (sigma_t, sigma_s, g, depth): (f64, f64, f64, f64),
    view: Vec3,
    dir: Vec3,
    radiance: f64,
) -> f64 {
    let (mu_v, mu_l) = (view.z as f64, dir.z as f64);
    // z = s mu_v: e^{-sigma_t z / mu_v} e^{-sigma_t (depth - z) / mu_l}, over z in [0, depth], ds = dz / mu_v.
    let k = sigma_t * (1.0 / mu_v - 1.0 / mu_l);
    let along = if k.abs() < 1e-12 {
        depth
    } else {
        (1.0 - (-k * depth).exp()) / k
    };
    sigma_s * hg(g, dot(view, dir)) * radiance * (-sigma_t * depth / mu_l).exp() * along / mu_v
}

#[test]
fn a_delta_sun_over_a_scattering_slab_gives_the_single_scattering_integral() {
    let (sigma_t, albedo, g, depth) = (1.5f64, 0.8f64, 0.4f64, 1.0f64);
    let to_sun = from_zenith(40.0);
    let lights = Lights {
        sun: DirectionalLight::new(-to_sun, 0.0, Spectrum::splat(2.0)),
        ..Lights::NONE
    };
    let medium = HomogeneousMedium {
        sigma_t: sigma_t as f32,
        albedo: Spectrum::splat(albedo as f32),
    };
    let view = from_zenith(-10.0);
    let expected = single_scattering_from((sigma_t, sigma_t * albedo, g, depth), view, to_sun, 2.0);
    // The lights are sampled whatever the environment's estimator.
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        let scene = scene(medium, slab(depth as f32), g as f32, lights, estimator);
        let m = moments(
            &scene,
            Ray::new(Vec3::new(0.0, 0.0, -1.0), view),
            false,
            50_000,
        );
        assert_mean(&m[0], expected, &format!("{estimator:?}"));
    }
}

/// A sun with extent is reached both by next-event estimation and by the phase function's
/// escapes: with a forward phase function looking into the disc both carry much of the light,
/// so a missing or wrong MIS weight on either side shows.
#[test]
fn a_sun_with_extent_over_a_scattering_slab_gives_the_single_scattering_integral() {
    let (sigma_t, albedo, g, depth) = (1.0f64, 0.9f64, 0.7f64, 0.6f64);
    let (irradiance, radius) = (2.0f64, 25.0f64);
    let to_sun = from_zenith(20.0);
    let lights = Lights {
        sun: DirectionalLight::new(-to_sun, radius.to_radians() as f32, Spectrum::splat(2.0)),
        ..Lights::NONE
    };
    let medium = HomogeneousMedium {
        sigma_t: sigma_t as f32,
        albedo: Spectrum::splat(albedo as f32),
    };
    let cos_radius = radius.to_radians().cos();
    let radiance = irradiance / (2.0 * PI * (1.0 - cos_radius));
    let view = to_sun;
    let frame = test_frame(to_sun);
    let scattered = integrate_2d(
        &|cos_theta, phi| {
            let dir = from_spherical(frame, cos_theta, phi);
            single_scattering_from((sigma_t, sigma_t * albedo, g, depth), view, dir, radiance)
        },
        (cos_radius, 1.0),
        (0.0, 2.0 * PI),
        1e-7,
    );
    // The camera ray looks at the disc's centre through the slab.
    let direct = radiance * (-sigma_t * depth / view.z as f64).exp();
    let scene = scene(
        medium,
        slab(depth as f32),
        g as f32,
        lights,
        Estimator::NextEvent,
    );
    let m = moments(
        &scene,
        Ray::new(Vec3::new(0.0, 0.0, -1.0), view),
        false,
        200_000,
    );
    assert_mean(&m[0], direct + scattered, "sun disc");
}

/// The spot's setting in the medium's box `[-5, 5]^3`: a ray along +x from `(-4, 0, 0)`, the
/// light 0.7 above the origin shining down (-y).
const SPOT_POSITION: Vec3 = Vec3::new(0.0, 0.7, 0.0);
const RAY_ORIGIN: Vec3 = Vec3::new(-4.0, 0.0, 0.0);

/// The single-scattering radiance along the ray from a light of intensity `intensity` with
/// falloff `falloff` (of the angle from the spot's axis in radians), with `sigma_t`, `sigma_s`, HG
/// `g`: `int_0^9 sigma_s e^{-sigma_t s} p(cos) I f / r^2 e^{-sigma_t r} ds`.
fn spot_single_scattering(
    (sigma_t, sigma_s, g): (f64, f64, f64),
    intensity: f64,
    falloff: &dyn Fn(f64) -> f64,
) -> f64 {
    let (lx, ly) = (SPOT_POSITION.x as f64, SPOT_POSITION.y as f64);
    let f = |s: f64| {
        let x = RAY_ORIGIN.x as f64 + s;
        let (dx, dy) = (lx - x, ly);
        let r = (dx * dx + dy * dy).sqrt();
        let cos = dx / r;
        // The angle from the axis (0, -1, 0) of the direction from the light to the point.
        let angle = (dy / r).clamp(-1.0, 1.0).acos();
        sigma_s * (-sigma_t * s).exp() * hg(g, cos) * intensity * falloff(angle) / (r * r)
            * (-sigma_t * r).exp()
    };
    integrate(&f, 0.0, 9.0, 1e-9)
}

fn spot_scene_lights(cone: bool) -> Lights {
    let intensity = Spectrum::splat(4.0);
    let spot = if cone {
        SpotLight::spot(
            SPOT_POSITION,
            Vec3::new(0.0, -1.0, 0.0),
            intensity,
            60f32.to_radians(),
            30f32.to_radians(),
        )
    } else {
        SpotLight::point(SPOT_POSITION, intensity)
    };
    Lights {
        spot,
        ..Lights::NONE
    }
}

/// Mitsuba 3's `falloff_curve`: 1 within the beam, linear in angle to 0 at the cutoff.
fn spot_falloff(angle: f64) -> f64 {
    let (cutoff, beam) = (60f64.to_radians(), 30f64.to_radians());
    if angle >= cutoff {
        0.0
    } else if angle <= beam {
        1.0
    } else {
        (cutoff - angle) / (cutoff - beam)
    }
}

#[test]
fn a_point_or_spot_light_in_a_grey_medium_gives_the_single_scattering_integral() {
    let (sigma_t, albedo, g) = (0.5f64, 0.8f64, 0.4f64);
    let medium = HomogeneousMedium {
        sigma_t: sigma_t as f32,
        albedo: Spectrum::splat(albedo as f32),
    };
    let bounds = Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0));
    for cone in [false, true] {
        let falloff: &dyn Fn(f64) -> f64 = if cone { &spot_falloff } else { &|_| 1.0 };
        let expected = spot_single_scattering((sigma_t, sigma_t * albedo, g), 4.0, falloff);
        let scene = scene(
            medium,
            bounds,
            g as f32,
            spot_scene_lights(cone),
            Estimator::NextEvent,
        );
        let m = moments(&scene, Ray::new(RAY_ORIGIN, Vec3::X), true, 100_000);
        assert_mean(&m[0], expected, if cone { "spot" } else { "point" });
    }
}

/// A chromatic medium: each channel's light is its own single-scattering integral, though the
/// path is tracked by one hero channel and its shadow ray estimates every channel's
/// transmittance at once.
#[test]
fn a_spot_light_in_a_chromatic_medium_gives_each_channels_single_scattering_integral() {
    let (extinction, albedo, g) = ([0.3f64, 0.5, 0.9], 0.8f64, 0.4f64);
    let medium = ChromaticMedium::new(
        Spectrum::from_array(extinction.map(|e| e as f32)),
        None,
        Spectrum::splat(albedo as f32),
        None,
    );
    let bounds = Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0));
    let scene = scene(
        medium,
        bounds,
        g as f32,
        spot_scene_lights(true),
        Estimator::NextEvent,
    );
    let m = moments(&scene, Ray::new(RAY_ORIGIN, Vec3::X), true, 200_000);
    for (c, sigma_t) in extinction.into_iter().enumerate() {
        let expected = spot_single_scattering((sigma_t, sigma_t * albedo, g), 4.0, &spot_falloff);
        assert_mean(&m[c], expected, &format!("channel {c}"));
    }
}

/// `S` as a type without the lights besides the environment ([`Scene::LIGHTS`] false), as the
/// GPU's box kernels see every scene (there, `VolumeScene` is such a type).
#[derive(Clone, Copy)]
struct Unlit<S>(S);

impl<S: Scene> Scene for Unlit<S> {
    type Medium = S::Medium;
    type Bsdf = S::Bsdf;
    type Phase = S::Phase;
    type Environment = S::Environment;
    type Shape = S::Shape;
    const LIGHTS: bool = false;
    fn camera(&self) -> &PerspectiveCamera {
        self.0.camera()
    }
    fn shape(&self) -> &S::Shape {
        self.0.shape()
    }
    fn medium(&self) -> &S::Medium {
        self.0.medium()
    }
    fn boundary(&self) -> &S::Bsdf {
        self.0.boundary()
    }
    fn phase(&self) -> &S::Phase {
        self.0.phase()
    }
    fn environment(&self) -> &S::Environment {
        self.0.environment()
    }
    fn lights(&self) -> &Lights {
        self.0.lights()
    }
    fn settings(&self) -> &PathSettings {
        self.0.settings()
    }
}

/// Every pixel's radiance sum over `spp` samples (the CPU's and naive-sk's per-pixel loop) and
/// the paths' segments.
fn image<S: Scene>(scene: &S, spp: u32) -> (Vec<[f64; 3]>, u64) {
    let camera = scene.camera();
    let mut counters = volpt_core::path::PathCounters::default();
    let mut sums = Vec::new();
    for py in 0..camera.height {
        for px in 0..camera.width {
            let mut sum = [0.0; 3];
            volpt_core::path::sample_pixel(scene, (px, py), 0..spp, 5, &mut sum, &mut counters);
            sums.push(sum);
        }
    }
    (sums, counters.segments)
}

/// A spot in fog behind an index-matched boundary, a sun with extent above it, a grey
/// environment, multiple scattering: every light and the environment matter.
fn fog<B>(
    boundary: B,
    lights: Lights,
) -> VolumeScene<HomogeneousMedium, B, HenyeyGreenstein, ConstantEnvironment> {
    VolumeScene {
        camera: camera(),
        bounds: Aabb::new(Vec3::splat(-1.5), Vec3::splat(1.5)),
        medium: HomogeneousMedium {
            sigma_t: 1.2,
            albedo: Spectrum::splat(0.8),
        },
        boundary,
        phase: HenyeyGreenstein { g: 0.3 },
        environment: ConstantEnvironment(Spectrum::splat(0.2)),
        lights,
        settings: PathSettings {
            estimator: Estimator::NextEvent,
            ..PathSettings::default()
        },
    }
}

fn sun_and_spot(sun_radius: f32) -> Lights {
    Lights {
        sun: DirectionalLight::new(Vec3::new(0.2, -1.0, 0.3), sun_radius, Spectrum::splat(3.0)),
        spot: SpotLight::spot(
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Spectrum::splat(2.0),
            50f32.to_radians(),
            20f32.to_radians(),
        ),
    }
}

/// The switch the GPU's kernel sets rest on: a scene type without lights (the box kernels')
/// renders a lit scene exactly as the same scene without its lights (same paths, same random
/// numbers), so its kernels need no light code; the lit type (`volpt_core::Lit`, the lit
/// kernels') renders the CPU's image of the lit scene bit for bit, and that image differs.
#[test]
fn a_scene_type_without_lights_renders_the_scene_as_without_them_and_the_lit_type_as_the_cpu() {
    let lit = fog(NullBoundary, sun_and_spot(0.3));
    let dark = fog(NullBoundary, Lights::NONE);
    let (lit_image, lit_segments) = image(&lit, 8);
    let (dark_image, dark_segments) = image(&dark, 8);
    assert_ne!(lit_image, dark_image, "the lights must show");
    assert_eq!(image(&Unlit(lit), 8), (dark_image, dark_segments));
    assert_eq!(image(&volpt_core::Lit(lit), 8), (lit_image, lit_segments));
    assert!(volpt_core::light::reached(&lit));
    assert!(!volpt_core::light::reached(&dark));
}

/// Behind a dielectric boundary a delta light adds nothing and draws no random number, so the
/// box kernels render such a scene exactly (`volpt_core::light::reached` is false); a sun with
/// extent is reached by escaping paths, and needs the lights.
#[test]
fn a_delta_light_behind_a_dielectric_renders_as_without_lights_and_a_sun_disc_does_not() {
    let boundary = volpt_core::SmoothDielectric { eta: 1.33 };
    let delta = fog(boundary, sun_and_spot(0.0));
    assert!(!volpt_core::light::reached(&delta));
    assert_eq!(image(&delta, 8), image(&fog(boundary, Lights::NONE), 8));
    let disc = fog(boundary, sun_and_spot(0.3));
    assert!(volpt_core::light::reached(&disc));
    assert_ne!(image(&disc, 8).0, image(&fog(boundary, Lights::NONE), 8).0);
}
