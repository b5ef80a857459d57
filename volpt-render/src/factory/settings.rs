//! The integrator settings a scene file asks for, and the estimator that pays for the scene.

use super::*;

/// The integrator settings a scene file asks for, with the estimator chosen for the scene.
pub fn path_settings(desc: &SceneDescription) -> PathSettings {
    PathSettings {
        max_depth: desc.integrator.max_depth.unwrap_or(PathSettings::UNLIMITED),
        rr_depth: desc.integrator.rr_depth.unwrap_or(PathSettings::UNLIMITED),
        estimator: default_estimator(desc),
        majorant_resolution: default_majorants(desc).resolution,
        ..PathSettings::default()
    }
}

/// Next-event estimation where it pays: a lat-long map behind an index-matched boundary (3x the
/// efficiency of path tracing on envmap-cube with an index-matched boundary), and a lat-long map
/// around a rough dielectric, which paths then sample where they meet the boundary (envmap-cube:
/// 2.6x less variance per sample, as much as Mitsuba 3's `volpath`, which does the same). Under a
/// constant environment a path tracer's escaping path already sees the whole light, and NEE's
/// shadow rays cost more than its lower variance saves (smoke: 0.6x); a smooth dielectric rules NEE
/// out (`docs/heterogeneous.md`).
pub fn default_estimator(desc: &SceneDescription) -> Estimator {
    match (&desc.boundary.bsdf, &desc.environment) {
        (BsdfDesc::Null | BsdfDesc::RoughDielectric { .. }, EnvironmentDesc::LatLong(_)) => {
            Estimator::NextEvent
        }
        _ => Estimator::PathTracing,
    }
}
