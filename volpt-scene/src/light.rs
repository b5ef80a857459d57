//! The lights besides the environment, everything about their descriptions in one place: what a
//! description says ([`LightsDesc`]: at most one sun and one point or spot light), how Mitsuba's
//! `directional`, `point` and `spot` emitters and a TOML scene's `[[lights]]` spell them, their
//! checks, their Mitsuba 3 export, how `volpt info` prints them, and the core's [`Lights`] built
//! from them. Angles are in degrees, as Mitsuba writes them.
//!
//! Mitsuba 3's parameters, which volpt reads and writes with the same meaning:
//! - `directional`: `irradiance` (W/m^2 on a surface facing the light; default 1), `direction`
//!   (where the light travels) or `to_world` (+z is where it travels).
//! - `point`: `intensity` (W/sr; default 1), `position` or `to_world`'s translation.
//! - `spot`: `intensity` (W/sr at the beam's centre; default 1), `cutoff_angle` (default 20),
//!   `beam_width` (default 3/4 of the cutoff), `to_world` (placed at its translation, shining
//!   along its +z).
//!
//! volpt's sun may have an angular radius (`angular_radius`, TOML only: Mitsuba's `directional`
//! is a delta direction); its disc then delivers the same irradiance.

use std::fmt;

use serde::{Deserialize, Serialize};
use volpt_core::{DirectionalLight, Lights, SpotLight, Vec3};

use crate::error::SceneError;
use crate::mitsuba::export::rgb_element;
use crate::mitsuba::plugin::Plugin;
use crate::mitsuba::spectrum::rgb;
use crate::mitsuba::transform::{apply_point, transform, IDENTITY_F64};
use crate::toml_scene::{Cx, OneOrThree};
use crate::validate::invalid;

/// The scene's lights besides the environment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LightsDesc {
    pub sun: Option<SunDesc>,
    pub spot: Option<SpotDesc>,
}

/// A distant light (Mitsuba's `directional`), with an angular radius.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SunDesc {
    /// Where the light travels (from the sun towards the scene); need not be unit.
    pub direction: [f32; 3],
    /// Linear RGB irradiance on a surface facing the light.
    pub irradiance: [f32; 3],
    /// The disc's angular radius in degrees; 0 for a delta direction (the real sun: 0.27).
    pub angular_radius: f32,
}

/// A point light (Mitsuba's `point`), or a spot (Mitsuba 3's `spot`) where it has a cone.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpotDesc {
    pub position: [f32; 3],
    /// Linear RGB radiant intensity (W/sr) at the beam's centre.
    pub intensity: [f32; 3],
    pub cone: Option<SpotCone>,
}

/// A spot's cone: full intensity within `beam_width` of `direction`, falling linearly in angle
/// to 0 at `cutoff_angle` (degrees).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpotCone {
    pub direction: [f32; 3],
    pub cutoff_angle: f32,
    pub beam_width: f32,
}

/// Mitsuba's default cutoff angle of a spot, degrees.
const DEFAULT_CUTOFF: f32 = 20.0;

impl SpotCone {
    /// Mitsuba's default beam width: 3/4 of the cutoff.
    fn default_beam(cutoff_angle: f32) -> f32 {
        cutoff_angle * 0.75
    }
}

