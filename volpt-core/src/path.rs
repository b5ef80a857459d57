//! One step of a volumetric path: the algorithm every backend and every scheduling strategy runs.
//!
//! A path starts at the camera and alternates free flights with interactions until it escapes to
//! the environment or dies:
//!
//! ```text
//! outside the box:  fly straight; miss the box -> add throughput * environment, done
//!                                 hit the box  -> boundary interaction
//! inside the box:   delta-track to the next collision before the exit face
//!                   collision   -> scatter: throughput *= albedo, sample the phase function
//!                   no collision -> boundary interaction at the exit face
//! boundary:         index-matched -> cross unchanged (not an interaction)
//!                   dielectric    -> reflect or refract, throughput *= BSDF weight
//! ```
//!
//! With [`Estimator::PathTracing`] this is pure path tracing with the environment as the only light,
//! an unbiased estimator of the volume rendering equation (Kajiya 1986; Veach 1997 ch. 4); every
//! sample is importance sampled exactly except the microfacet masking, so weights stay near 1. With
//! [`Estimator::NextEvent`] and an index-matched boundary, each scattering event also looks at the
//! environment directly ([`next_event_estimate`]); with a rough dielectric boundary under a map, each
//! interaction with the boundary does ([`boundary_next_event_estimate`]). Depth and roulette follow Mitsuba's
//! `volpath`: `depth` counts scattering events and dielectric interactions, a path may see the light
//! after at most `max_depth - 1` of them, and from `rr_depth` on it survives with probability
//! `min(max(throughput) * eta^2, 0.95)`, or by the thesis's `min(1, max(throughput) * eta^2)`
//! ([`Roulette`]); before `rr_depth`, or with roulette off, a path faces roulette only once that
//! weight is negligible ([`NEGLIGIBLE_WEIGHT`]).
//!
//! A chromatic medium is tracked by the path's hero channel with spectral MIS
//! ([`crate::chromatic`]): the light a path gathers is then its throughput times its path
//! densities `r_u`. What a path carries for that is its medium's [`Medium::Spectral`]
//! ([`crate::spectral`]): nothing for a grey medium, whose paths compile plain tracking.

use core::ops::Range;

use crate::bsdf::Bsdf;
use crate::environment::Environment;
use crate::geometry::BoxHit;
use crate::light;
use crate::medium::Medium;
use crate::phase::PhaseFunction;
use crate::rng::Rng;
use crate::scene::Scene;
use crate::shape::Shape;
use crate::spectral::SpectralState;
use crate::tracking::FreeFlight;
use crate::{Ray, Spectrum, Vec3};

/// The integrator's limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PathSettings {
    /// Longest path in segments (Mitsuba's `max_depth`); `u32::MAX` for unlimited.
    pub max_depth: u32,
    /// Depth from which Russian roulette runs by [`Self::roulette`]; `u32::MAX` for never (a path of
    /// negligible weight faces roulette whatever this says, [`NEGLIGIBLE_WEIGHT`]).
    pub rr_depth: u32,
    /// A safety bound on free flights per path. Without roulette and depth limit, a path in a
    /// non-absorbing medium behind a reflecting boundary can in principle bounce for ever; a path
    /// that reaches this bound is dropped (it contributes zero) and counted as truncated.
    pub max_segments: u32,
    /// A safety bound on delta tracking's tentative collisions per path. A free flight costs
    /// `majorant * length` steps, so an enormous majorant (one dense voxel among empty ones) or a
    /// non-finite one would track for ever; a path that reaches this bound is dropped and counted
    /// as truncated, and separately as cut by tracking.
    pub max_tracking_steps: u32,
    /// Cells of the majorant grid along the box's longest axis (the render factory builds it);
    /// 0 or 1 tracks with one global majorant.
    pub majorant_resolution: u32,
    /// How a path gathers the environment's light.
    pub estimator: Estimator,
    /// Russian roulette's survival probability (from `rr_depth` on).
    pub roulette: Roulette,
}

