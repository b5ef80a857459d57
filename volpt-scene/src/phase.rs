//! The phase function, everything about its descriptions in one place: what a description says
//! ([`PhaseDesc`]), how Mitsuba's `<phase>` and a TOML scene's `[phase]` spell it, its checks, its
//! Mitsuba 3 export, how `volpt info` prints it, the numbers a scene takes between renders, one
//! example of each kind, and how each registry phase part is built from it ([`FromDescription`]):
//! isotropic where Henyey-Greenstein's asymmetry is 0, Henyey-Greenstein as the general one.

use std::fmt;

use serde::{Deserialize, Serialize};
use volpt_core::{HenyeyGreenstein, Isotropic};

use crate::error::SceneError;
use crate::from_description::FromDescription;
use crate::mitsuba::plugin::{quoted, Ctx, Plugin};
use crate::mitsuba::xml::Element;
use crate::param::NumberParam;
use crate::simplification::Simplification;
use crate::toml_scene::Cx;
use crate::validate::invalid;

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum PhaseDesc {
    Isotropic,
    HenyeyGreenstein { g: f32 },
}

/// Mitsuba's default asymmetry for `hg` (0.6 and 3 alike).
const DEFAULT_G: f32 = 0.8;

/// Henyey-Greenstein's asymmetry: |g| = 1 is a delta distribution, which HG sampling cannot
/// represent.
fn asymmetry(g: f32) -> bool {
    g > -1.0 && g < 1.0
}

impl PhaseDesc {
    /// Mitsuba's `<phase>`: `hg` or `isotropic`.
    pub(crate) fn from_mitsuba(el: &Element, ctx: &Ctx<'_>) -> Result<Self, SceneError> {
        let p = Plugin::new(el, ctx);
        let phase = match p.kind()? {
            "isotropic" => PhaseDesc::Isotropic,
            "hg" => {
                let g = match p.find(&["g"])? {
                    None => DEFAULT_G,
                    Some(arg) => {
                        let g = arg.float()?;
                        if !asymmetry(g) {
                            return Err(arg.invalid("a number in (-1, 1)", quoted(arg.value()?)));
                        }
                        g
                    }
                };
                PhaseDesc::HenyeyGreenstein { g }
            }
            _ => return Err(p.unsupported("volpt's phase functions are hg and isotropic")),
        };
        p.finish()?;
        Ok(phase)
    }

    /// Checks the numbers a renderer relies on; `source` names the scene in errors.
    pub(crate) fn check(&self, source: &str) -> Result<(), SceneError> {
        match *self {
            PhaseDesc::Isotropic => Ok(()),
            PhaseDesc::HenyeyGreenstein { g } if asymmetry(g) => Ok(()),
            PhaseDesc::HenyeyGreenstein { g } => Err(invalid(
                source,
                "phase g",
                "a number in (-1, 1)",
                g.to_string(),
            )),
        }
    }

    /// The `<phase>` element of a Mitsuba 3 medium.
    pub(crate) fn to_mitsuba3(self) -> String {
        match self {
            PhaseDesc::Isotropic => "<phase type=\"isotropic\"/>".to_owned(),
            PhaseDesc::HenyeyGreenstein { g } => {
                format!("<phase type=\"hg\">\n                <float name=\"g\" value=\"{g}\"/>\n            </phase>")
            }
        }
    }

    /// The numbers of the phase a scene takes between renders.
    pub const PARAMS: &'static [NumberParam] = &[NumberParam {
        key: "phase.g",
        about: "Henyey-Greenstein's mean cosine in (-1, 1); 0 is isotropic",
        accepts: asymmetry,
        expected: "a number in (-1, 1)",
    }];

    /// The value of parameter `key`, if it is one of [`PhaseDesc::PARAMS`].
    pub fn param(&self, key: &str) -> Option<f32> {
        match key {
            "phase.g" => Some(match *self {
                PhaseDesc::Isotropic => 0.0,
                PhaseDesc::HenyeyGreenstein { g } => g,
            }),
            _ => None,
        }
    }

    /// Sets parameter `key` to `value`, which its [`NumberParam::accepts`]; whether `key` is one
    /// of [`PhaseDesc::PARAMS`] (the phase is left alone if not).
    pub fn set_param(&mut self, key: &str, value: f32) -> bool {
        match key {
            // g = 0 stays a Henyey-Greenstein phase: the factory picks the isotropic part for it,
            // and `volpt info` says so.
            "phase.g" => *self = PhaseDesc::HenyeyGreenstein { g: value },
            _ => return false,
        }
        true
    }

    /// One description of each kind; together they select every registry phase part (tests
    /// cover the registry with them).
    pub fn examples() -> Vec<Self> {
        vec![PhaseDesc::Isotropic, PhaseDesc::HenyeyGreenstein { g: 0.6 }]
    }
}

/// As `volpt info` prints it.
impl fmt::Display for PhaseDesc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PhaseDesc::Isotropic => f.write_str("isotropic"),
            PhaseDesc::HenyeyGreenstein { g } => write!(f, "Henyey-Greenstein, g {g}"),
        }
    }
}

/// A TOML scene's `[phase]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseSpec {
    /// Henyey-Greenstein asymmetry; absent means isotropic.
    pub g: Option<f32>,
}

impl PhaseSpec {
    pub(crate) fn phase(&self, cx: &Cx<'_>) -> Result<PhaseDesc, SceneError> {
        match self.g {
            None => Ok(PhaseDesc::Isotropic),
            Some(g) if asymmetry(g) => Ok(PhaseDesc::HenyeyGreenstein { g }),
            Some(g) => Err(cx.invalid("phase.g", "a value in (-1, 1)", g)),
        }
    }
}

impl FromDescription<'_> for Isotropic {
    type Input = PhaseDesc;

    fn specialised(input: &PhaseDesc, fired: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match *input {
            PhaseDesc::Isotropic => Some(Isotropic),
            PhaseDesc::HenyeyGreenstein { g: 0.0 } => {
                fired(Simplification::ZeroAsymmetry);
                Some(Isotropic)
            }
            PhaseDesc::HenyeyGreenstein { .. } => None,
        }
    }

    fn general(_: &PhaseDesc) -> Option<Self> {
        None
    }
}

impl FromDescription<'_> for HenyeyGreenstein {
    type Input = PhaseDesc;

    fn specialised(input: &PhaseDesc, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match *input {
            PhaseDesc::HenyeyGreenstein { g } => Some(HenyeyGreenstein { g }),
            PhaseDesc::Isotropic => None,
        }
    }

    /// Isotropic scattering is Henyey-Greenstein with g = 0.
    fn general(input: &PhaseDesc) -> Option<Self> {
        Some(match *input {
            PhaseDesc::Isotropic => HenyeyGreenstein { g: 0.0 },
            PhaseDesc::HenyeyGreenstein { g } => HenyeyGreenstein { g },
        })
    }
}
