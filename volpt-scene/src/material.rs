//! Material-indexed volumes in a description: a table of materials (each with RGB `sigma_s`,
//! RGB `sigma_a` and Henyey-Greenstein `g`) and one material index per voxel
//! ([`volpt_core::material`]), as a TOML scene's `[[materials]]` spell them with an index grid in
//! any grid format volpt reads, or a folder of PNG slices whose colours name the materials
//! ([`crate::slices`]). Their checks, and their table as `volpt info` prints it.
//!
//! Units are the scene's: coefficients per world unit (a print's voxels are typically tens of
//! micrometres; give coefficients per millimetre with the box in millimetres).

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};
use volpt_core::material::{wide_indices, Material, MATERIAL_FLOATS, MAX_MATERIALS};
use volpt_core::Spectrum;

use crate::description::{Bounds, GridConvention, GridDesc, SampleLayout};
use crate::error::{MaterialProblem, SceneError};
use crate::phase::PhaseDesc;
use crate::toml_scene::OneOrThree;

/// One material of a table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialDesc {
    pub name: String,
    /// Scattering coefficient per channel, per world unit.
    pub sigma_s: [f32; 3],
    /// Absorption coefficient per channel, per world unit.
    pub sigma_a: [f32; 3],
    /// Henyey-Greenstein asymmetry, in (-1, 1).
    pub g: f32,
    /// The colour that names this material in a PNG slice stack (8-bit sRGB values as stored).
    pub colour: Option<[u8; 3]>,
}

impl MaterialDesc {
    /// The material's coefficients as the core's table holds them.
    pub fn material(&self) -> Material {
        Material::from_coefficients(self.sigma_s, self.sigma_a, self.g)
    }

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
        // The sum must be finite too: it is the extinction.
        if bad(&[0, 1, 2].map(|c| self.sigma_s[c] + self.sigma_a[c])) {
            return Some((
                "sigma_s + sigma_a",
                "a finite extinction",
                format!("{:?} + {:?}", self.sigma_s, self.sigma_a),
            ));
        }
        if !(self.g > -1.0 && self.g < 1.0) {
            return Some(("g", "a number in (-1, 1)", self.g.to_string()));
        }
        None
    }
}

/// A material-indexed volume: the table, and one index per voxel of `resolution` voxels tiling
/// `bounds` (x fastest), packed four to a word as [`volpt_core::MaterialGrid`] reads them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IndexedDesc {
    materials: Vec<MaterialDesc>,
    pub resolution: [u32; 3],
    pub bounds: Bounds,
    /// Not serialised: hashed on its own with the grids' values (the facade's fingerprint).
    #[serde(skip)]
    indices: Vec<u32>,
    /// The materials' rows as the core reads them ([`MATERIAL_FLOATS`] each), kept with them.
    #[serde(skip)]
    table: Vec<f32>,
}

impl IndexedDesc {
    /// The volume of `indices` (one per voxel, x fastest: bytes, or `u16`s for more than 256
    /// materials) over `bounds` with `materials`; `path` names the index grid's file in errors.
    /// Refuses a table of more than 65536 materials, a grid whose size is not the resolution's,
    /// and an index outside the table.
    pub fn new<I: MaterialIndex>(
        path: &Path,
        materials: Vec<MaterialDesc>,
        resolution: [u32; 3],
        bounds: Bounds,
        indices: &[I],
    ) -> Result<Self, SceneError> {
        let error = |problem| SceneError::Material {
            path: path.to_owned(),
            problem,
        };
        if materials.is_empty() || materials.len() > MAX_MATERIALS {
            return Err(error(MaterialProblem::TableSize {
                found: materials.len(),
            }));
        }
        if let Some((k, (field, expected, found))) = materials
            .iter()
            .enumerate()
            .find_map(|(k, m)| Some((k, m.problem()?)))
        {
            return Err(SceneError::InvalidScene {
                source_name: path.display().to_string(),
                field: format!("materials[{k}].{field}"),
                expected: expected.into(),
                found,
            });
        }
        let table = materials.iter().flat_map(|m| m.material().row()).collect();
        let mut desc = Self {
            materials,
            resolution,
            bounds,
            indices: Vec::new(),
            table,
        };
        desc.set_indices(indices).map_err(error)?;
        Ok(desc)
    }