impl PathSettings {
    pub const UNLIMITED: u32 = u32::MAX;
    /// Measured on the thesis scenes (`docs/heterogeneous.md`).
    pub const DEFAULT_MAJORANT_RESOLUTION: u32 = 32;
}

/// Russian roulette's survival probability `q`; a surviving path's throughput is divided by `q`, so
/// any `q` in (0, 1] keeps the estimator unbiased and only changes its variance and cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Roulette {
    /// Mitsuba's `volpath`: `q = min(max(throughput) * eta^2, 0.95)`. In an albedo-1 region the
    /// cap divides the throughput by 0.95 at every bounce a path survives: long paths come back
    /// as fireflies (cgg-logo at `rr_depth` 0 is 45x less efficient than without roulette).
    #[default]
    Mitsuba,
    /// The thesis's: `q = min(1, max(throughput) * eta^2)`, no cap: a path whose throughput has
    /// not dropped always survives, so the throughput never grows and roulette only ends paths
    /// that carry little. The thesis writes `min(1, max(throughput))` of a throughput without the
    /// radiance's `1/eta^2` at a refraction (its GGX weight is the masking term alone); volpt's
    /// throughput has it, and without the `eta^2` every path that entered a denser medium would
    /// face a roulette at once (`1 - 1/eta^2`, 7.5% of the paths at the thesis's boundary, the
    /// survivors' throughput raised by `eta^2`): 1.13-1.35x the thesis's variance on its scenes.
    Throughput,
}

/// The weight `max(throughput) * eta^2` below which a path faces Russian roulette whatever the
/// scene's `rr_depth` says: it survives with probability `weight / NEGLIGIBLE_WEIGHT` and then
/// carries this weight (up to rounding). Unbiased like any roulette (to the 2^-24 resolution of
/// [`Rng::next_f32`], which matters only below a weight of 2^-64); it only ends paths whose light is
/// at most 2^-40 of the environment's, which without it can run for thousands of segments: in an
/// albedo-0.9 medium without roulette the throughput `0.9^k` stalls among the subnormals (0.9
/// times 2^-147 rounds back to it) and never reaches 0, so a random walk deep in a dense box (the
/// thesis's homogeneous benchmark) runs until it escapes. There, in a simulation of a million
/// walks, the longest path shrinks from 13,931 segments to 367 and the mean from 85.5 to 42.8,
/// while the mean and variance of the returned light agree to ten digits: the roulette's added
/// variance is not measurable (`bench/results/2026-11-27-h100-session6/walk.py`).
pub const NEGLIGIBLE_WEIGHT: f32 = 1.0 / (1u64 << 40) as f32;

/// How a path gathers the environment's light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Estimator {
    /// Only where a path escapes: the phase function alone picks the directions.
    PathTracing,
    /// Also towards a direction sampled from the environment, both strategies weighted by multiple
    /// importance sampling: behind an index-matched boundary at every scattering event, with the
    /// transmittance to the box estimated by ratio tracking; with a rough dielectric boundary at
    /// every interaction with it (the shadow ray leaves the convex box at once; from inside the
    /// medium it would meet the boundary, which bends it), unless the environment is constant
    /// ([`Environment::IS_CONSTANT`]). Behind a smooth dielectric it is path tracing.
    NextEvent,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            max_depth: Self::UNLIMITED,
            rr_depth: 5,
            max_segments: 1 << 22,
            // ~0.1-1 s of one core per path at the worst: bounded, yet far beyond any path of a
            // scene whose majorant is not wasted (the thesis scenes use ~100 steps per path).
            max_tracking_steps: 1 << 26,
            majorant_resolution: Self::DEFAULT_MAJORANT_RESOLUTION,
            // The render factory picks the estimator per scene (`default_estimator`).
            estimator: Estimator::PathTracing,
            roulette: Roulette::Mitsuba,
        }
    }
}

