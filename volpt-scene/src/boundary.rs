//! The boundary's surface, everything about its descriptions in one place: what a description
//! says ([`BsdfDesc`]), how Mitsuba's `<bsdf>` and a TOML scene's `[boundary]` spell it, its
//! checks, its Mitsuba 3 export, how `volpt info` prints it, one example of each kind, and how
//! each registry boundary part is built from it ([`FromDescription`]): index-matched where a
//! dielectric of IOR ratio 1 is exactly that, a smooth or a GGX rough dielectric.

use std::fmt;

use serde::{Deserialize, Serialize};
use volpt_core::microfacet::Ggx;
use volpt_core::{NullBoundary, RoughDielectric, SmoothDielectric};

use crate::description::SceneDescription;
use crate::error::SceneError;
use crate::from_description::FromDescription;
use crate::mitsuba::ior::{ior, named_ior};
use crate::mitsuba::plugin::{quoted, Ctx, Plugin};
use crate::mitsuba::xml::Element;
use crate::simplification::Simplification;
use crate::toml_scene::Cx;
use crate::validate::invalid;

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum BsdfDesc {
    /// Index-matched boundary: light crosses it unchanged.
    Null,
    /// Smooth dielectric interface.
    Dielectric { int_ior: f32, ext_ior: f32 },
    /// GGX (Trowbridge-Reitz) rough dielectric interface with isotropic roughness `alpha`.
    RoughDielectric {
        alpha: f32,
        int_ior: f32,
        ext_ior: f32,
    },
}

/// The roughest GGX boundary volpt renders. Mitsuba sets no upper bound, and neither does GGX, but
/// its terms hold `alpha^2` and `alpha^4` in f32: 1e4 keeps them finite with room to spare, and
/// any alpha above a few is already as rough as a surface gets.
pub const MAX_ALPHA: f32 = 1e4;

/// The Mitsuba BSDF plugins volpt reads, in words.
pub(crate) const MITSUBA_KINDS: &str = "null, dielectric or roughdielectric";

/// Mitsuba's defaults: BK7 glass inside, air outside.
const DEFAULT_INT_IOR: &str = "bk7";
const DEFAULT_EXT_IOR: &str = "air";
/// Mitsuba's default roughness for `roughdielectric`.
const DEFAULT_ALPHA: f32 = 0.1;

impl BsdfDesc {
    /// Mitsuba's boundary `<bsdf>`: `null`, `dielectric` or `roughdielectric` (GGX).
    pub(crate) fn from_mitsuba(el: &Element, ctx: &Ctx<'_>) -> Result<Self, SceneError> {
        let p = Plugin::new(el, ctx);
        let bsdf = match p.kind()? {
            "null" => BsdfDesc::Null,
            "dielectric" => {
                let (int_ior, ext_ior) = mitsuba_iors(&p)?;
                BsdfDesc::Dielectric { int_ior, ext_ior }
            }
            "roughdielectric" => {
                let (int_ior, ext_ior) = mitsuba_iors(&p)?;
                check_ggx(&p)?;
                let alpha = mitsuba_alpha(&p)?;
                // Visible-normal sampling only changes noise, and volpt picks its own strategy.
                p.ignore(&["sampleVisible", "sample_visible"]);
                BsdfDesc::RoughDielectric {
                    alpha,
                    int_ior,
                    ext_ior,
                }
            }
            _ => {
                return Err(p.unsupported(format!("volpt's boundary bsdf must be {MITSUBA_KINDS}")))
            }
        };
        p.finish()?;
        Ok(bsdf)
    }

