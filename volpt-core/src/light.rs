//! Lights besides the environment: a distant light (the sun: a disc of angular radius `r`, a delta
//! direction at `r = 0`) and a point light whose emission a spot's cone may limit. They light the
//! medium by next-event estimation at its scattering events ([`samples`], weighed in `path`'s
//! next-event estimation with the environment's sample, one shadow ray each) where nothing
//! but the medium lies between a collision and the light: behind an index-matched boundary. A
//! dielectric boundary bends the shadow ray, so a delta light cannot be reached through it (Mitsuba
//! 3's `volpath` treats the surface as an occluder there and renders no direct light, silently;
//! the factory says so instead). A sun with extent is also seen by paths that escape towards it
//! ([`escaped_sun`]), weighted by multiple importance sampling against the phase function.
//!
//! A scene holds at most one light of each kind ([`Lights`]): fixed slots keep the kernels free of
//! an indexed array (which a GPU would place in local memory), and a light that is off costs one
//! branch per scattering event. Whether a scene type traces them at all is the type's
//! ([`Scene::LIGHTS`]): the GPU's box kernels compile without them, its lit kernels with them.

use bytemuck::{Pod, Zeroable};

use crate::bsdf::Bsdf;
use crate::environment::Environment;
use crate::math::{normalize, sqrt, PI};
use crate::path::{power_heuristic, PathOf};
use crate::sampling::direction_about;
use crate::scene::Scene;
use crate::spectral::SpectralState;
use crate::{Spectrum, Vec2, Vec3};

/// A distant light (Mitsuba 3's `directional` at radius 0; pbrt-v4's `DistantLight`): uniform
/// radiance from a disc of angular radius `r` about `to_light`, normalised so that the radiance
/// integrated over the disc's solid angle is `irradiance` whatever `r`. A medium's in-scattering
/// `int phase(w) L(w) dw` then tends to `phase(to_light) * irradiance` as `r -> 0`, the delta light's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction towards the disc's centre (light travels along `-to_light`).
    pub to_light: Vec3,
    /// `cos r`; 1 for a delta direction.
    pub cos_radius: f32,
    /// The disc's radiance, `irradiance / (2 pi (1 - cos r))`; for a delta direction the irradiance.
    pub radiance: Spectrum,
    /// The density of a direction sampled uniformly in the disc's cone, `1 / (2 pi (1 - cos r))`;
    /// 0 for a delta direction.
    pub pdf: f32,
}

impl DirectionalLight {
    /// No light.
    pub const OFF: Self = Self {
        to_light: Vec3::Z,
        cos_radius: 1.0,
        radiance: Spectrum::ZERO,
        pdf: 0.0,
    };

    /// A sun whose light travels along `direction` (Mitsuba's `direction`, need not be unit),
    /// `radius` radians wide (clamped to [0, pi/2]), delivering `irradiance` (W/m^2 on a surface
    /// facing it, per channel). A radius whose cone rounds to a delta (`cos r` = 1 in `f32`) is one.
    pub fn new(direction: Vec3, radius: f32, irradiance: Spectrum) -> Self {
        let cos_radius = libm::cosf(radius.clamp(0.0, 0.5 * PI));
        let to_light = normalize(-direction);
        if cos_radius >= 1.0 {
            return Self {
                to_light,
                cos_radius: 1.0,
                radiance: irradiance,
                pdf: 0.0,
            };
        }
        let solid_angle = 2.0 * PI * (1.0 - cos_radius);
        Self {
            to_light,
            cos_radius,
            radiance: irradiance / solid_angle,
            pdf: 1.0 / solid_angle,
        }
    }

    #[inline(always)]
    pub fn is_on(&self) -> bool {
        self.radiance.max_element() > 0.0
    }

    /// Whether the light is a single direction (reached only by next-event estimation).
    #[inline(always)]
    pub fn is_delta(&self) -> bool {
        self.pdf == 0.0
    }

    /// The irradiance the light delivers (the radiance times the disc's solid angle).
    pub fn irradiance(&self) -> Spectrum {
        if self.is_delta() {
            self.radiance
        } else {
            self.radiance / self.pdf
        }
    }

    /// The disc's angular radius in radians.
    pub fn radius(&self) -> f32 {
        libm::acosf(self.cos_radius)
    }

