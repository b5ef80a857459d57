//! `<integrator type="volpath">`: path depth and Russian roulette.

use super::plugin::{Ctx, Plugin};
use super::xml::Element;
use crate::description::IntegratorDesc;
use crate::error::SceneError;

/// Mitsuba's defaults: unlimited depth, Russian roulette from depth 5.
pub(crate) const DEFAULT_INTEGRATOR: IntegratorDesc = IntegratorDesc {
    max_depth: None,
    rr_depth: Some(5),
};

pub(crate) fn integrator(el: &Element, ctx: &Ctx<'_>) -> Result<IntegratorDesc, SceneError> {
    let p = Plugin::new(el, ctx);
    // `volpathmis` (spectral MIS, which volpt always uses on chromatic media) is the same family.
    if !matches!(
        p.kind()?,
        "volpath" | "volpathmis" | "volpath_simple" | "volpathsimple"
    ) {
        return Err(p.unsupported("volpt implements Mitsuba's volumetric path tracer: use volpath"));
    }
    let max_depth = match p.find(&["maxDepth", "max_depth"])? {
        None => DEFAULT_INTEGRATOR.max_depth,
        Some(arg) => match arg.integer()? {
            -1 => None,
            v => Some(
                u32::try_from(v)
                    .map_err(|_| arg.invalid("-1 (unlimited) or a depth >= 0", v.to_string()))?,
            ),
        },
    };
    let rr_depth = match p.find(&["rrDepth", "rr_depth"])? {
        None => DEFAULT_INTEGRATOR.rr_depth,
        Some(arg) => match arg.integer()? {
            v if v < 0 => None,
            v => Some(
                u32::try_from(v)
                    .map_err(|_| arg.invalid("a depth that fits 32 bits", v.to_string()))?,
            ),
        },
    };
    // Only affect surfaces with shading normals, which a box boundary does not have.
    p.ignore(&["strictNormals", "strict_normals"]);
    p.finish()?;
    Ok(IntegratorDesc {
        max_depth,
        rr_depth,
    })
}
