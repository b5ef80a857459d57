//! Mitsuba scene files (0.5/0.6 and 3 dialects) to a [`SceneDescription`], and back to Mitsuba 3
//! ([`write_mitsuba3`]).
//!
//! volpt renders one kind of scene: a camera looking at a box-bounded participating medium under
//! a constant or lat-long (`envmap`) environment. Whatever else a Mitsuba file says is either
//! harmless and ignored (with a warning when it might change the image) or an error that names the
//! element and its line.
//!
//! Layers, bottom up: `xml` (element tree with lines) -> `preprocess` (`<default>`, `$name`,
//! `<include>`, the dialect) -> `plugin` (typed parameter access, `<ref>`) -> one builder per
//! plugin family, assembled here.

mod boxes;
pub(crate) mod emitter;
pub(crate) mod export;
mod integrator;
pub(crate) mod ior;
pub(crate) mod plugin;
pub(crate) mod preprocess;
pub mod presets;
mod sensor;
mod shape;
pub(crate) mod spectrum;
pub(crate) mod transform;
pub(crate) mod volume;
pub(crate) mod xml;

use std::path::Path;

pub use export::{write_mitsuba3, NO_ROULETTE_DEPTH};
pub use ior::named_ior;

use self::emitter::environment;
use self::integrator::{integrator, DEFAULT_INTEGRATOR};
use self::plugin::{Ctx, Plugin, OBJECT_TAGS};
use self::sensor::sensor;
use self::shape::boundary;
use self::xml::Element;
use crate::description::{LightsDesc, SceneDescription};
use crate::error::SceneError;

/// Loads a Mitsuba scene, with `params` as `(name, value)` pairs overriding its `<default>`s.
pub fn load(path: &Path, params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
    let doc = preprocess::load(path, params)?;
    let ctx = Ctx::new(&doc.root, doc.dialect)?;
    scene(&doc.root, &ctx)
}

fn scene(root: &Element, ctx: &Ctx<'_>) -> Result<SceneDescription, SceneError> {
    let mut sensors = Vec::new();
    let mut integrators = Vec::new();
    let mut emitters = Vec::new();
    let mut shapes = Vec::new();
    for child in &root.children {
        match child.tag.as_str() {
            "sensor" => sensors.push(child),
            "integrator" => integrators.push(child),
            "emitter" => emitters.push(child),
            "shape" => shapes.push(child),
            // Declarations for `<ref>`s; built where they are referenced.
            tag if OBJECT_TAGS.contains(&tag) && child.attr("id").is_some() => {}
            tag if OBJECT_TAGS.contains(&tag) => tracing::warn!(
                "{}:{}: {} has no id, so nothing can refer to it; it is ignored",
                child.file.display(),
                child.line,
                child.describe()
            ),
            _ => {
                return Err(SceneError::Unsupported {
                    path: child.file.to_path_buf(),
                    line: child.line,
                    what: child.describe(),
                    reason: "not an element volpt knows at the top of a <scene>".into(),
                })
            }
        }
    }
    let one = |list: &[&Element], what: &str| -> Result<(), SceneError> {
        match list {
            [_, second, ..] => Err(SceneError::Unsupported {
                path: second.file.to_path_buf(),
                line: second.line,
                what: format!("a second {}", second.describe()),
                reason: format!("volpt renders one {what}"),
            }),
            _ => Ok(()),
        }
    };
    one(&sensors, "sensor")?;
    one(&integrators, "integrator")?;
    one(&shapes, "shape: the closed surface that bounds the medium")?;

    let sensor_el = sensors.first().ok_or_else(|| SceneError::Missing {
        path: root.file.to_path_buf(),
        line: root.line,
        element: "<scene>".into(),
        what: "a <sensor type=\"perspective\">".into(),
    })?;
    let shape_el = shapes.first().ok_or_else(|| SceneError::Missing {
        path: root.file.to_path_buf(),
        line: root.line,
        element: "<scene>".into(),
        what: "a <shape> (a cube, a sphere, or an obj or ply mesh) holding the medium".into(),
    })?;
    let sensor = sensor(sensor_el, ctx)?;
    let integrator = match integrators.first() {
        Some(el) => integrator(el, ctx)?,
        None => DEFAULT_INTEGRATOR,
    };
    // Lights besides the environment are their own emitters; the rest is the environment.
    let mut lights = LightsDesc::default();
    let mut environments = Vec::new();
    for el in emitters {
        let p = Plugin::new(el, ctx);
        if LightsDesc::is_mitsuba_light(p.kind()?) {
            lights.add_mitsuba(&p)?;
            p.finish()?;
        } else {
            environments.push(el);
        }
    }
    let environment = environment(&environments, ctx)?;
    let (boundary, medium) = boundary(shape_el, ctx)?;
    Ok(SceneDescription {
        camera: sensor.camera,
        film: sensor.film,
        spp: sensor.spp,
        integrator,
        boundary,
        medium,
        environment,
        lights,
    })
}