/// The spectral state of a path of scene `S` ([`Medium::Spectral`]).
pub type SpectralOf<S> = <<S as Scene>::Medium as Medium>::Spectral;

/// The state of a path of scene `S`.
pub type PathOf<S> = PathState<SpectralOf<S>>;

/// Everything a path carries between steps: small and `Copy`, so that strategies can park paths in
/// device memory and resume them anywhere. `X` is what its medium's extinction needs
/// ([`crate::spectral`]): nothing for a grey one.
#[derive(Clone, Copy, Debug)]
pub struct PathState<X = ()> {
    pub ray: Ray,
    pub throughput: Spectrum,
    /// Radiance gathered so far (only ever added when the path escapes).
    pub radiance: Spectrum,
    pub rng: Rng,
    /// Interactions so far (scattering events and dielectric reflections or refractions).
    pub depth: u32,
    /// Product of the relative indices crossed, for roulette.
    pub eta_scale: f32,
    /// Free flights so far (one per step).
    pub segments: u32,
    /// Tentative collisions of delta tracking so far.
    pub tracking_steps: u32,
    pub inside: bool,
    pub alive: bool,
    /// Whether, and by which safety bound, the path was cut.
    pub truncated: Truncation,
    /// The phase function's density of the current direction if next-event estimation also
    /// sampled the environment at its origin (the escape is then weighted by MIS), else 0.
    pub mis_pdf: f32,
    /// The hero channel and path densities of a chromatic medium's path; nothing for a grey one.
    pub spectral: X,
}

/// Which safety bound of [`PathSettings`] ended a path (it then contributes zero).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Truncation {
    None,
    /// `max_segments` free flights.
    Segments,
    /// `max_tracking_steps` tentative collisions.
    TrackingSteps,
}

impl<X: SpectralState> PathState<X> {
    /// Sample `sample` of pixel `(px, py)`: a camera ray through a uniformly jittered film position.
    #[inline]
    pub fn from_camera<S: Scene>(scene: &S, px: u32, py: u32, sample: u32, seed: u32) -> Self
    where
        S::Medium: Medium<Spectral = X>,
    {
        let camera = scene.camera();
        let mut rng = Rng::new(seed, py * camera.width + px, sample);
        let ray = camera.generate_ray(px, py, rng.next_2d());
        let spectral = X::start(&mut rng);
        Self {
            ray,
            throughput: Spectrum::ONE,
            radiance: Spectrum::ZERO,
            rng,
            depth: 0,
            eta_scale: 1.0,
            segments: 0,
            tracking_steps: 0,
            inside: scene.shape().contains(ray.origin),
            alive: true,
            truncated: Truncation::None,
            mis_pdf: 0.0,
            spectral,
        }
    }

    /// What the path's light is multiplied by: its throughput, times its path densities `r_u` in a
    /// chromatic medium (the balance heuristic's weight over the channels).
    #[inline(always)]
    fn weight(&self) -> Spectrum {
        self.spectral.weight(self.throughput)
    }

    /// Whether this path samples the environment at its scattering events.
    #[inline]
    fn uses_next_event<S: Scene>(scene: &S) -> bool {
        S::Bsdf::IS_NULL && scene.settings().estimator == Estimator::NextEvent
    }

    /// Whether this path samples the environment at its interactions with the boundary (a rough
    /// dielectric under an environment that is not constant; [`boundary_next_event_estimate`]).
    #[inline]
    fn uses_boundary_next_event<S: Scene>(scene: &S) -> bool {
        S::Bsdf::IS_ROUGH
            && !S::Environment::IS_CONSTANT
            && scene.settings().estimator == Estimator::NextEvent
    }

    /// Ends the path at a safety bound; it contributes zero.
    #[inline]
    pub(crate) fn truncate(&mut self, bound: Truncation) {
        self.truncated = bound;
        self.radiance = Spectrum::ZERO;
        self.alive = false;
    }