    /// A look direction towards the light: the centre for a delta light, else uniform in the
    /// disc's cone (pbrt-v4's `SampleUniformCone`; Mitsuba's `square_to_uniform_cone`):
    /// `cos = 1 - u.x (1 - cos r)`, azimuth `2 pi u.y`.
    #[inline(always)]
    fn sample(&self, u: Vec2) -> Vec3 {
        let cos_theta = 1.0 - u.x * (1.0 - self.cos_radius);
        direction_about(self.to_light, cos_theta, u.y)
    }

    /// Whether the look direction `dir` sees the disc (false for a delta light).
    #[inline(always)]
    pub fn sees(&self, dir: Vec3) -> bool {
        !self.is_delta() && dir.dot(self.to_light) >= self.cos_radius
    }
}

/// A point light of radiant intensity `intensity` (W/sr), limited to a cone about `axis` with a
/// linear falloff in angle from `beam_width` to `cutoff_angle` (Mitsuba 3's `spot`; pbrt-v4's
/// `SpotLight` falls off smoothly in cosine instead). Mitsuba's `point` is the cone of half-angle
/// pi: no falloff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit direction of the beam's centre.
    pub axis: Vec3,
    pub intensity: Spectrum,
    /// `cos(cutoff_angle)`; below -1 for a point light.
    pub cos_cutoff: f32,
    /// `cos(beam_width)`; below -1 for a point light.
    pub cos_beam: f32,
    /// The cutoff angle in radians.
    pub cutoff: f32,
    /// `1 / (cutoff_angle - beam_width)`.
    pub inv_transition: f32,
}

impl SpotLight {
    /// No light.
    pub const OFF: Self = Self {
        position: Vec3::ZERO,
        axis: Vec3::Z,
        intensity: Spectrum::ZERO,
        cos_cutoff: -2.0,
        cos_beam: -2.0,
        cutoff: PI,
        inv_transition: 0.0,
    };

    /// A point light at `position` radiating `intensity` in every direction (Mitsuba's `point`).
    pub fn point(position: Vec3, intensity: Spectrum) -> Self {
        Self {
            position,
            intensity,
            ..Self::OFF
        }
    }

    /// A spot at `position` shining along `axis` (need not be unit), full `intensity` within
    /// `beam_width` radians of it, falling linearly in angle to 0 at `cutoff_angle` (Mitsuba 3's
    /// `spot`; `beam_width` is clamped to at most `cutoff_angle`).
    pub fn spot(
        position: Vec3,
        axis: Vec3,
        intensity: Spectrum,
        cutoff_angle: f32,
        beam_width: f32,
    ) -> Self {
        let beam_width = beam_width.min(cutoff_angle);
        let width = cutoff_angle - beam_width;
        Self {
            position,
            axis: normalize(axis),
            intensity,
            cos_cutoff: libm::cosf(cutoff_angle),
            cos_beam: libm::cosf(beam_width),
            cutoff: cutoff_angle,
            inv_transition: if width > 0.0 { 1.0 / width } else { 0.0 },
        }
    }

    #[inline(always)]
    pub fn is_on(&self) -> bool {
        self.intensity.max_element() > 0.0
    }

    /// Whether the light shines in every direction (Mitsuba's `point`).
    pub fn is_point(&self) -> bool {
        self.cos_cutoff < -1.0
    }

    /// The beam's width in radians (full intensity within it).
    pub fn beam_width(&self) -> f32 {
        if self.inv_transition > 0.0 {
            self.cutoff - 1.0 / self.inv_transition
        } else {
            self.cutoff
        }
    }

    /// The fraction of `intensity` emitted along unit direction `w` (Mitsuba 3's
    /// `falloff_curve`): 1 inside the beam, `(cutoff - angle) / (cutoff - beam)` across the
    /// transition, 0 outside the cutoff.
    #[inline(always)]
    pub fn falloff(&self, w: Vec3) -> f32 {
        let cos_theta = w.dot(self.axis);
        if cos_theta <= self.cos_cutoff {
            0.0
        } else if cos_theta >= self.cos_beam {
            1.0
        } else {
            (self.cutoff - libm::acosf(cos_theta)) * self.inv_transition
        }
    }
}

/// The scene's lights besides the environment: at most one of each kind, each off unless set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lights {
    pub sun: DirectionalLight,
    pub spot: SpotLight,
}

