//! What the path step needs from a scene, and the one generic scene that provides it.

use crate::bsdf::Bsdf;
use crate::camera::PerspectiveCamera;
use crate::environment::Environment;
use crate::light::Lights;
use crate::medium::Medium;
use crate::path::PathSettings;
use crate::phase::PhaseFunction;
use crate::shape::Shape;
use crate::{Aabb, Spectrum, Vec3};

/// A solid participating medium inside a closed boundary (a box or a triangle mesh), lit by its
/// environment and the lights besides it ([`Lights`]: a sun, a point or spot).
///
/// Backends are generic over `Scene`, so every combination of parts is monomorphised: a scene whose
/// boundary is index-matched compiles no Fresnel code, and a constant albedo reads no grid.
pub trait Scene {
    type Medium: Medium;
    type Bsdf: Bsdf;
    type Phase: PhaseFunction;
    type Environment: Environment;
    type Shape: Shape;

    /// Whether this scene type traces the lights besides the environment ([`Scene::lights`]): a
    /// property of the type, so that a GPU kernel of a type without them compiles none of their
    /// code; a scene type with them samples those that are on (a run-time branch).
    const LIGHTS: bool = true;

    fn camera(&self) -> &PerspectiveCamera;
    /// The boundary's geometry.
    fn shape(&self) -> &Self::Shape;
    /// The boundary's bounding box (the box itself for a box).
    #[inline]
    fn bounds(&self) -> Aabb {
        self.shape().bounds()
    }
    fn medium(&self) -> &Self::Medium;
    fn boundary(&self) -> &Self::Bsdf;
    fn phase(&self) -> &Self::Phase;
    fn environment(&self) -> &Self::Environment;
    /// The lights besides the environment; none unless the scene has them.
    #[inline]
    fn lights(&self) -> &Lights {
        &Lights::NONE
    }
    fn settings(&self) -> &PathSettings;

    #[inline]
    fn background(&self, dir: Vec3) -> Spectrum {
        self.environment().radiance(dir)
    }
}

/// The scene every backend renders. The boundary's shape `S` is a box unless named: the registry's
/// variants, and so the GPU kernels, are box scenes.
#[derive(Clone, Copy, Debug)]
pub struct VolumeScene<M, B, P, E, S = Aabb> {
    pub camera: PerspectiveCamera,
    /// The boundary's geometry: an [`Aabb`], or a [`crate::TriangleMesh`].
    pub bounds: S,
    pub medium: M,
    pub boundary: B,
    pub phase: P,
    pub environment: E,
    /// The lights besides the environment ([`Lights::NONE`] for none).
    pub lights: Lights,
    pub settings: PathSettings,
}

impl<M: Medium, B: Bsdf, P: PhaseFunction, E: Environment, S: Shape> Scene
    for VolumeScene<M, B, P, E, S>
{
    type Medium = M;
    type Bsdf = B;
    type Phase = P;
    type Environment = E;
    type Shape = S;

    /// On the CPU, yes; in a GPU kernel, only as [`Lit`]`<VolumeScene>`: the box kernels
    /// (`volpt_device::KernelSet::Box`) are of this type and compile without the lights, exactly
    /// as before there were any. Sampled at run time in every kernel, the lights raised their
    /// registers (smoke's index-matched kernel from 80 to 158) and cost grey scenes without lights
    /// up to 41% under regeneration-sk (H200, 2026-11-29, `bench/results/2026-11-29-h200-session11`);
    /// a scene with a light on gets a kernel of the lit set instead.
    const LIGHTS: bool = !cfg!(target_arch = "nvptx64");

    #[inline]
    fn camera(&self) -> &PerspectiveCamera {
        &self.camera
    }
    #[inline]
    fn shape(&self) -> &S {
        &self.bounds
    }
    #[inline]
    fn bounds(&self) -> Aabb {
        self.bounds.bounds()
    }
    #[inline]
    fn medium(&self) -> &M {
        &self.medium
    }
    #[inline]
    fn boundary(&self) -> &B {
        &self.boundary
    }
    #[inline]
    fn phase(&self) -> &P {
        &self.phase
    }
    #[inline]
    fn environment(&self) -> &E {
        &self.environment
    }
    #[inline]
    fn lights(&self) -> &Lights {
        &self.lights
    }
    #[inline]
    fn settings(&self) -> &PathSettings {
        &self.settings
    }
}

/// `scene` with its boundary's geometry replaced by `shape` (a closed mesh of the same box, say):
/// every other part is the scene's own.
#[derive(Clone, Copy, Debug)]
pub struct WithShape<'s, S, Sh> {
    pub scene: &'s S,
    pub shape: Sh,
}

impl<S: Scene, Sh: Shape> Scene for WithShape<'_, S, Sh> {
    type Medium = S::Medium;
    type Bsdf = S::Bsdf;
    type Phase = S::Phase;
    type Environment = S::Environment;
    type Shape = Sh;

    const LIGHTS: bool = S::LIGHTS;

    #[inline]
    fn camera(&self) -> &PerspectiveCamera {
        self.scene.camera()
    }
    #[inline]
    fn shape(&self) -> &Sh {
        &self.shape
    }
    #[inline]
    fn medium(&self) -> &S::Medium {
        self.scene.medium()
    }
    #[inline]
    fn boundary(&self) -> &S::Bsdf {
        self.scene.boundary()
    }
    #[inline]
    fn phase(&self) -> &S::Phase {
        self.scene.phase()
    }
    #[inline]
    fn environment(&self) -> &S::Environment {
        self.scene.environment()
    }
    #[inline]
    fn lights(&self) -> &Lights {
        self.scene.lights()
    }
    #[inline]
    fn settings(&self) -> &PathSettings {
        self.scene.settings()
    }
}

/// `scene` with the lights besides the environment, as a type: its [`Scene::LIGHTS`] is true
/// wherever it is compiled. The GPU's lit kernels (`volpt_device::KernelSet::Lit`) are of this
/// type; the box kernels, of the plain [`VolumeScene`], compile without the lights.
#[derive(Clone, Copy, Debug)]
pub struct Lit<S>(pub S);

impl<S: Scene> Scene for Lit<S> {
    type Medium = S::Medium;
    type Bsdf = S::Bsdf;
    type Phase = S::Phase;
    type Environment = S::Environment;
    type Shape = S::Shape;

    const LIGHTS: bool = true;

    #[inline(always)]
    fn camera(&self) -> &PerspectiveCamera {
        self.0.camera()
    }
    #[inline(always)]
    fn shape(&self) -> &S::Shape {
        self.0.shape()
    }
    #[inline(always)]
    fn bounds(&self) -> Aabb {
        self.0.bounds()
    }
    #[inline(always)]
    fn medium(&self) -> &S::Medium {
        self.0.medium()
    }
    #[inline(always)]
    fn boundary(&self) -> &S::Bsdf {
        self.0.boundary()
    }
    #[inline(always)]
    fn phase(&self) -> &S::Phase {
        self.0.phase()
    }
    #[inline(always)]
    fn environment(&self) -> &S::Environment {
        self.0.environment()
    }
    #[inline(always)]
    fn lights(&self) -> &Lights {
        self.0.lights()
    }
    #[inline(always)]
    fn settings(&self) -> &PathSettings {
        self.0.settings()
    }
    #[inline(always)]
    fn background(&self, dir: Vec3) -> Spectrum {
        self.0.background(dir)
    }
}