    /// Checks the numbers a renderer relies on; `source` names the scene in errors.
    pub(crate) fn check(&self, source: &str) -> Result<(), SceneError> {
        match *self {
            BsdfDesc::Null => {}
            BsdfDesc::Dielectric { int_ior, ext_ior } => check_iors(source, int_ior, ext_ior)?,
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            } => {
                check_iors(source, int_ior, ext_ior)?;
                if !(alpha > 0.0 && alpha <= MAX_ALPHA) {
                    return Err(invalid(
                        source,
                        "boundary alpha",
                        &format!("a roughness in (0, {MAX_ALPHA:e}]"),
                        alpha.to_string(),
                    ));
                }
                if alpha > 1.0 {
                    // Mitsuba accepts it too: GGX is defined for any alpha, the surface is just
                    // rougher than any real one.
                    tracing::warn!(
                        "{source}: boundary alpha {alpha} is above 1, rougher than any real \
                         surface; rendered as GGX with that alpha, as Mitsuba does"
                    );
                }
            }
        }
        Ok(())
    }

    /// The `<bsdf>` element of a Mitsuba 3 shape.
    pub(crate) fn to_mitsuba3(self) -> String {
        match self {
            BsdfDesc::Null => "<bsdf type=\"null\"/>".to_owned(),
            BsdfDesc::Dielectric { int_ior, ext_ior } => format!(
                "<bsdf type=\"dielectric\">\n            <float name=\"int_ior\" value=\"{int_ior}\"/>\n            \
                 <float name=\"ext_ior\" value=\"{ext_ior}\"/>\n        </bsdf>"
            ),
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            } => format!(
                "<bsdf type=\"roughdielectric\">\n            <string name=\"distribution\" value=\"ggx\"/>\n            \
                 <float name=\"alpha\" value=\"{alpha}\"/>\n            <float name=\"int_ior\" value=\"{int_ior}\"/>\n            \
                 <float name=\"ext_ior\" value=\"{ext_ior}\"/>\n        </bsdf>"
            ),
        }
    }

    /// One description of each kind; together they select every registry boundary part where
    /// depth is counted (tests cover the registry with them).
    pub fn examples() -> Vec<Self> {
        vec![
            BsdfDesc::Null,
            BsdfDesc::Dielectric {
                int_ior: 1.33,
                ext_ior: 1.0,
            },
            BsdfDesc::RoughDielectric {
                alpha: 0.3,
                int_ior: 1.5,
                ext_ior: 1.1,
            },
        ]
    }
}

/// As `volpt info` prints it.
impl fmt::Display for BsdfDesc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BsdfDesc::Null => f.write_str("index-matched (null)"),
            BsdfDesc::Dielectric { int_ior, ext_ior } => {
                write!(f, "smooth dielectric, int IOR {int_ior}, ext IOR {ext_ior}")
            }
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            } => write!(
                f,
                "GGX rough dielectric, alpha {alpha}, int IOR {int_ior}, ext IOR {ext_ior}"
            ),
        }
    }
}

fn mitsuba_iors(p: &Plugin<'_>) -> Result<(f32, f32), SceneError> {
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
fn mitsuba_alpha(p: &Plugin<'_>) -> Result<f32, SceneError> {
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

fn check_iors(source: &str, int_ior: f32, ext_ior: f32) -> Result<(), SceneError> {
    if int_ior.is_finite() && ext_ior.is_finite() && int_ior > 0.0 && ext_ior > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            source,
            "boundary int_ior and ext_ior",
            "finite indices of refraction > 0",
            format!("{int_ior} and {ext_ior}"),
        ))
    }
}

/// A TOML scene's `[boundary]`: its surface, and the box (read by the TOML loader).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// `null` (index-matched), `dielectric` or `roughdielectric` (GGX).
    #[serde(default)]
    pub bsdf: BsdfKind,
    #[serde(default = "thesis_alpha")]
    pub alpha: f32,
    /// A number or a Mitsuba IOR name (`water`, `air`, ...).
    #[serde(default = "thesis_int_ior")]
    pub int_ior: Ior,
    #[serde(default = "thesis_ext_ior")]
    pub ext_ior: Ior,
    /// The boundary box; by default the volume's (or the mesh's bounding box).
    pub bounds: Option<[[f32; 3]; 2]>,
    /// A closed triangle mesh (`.obj`, `.ply`, `.stl`) as the boundary instead of a box,
    /// relative to the scene file; placed by `scale`, then `rotate`, then `translate`.
    pub mesh: Option<String>,
    /// The mesh file's unit in scene units, one factor or one per axis (`0.001` reads a
    /// millimetre file in metres).
    pub scale: Option<MeshScale>,
    /// A rotation of the mesh about the origin: `{ axis = [x, y, z], angle = degrees }`,
    /// counter-clockwise looking down the axis (Mitsuba's `<rotate>`).
    pub rotate: Option<MeshRotation>,
    /// Where the mesh's origin goes.
    pub translate: Option<[f32; 3]>,
}

