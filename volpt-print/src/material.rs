//! The material table of a print: each printer material's scattering and absorption (RGB, per
//! world unit of the scene: give them per millimetre with the voxel size in millimetres), its
//! Henyey-Greenstein `g`, and the palette colour that names it in a slice stack.
//!
//! The fields and their TOML spelling (`[[materials]]` with `name`, `sigma_s`, `sigma_a`, `g`,
//! `colour`) are those of volpt-scene's material table (the material-indexed volumes issue), so
//! that a print's `materials.toml` reads as that table. volpt-scene's `MaterialDesc` reached main
//! at the end of the session that wrote this; this type becomes it (its colour optional there,
//! required here) when the predictor moves onto material-indexed volumes.

use serde::{Deserialize, Serialize};

/// One printer material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    /// The colour that names this material in a slice stack (8-bit sRGB values as stored).
    pub colour: [u8; 3],
    /// Scattering coefficient per channel, per world unit.
    pub sigma_s: [f32; 3],
    /// Absorption coefficient per channel, per world unit.
    pub sigma_a: [f32; 3],
    /// Henyey-Greenstein asymmetry, in (-1, 1).
    #[serde(default)]
    pub g: f32,
}

impl Material {
    /// Why the material's numbers are not ones a renderer can use, if they are not: `(field,
    /// expected, found)`.
    pub fn problem(&self) -> Option<(&'static str, &'static str, String)> {
        let bad = |v: &[f32; 3]| v.iter().any(|c| !(c.is_finite() && *c >= 0.0));
        if bad(&self.sigma_s) {
            return Some((
                "sigma_s",
                "three finite numbers >= 0",
                format!("{:?}", self.sigma_s),
            ));
        }
        if bad(&self.sigma_a) {
            return Some((
                "sigma_a",
                "three finite numbers >= 0",
                format!("{:?}", self.sigma_a),
            ));
        }
        if !(self.g > -1.0 && self.g < 1.0) {
            return Some(("g", "a number in (-1, 1)", self.g.to_string()));
        }
        None
    }
}

/// Where each ink of the five-tone process sits in a material table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inks {
    pub cyan: u8,
    pub magenta: u8,
    pub yellow: u8,
    pub black: u8,
    pub white: u8,
}

impl Inks {
    /// The names [`Inks::find`] looks for, in [`Inks::indices`]' order.
    pub const NAMES: [&'static str; 5] = ["cyan", "magenta", "yellow", "black", "white"];

    /// The inks of a table whose materials are named `cyan`, `magenta`, `yellow`, `black` and
    /// `white` (case-insensitive); the name missing, if one is.
    pub fn find(materials: &[Material]) -> Result<Inks, &'static str> {
        let mut found = [0u8; 5];
        for (slot, name) in found.iter_mut().zip(Self::NAMES) {
            let k = materials
                .iter()
                .position(|m| m.name.eq_ignore_ascii_case(name))
                .ok_or(name)?;
            *slot = u8::try_from(k).map_err(|_| name)?;
        }
        let [cyan, magenta, yellow, black, white] = found;
        Ok(Inks {
            cyan,
            magenta,
            yellow,
            black,
            white,
        })
    }

    /// The table indices in the order cyan, magenta, yellow, black, white.
    pub fn indices(&self) -> [u8; 5] {
        [self.cyan, self.magenta, self.yellow, self.black, self.white]
    }
}

/// A material table file (`--materials M.toml`): `[[materials]]` as in a slice stack's
/// `materials.toml`, and optionally the print's `voxel_size`. A stack's own `materials.toml` is
/// one: its `width`, `height` and `layers` are taken and not used (a compensation's print has the
/// target's size and the depth asked for).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    pub voxel_size: Option<[f64; 3]>,
    pub materials: Vec<Material>,
    #[serde(default, rename = "width")]
    _width: Option<u32>,
    #[serde(default, rename = "height")]
    _height: Option<u32>,
    #[serde(default, rename = "layers")]
    _layers: Option<u32>,
}

impl MaterialFile {
    /// Reads and checks the table in `path` (every material's numbers, distinct palette colours).
    pub fn read(path: &std::path::Path) -> Result<MaterialFile, crate::PrintError> {
        let text = volpt_scene::limits::read_text(path)?;
        let file: MaterialFile = toml::from_str(&text).map_err(|e| crate::PrintError::Toml {
            path: path.to_path_buf(),
            source: Box::new(e),
        })?;
        let invalid = |field: String, expected: &str, found: String| crate::PrintError::Invalid {
            path: path.to_path_buf(),
            field,
            expected: expected.into(),
            found,
        };
        for (k, m) in file.materials.iter().enumerate() {
            if let Some((field, expected, found)) = m.problem() {
                return Err(invalid(format!("materials[{k}].{field}"), expected, found));
            }
        }
        crate::print::check_table(&file.materials)
            .map_err(|(field, expected, found)| invalid(field.into(), &expected, found))?;
        if let Some(size) = file
            .voxel_size
            .filter(|s| !s.iter().all(|v| v.is_finite() && *v > 0.0))
        {
            return Err(invalid(
                "voxel_size".into(),
                "three finite sizes > 0",
                format!("{size:?}"),
            ));
        }
        Ok(file)
    }
}