impl LightsDesc {
    /// The lights' parameters a scene takes between renders (the facade's `Scene::get` and
    /// `Scene::set`): a scene has those of the lights it has.
    pub const PARAMS: &'static [(&'static str, &'static str)] = &[
        (
            "sun.direction",
            "where the sun's light travels (from the sun), a 3-vector",
        ),
        (
            "sun.irradiance",
            "the sun's irradiance on a surface facing it, RGB >= 0",
        ),
        (
            "sun.angular_radius",
            "the sun disc's angular radius in degrees, in [0, 90]; 0 is a delta direction",
        ),
        (
            "light.position",
            "the point or spot light's position, a 3-vector",
        ),
        (
            "light.intensity",
            "the point or spot light's radiant intensity (W/sr), RGB >= 0",
        ),
        (
            "light.direction",
            "where the spot's beam points, a 3-vector",
        ),
    ];

    pub fn is_empty(&self) -> bool {
        self.sun.is_none() && self.spot.is_none()
    }

    /// The core's lights: what every backend renders.
    pub fn lights(&self) -> Lights {
        let v = Vec3::from_array;
        Lights {
            sun: self.sun.map_or(DirectionalLight::OFF, |s| {
                DirectionalLight::new(
                    v(s.direction),
                    s.angular_radius.to_radians(),
                    v(s.irradiance),
                )
            }),
            spot: self.spot.map_or(SpotLight::OFF, |s| match s.cone {
                None => SpotLight::point(v(s.position), v(s.intensity)),
                Some(c) => SpotLight::spot(
                    v(s.position),
                    v(c.direction),
                    v(s.intensity),
                    c.cutoff_angle.to_radians(),
                    c.beam_width.to_radians(),
                ),
            }),
        }
    }

    /// Whether a light is on that only next-event estimation reaches (a delta sun, a point or
    /// spot): behind a dielectric boundary it adds nothing.
    pub fn any_delta(&self) -> bool {
        self.lights().any_delta()
    }

    /// Checks the numbers a renderer relies on; `source` names the scene in errors.
    pub(crate) fn check(&self, source: &str) -> Result<(), SceneError> {
        let colour = |field: &str, rgb: &[f32; 3]| {
            if rgb.iter().all(|v| v.is_finite() && *v >= 0.0) {
                Ok(())
            } else {
                Err(invalid(
                    source,
                    field,
                    "three finite numbers >= 0",
                    format!("{rgb:?}"),
                ))
            }
        };
        let direction = |field: &str, d: &[f32; 3]| {
            let length2: f32 = d.iter().map(|c| c * c).sum();
            if d.iter().all(|c| c.is_finite()) && length2 > 0.0 && length2.is_finite() {
                Ok(())
            } else {
                Err(invalid(
                    source,
                    field,
                    "a finite, non-zero direction",
                    format!("{d:?}"),
                ))
            }
        };
        if let Some(sun) = &self.sun {
            colour("sun irradiance", &sun.irradiance)?;
            direction("sun direction", &sun.direction)?;
            if !(0.0..=90.0).contains(&sun.angular_radius) {
                return Err(invalid(
                    source,
                    "sun angular_radius",
                    "degrees in [0, 90]",
                    sun.angular_radius.to_string(),
                ));
            }
        }
        if let Some(spot) = &self.spot {
            colour("light intensity", &spot.intensity)?;
            if !spot.position.iter().all(|c| c.is_finite()) {
                return Err(invalid(
                    source,
                    "light position",
                    "finite coordinates",
                    format!("{:?}", spot.position),
                ));
            }
            if let Some(cone) = &spot.cone {
                direction("spot direction", &cone.direction)?;
                let ok = cone.cutoff_angle > 0.0
                    && cone.cutoff_angle <= 180.0
                    && cone.beam_width >= 0.0
                    && cone.beam_width <= cone.cutoff_angle;
                if !ok {
                    return Err(invalid(
                        source,
                        "spot cutoff_angle and beam_width",
                        "degrees with 0 <= beam_width <= cutoff_angle <= 180, cutoff_angle > 0",
                        format!(
                            "cutoff_angle {}, beam_width {}",
                            cone.cutoff_angle, cone.beam_width
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The `<emitter>`s of a Mitsuba 3 scene (empty for none). A sun with an angular radius has
    /// no Mitsuba 3 spelling (`directional` is a delta direction): an error naming it.
    pub(crate) fn to_mitsuba3(self, xml: &std::path::Path) -> Result<String, SceneError> {
        let mut out = String::new();
        let xyz = |name: &str, tag: &str, v: &[f32; 3]| {
            format!(
                "<{tag} name=\"{name}\" x=\"{}\" y=\"{}\" z=\"{}\"/>",
                v[0], v[1], v[2]
            )
        };
        if let Some(sun) = &self.sun {
            if sun.angular_radius > 0.0 {
                return Err(SceneError::Export {
                    path: xml.to_path_buf(),
                    reason: format!(
                        "the sun has an angular radius of {} degrees, which Mitsuba 3's \
                         `directional` (a delta direction) cannot express; set it to 0 to export",
                        sun.angular_radius
                    ),
                });
            }
            out += &format!(
                "\n    <emitter type=\"directional\">\n        {}\n        {}\n    </emitter>\n",
                xyz("direction", "vector", &sun.direction),
                rgb_element("irradiance", &sun.irradiance)
            );
        }
        if let Some(spot) = &self.spot {
            let [x, y, z] = spot.position;
            out += &match spot.cone {
                None => format!(
                    "\n    <emitter type=\"point\">\n        {}\n        {}\n    </emitter>\n",
                    xyz("position", "point", &spot.position),
                    rgb_element("intensity", &spot.intensity)
                ),
                Some(c) => {
                    let [dx, dy, dz] = c.direction;
                    // Any `up` not along the axis: the spot is symmetric about it.
                    let up = if dx.abs() <= dy.abs().min(dz.abs()) {
                        "1, 0, 0"
                    } else if dy.abs() <= dz.abs() {
                        "0, 1, 0"
                    } else {
                        "0, 0, 1"
                    };
                    format!(
                        "\n    <emitter type=\"spot\">\n        <transform name=\"to_world\">\n            \
                         <lookat origin=\"{x}, {y}, {z}\" target=\"{}, {}, {}\" up=\"{up}\"/>\n        \
                         </transform>\n        {}\n        <float name=\"cutoff_angle\" value=\"{}\"/>\n        \
                         <float name=\"beam_width\" value=\"{}\"/>\n    </emitter>\n",
                        x + dx,
                        y + dy,
                        z + dz,
                        rgb_element("intensity", &spot.intensity),
                        c.cutoff_angle,
                        c.beam_width
                    )
                }
            };
        }
        Ok(out)
    }

    /// The light description a Mitsuba `directional`, `point` or `spot` emitter adds to `self`;
    /// an error for a second light of a kind (volpt renders one sun and one point or spot).
    pub(crate) fn add_mitsuba(&mut self, p: &Plugin<'_>) -> Result<(), SceneError> {
        let kind = p.kind()?;
        let colour = |names: &[&str]| -> Result<[f32; 3], SceneError> {
            match p.find(names)? {
                None => Ok([1.0; 3]),
                Some(arg) => {
                    let v = rgb(&arg)?;
                    if v.iter().any(|&c| c < 0.0) {
                        return Err(arg.invalid("a value >= 0", format!("{v:?}")));
                    }
                    Ok(v)
                }
            }
        };
        let to_world = match p.find(&["toWorld", "to_world"])? {
            None => None,
            Some(arg) => Some(transform(&arg)?),
        };
        let m = to_world.unwrap_or(IDENTITY_F64);
        let origin = apply_point(&m, [0.0; 3]);
        let z_axis = {
            let tip = apply_point(&m, [0.0, 0.0, 1.0]);
            [0, 1, 2].map(|i| (tip[i] - origin[i]) as f32)
        };
        let point = |names: &[&str]| -> Result<Option<[f32; 3]>, SceneError> {
            Ok(match p.find(names)? {
                None => None,
                Some(arg) => Some(arg.point()?.map(|c| c as f32)),
            })
        };
        let second = |what: &str| SceneError::Unsupported {
            path: p.el.file.to_path_buf(),
            line: p.el.line,
            what: format!("a second {what} {}", p.el.describe()),
            reason: "volpt renders at most one directional light and one point or spot light"
                .into(),
        };
        match kind {
            "directional" => {
                if self.sun.is_some() {
                    return Err(second("directional light"));
                }
                let direction = match point(&["direction"])? {
                    Some(d) if to_world.is_some() => {
                        let _ = d;
                        return Err(p.unsupported(
                            "only one of `direction` and `to_world` may be given (as in Mitsuba)",
                        ));
                    }
                    Some(d) => d,
                    None => z_axis,
                };
                self.sun = Some(SunDesc {
                    direction,
                    irradiance: colour(&["irradiance"])?,
                    angular_radius: 0.0,
                });
            }
            "point" | "spot" => {
                if self.spot.is_some() {
                    return Err(second("point or spot light"));
                }
                let position = match point(&["position"])? {
                    Some(q) => q,
                    None => origin.map(|c| c as f32),
                };
                let cone = if kind == "spot" {
                    let angle = |names: &[&str], default: f32| -> Result<f32, SceneError> {
                        Ok(match p.find(names)? {
                            None => default,
                            Some(arg) => arg.float()?,
                        })
                    };
                    let cutoff_angle = angle(&["cutoff_angle", "cutoffAngle"], DEFAULT_CUTOFF)?;
                    let beam_width = angle(
                        &["beam_width", "beamWidth"],
                        SpotCone::default_beam(cutoff_angle),
                    )?;
                    Some(SpotCone {
                        direction: z_axis,
                        cutoff_angle,
                        beam_width,
                    })
                } else {
                    None
                };
                self.spot = Some(SpotDesc {
                    position,
                    intensity: colour(&["intensity"])?,
                    cone,
                });
            }
            _ => unreachable!("add_mitsuba is called for light kinds only"),
        }
        p.ignore(&["samplingWeight", "sampling_weight"]);
        Ok(())
    }

    /// Whether a Mitsuba emitter type is one of these lights.
    pub(crate) fn is_mitsuba_light(kind: &str) -> bool {
        matches!(kind, "directional" | "point" | "spot")
    }

    /// One description with each kind of light, as tests use.
    pub fn example() -> Self {
        Self {
            sun: Some(SunDesc {
                direction: [0.3, -1.0, 0.2],
                irradiance: [2.0, 1.8, 1.5],
                angular_radius: 0.0,
            }),
            spot: Some(SpotDesc {
                position: [0.0, 2.0, 0.0],
                intensity: [5.0; 3],
                cone: Some(SpotCone {
                    direction: [0.0, -1.0, 0.0],
                    cutoff_angle: 30.0,
                    beam_width: 20.0,
                }),
            }),
        }
    }
}

/// As `volpt info` prints it: one line per light, or "none".
impl fmt::Display for LightsDesc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return write!(f, "none besides the environment");
        }
        let mut first = true;
        let mut sep = |f: &mut fmt::Formatter<'_>| {
            let s = if first { "" } else { "; " };
            first = false;
            write!(f, "{s}")
        };
        if let Some(sun) = &self.sun {
            sep(f)?;
            write!(
                f,
                "sun travelling along {:?}, irradiance {:?}, ",
                sun.direction, sun.irradiance
            )?;
            if sun.angular_radius > 0.0 {
                write!(
                    f,
                    "a disc of angular radius {} deg (next-event estimation weighted against the \
                     phase function)",
                    sun.angular_radius
                )?;
            } else {
                write!(f, "a delta direction")?;
            }
        }
        if let Some(spot) = &self.spot {
            sep(f)?;
            match spot.cone {
                None => write!(
                    f,
                    "point light at {:?}, intensity {:?}",
                    spot.position, spot.intensity
                )?,
                Some(c) => write!(
                    f,
                    "spot at {:?} shining along {:?}, intensity {:?}, cutoff {} deg, beam {} deg",
                    spot.position, c.direction, spot.intensity, c.cutoff_angle, c.beam_width
                )?,
            }
        }
        Ok(())
    }
}

/// One of a TOML scene's `[[lights]]`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum LightSpec {
    /// A distant light: `direction` is where its light travels.
    Sun {
        direction: [f32; 3],
        #[serde(default = "unit")]
        irradiance: OneOrThree,
        /// Degrees; 0 (default) for a delta direction.
        #[serde(default)]
        angular_radius: f32,
    },
    Point {
        position: [f32; 3],
        #[serde(default = "unit")]
        intensity: OneOrThree,
    },
    Spot {
        position: [f32; 3],
        /// Where the beam's centre points; or give `target`.
        direction: Option<[f32; 3]>,
        /// A point the beam's centre passes through, instead of `direction`.
        target: Option<[f32; 3]>,
        #[serde(default = "unit")]
        intensity: OneOrThree,
        /// Degrees (default 20, as Mitsuba).
        #[serde(default = "default_cutoff")]
        cutoff_angle: f32,
        /// Degrees (default 3/4 of the cutoff, as Mitsuba).
        beam_width: Option<f32>,
    },
}

fn unit() -> OneOrThree {
    OneOrThree::One(1.0)
}

fn default_cutoff() -> f32 {
    DEFAULT_CUTOFF
}

impl LightSpec {
    /// The scene's lights from its `[[lights]]`, checked.
    pub(crate) fn lights(specs: &[LightSpec], cx: &Cx<'_>) -> Result<LightsDesc, SceneError> {
        let mut desc = LightsDesc::default();
        for spec in specs {
            let second = |kind: &str| {
                cx.invalid(
                    "lights.type",
                    "at most one sun and one point or spot light",
                    format!("a second {kind}"),
                )
            };
            match spec {
                LightSpec::Sun {
                    direction,
                    irradiance,
                    angular_radius,
                } => {
                    if desc.sun.is_some() {
                        return Err(second("sun"));
                    }
                    desc.sun = Some(SunDesc {
                        direction: *direction,
                        irradiance: irradiance.rgb(),
                        angular_radius: *angular_radius,
                    });
                }
                LightSpec::Point {
                    position,
                    intensity,
                } => {
                    if desc.spot.is_some() {
                        return Err(second("point or spot light"));
                    }
                    desc.spot = Some(SpotDesc {
                        position: *position,
                        intensity: intensity.rgb(),
                        cone: None,
                    });
                }
                LightSpec::Spot {
                    position,
                    direction,
                    target,
                    intensity,
                    cutoff_angle,
                    beam_width,
                } => {
                    if desc.spot.is_some() {
                        return Err(second("point or spot light"));
                    }
                    let direction = match (direction, target) {
                        (Some(d), None) => *d,
                        (None, Some(t)) => [0, 1, 2].map(|i| t[i] - position[i]),
                        _ => {
                            return Err(cx.invalid(
                                "lights.direction",
                                "a spot's `direction` or its `target` (one of them)",
                                format!("direction {direction:?}, target {target:?}"),
                            ))
                        }
                    };
                    desc.spot = Some(SpotDesc {
                        position: *position,
                        intensity: intensity.rgb(),
                        cone: Some(SpotCone {
                            direction,
                            cutoff_angle: *cutoff_angle,
                            beam_width: beam_width.unwrap_or(SpotCone::default_beam(*cutoff_angle)),
                        }),
                    });
                }
            }
        }
        // Checked with the whole scene (`validate`).
        Ok(desc)
    }
}