    /// Counts an interaction; false (and the path ends) if it is one more than `max_depth` allows.
    #[inline]
    fn begin_interaction(&mut self, settings: &PathSettings) -> bool {
        self.depth += 1;
        self.alive = self.depth < settings.max_depth;
        self.alive
    }

    /// Russian roulette after an interaction: from `rr_depth` on by the scene's rule, before it
    /// (or with roulette off) only once the path's weight is negligible ([`NEGLIGIBLE_WEIGHT`]).
    #[inline]
    fn russian_roulette(&mut self, settings: &PathSettings) {
        let weight = self.weight().max_element() * self.eta_scale * self.eta_scale;
        let q = if self.depth > settings.rr_depth {
            match settings.roulette {
                Roulette::Mitsuba => weight.min(0.95),
                Roulette::Throughput => weight.min(1.0),
            }
        } else if weight < NEGLIGIBLE_WEIGHT {
            weight / NEGLIGIBLE_WEIGHT
        } else {
            return;
        };
        if self.rng.next_f32() < q {
            self.throughput /= q;
        } else {
            self.alive = false;
        }
    }
}

/// Advances `path` by one free flight and the event that ends it.
#[inline(always)]
pub fn step<S: Scene>(scene: &S, path: &mut PathOf<S>) {
    advance::<S, false>(scene, path);
}

/// [`step`] up to a real collision: one free flight and the event that ends it, unless that event
/// is scattering in the medium, whose point it returns for [`scatter`]. The split lets a strategy
/// fetch the albedo of many paths' collisions together (sorting-sk reads them in Morton order);
/// the albedo draws no random number (a stochastic lookup peeks at the next one,
/// [`crate::rng::Rng::peek_u64`]), so the path is the same either way.
#[inline(always)]
pub fn fly<S: Scene>(scene: &S, path: &mut PathOf<S>) -> Option<Vec3> {
    advance::<S, true>(scene, path)
}

/// [`step`], or with `DEFER_SCATTER` [`fly`]: one body, so that `step` compiles as it did before
/// the split (returning the collision from the middle of the step reordered the kernels' code and
/// cost regeneration-sk 3% on the cubes, H100, 2026-11-24).
#[inline(always)]
fn advance<S: Scene, const DEFER_SCATTER: bool>(scene: &S, path: &mut PathOf<S>) -> Option<Vec3> {
    // Mitsuba's max_depth 0 allows no segment at all: the image is black.
    if scene.settings().max_depth == 0 {
        path.alive = false;
        return None;
    }
    path.segments += 1;
    if path.segments > scene.settings().max_segments {
        path.truncate(Truncation::Segments);
        return None;
    }
    if path.inside {
        // Cast through a mesh only if the flight may reach it.
        let t_exit = scene.shape().flight_exit(&path.ray);
        let collision = path.spectral.free_flight(
            scene.medium(),
            &path.ray,
            t_exit,
            &mut path.rng,
            &mut path.tracking_steps,
            scene.settings().max_tracking_steps,
        );
        if path.spectral.is_void() {
            // No channel's density is left: the path weighs nothing (`chromatic::rescale`).
            path.alive = false;
            return None;
        }
        match collision {
            FreeFlight::Collision(t) => {
                let p = path.ray.at(t);
                if DEFER_SCATTER {
                    return Some(p);
                }
                scatter(scene, path, p, None);
            }
            FreeFlight::Escaped => {
                let exit = scene.shape().escaped_exit(&path.ray, &t_exit);
                interact_with_boundary(scene, path, exit)
            }
            FreeFlight::OutOfSteps => path.truncate(Truncation::TrackingSteps),
        }
    } else {
        match scene.shape().entry(&path.ray) {
            Some(hit) => interact_with_boundary(scene, path, hit),
            None => {
                let mut light = path.weight() * scene.background(path.ray.dir);
                let weighted = PathOf::<S>::uses_next_event(scene)
                    || PathOf::<S>::uses_boundary_next_event(scene);
                if weighted && path.mis_pdf > 0.0 {
                    let light_pdf = scene.environment().pdf(path.ray.dir);
                    light *= power_heuristic(path.mis_pdf, light_pdf);
                }
                path.radiance += light + light::escaped_sun(scene, path);
                path.alive = false;
            }
        }
    }
    None
}