impl Default for Lights {
    fn default() -> Self {
        Self::NONE
    }
}

impl Lights {
    pub const NONE: Self = Self {
        sun: DirectionalLight::OFF,
        spot: SpotLight::OFF,
    };

    /// Whether any light is on (then paths behind an index-matched boundary sample them).
    #[inline(always)]
    pub fn any(&self) -> bool {
        self.sun.is_on() || self.spot.is_on()
    }

    /// Whether a light is on that only next-event estimation reaches (a delta direction or a
    /// point): behind a dielectric boundary it adds nothing.
    pub fn any_delta(&self) -> bool {
        (self.sun.is_on() && self.sun.is_delta()) || self.spot.is_on()
    }
}

/// What [`Lights`] sends to a kernel: the very `f32`s the host computed.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightsParams {
    pub sun_to_light: [f32; 3],
    pub sun_cos_radius: f32,
    pub sun_radiance: [f32; 3],
    pub sun_pdf: f32,
    pub spot_position: [f32; 3],
    pub spot_cos_cutoff: f32,
    pub spot_axis: [f32; 3],
    pub spot_cos_beam: f32,
    pub spot_intensity: [f32; 3],
    pub spot_cutoff: f32,
    pub spot_inv_transition: f32,
    /// Keeps the parameters a multiple of 8 bytes; always 0.
    pub padding: f32,
}

impl From<&Lights> for LightsParams {
    fn from(l: &Lights) -> Self {
        Self {
            sun_to_light: l.sun.to_light.to_array(),
            sun_cos_radius: l.sun.cos_radius,
            sun_radiance: l.sun.radiance.to_array(),
            sun_pdf: l.sun.pdf,
            spot_position: l.spot.position.to_array(),
            spot_cos_cutoff: l.spot.cos_cutoff,
            spot_axis: l.spot.axis.to_array(),
            spot_cos_beam: l.spot.cos_beam,
            spot_intensity: l.spot.intensity.to_array(),
            spot_cutoff: l.spot.cutoff,
            spot_inv_transition: l.spot.inv_transition,
            padding: 0.0,
        }
    }
}

impl From<&LightsParams> for Lights {
    #[inline]
    fn from(p: &LightsParams) -> Self {
        Self {
            sun: DirectionalLight {
                to_light: Vec3::from_array(p.sun_to_light),
                cos_radius: p.sun_cos_radius,
                radiance: Vec3::from_array(p.sun_radiance),
                pdf: p.sun_pdf,
            },
            spot: SpotLight {
                position: Vec3::from_array(p.spot_position),
                axis: Vec3::from_array(p.spot_axis),
                intensity: Vec3::from_array(p.spot_intensity),
                cos_cutoff: p.spot_cos_cutoff,
                cos_beam: p.spot_cos_beam,
                cutoff: p.spot_cutoff,
                inv_transition: p.spot_inv_transition,
            },
        }
    }
}

/// One light's contribution as next-event estimation sees it from a collision: the look direction,
/// how far the light is (infinite for the sun and the environment), the light arriving (radiance,
/// or intensity over distance squared for a point) and the sample's density (1 for a delta light).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightSample {
    pub dir: Vec3,
    pub distance: f32,
    pub light: Spectrum,
    pub pdf: f32,
    /// Whether no other strategy can reach the light (its MIS weight is then 1).
    pub delta: bool,
}

/// The sun as seen from anywhere: its centre, or the direction in its disc that `u` picks.
#[inline(always)]
pub(crate) fn sample_sun(sun: &DirectionalLight, u: Vec2) -> LightSample {
    if sun.is_delta() {
        LightSample {
            dir: sun.to_light,
            distance: f32::INFINITY,
            light: sun.radiance,
            pdf: 1.0,
            delta: true,
        }
    } else {
        LightSample {
            dir: sun.sample(u),
            distance: f32::INFINITY,
            light: sun.radiance,
            pdf: sun.pdf,
            delta: false,
        }
    }
}

