//! A print's material table: volpt-scene's [`MaterialDesc`] (each printer material's RGB
//! `sigma_s`, `sigma_a` per world unit of the scene, its Henyey-Greenstein `g`, and the palette
//! `colour` that names it in a slice stack), read from TOML by volpt-scene's `[[materials]]`
//! reader ([`MaterialSpec`]: `sigma_s`/`sigma_a` or `sigma_t`/`albedo`, `colour` as `[r, g, b]`
//! or `"#rrggbb"`). What is a print's own: where its five inks are ([`Inks`]), and that every
//! material has a distinct colour ([`crate::print::check_table`]).

use serde::Deserialize;
use volpt_scene::material::{MaterialDesc, MaterialSpec};
use volpt_scene::SceneError;

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
    pub fn find(materials: &[MaterialDesc]) -> Result<Inks, &'static str> {
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
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialFile {
    pub voxel_size: Option<[f64; 3]>,
    pub materials: Vec<MaterialDesc>,
}

/// `M.toml` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spelt {
    voxel_size: Option<[f64; 3]>,
    materials: Vec<MaterialSpec>,
    #[serde(default, rename = "width")]
    _width: Option<u32>,
    #[serde(default, rename = "height")]
    _height: Option<u32>,
    #[serde(default, rename = "layers")]
    _layers: Option<u32>,
}

/// The materials of a table file's `[[materials]]`, each checked by volpt-scene's reader, then as
/// a print's table ([`crate::print::check_table`]: a distinct colour each).
pub(crate) fn read_table(
    path: &std::path::Path,
    specs: &[MaterialSpec],
) -> Result<Vec<MaterialDesc>, crate::PrintError> {
    let invalid = |field: String, expected: &str, found: String| crate::PrintError::Invalid {
        path: path.to_path_buf(),
        field,
        expected: expected.into(),
        found,
    };
    let materials = specs
        .iter()
        .enumerate()
        .map(|(k, spec)| {
            spec.material(&|field, expected, found| {
                let field = match field {
                    "" => format!("materials[{k}]"),
                    f => format!("materials[{k}].{f}"),
                };
                SceneError::InvalidScene {
                    source_name: path.display().to_string(),
                    field,
                    expected: expected.into(),
                    found,
                }
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    crate::print::check_table(&materials)
        .map_err(|(field, expected, found)| invalid(field.into(), &expected, found))?;
    Ok(materials)
}

impl MaterialFile {
    /// Reads and checks the table in `path` (every material's numbers, distinct palette colours).
    pub fn read(path: &std::path::Path) -> Result<MaterialFile, crate::PrintError> {
        let text = volpt_scene::limits::read_text(path)?;
        let file: Spelt = toml::from_str(&text).map_err(|e| crate::PrintError::Toml {
            path: path.to_path_buf(),
            source: Box::new(e),
        })?;
        let materials = read_table(path, &file.materials)?;
        if let Some(size) = file
            .voxel_size
            .filter(|s| !s.iter().all(|v| v.is_finite() && *v > 0.0))
        {
            return Err(crate::PrintError::Invalid {
                path: path.to_path_buf(),
                field: "voxel_size".into(),
                expected: "three finite sizes > 0".into(),
                found: format!("{size:?}"),
            });
        }
        Ok(MaterialFile {
            voxel_size: file.voxel_size,
            materials,
        })
    }
}