/// Runs `path` to its end.
#[inline]
pub fn trace<S: Scene>(scene: &S, path: &mut PathOf<S>) {
    while path.alive {
        step(scene, path);
    }
}

/// Traces samples `samples` of pixel `(px, py)` in order and adds their radiance to `sum` in `f64`.
///
/// This is the per-pixel loop of the CPU renderer and of the GPU's naive strategy: one loop, one
/// summation order, so their images agree bit for bit. Always inlined, like [`step`]: a GPU call
/// taking the scene by address moves it into local memory.
#[inline(always)]
pub fn sample_pixel<S: Scene>(
    scene: &S,
    (px, py): (u32, u32),
    samples: Range<u32>,
    seed: u32,
    sum: &mut [f64; 3],
    counters: &mut PathCounters,
) {
    for sample in samples {
        let mut path = PathState::from_camera(scene, px, py, sample, seed);
        trace(scene, &mut path);
        counters.record(&path);
        for (s, r) in sum.iter_mut().zip(path.radiance.to_array()) {
            *s += r as f64;
        }
    }
}

/// A real collision at `p`: the albedo (`albedo` if the caller has read it, else read here, only
/// if the path goes on) scales the throughput (the scattering/extinction ratio of the collision
/// estimator) and the phase function, sampled exactly, gives the new direction.
/// Always inlined: a GPU call taking the scene by address moves it into local memory.
#[inline(always)]
pub fn scatter<S: Scene>(scene: &S, path: &mut PathOf<S>, p: Vec3, albedo: Option<Spectrum>) {
    let settings = scene.settings();
    if !path.begin_interaction(settings) {
        return;
    }
    path.throughput *= match albedo {
        Some(albedo) => albedo,
        // The low bits of the number the phase (or light) sample draws next: free random bits
        // for a stochastic albedo lookup, independent of that sample's top 24 bits.
        None => scene.medium().albedo_random(p, path.rng.peek_u64()),
    };
    if path.throughput == Spectrum::ZERO {
        // A black albedo absorbs the path: nothing it could gather would count.
        path.alive = false;
        return;
    }
    let next_event = PathOf::<S>::uses_next_event(scene);
    let phase = collision_phase(scene, p);
    // The scene's other lights are sampled behind an index-matched boundary whatever the
    // estimator: a delta light is reached by no other strategy.
    let lights = S::Bsdf::IS_NULL && S::LIGHTS && scene.lights().any();
    if (next_event || lights) && !next_event_estimate(scene, path, p, &phase, next_event) {
        return;
    }
    let sample = phase.sample(path.ray.dir, path.rng.next_2d());
    path.ray = Ray::new(p, sample.wo);
    if next_event || lights {
        path.mis_pdf = sample.pdf;
    }
    path.russian_roulette(settings);
}

/// The phase function at a collision at `p`: the scene's, with the asymmetry of the material
/// there where the medium's materials carry their own ([`Medium::phase_g`]). A material-indexed
/// volume whose materials' `g` differ is rendered by a Henyey-Greenstein variant (the factory's
/// choice) whose `g` each collision replaces; a grey medium reads nothing.
#[inline(always)]
fn collision_phase<S: Scene>(scene: &S, p: Vec3) -> S::Phase {
    match scene.medium().phase_g(p) {
        Some(g) => scene.phase().with_g(g),
        None => *scene.phase(),
    }
}

