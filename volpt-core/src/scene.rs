//! What the path step needs from a scene, and the one generic scene that provides it.

use crate::bsdf::Bsdf;
use crate::camera::PerspectiveCamera;
use crate::environment::Environment;
use crate::medium::Medium;
use crate::path::PathSettings;
use crate::phase::PhaseFunction;
use crate::{Aabb, Spectrum, Vec3};

/// A solid participating medium inside a box boundary, lit by its environment.
///
/// Backends are generic over `Scene`, so every combination of parts is monomorphised: a scene whose
/// boundary is index-matched compiles no Fresnel code, and a constant albedo reads no grid.
pub trait Scene {
    type Medium: Medium;
    type Bsdf: Bsdf;
    type Phase: PhaseFunction;
    type Environment: Environment;

    fn camera(&self) -> &PerspectiveCamera;
    fn bounds(&self) -> Aabb;
    fn medium(&self) -> &Self::Medium;
    fn boundary(&self) -> &Self::Bsdf;
    fn phase(&self) -> &Self::Phase;
    fn environment(&self) -> &Self::Environment;
    fn settings(&self) -> &PathSettings;

    #[inline]
    fn background(&self, dir: Vec3) -> Spectrum {
        self.environment().radiance(dir)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct VolumeScene<M, B, P, E> {
    pub camera: PerspectiveCamera,
    pub bounds: Aabb,
    pub medium: M,
    pub boundary: B,
    pub phase: P,
    pub environment: E,
    pub settings: PathSettings,
}

impl<M: Medium, B: Bsdf, P: PhaseFunction, E: Environment> Scene for VolumeScene<M, B, P, E> {
    type Medium = M;
    type Bsdf = B;
    type Phase = P;
    type Environment = E;

    #[inline]
    fn camera(&self) -> &PerspectiveCamera {
        &self.camera
    }
    #[inline]
    fn bounds(&self) -> Aabb {
        self.bounds
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
    fn settings(&self) -> &PathSettings {
        &self.settings
    }
}