    /// Replaces every voxel's index (a printing application's next iteration): `indices` holds
    /// one per voxel of the same resolution (bytes or `u16`s), each below the table's length. On
    /// an error the volume is left as it was.
    pub fn set_indices<I: MaterialIndex>(&mut self, indices: &[I]) -> Result<(), MaterialProblem> {
        let voxels = self.voxels();
        if indices.len() as u64 != voxels {
            return Err(MaterialProblem::GridSize {
                resolution: self.resolution,
                expected: voxels,
                found: indices.len() as u64,
            });
        }
        let count = self.materials.len();
        if let Some(i) = indices.iter().position(|&k| k.get() as usize >= count) {
            return Err(MaterialProblem::IndexOutOfTable {
                voxel: self.voxel(i as u64),
                index: indices[i].get(),
                materials: count,
            });
        }
        self.indices = pack(indices, wide_indices(count));
        Ok(())
    }

    /// The volume of an index grid read by one of volpt's grid readers (`grid`'s values must be
    /// the integers `0 .. materials.len()`).
    pub fn from_grid(
        path: &Path,
        materials: Vec<MaterialDesc>,
        grid: &GridDesc,
    ) -> Result<Self, SceneError> {
        let error = |problem| SceneError::Material {
            path: path.to_owned(),
            problem,
        };
        if grid.channels != 1 || grid.layout != SampleLayout::Dense {
            return Err(error(MaterialProblem::NotAnIndexGrid {
                what: format!(
                    "{} channels, {:?} samples (expected one channel of dense samples)",
                    grid.channels, grid.layout
                ),
            }));
        }
        let mut indices = Vec::with_capacity(grid.data.len());
        for (i, &v) in grid.data.iter().enumerate() {
            // An index is an integer: 2.5 or -1 is not a material (nor is NaN).
            if !(v >= 0.0 && v < MAX_MATERIALS as f32 && v == v.trunc()) {
                let voxel = [
                    (i as u64 % grid.resolution[0] as u64) as u32,
                    (i as u64 / grid.resolution[0] as u64 % grid.resolution[1] as u64) as u32,
                    (i as u64 / (grid.resolution[0] as u64 * grid.resolution[1] as u64)) as u32,
                ];
                return Err(error(MaterialProblem::NotAnIndex { voxel, value: v }));
            }
            indices.push(v as u16);
        }
        Self::new(path, materials, grid.resolution, grid.bounds, &indices)
    }

    /// Voxels in the grid.
    pub fn voxels(&self) -> u64 {
        self.resolution.iter().map(|&r| r as u64).product()
    }

    /// The voxel `(x, y, z)` of index `i` (x fastest).
    fn voxel(&self, i: u64) -> [u32; 3] {
        let [nx, ny, _] = self.resolution.map(|r| r as u64);
        [
            (i % nx) as u32,
            (i / nx % ny) as u32,
            (i / (nx * ny)) as u32,
        ]
    }

    /// The index of voxel `i` (x fastest).
    pub fn index(&self, i: u64) -> u32 {
        if wide_indices(self.materials.len()) {
            (self.indices[(i >> 1) as usize] >> ((i & 1) * 16)) & 0xffff
        } else {
            (self.indices[(i >> 2) as usize] >> ((i & 3) * 8)) & 0xff
        }
    }

    /// The indices, four bytes to a word (little end first; two `u16`s for more than 256
    /// materials), as the core's grid reads them.
    pub fn packed_indices(&self) -> &[u32] {
        &self.indices
    }

    /// The table's rows, [`MATERIAL_FLOATS`] per material.
    pub fn table(&self) -> &[f32] {
        &self.table
    }

    /// The materials, in index order.
    pub fn materials(&self) -> &[MaterialDesc] {
        &self.materials
    }

