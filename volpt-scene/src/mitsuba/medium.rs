//! The interior `<medium>`: `homogeneous` or `heterogeneous`, with its phase function.
//!
//! volpt tracks a grey extinction with an RGB albedo, so extinction must be equal in R, G and B;
//! the albedo may vary. Parameter names differ between generations (Mitsuba 0.6 `sigmaA`,
//! `sigmaS`, `density`; Mitsuba 3 `sigma_t`, `albedo`) and both are accepted in either. Where a
//! parameter is absent, Mitsuba 3's defaults apply (extinction 1, albedo 0.75); Mitsuba 0.6 has
//! material-preset defaults volpt does not carry, so there it must be given.

use super::plugin::{quoted, Arg, Ctx, Plugin};
use super::preprocess::Dialect;
use super::volume::{constant_error, volume, Role, VolumeValue};
use super::xml::Element;
use crate::description::{AlbedoDesc, DensityDesc, MediumDesc, PhaseDesc};
use crate::error::SceneError;

/// Mitsuba 3's defaults for `sigma_t` and `albedo`.
const DEFAULT_SIGMA_T: f32 = 1.0;
const DEFAULT_ALBEDO: f32 = 0.75;

pub(crate) fn medium(el: &Element, ctx: &Ctx<'_>) -> Result<MediumDesc, SceneError> {
    let p = Plugin::new(el, ctx);
    let kind = p.kind()?;
    if kind != "homogeneous" && kind != "heterogeneous" {
        return Err(p.unsupported("volpt's media are homogeneous and heterogeneous"));
    }
    if let Some(arg) = p.find(&["densityMultiplier"])? {
        return Err(SceneError::Unsupported {
            path: arg.written.file.to_path_buf(),
            line: arg.written.line,
            what: arg.written.describe(),
            reason: "this old name is not read: use <float name=\"scale\"> instead".into(),
        });
    }
    if let Some(arg) = p.find(&["material"])? {
        return Err(SceneError::Unsupported {
            path: arg.written.file.to_path_buf(),
            line: arg.written.line,
            what: arg.written.describe(),
            reason: "volpt has no material presets: give the coefficients (sigma_t and albedo)"
                .into(),
        });
    }
    let scale = match p.find(&["scale"])? {
        None => 1.0,
        Some(arg) => {
            let v = arg.float()?;
            if v < 0.0 {
                return Err(arg.invalid("a scale >= 0", quoted(arg.value()?)));
            }
            v
        }
    };
    let phase = match p.object("phase")? {
        Some(arg) => PhaseDesc::from_mitsuba(arg.target, ctx)?,
        None => PhaseDesc::Isotropic,
    };
    let (density, albedo) = if kind == "homogeneous" {
        homogeneous(&p)?
    } else {
        heterogeneous(&p)?
    };
    // Sampling hints for Mitsuba's integrators.
    p.ignore(&["sample_emitters", "has_spectral_extinction", "stepSize"]);
    p.finish()?;
    Ok(MediumDesc {
        density,
        scale,
        albedo,
        phase,
        lookup: Default::default(),
        storage: Default::default(),
    })
}

fn homogeneous(p: &Plugin<'_>) -> Result<(DensityDesc, AlbedoDesc), SceneError> {
    let sigma_a = p.find(&["sigmaA", "sigma_a"])?;
    let sigma_s = p.find(&["sigmaS", "sigma_s"])?;
    let sigma_t = p.find(&["sigmaT", "sigma_t"])?;
    let albedo = p.find(&["albedo"])?;
    match (sigma_a, sigma_s) {
        (Some(a_arg), Some(s_arg)) => {
            if let Some(extra) = sigma_t.or(albedo) {
                return Err(extra.invalid(
                    "either sigmaA and sigmaS, or sigmaT and albedo",
                    "both kinds",
                ));
            }
            let a = non_negative(&a_arg, constant(p, &a_arg)?)?;
            let s = non_negative(&s_arg, constant(p, &s_arg)?)?;
            let t = [a[0] + s[0], a[1] + s[1], a[2] + s[2]];
            let grey_t = grey(
                &a_arg,
                "sigmaA + sigmaS equal in R, G and B (volpt's extinction is grey)",
                t,
            )?;
            let albedo = s.map(|s| if grey_t > 0.0 { s / grey_t } else { 0.0 });
            Ok((DensityDesc::Constant(grey_t), AlbedoDesc::Constant(albedo)))
        }
        (Some(one), None) | (None, Some(one)) => {
            Err(one.invalid("sigmaA and sigmaS given together", "only one of them"))
        }
        (None, None) => {
            let sigma_t = match sigma_t {
                Some(arg) => {
                    let v = non_negative(&arg, constant(p, &arg)?)?;
                    grey(
                        &arg,
                        "an extinction equal in R, G and B (volpt's extinction is grey)",
                        v,
                    )?
                }
                None => default_for(
                    p,
                    DEFAULT_SIGMA_T,
                    "<float name=\"sigma_t\"> (or sigmaA and sigmaS)",
                )?,
            };
            let albedo = match albedo {
                Some(arg) => in_unit_range(&arg, constant(p, &arg)?)?,
                None => [default_for(p, DEFAULT_ALBEDO, "<rgb name=\"albedo\">")?; 3],
            };
            Ok((DensityDesc::Constant(sigma_t), AlbedoDesc::Constant(albedo)))
        }
    }
}