/// The point or spot light as seen from `p`: the inverse-square law times the falloff (pbrt-v4
/// `PointLight::SampleLi`: `I / r^2`, density 1 of a delta position); `None` where it sends no
/// light (outside the cone, or `p` on the light).
#[inline(always)]
pub(crate) fn sample_spot(spot: &SpotLight, p: Vec3) -> Option<LightSample> {
    let to_light = spot.position - p;
    let distance2 = to_light.dot(to_light);
    if distance2 <= 0.0 {
        return None;
    }
    let distance = sqrt(distance2);
    let dir = to_light * (1.0 / distance);
    let falloff = spot.falloff(-dir);
    if falloff <= 0.0 {
        return None;
    }
    Some(LightSample {
        dir,
        distance,
        light: spot.intensity * (falloff / distance2),
        pdf: 1.0,
        delta: true,
    })
}

/// Whether paths of `scene` reach any of its lights besides the environment: any light that is on
/// behind an index-matched boundary; behind a dielectric one only a sun with extent, by escaping
/// into its disc (a delta light adds nothing there, and draws no random number). A scene whose
/// paths reach none renders exactly as without its lights: the GPU's box kernels render it.
pub fn reached<S: Scene>(scene: &S) -> bool {
    let lights = scene.lights();
    if S::Bsdf::IS_NULL {
        lights.any()
    } else {
        lights.sun.is_on() && !lights.sun.is_delta()
    }
}

/// Next-event estimation's light slots in a scene of type `S`: the environment, the sun, the point
/// or spot; the environment's alone where the type has no lights ([`Scene::LIGHTS`]), so that the
/// loop of an unlit kernel is the straight code of one sample.
#[inline(always)]
pub(crate) const fn slots<S: Scene>() -> u32 {
    if S::LIGHTS {
        3
    } else {
        1
    }
}

/// Slot `slot`'s sample for next-event estimation from a collision at `p` (0: the environment's,
/// where `environment`; 1: the sun's; 2: the point or spot's; `None` for a light that is off or
/// sends nothing to `p`), which [`crate::path`]'s next-event estimation weighs in one loop,
/// drawing each sample in its own turn. A delta light (the sun at radius 0, a point or spot:
/// `L / p` is then the irradiance, or `I falloff / r^2`) is reached by no other strategy, so its
/// weight is 1; a sun with extent is also reached by the phase function's sample when the path
/// escapes into the disc ([`escaped_sun`]), so both take the power heuristic (pbrt-v4 section
/// 14.2.2, `SampleLd`). Draws the sun's two numbers only for a sun with extent.
#[inline(always)]
pub(crate) fn sample<S: Scene>(
    scene: &S,
    path: &mut PathOf<S>,
    p: Vec3,
    slot: u32,
    environment: bool,
) -> Option<LightSample> {
    let lights = scene.lights();
    match slot {
        0 if environment => scene
            .environment()
            .sample(path.rng.next_2d())
            .map(LightSample::from),
        1 if lights.sun.is_on() => {
            let u = if lights.sun.is_delta() {
                Vec2::ZERO
            } else {
                path.rng.next_2d()
            };
            Some(sample_sun(&lights.sun, u))
        }
        2 if lights.spot.is_on() => sample_spot(&lights.spot, p),
        _ => None,
    }
}

impl From<crate::environment::LightSample> for LightSample {
    /// The environment's sample: a direction of the map, from infinitely far away.
    #[inline(always)]
    fn from(l: crate::environment::LightSample) -> Self {
        Self {
            dir: l.dir,
            distance: f32::INFINITY,
            light: l.radiance,
            pdf: l.pdf,
            delta: false,
        }
    }
}

/// The sun's light reaching a path that escapes along its disc, weighted against next-event
/// estimation's sample of the disc (power heuristic) where the path's last scattering event took
/// one: behind an index-matched boundary, where `mis_pdf` holds the phase function's density of
/// the escaping direction. Zero for a delta sun (no escaping direction hits it) or one that is off.
#[inline(always)]
pub(crate) fn escaped_sun<S: Scene>(scene: &S, path: &PathOf<S>) -> Spectrum {
    let sun = &scene.lights().sun;
    if !S::LIGHTS || !sun.is_on() || !sun.sees(path.ray.dir) {
        return Spectrum::ZERO;
    }
    let light = path.spectral.weight(path.throughput) * sun.radiance;
    if S::Bsdf::IS_NULL && path.mis_pdf > 0.0 {
        light * power_heuristic(path.mis_pdf, sun.pdf)
    } else {
        light
    }
}