/// Next-event estimation at a scattering event at `p` (Veach 1997, ch. 9; pbrt-v4 section 14.2.2):
/// a look direction `w` sampled from the environment (if `environment`) with density `p_env` adds
/// `throughput * phase(w) * T(p, w) * L_env(w) * w_env / p_env`, with `T` the transmittance to the
/// box estimated by ratio tracking and `w_env = p_env^2 / (p_env^2 + phase(w)^2)` the power
/// heuristic; the path's phase-sampled continuation keeps `phase(wo)` so that, should it escape,
/// its light takes the complementary weight. Both strategies together are unbiased. Each of the
/// scene's other lights adds the same with its own sample ([`light::sample`]: weight 1 for a
/// delta light; `T` up to a point light). Valid only where nothing but the medium lies between
/// `p` and the lights: an index-matched boundary. False (and the path is cut) when ratio tracking
/// runs out of steps.
#[inline(always)]
fn next_event_estimate<S: Scene>(
    scene: &S,
    path: &mut PathOf<S>,
    p: Vec3,
    phase: &S::Phase,
    environment: bool,
) -> bool {
    // One loop over the lights and one body: one copy of ratio tracking in the kernels. Each
    // light is sampled in its turn: samples drawn before the loop would all stay live through its
    // ratio tracking (smoke's kernel took 158 registers instead of 80 so).
    for slot in 0..const { light::slots::<S>() } {
        let Some(light) = light::sample(scene, path, p, slot, environment) else {
            continue;
        };
        let phase = phase.eval(path.ray.dir, light.dir);
        let mis = if light.delta {
            1.0
        } else {
            power_heuristic(light.pdf, phase)
        };
        let shadow = Ray::new(p, light.dir);
        let Some(transmittance) = shadow_transmittance(scene, path, shadow, light.distance) else {
            path.truncate(Truncation::TrackingSteps);
            return false;
        };
        path.radiance += path.spectral.next_event_light(
            path.throughput,
            light.light,
            mis,
            phase,
            light.pdf,
            transmittance,
        );
    }
    true
}

/// The transmittance along `shadow` up to `distance` (a point light's; infinite for the
/// environment), estimated by ratio tracking over each chord through the medium: one for a convex
/// shape (the box's code is the single call); a ray that leaves a non-convex one (a torus) may
/// enter it again. `None` when tracking runs out of steps. Per channel for a chromatic medium
/// ([`SpectralState::Transmittance`]).
///
/// One ratio tracking, in the loop: a shape convex only at run time then costs the box no second
/// copy of it.
#[inline(always)]
fn shadow_transmittance<S: Scene>(
    scene: &S,
    path: &mut PathOf<S>,
    shadow: Ray,
    distance: f32,
) -> Option<Transmittance<S>> {
    let (mut shadow, mut distance) = (shadow, distance);
    // The product of the chords before this one.
    let mut before: Option<Transmittance<S>> = None;
    loop {
        let chord = chord_transmittance(scene, path, &shadow, distance)?;
        let transmittance = match before {
            Some(mut t) => {
                t *= chord;
                t
            }
            None => chord,
        };
        if scene.shape().convex() || !SpectralOf::<S>::transmits(transmittance) {
            return Some(transmittance);
        }
        let exit = scene.shape().exit(&shadow);
        match scene.shape().entry(&Ray::new(exit.point, shadow.dir)) {
            Some(entry) if entry.point.distance(shadow.origin) < distance => {
                distance -= entry.point.distance(shadow.origin);
                shadow.origin = entry.point;
            }
            _ => return Some(transmittance),
        }
        before = Some(transmittance);
    }
}

/// A transmittance estimate of scene `S`'s medium.
type Transmittance<S> = <SpectralOf<S> as SpectralState>::Transmittance;

