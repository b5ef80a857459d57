//! The boundary's `<bsdf>`: `null`, `dielectric` or `roughdielectric` (GGX).

use super::ior::{ior, named_ior};
use super::plugin::{quoted, Ctx, Plugin};
use super::xml::Element;
use crate::description::BsdfDesc;
use crate::error::SceneError;

/// Mitsuba's defaults: BK7 glass inside, air outside.
const DEFAULT_INT_IOR: &str = "bk7";
const DEFAULT_EXT_IOR: &str = "air";
/// Mitsuba's default roughness for `roughdielectric`.
const DEFAULT_ALPHA: f32 = 0.1;

pub(crate) fn bsdf(el: &Element, ctx: &Ctx<'_>) -> Result<BsdfDesc, SceneError> {
    let p = Plugin::new(el, ctx);
    let bsdf = match p.kind()? {
        "null" => BsdfDesc::Null,
        "dielectric" => {
            let (int_ior, ext_ior) = iors(&p)?;
            BsdfDesc::Dielectric { int_ior, ext_ior }
        }
        "roughdielectric" => {
            let (int_ior, ext_ior) = iors(&p)?;
            check_ggx(&p)?;
            let alpha = alpha(&p)?;
            // Visible-normal sampling only changes noise, and volpt picks its own strategy.
            p.ignore(&["sampleVisible", "sample_visible"]);
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            }
        }
        _ => {
            return Err(
                p.unsupported("volpt's boundary bsdf must be null, dielectric or roughdielectric")
            )
        }
    };
    p.finish()?;
    Ok(bsdf)
}

fn iors(p: &Plugin<'_>) -> Result<(f32, f32), SceneError> {
    let read = |names: &[&str], default: &str| -> Result<f32, SceneError> {
        match p.find(names)? {
            Some(arg) => ior(&arg),
            None => Ok(named_ior(default).unwrap_or(1.0)),
        }
    };
    Ok((
        read(&["intIOR", "int_ior"], DEFAULT_INT_IOR)?,
        read(&["extIOR", "ext_ior"], DEFAULT_EXT_IOR)?,
    ))
}

/// Both Mitsuba 0.6 and 3 default to Beckmann, which volpt does not implement.
fn check_ggx(p: &Plugin<'_>) -> Result<(), SceneError> {
    let Some(arg) = p.find(&["distribution"])? else {
        return Err(p.unsupported(
            "no distribution is given, so Mitsuba uses beckmann, which volpt does not implement: \
             add <string name=\"distribution\" value=\"ggx\"/>",
        ));
    };
    let raw = arg.string()?;
    if raw.trim().eq_ignore_ascii_case("ggx") {
        Ok(())
    } else {
        Err(SceneError::Unsupported {
            path: arg.target.file.to_path_buf(),
            line: arg.target.line,
            what: format!("{} value {}", arg.target.describe(), quoted(raw)),
            reason: "volpt implements the ggx microfacet distribution only".into(),
        })
    }
}

/// Isotropic roughness: `alpha`, or `alphaU` = `alphaV` (anisotropy is not supported).
fn alpha(p: &Plugin<'_>) -> Result<f32, SceneError> {
    let alpha = p.find(&["alpha"])?;
    let u = p.find(&["alphaU", "alpha_u"])?;
    let v = p.find(&["alphaV", "alpha_v"])?;
    let (arg, value) = match (alpha, u, v) {
        (None, None, None) => return Ok(DEFAULT_ALPHA),
        (Some(a), None, None) => (a, a.float()?),
        (None, Some(u), Some(v)) => {
            let (au, av) = (u.float()?, v.float()?);
            if au != av {
                return Err(v.invalid(
                    &format!("the same roughness as alphaU ({au}): volpt's rough dielectric is isotropic"),
                    quoted(v.value()?),
                ));
            }
            (u, au)
        }
        (Some(a), _, _) => {
            return Err(a.invalid("either alpha or alphaU and alphaV, not both", "both"));
        }
        (None, Some(one), None) | (None, None, Some(one)) => {
            return Err(one.invalid("alphaU and alphaV given together", "only one of them"));
        }
    };
    if value > 0.0 {
        Ok(value)
    } else {
        Err(arg.invalid("a roughness > 0", quoted(arg.value()?)))
    }
}