/// `boundary.scale`: one factor, or one per axis.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum MeshScale {
    Uniform(f32),
    PerAxis([f32; 3]),
}

/// `boundary.rotate`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshRotation {
    pub axis: [f32; 3],
    pub angle: f32,
}

impl Default for BoundarySpec {
    fn default() -> Self {
        Self {
            bsdf: BsdfKind::default(),
            alpha: thesis_alpha(),
            int_ior: thesis_int_ior(),
            ext_ior: thesis_ext_ior(),
            bounds: None,
            mesh: None,
            scale: None,
            rotate: None,
            translate: None,
        }
    }
}

/// The boundary's surface (`boundary.bsdf`), named as Mitsuba's plugins.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BsdfKind {
    Null,
    Dielectric,
    /// The thesis's boundary, the default.
    #[default]
    RoughDielectric,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Ior {
    Value(f32),
    Named(String),
}

fn thesis_alpha() -> f32 {
    0.1
}
fn thesis_int_ior() -> Ior {
    Ior::Value(1.05)
}
fn thesis_ext_ior() -> Ior {
    Ior::Value(1.01)
}

impl BoundarySpec {
    /// The mesh `[boundary]` names, read from `path` (the resolved `boundary.mesh`) and placed;
    /// `None` for a box boundary.
    pub(crate) fn mesh(
        &self,
        cx: &Cx<'_>,
        path: Option<&std::path::Path>,
    ) -> Result<Option<std::sync::Arc<crate::mesh::MeshDesc>>, SceneError> {
        let Some(path) = path else {
            for (field, set) in [
                ("boundary.scale", self.scale.is_some()),
                ("boundary.rotate", self.rotate.is_some()),
                ("boundary.translate", self.translate.is_some()),
            ] {
                if set {
                    return Err(cx.invalid(field, "a boundary.mesh to place", "no mesh"));
                }
            }
            return Ok(None);
        };
        if let Some(b) = self.bounds {
            return Err(cx.invalid(
                "boundary.bounds",
                "no box with a boundary.mesh (the mesh's bounding box is the boundary's)",
                format!("{b:?}"),
            ));
        }
        let scale = match self.scale {
            None => [1.0; 3],
            Some(MeshScale::Uniform(s)) => [s; 3],
            Some(MeshScale::PerAxis(s)) => s,
        };
        if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
            return Err(cx.invalid(
                "boundary.scale",
                "finite, non-zero factors",
                format!("{scale:?}"),
            ));
        }
        let rotation = match self.rotate {
            None => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            Some(MeshRotation { axis, angle }) => {
                let axis = axis.map(f64::from);
                let len = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
                if !(len.is_finite() && len > 0.0 && angle.is_finite()) {
                    return Err(cx.invalid(
                        "boundary.rotate",
                        "{ axis = [x, y, z] (not zero), angle = degrees }",
                        format!("axis {axis:?}, angle {angle}"),
                    ));
                }
                rotation(axis.map(|a| a / len), f64::from(angle).to_radians())
            }
        };
        let translate = self.translate.unwrap_or([0.0; 3]);
        if !translate.iter().all(|t| t.is_finite()) {
            return Err(cx.invalid(
                "boundary.translate",
                "three finite numbers",
                format!("{translate:?}"),
            ));
        }
        // translate * rotate * scale.
        let mut to_world = [[0.0; 4]; 4];
        for r in 0..3 {
            for c in 0..3 {
                to_world[r][c] = rotation[r][c] * f64::from(scale[c]);
            }
            to_world[r][3] = f64::from(translate[r]);
        }
        to_world[3][3] = 1.0;
        let soup = crate::mesh::read_mesh(path)?;
        crate::mesh::MeshDesc::placed(path, &soup, &to_world).map(Some)
    }

    /// The surface `[boundary]` describes.
    pub(crate) fn bsdf(&self, cx: &Cx<'_>) -> Result<BsdfDesc, SceneError> {
        let ior = |ior: &Ior, field: &str| match ior {
            Ior::Value(v) if v.is_finite() && *v > 0.0 => Ok(*v),
            Ior::Value(v) => Err(cx.invalid(field, "a positive index of refraction", v)),
            Ior::Named(name) => named_ior(name)
                .ok_or_else(|| cx.invalid(field, "a number or a Mitsuba IOR name", name)),
        };
        Ok(match self.bsdf {
            BsdfKind::Null => BsdfDesc::Null,
            BsdfKind::Dielectric => BsdfDesc::Dielectric {
                int_ior: ior(&self.int_ior, "boundary.int_ior")?,
                ext_ior: ior(&self.ext_ior, "boundary.ext_ior")?,
            },
            BsdfKind::RoughDielectric => {
                if !(self.alpha.is_finite() && self.alpha > 0.0) {
                    return Err(cx.invalid("boundary.alpha", "a positive roughness", self.alpha));
                }
                BsdfDesc::RoughDielectric {
                    alpha: self.alpha,
                    int_ior: ior(&self.int_ior, "boundary.int_ior")?,
                    ext_ior: ior(&self.ext_ior, "boundary.ext_ior")?,
                }
            }
        })
    }
}