    /// Replaces material `k` (its index stays), if `material`'s numbers are usable: else says
    /// why, `(field, expected, found)`, and leaves the table as it was.
    pub fn set_material(
        &mut self,
        k: usize,
        material: MaterialDesc,
    ) -> Result<(), (&'static str, &'static str, String)> {
        if let Some(problem) = material.problem() {
            return Err(problem);
        }
        let row = material.material().row();
        self.table[k * MATERIAL_FLOATS..(k + 1) * MATERIAL_FLOATS].copy_from_slice(&row);
        self.materials[k] = material;
        Ok(())
    }

    /// How many voxels hold each material.
    pub fn histogram(&self) -> Vec<u64> {
        let mut counts = vec![0u64; self.materials.len()];
        for i in 0..self.voxels() {
            counts[self.index(i) as usize] += 1;
        }
        counts
    }

    /// The largest extinction channel of the materials the grid holds, unscaled.
    pub fn max_extinction(&self) -> f32 {
        self.histogram()
            .iter()
            .zip(&self.materials)
            .filter(|(&n, _)| n > 0)
            .map(|(_, m)| m.material().sigma_t.max_element())
            .fold(0.0, f32::max)
    }

    /// Whether the materials' asymmetries differ from 0 anywhere (the scene then renders with a
    /// Henyey-Greenstein variant whose `g` each collision replaces).
    pub fn anisotropic(&self) -> bool {
        self.materials.iter().any(|m| m.g != 0.0)
    }

    /// The medium's phase description: isotropic where every material's `g` is 0, else
    /// Henyey-Greenstein with the first non-zero `g`, which each collision replaces by its
    /// material's (`volpt_core::Medium::phase_g`). Not `g = 0`: the factory would specialise that
    /// to the isotropic phase, which has no asymmetry to replace.
    pub fn phase(&self) -> PhaseDesc {
        match self.materials.iter().find(|m| m.g != 0.0) {
            Some(m) => PhaseDesc::HenyeyGreenstein { g: m.g },
            None => PhaseDesc::Isotropic,
        }
    }

    /// The volume as the RGB grids of its materials' extinction (before the medium's scale)
    /// and albedo, voxel by voxel, cell-centred over its box (read nearest, they are the same
    /// medium): what Mitsuba 3, which has no material table, reads. 24 bytes a voxel.
    pub fn expanded_grids(&self) -> (GridDesc, GridDesc) {
        let rows: Vec<Material> = self.materials.iter().map(MaterialDesc::material).collect();
        let expand = |field: fn(&Material) -> Spectrum| GridDesc {
            resolution: self.resolution,
            channels: 3,
            bounds: self.bounds,
            convention: GridConvention::Cell,
            data: (0..self.voxels())
                .flat_map(|i| field(&rows[self.index(i) as usize]).to_array())
                .collect(),
            layout: SampleLayout::Dense,
        };
        (expand(|m| m.sigma_t), expand(|m| m.albedo))
    }

    /// Bytes on a GPU: one per voxel (two for more than 256 materials; rounded up to a word),
    /// and the table.
    pub fn device_bytes(&self) -> u64 {
        self.indices.len() as u64 * 4 + (self.materials.len() * MATERIAL_FLOATS * 4) as u64
    }
}

/// A material index as a caller holds it: a byte, or a `u16` for a table of more than 256.
pub trait MaterialIndex: Copy {
    /// The index's value.
    fn get(self) -> u32;
    /// Index `k`, which the caller knows fits.
    fn narrow(k: usize) -> Self;
}

impl MaterialIndex for u8 {
    fn get(self) -> u32 {
        self.into()
    }
    fn narrow(k: usize) -> Self {
        k as u8
    }
}

impl MaterialIndex for u16 {
    fn get(self) -> u32 {
        self.into()
    }
    fn narrow(k: usize) -> Self {
        k as u16
    }
}

/// The indices (each below the table's length, checked) packed as the core reads them: one byte
/// per voxel, four to a word, or where `wide` two bytes, two to a word; little end first.
fn pack<I: MaterialIndex>(indices: &[I], wide: bool) -> Vec<u32> {
    let (per_word, bits) = if wide { (2, 16) } else { (4, 8) };
    indices
        .chunks(per_word)
        .map(|c| {
            c.iter()
                .enumerate()
                .fold(0u32, |word, (j, k)| word | k.get() << (bits * j))
        })
        .collect()
}