/// Ratio tracking's estimate along `ray`, from inside the medium to where it leaves the shape or
/// to `distance`, whichever is nearer.
/// A function, not a closure: a closure called from two places may stay a function of its own,
/// which on a GPU takes the scene into local memory.
#[inline(always)]
fn chord_transmittance<S: Scene>(
    scene: &S,
    path: &mut PathOf<S>,
    ray: &Ray,
    distance: f32,
) -> Option<Transmittance<S>> {
    let exit = scene.shape().exit_distance(ray);
    // Compared, not `min`: an infinite `distance` (the environment's) folds away.
    let t_max = if distance < exit { distance } else { exit };
    SpectralOf::<S>::transmittance(
        scene.medium(),
        ray,
        t_max,
        &mut path.rng,
        &mut path.tracking_steps,
        scene.settings().max_tracking_steps,
    )
}

/// Next-event estimation at a rough boundary hit at `hit` (Veach 1997, ch. 9; Mitsuba 3's `volpath`
/// does the same at every non-delta BSDF): a look direction `w` sampled from the environment with
/// density `p_env` adds `throughput * f(w) |cos(w)| * L_env(w) * w_env / p_env`, with
/// `w_env = p_env^2 / (p_env^2 + p_bsdf(w)^2)`; [`interact_with_boundary`] keeps `p_bsdf` of the
/// sampled direction so that, when it escapes, its light takes the complementary weight. Only a
/// direction out of the box reaches the environment: the box is convex and alone, so nothing lies
/// in its way and the transmittance is 1 (reflection for a path that arrives from outside,
/// refraction out for one from inside); a direction into the box meets the medium and the boundary
/// again, which a straight shadow ray cannot pass, so it adds nothing and the BSDF's sample of it
/// keeps its full weight (`mis_pdf` 0). A non-convex mesh may lie in the way out: a direction that
/// meets it again adds nothing here, and the BSDF's sample of it meets the mesh before any light,
/// where its weight is set anew.
#[inline(always)]
fn boundary_next_event_estimate<S: Scene>(scene: &S, path: &mut PathOf<S>, hit: &BoxHit) {
    let Some(light) = scene.environment().sample(path.rng.next_2d()) else {
        return;
    };
    if light.dir.dot(hit.normal) <= 0.0 {
        return;
    }
    // A non-convex shape may stand in the way, which bends the shadow ray.
    if !scene.shape().convex()
        && scene
            .shape()
            .entry(&Ray::new(hit.point, light.dir))
            .is_some()
    {
        return;
    }
    let d = path.ray.dir;
    let shading = shading_normal::<S>(hit, d);
    if !lobe_matches_side::<S>(hit, shading, d, light.dir) {
        return;
    }
    let bsdf = scene.boundary().eval(shading, d, light.dir);
    if bsdf.value <= 0.0 {
        return;
    }
    let weight = power_heuristic(light.pdf, bsdf.pdf) * bsdf.value / light.pdf;
    path.radiance += path.weight() * light.radiance * weight;
}

/// Veach's power heuristic with exponent 2: the weight of a strategy of density `a` against one of
/// density `b`.
#[inline]
pub(crate) fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}

/// The normal the boundary's BSDF scatters about at `hit` for a ray along `d`: the shading normal
/// ([`BoxHit::shading`]). The BSDF reads which side a ray comes from off the normal it is given,
/// so where the shading normal puts the ray on the other side than the geometric one does (a
/// grazing ray on bent vertex normals), the geometric normal is used.
#[inline(always)]
fn shading_normal<S: Scene>(hit: &BoxHit, d: Vec3) -> Vec3 {
    if S::Shape::SHADING_NORMALS && d.dot(hit.shading) * d.dot(hit.normal) > 0.0 {
        hit.shading
    } else {
        hit.normal
    }
}