/// What the factory reads for the boundary axis.
#[derive(Clone, Copy, Debug)]
pub struct BoundaryInput {
    pub bsdf: BsdfDesc,
    /// Neither depth limit nor roulette: the path does not count its interactions.
    pub depth_not_counted: bool,
}

impl BoundaryInput {
    pub fn of(desc: &SceneDescription) -> Self {
        Self {
            bsdf: desc.boundary.bsdf,
            depth_not_counted: desc.integrator.max_depth.is_none()
                && desc.integrator.rr_depth.is_none(),
        }
    }
}

impl FromDescription<'_> for NullBoundary {
    type Input = BoundaryInput;

    fn specialised(input: &BoundaryInput, fired: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.bsdf {
            BsdfDesc::Null => Some(NullBoundary),
            BsdfDesc::Dielectric { int_ior, ext_ior }
                if int_ior == ext_ior && input.depth_not_counted =>
            {
                fired(Simplification::UnitIorRatio);
                Some(NullBoundary)
            }
            _ => None,
        }
    }

    /// No other boundary equals an index-matched one exactly; the rule that makes a unit IOR ratio
    /// index-matched holds here too, unreported.
    fn general(input: &BoundaryInput) -> Option<Self> {
        Self::specialised(input, &mut |_| ())
    }
}

impl FromDescription<'_> for SmoothDielectric {
    type Input = BoundaryInput;

    fn specialised(input: &BoundaryInput, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.bsdf {
            BsdfDesc::Dielectric { int_ior, ext_ior } => Some(SmoothDielectric {
                eta: int_ior / ext_ior,
            }),
            _ => None,
        }
    }

    /// No rough dielectric equals a smooth one exactly.
    fn general(input: &BoundaryInput) -> Option<Self> {
        Self::specialised(input, &mut |_| ())
    }
}

impl FromDescription<'_> for RoughDielectric {
    type Input = BoundaryInput;

    fn specialised(input: &BoundaryInput, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.bsdf {
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            } => Some(RoughDielectric {
                eta: int_ior / ext_ior,
                distribution: Ggx { alpha },
            }),
            _ => None,
        }
    }

    fn general(input: &BoundaryInput) -> Option<Self> {
        Self::specialised(input, &mut |_| ())
    }
}

/// The rotation by `angle` radians about the unit `axis`, counter-clockwise looking down it
/// (Rodrigues).
fn rotation([x, y, z]: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}