fn heterogeneous(p: &Plugin<'_>) -> Result<(DensityDesc, AlbedoDesc), SceneError> {
    let density = match p.find(&["density", "sigma_t"])? {
        None => DensityDesc::Constant(default_for(
            p,
            DEFAULT_SIGMA_T,
            "<volume name=\"density\">",
        )?),
        Some(arg) => match volume(&arg, p.ctx, Role::Density)? {
            VolumeValue::Grid(grid) => DensityDesc::Grid(grid),
            VolumeValue::Constant(v) => {
                let v = non_negative(&arg, v)?;
                DensityDesc::Constant(grey(
                    &arg,
                    "an extinction equal in R, G and B (volpt's extinction is grey)",
                    v,
                )?)
            }
        },
    };
    let albedo = match p.find(&["albedo"])? {
        None => {
            AlbedoDesc::Constant([default_for(p, DEFAULT_ALBEDO, "<volume name=\"albedo\">")?; 3])
        }
        Some(arg) => match volume(&arg, p.ctx, Role::Albedo)? {
            VolumeValue::Grid(grid) => AlbedoDesc::Grid(grid),
            VolumeValue::Constant(v) => AlbedoDesc::Constant(in_unit_range(&arg, v)?),
        },
    };
    if let Some(arg) = p.find(&["method"])? {
        let raw = arg.string()?;
        if !raw.trim().eq_ignore_ascii_case("woodcock") {
            tracing::warn!(
                "{}:{}: {} value {}: volpt always uses delta (Woodcock) tracking, which is unbiased",
                arg.target.file.display(),
                arg.target.line,
                arg.target.describe(),
                quoted(raw)
            );
        }
    }
    Ok((density, albedo))
}

/// A constant parameter of a homogeneous medium (a grid would need a heterogeneous one).
fn constant(p: &Plugin<'_>, arg: &Arg<'_>) -> Result<[f32; 3], SceneError> {
    match volume(arg, p.ctx, Role::Density)? {
        VolumeValue::Constant(v) => Ok(v),
        VolumeValue::Grid(_) => Err(SceneError::Unsupported {
            path: arg.target.file.to_path_buf(),
            line: arg.target.line,
            what: arg.target.describe(),
            reason: "a grid in a homogeneous medium: use <medium type=\"heterogeneous\">".into(),
        }),
    }
}

/// Mitsuba 3's default, or an error in a Mitsuba 0.6 scene (whose defaults are presets).
fn default_for(p: &Plugin<'_>, value: f32, what: &str) -> Result<f32, SceneError> {
    match p.ctx.dialect {
        Dialect::Mitsuba3 => Ok(value),
        Dialect::Mitsuba06 => Err(p.missing(format!(
            "{what} (Mitsuba 0.6 would fall back to a material preset, which volpt does not have)"
        ))),
    }
}

fn grey(arg: &Arg<'_>, expected: &str, v: [f32; 3]) -> Result<f32, SceneError> {
    let max = v.iter().fold(0.0f32, |m, c| m.max(c.abs()));
    if v.iter().all(|c| (c - v[0]).abs() <= 1e-6 * max) {
        Ok(v[0])
    } else {
        Err(constant_error(arg, expected, v))
    }
}

fn non_negative(arg: &Arg<'_>, v: [f32; 3]) -> Result<[f32; 3], SceneError> {
    if v.iter().all(|&c| c >= 0.0) {
        Ok(v)
    } else {
        Err(constant_error(arg, "a coefficient >= 0", v))
    }
}

fn in_unit_range(arg: &Arg<'_>, v: [f32; 3]) -> Result<[f32; 3], SceneError> {
    if v.iter().all(|c| (0.0..=1.0).contains(c)) {
        Ok(v)
    } else {
        Err(constant_error(arg, "an albedo in [0, 1]", v))
    }
}