/// The table as `volpt info` prints it: one line per material, with its voxel count.
pub struct InfoTable<'d>(pub &'d IndexedDesc);

impl fmt::Display for InfoTable<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = self.0;
        let counts = d.histogram();
        writeln!(
            f,
            "material-indexed {}x{}x{} voxels, bounds {:?} .. {:?}, {} materials; GPU memory {} bytes \
             ({} a voxel and the table)",
            d.resolution[0],
            d.resolution[1],
            d.resolution[2],
            d.bounds.min,
            d.bounds.max,
            d.materials.len(),
            d.device_bytes(),
            // More than 256 materials take u16 indices (`pack`).
            if d.materials.len() > 256 { "2 bytes" } else { "1 byte" }
        )?;
        for (k, (m, n)) in d.materials.iter().zip(counts).enumerate() {
            let t = m.material();
            write!(
                f,
                "  {k:>3} {:<12} sigma_s {:?} sigma_a {:?} sigma_t {:?} albedo {:?} g {} voxels {n}",
                m.name,
                m.sigma_s,
                m.sigma_a,
                t.sigma_t.to_array(),
                t.albedo.to_array(),
                m.g
            )?;
            if let Some(c) = m.colour {
                write!(f, " colour #{:02x}{:02x}{:02x}", c[0], c[1], c[2])?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

/// A TOML scene's `[[materials]]` entry: `sigma_s` and `sigma_a`, or `albedo` and `sigma_t`
/// (each one number or three), `g` (default 0) and, for PNG slices, the `colour` naming it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    pub sigma_s: Option<OneOrThree>,
    pub sigma_a: Option<OneOrThree>,
    pub sigma_t: Option<OneOrThree>,
    pub albedo: Option<OneOrThree>,
    #[serde(default)]
    pub g: f32,
    /// `[r, g, b]`, 0-255, or `"#rrggbb"`.
    pub colour: Option<Colour>,
}

/// A palette colour: `[r, g, b]` or `"#rrggbb"`.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Colour {
    Rgb([u8; 3]),
    Hex(String),
}

impl Colour {
    fn rgb(&self) -> Option<[u8; 3]> {
        match self {
            Colour::Rgb(c) => Some(*c),
            Colour::Hex(s) => {
                let hex = s.strip_prefix('#')?;
                if hex.len() != 6 || !hex.is_ascii() {
                    return None;
                }
                let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
                Some([byte(0)?, byte(2)?, byte(4)?])
            }
        }
    }
}

impl MaterialSpec {
    /// The material this entry describes; `invalid(field, expected, found)` makes the error of a
    /// field (`materials[k].field`).
    pub fn material(
        &self,
        invalid: &dyn Fn(&str, &str, String) -> SceneError,
    ) -> Result<MaterialDesc, SceneError> {
        let rgb = |v: Option<OneOrThree>| v.map(OneOrThree::rgb);
        let (sigma_s, sigma_a) = match (
            rgb(self.sigma_s),
            rgb(self.sigma_a),
            rgb(self.sigma_t),
            rgb(self.albedo),
        ) {
            (Some(s), Some(a), None, None) => (s, a),
            (None, None, Some(t), Some(albedo)) => {
                if albedo.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(invalid(
                        "albedo",
                        "components in [0, 1]",
                        format!("{albedo:?}"),
                    ));
                }
                let s = [0, 1, 2].map(|c| albedo[c] * t[c]);
                (s, [0, 1, 2].map(|c| t[c] - s[c]))
            }
            _ => {
                return Err(invalid(
                    "",
                    "sigma_s and sigma_a, or sigma_t and albedo",
                    "another combination".into(),
                ))
            }
        };
        let colour = match &self.colour {
            None => None,
            Some(c) => Some(c.rgb().ok_or_else(|| {
                invalid(
                    "colour",
                    "[r, g, b] of 0-255 or \"#rrggbb\"",
                    format!("{c:?}"),
                )
            })?),
        };
        let desc = MaterialDesc {
            name: self.name.clone(),
            sigma_s,
            sigma_a,
            g: self.g,
            colour,
        };
        if let Some((field, expected, found)) = desc.problem() {
            return Err(invalid(field, expected, found));
        }
        Ok(desc)
    }
}