/// Whether `wo`, scattered at `hit` by a ray along `d`, lies on the side of the surface its lobe
/// about the shading normal `shading` says: a reflection stays on the ray's side of the geometric
/// surface, a transmission crosses it. A direction where they disagree would cross the surface
/// without its refraction (or refract without crossing), and leak or create light; such a
/// direction carries nothing, for sampling and for next-event estimation alike (Veach 1997, 5.3;
/// pbrt-v3's rule). Dropping it only removes energy; each transmission left still crosses the
/// surface, so its `1 / eta^2` radiance factor pairs with the crossing back, as with face normals.
#[inline(always)]
fn lobe_matches_side<S: Scene>(hit: &BoxHit, shading: Vec3, d: Vec3, wo: Vec3) -> bool {
    !S::Shape::SHADING_NORMALS
        || (d.dot(hit.normal) * wo.dot(hit.normal) > 0.0)
            == (d.dot(shading) * wo.dot(shading) > 0.0)
}

// Inlined into every kernel's step: called by address, it would take the scene with it and keep
// a copy of it in local memory (`ptx_entries::no_kernel_keeps_the_scene_in_local_memory`).
#[inline(always)]
fn interact_with_boundary<S: Scene>(scene: &S, path: &mut PathOf<S>, hit: BoxHit) {
    if S::Bsdf::IS_NULL {
        path.ray.origin = hit.point;
        path.inside = !path.inside;
        return;
    }
    let settings = scene.settings();
    if !path.begin_interaction(settings) {
        return;
    }
    let next_event = PathOf::<S>::uses_boundary_next_event(scene);
    if next_event {
        boundary_next_event_estimate(scene, path, &hit);
    }
    let u_lobe = path.rng.next_f32();
    let u = path.rng.next_2d();
    let d = path.ray.dir;
    let shading = shading_normal::<S>(&hit, d);
    match scene.boundary().sample(shading, d, u_lobe, u) {
        Some(sample) if !lobe_matches_side::<S>(&hit, shading, d, sample.wo) => {
            path.alive = false;
        }
        Some(sample) => {
            if next_event {
                // A direction out of the box escapes at once (the box is convex), where its light
                // takes the MIS weight against the environment's density. The BSDF's own density
                // of it, kept positive: 0 in `mis_pdf` would mean "unweighted" (a direction whose
                // density rounds to 0 leaves its light to the environment's sample, which weights
                // it by 1 and the BSDF's value of it, 0 too).
                path.mis_pdf = if sample.wo.dot(hit.normal) > 0.0 {
                    let bsdf = scene.boundary().eval(shading, d, sample.wo);
                    bsdf.pdf.max(f32::MIN_POSITIVE)
                } else {
                    0.0
                };
            }
            path.throughput *= sample.weight;
            if sample.transmitted {
                path.inside = !path.inside;
                path.eta_scale *= sample.eta;
            }
            path.ray = Ray::new(hit.point, sample.wo);
            path.russian_roulette(settings);
        }
        None => path.alive = false,
    }
}

/// Totals over many paths, for throughput reports. Segments are free flights (each ends in a
/// collision, a boundary or the environment); tracking steps are delta tracking's tentative collisions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathCounters {
    pub paths: u64,
    pub segments: u64,
    pub tracking_steps: u64,
    /// Paths cut by either safety bound of [`PathSettings`].
    pub truncated: u64,
    /// Of those, the paths cut by `max_tracking_steps`.
    pub truncated_tracking: u64,
}

impl PathCounters {
    #[inline]
    pub fn record<X>(&mut self, path: &PathState<X>) {
        self.paths += 1;
        self.segments += path.segments as u64;
        self.tracking_steps += path.tracking_steps as u64;
        self.truncated += (path.truncated != Truncation::None) as u64;
        self.truncated_tracking += (path.truncated == Truncation::TrackingSteps) as u64;
    }

    #[inline]
    pub fn merge(self, other: Self) -> Self {
        Self {
            paths: self.paths + other.paths,
            segments: self.segments + other.segments,
            tracking_steps: self.tracking_steps + other.tracking_steps,
            truncated: self.truncated + other.truncated,
            truncated_tracking: self.truncated_tracking + other.truncated_tracking,
        }
    }
}
