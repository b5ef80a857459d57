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
/// efficiency of path tracing on envmap-cube with an index-matched boundary). Around a rough
/// dielectric, sampling the map where paths meet the boundary divides envmap-cube's variance per
/// sample by 2.6 (as low as Mitsuba 3's `volpath`, which does the same), for 1.45x the time on the
/// CPU but 3.6x on an H100 (its light samples are dependent reads of the map's distribution in
/// paths of 3.4 segments): 1.8x the efficiency on the CPU, about 0.7x on the GPU, so both
/// backends keep path tracing there and trace the same paths. Under a constant environment a path
/// tracer's escaping path already sees the whole light, and NEE's shadow rays cost more than its
/// lower variance saves (smoke: 0.6x); a smooth dielectric rules NEE out (`docs/heterogeneous.md`).
pub fn default_estimator(desc: &SceneDescription) -> Estimator {
    match (&desc.boundary.bsdf, &desc.environment) {
        (BsdfDesc::Null, EnvironmentDesc::LatLong(_)) => Estimator::NextEvent,
        _ => Estimator::PathTracing,
    }
}
