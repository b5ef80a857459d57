//! The medium, everything about its descriptions in one place: what a description says
//! ([`MediumDesc`]: its density, albedo, grid lookup and storage; its phase function is
//! [`crate::phase`]'s), how Mitsuba's `<medium>` and a TOML scene's `[albedo]` spell it (a TOML
//! scene's density is its `[volume]` grid file), its checks, its Mitsuba 3 export, how `volpt info`
//! prints it, the numbers a scene takes between renders, the values serde leaves out, one example
//! of each kind, and how each registry medium part is built from it ([`FromDescription`]): a
//! homogeneous medium where density and albedo are constants, else a grid medium whose reads
//! ([`GridReads`]) are the ones the description's lookup and storage ask for ([`ReadsRule`]).

use std::fmt;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use volpt_core::grid::{
    AnyLayout, DenseTrilinear, Grid, GridLookup as CoreLookup, GridMapping, GridReads, TexelFormat,
    TextureTrilinear,
};
use volpt_core::{
    Aabb, ChromaticMedium, ConstantAlbedo, GridAlbedo, GridMedium, HomogeneousMedium, MaterialGrid,
    Spectrum, Vec3,
};

use crate::description::{Bounds, GridConvention, GridDesc, SampleLayout, SceneDescription};
use crate::error::SceneError;
use crate::from_description::FromDescription;
use crate::material::{IndexedDesc, InfoTable, MaterialDesc};
use crate::mitsuba::export::rgb_element;
use crate::mitsuba::plugin::{quoted, Arg, Ctx, Plugin};
use crate::mitsuba::preprocess::Dialect;
use crate::mitsuba::volume::{constant_error, volume, Filter, Role, VolumeValue};
use crate::mitsuba::xml::Element;
use crate::phase::PhaseDesc;
use crate::simplification::Simplification;
use crate::toml_scene::{Cx, OneOrThree};
use crate::transfer::TransferFunction;
use crate::validate::{check_grid, CheckedData};

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MediumDesc {
    /// Density; the extinction coefficient is `scale * density`.
    pub density: DensityDesc,
    pub scale: f32,
    pub albedo: AlbedoDesc,
    pub phase: PhaseDesc,
    /// How the medium's grids are reconstructed between their samples.
    pub lookup: GridLookup,
    /// How a GPU stores the medium's grids (a renderer's choice, which the description carries
    /// so that the kernel chosen for the scene can read it).
    pub storage: GridStorage,
}

/// How a GPU stores a medium's grids.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum GridStorage {
    /// Samples in x-fastest order.
    #[default]
    Dense,
    /// 8^3-sample bricks, each contiguous: fewer bus transactions for volumes read across PCIe.
    Bricked,
}

/// How a grid is reconstructed between its samples (Mitsuba 3's `filter_type`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum GridLookup {
    /// Trilinear interpolation of the eight samples around a point.
    #[default]
    Trilinear,
    /// The value of the nearest sample.
    Nearest,
    /// Trilinear filtering by a GPU's texture unit, whose weights have 8 fractional bits (the CPU
    /// computes the same filter): an approximation of `Trilinear`, one instruction per lookup.
    Texture,
    /// `Texture` of samples held in half precision (rounded toward zero; at most 65504).
    TextureHalf,
    /// One of the eight samples around a point, chosen with probability equal to its trilinear
    /// weight: an unbiased estimate of `Trilinear` for one read (on a GPU through the texture
    /// unit, one texel unfiltered; bricked grids in software).
    Stochastic,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum DensityDesc {
    Constant(f32),
    /// One channel (a grey extinction), or three: a density per channel, a chromatic extinction
    /// (Mitsuba 3's RGB `sigma_t` `gridvolume`; [`volpt_core::ChromaticMedium::per_channel`]).
    /// The readers store a three-channel grid whose channels agree in every sample as one
    /// channel ([`grey_if_equal`]).
    Grid(GridDesc),
    /// A constant density per channel: a chromatic extinction, `scale * rgb` (milk, skin, a
    /// print's resin; [`volpt_core::ChromaticMedium`]). Equal channels render as `Constant`.
    Rgb([f32; 3]),
    /// A material-indexed volume ([`crate::material`]): each voxel's material gives its
    /// extinction (times `scale`), albedo and phase asymmetry; the medium's own albedo is not read.
    Indexed(IndexedDesc),
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum AlbedoDesc {
    Constant([f32; 3]),
    /// A 3-channel grid (a 1-channel grid is expanded to grey RGB by the loader).
    Grid(GridDesc),
}

/// Mitsuba 3's defaults for `sigma_t` and `albedo`.
const DEFAULT_SIGMA_T: f32 = 1.0;
const DEFAULT_ALBEDO: f32 = 0.75;

/// Writes a grid's file for a Mitsuba 3 scene and returns the `gridvolume` that reads it; its
/// arguments: the grid, what it holds, Mitsuba's parameter, its `filter_type`.
pub(crate) type GridWriter<'a> =
    dyn FnMut(&GridDesc, &str, &str, &str) -> Result<String, SceneError> + 'a;

impl MediumDesc {
    /// Mitsuba's interior `<medium>`: `homogeneous` or `heterogeneous`, with its phase function.
    ///
    /// The extinction may differ between R, G and B (a chromatic medium): an RGB constant, or a
    /// three-channel `gridvolume` (a density per channel, scaled by `scale`). Parameter names differ between generations (Mitsuba 0.6 `sigmaA`,
    /// `sigmaS`, `density`; Mitsuba 3 `sigma_t`, `albedo`) and both are accepted in either. Where
    /// a parameter is absent, Mitsuba 3's defaults apply (extinction 1, albedo 0.75); Mitsuba 0.6
    /// has material-preset defaults volpt does not carry, so there it must be given.
    pub(crate) fn from_mitsuba(el: &Element, ctx: &Ctx<'_>) -> Result<Self, SceneError> {
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
        if kind == "heterogeneous" {
            if let Some(arg) = p.find(&["material"])? {
                return Err(SceneError::Unsupported {
                    path: arg.written.file.to_path_buf(),
                    line: arg.written.line,
                    what: arg.written.describe(),
                    reason: "material presets are read for homogeneous media (a preset is \
                             one constant extinction)"
                        .into(),
                });
            }
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
        let (density, albedo, lookup) = if kind == "homogeneous" {
            let (density, albedo) = homogeneous(&p)?;
            (density, albedo, GridLookup::Trilinear)
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
            lookup,
            storage: Default::default(),
        })
    }
}

/// A density grid of three channels that agree in every sample as the grey grid it is (one
/// channel): a chromatic medium whose channels are equal renders as a grey one. Other grids are
/// returned as they are.
pub(crate) fn grey_if_equal(grid: GridDesc) -> GridDesc {
    let grey = grid.channels == 3
        && grid.layout == SampleLayout::Dense
        && grid
            .data
            .chunks_exact(3)
            .all(|v| v[0].to_bits() == v[1].to_bits() && v[0].to_bits() == v[2].to_bits());
    if !grey {
        return grid;
    }
    GridDesc {
        channels: 1,
        data: grid.data.iter().step_by(3).copied().collect(),
        ..grid
    }
}

/// A preset's extinction and albedo ([`crate::mitsuba::presets`]).
fn from_preset(sigma_s: [f32; 3], sigma_a: [f32; 3]) -> (DensityDesc, AlbedoDesc) {
    let t = [0, 1, 2].map(|c| sigma_a[c] + sigma_s[c]);
    let albedo = [0, 1, 2].map(|c| if t[c] > 0.0 { sigma_s[c] / t[c] } else { 0.0 });
    (extinction(t), AlbedoDesc::Constant(albedo))
}

fn homogeneous(p: &Plugin<'_>) -> Result<(DensityDesc, AlbedoDesc), SceneError> {
    let sigma_a = p.find(&["sigmaA", "sigma_a"])?;
    let sigma_s = p.find(&["sigmaS", "sigma_s"])?;
    let sigma_t = p.find(&["sigmaT", "sigma_t"])?;
    let albedo = p.find(&["albedo"])?;
    if let Some(arg) = p.find(&["material"])? {
        if let Some(other) = sigma_a.or(sigma_s).or(sigma_t).or(albedo) {
            return Err(other.invalid(
                "either a preset material or coefficients",
                "both (as Mitsuba 0.6 refuses)",
            ));
        }
        let name = arg.string()?;
        let Some((s, a)) = crate::mitsuba::presets::preset(name) else {
            return Err(arg.invalid(
                &format!(
                    "one of Mitsuba 0.6's presets ({})",
                    crate::mitsuba::presets::preset_names()
                ),
                quoted(name),
            ));
        };
        return Ok(from_preset(s, a));
    }
    if p.ctx.dialect == Dialect::Mitsuba06 && sigma_a.or(sigma_s).or(sigma_t).or(albedo).is_none() {
        // Mitsuba 0.6's medium without coefficients is its default preset.
        let (s, a) = crate::mitsuba::presets::preset(crate::mitsuba::presets::DEFAULT_PRESET)
            .expect("the default preset is in the table");
        return Ok(from_preset(s, a));
    }
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
            let albedo = [0, 1, 2].map(|c| if t[c] > 0.0 { s[c] / t[c] } else { 0.0 });
            Ok((extinction(t), AlbedoDesc::Constant(albedo)))
        }
        (Some(one), None) | (None, Some(one)) => {
            Err(one.invalid("sigmaA and sigmaS given together", "only one of them"))
        }
        (None, None) => {
            let sigma_t = match sigma_t {
                Some(arg) => extinction(non_negative(&arg, constant(p, &arg)?)?),
                None => DensityDesc::Constant(default_for(
                    p,
                    DEFAULT_SIGMA_T,
                    "<float name=\"sigma_t\"> (or sigmaA and sigmaS)",
                )?),
            };
            let albedo = match albedo {
                Some(arg) => in_unit_range(&arg, constant(p, &arg)?)?,
                None => [default_for(p, DEFAULT_ALBEDO, "<rgb name=\"albedo\">")?; 3],
            };
            Ok((sigma_t, AlbedoDesc::Constant(albedo)))
        }
    }
}

/// A heterogeneous medium's extinction and albedo, and how its grids are read: nearest where
/// every grid's `filter_type` says so (volpt reads a medium's grids one way), else trilinearly
/// (grids whose filters differ are warned about).
fn heterogeneous(p: &Plugin<'_>) -> Result<(DensityDesc, AlbedoDesc, GridLookup), SceneError> {
    let mut filters = Vec::new();
    let density = match p.find(&["density", "sigma_t"])? {
        None => DensityDesc::Constant(default_for(
            p,
            DEFAULT_SIGMA_T,
            "<volume name=\"density\">",
        )?),
        Some(arg) => match volume(&arg, p.ctx, Role::Density)? {
            VolumeValue::Grid(grid, filter) => {
                filters.push(filter);
                DensityDesc::Grid(grey_if_equal(grid))
            }
            VolumeValue::Constant(v) => extinction(non_negative(&arg, v)?),
        },
    };
    let albedo = match p.find(&["albedo"])? {
        None => {
            AlbedoDesc::Constant([default_for(p, DEFAULT_ALBEDO, "<volume name=\"albedo\">")?; 3])
        }
        Some(arg) => match volume(&arg, p.ctx, Role::Albedo)? {
            VolumeValue::Grid(grid, filter) => {
                filters.push(filter);
                AlbedoDesc::Grid(grid)
            }
            VolumeValue::Constant(v) => AlbedoDesc::Constant(in_unit_range(&arg, v)?),
        },
    };
    let lookup = match filters[..] {
        [Filter::Nearest] | [Filter::Nearest, Filter::Nearest] => GridLookup::Nearest,
        [Filter::Trilinear, Filter::Nearest] | [Filter::Nearest, Filter::Trilinear] => {
            tracing::warn!(
                "{}:{}: the medium's grids have different filter_type values: volpt reads both \
                 trilinearly",
                p.el.file.display(),
                p.el.line
            );
            GridLookup::Trilinear
        }
        _ => GridLookup::Trilinear,
    };
    p.warn_unless(
        &["method"],
        "woodcock",
        "delta (Woodcock) tracking, which is unbiased",
    )?;
    Ok((density, albedo, lookup))
}

/// A constant parameter of a homogeneous medium (a grid would need a heterogeneous one).
fn constant(p: &Plugin<'_>, arg: &Arg<'_>) -> Result<[f32; 3], SceneError> {
    match volume(arg, p.ctx, Role::Density)? {
        VolumeValue::Constant(v) => Ok(v),
        VolumeValue::Grid(..) => Err(SceneError::Unsupported {
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
            "{what} (Mitsuba 0.6 would fall back to a material preset, which volpt reads for \
             homogeneous media only)"
        ))),
    }
}

/// A constant extinction: grey where R, G and B agree (to rounding), else chromatic.
fn extinction(v: [f32; 3]) -> DensityDesc {
    let max = v.iter().fold(0.0f32, |m, c| m.max(c.abs()));
    if v.iter().all(|c| (c - v[0]).abs() <= 1e-6 * max) {
        DensityDesc::Constant(v[0])
    } else {
        DensityDesc::Rgb(v)
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

/// A TOML scene's `[albedo]` (its density is `[volume]`'s grid).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlbedoSpec {
    /// A transfer function file (docs/guide.md, "Transfer functions") applied to the normalised density.
    pub transfer_function: Option<String>,
    /// A constant albedo, grey or RGB (default 0.9 grey, unless a transfer function is given).
    pub value: Option<OneOrThree>,
    /// A vec3 grid of the volume's `.vdb` file holding the albedo (the thesis's RGB albedo grid).
    pub grid: Option<String>,
}

impl AlbedoSpec {
    /// The albedo `[albedo]` describes: `grid` where it names one (read from the volume's file),
    /// a transfer function applied to the `density` grid, or a constant; `resolve` makes a path
    /// of the file relative to the scene's.
    pub(crate) fn albedo(
        &self,
        cx: &Cx<'_>,
        grid: Option<GridDesc>,
        density: &GridDesc,
        resolve: &dyn Fn(&str, &str) -> Result<PathBuf, SceneError>,
    ) -> Result<AlbedoDesc, SceneError> {
        Ok(match (&self.transfer_function, self.value) {
            _ if grid.is_some() => AlbedoDesc::Grid(grid.unwrap()),
            (Some(_), Some(_)) => {
                return Err(cx.invalid("albedo", "either transfer_function or value", "both"))
            }
            (Some(tf), None) => {
                let tf = TransferFunction::read(&resolve(tf, "albedo.transfer_function")?)?;
                AlbedoDesc::Grid(tf.apply(density))
            }
            (None, value) => {
                let rgb = value.map_or([0.9; 3], OneOrThree::rgb);
                if rgb.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(cx.invalid(
                        "albedo.value",
                        "components in [0, 1]",
                        format!("{rgb:?}"),
                    ));
                }
                AlbedoDesc::Constant(rgb)
            }
        })
    }
}

impl MediumDesc {
    /// Checks the numbers a renderer relies on (`checked`: the grids' values as checked when the
    /// scene was assembled, not read again); `invalid` makes the error of a field. Returns the
    /// largest density (delta tracking's majorant over the scale) and what the grids held.
    pub(crate) fn check(
        &self,
        checked: Option<CheckedData>,
        invalid: &impl Fn(&str, &str, String) -> SceneError,
    ) -> Result<(f32, CheckedData), SceneError> {
        if !(self.scale.is_finite() && self.scale >= 0.0) {
            return Err(invalid(
                "medium scale",
                "a finite number >= 0",
                self.scale.to_string(),
            ));
        }
        let max_density = match &self.density {
            DensityDesc::Constant(d) => {
                if !(d.is_finite() && *d >= 0.0) {
                    return Err(invalid(
                        "medium density",
                        "a finite number >= 0",
                        d.to_string(),
                    ));
                }
                *d
            }
            DensityDesc::Rgb(rgb) => {
                if !rgb.iter().all(|d| d.is_finite() && *d >= 0.0) {
                    return Err(invalid(
                        "medium density",
                        "three finite numbers >= 0",
                        format!("{rgb:?}"),
                    ));
                }
                rgb.iter().copied().fold(0.0, f32::max)
            }
            DensityDesc::Indexed(indexed) => {
                if let Some((k, (field, expected, found))) = indexed
                    .materials()
                    .iter()
                    .enumerate()
                    .find_map(|(k, m)| Some((k, m.problem()?)))
                {
                    return Err(invalid(&format!("materials[{k}].{field}"), expected, found));
                }
                if matches!(self.albedo, AlbedoDesc::Grid(_)) {
                    return Err(invalid(
                        "medium albedo",
                        "the materials' own albedos (no albedo grid beside a material-indexed volume)",
                        "an albedo grid".into(),
                    ));
                }
                indexed.max_extinction()
            }
            DensityDesc::Grid(grid) => match checked {
                Some(data) => data.largest_density,
                None => check_grid(grid, "density grid", f32::MAX, invalid)?,
            },
        };
        let largest_density = match &self.density {
            DensityDesc::Constant(_) | DensityDesc::Rgb(_) | DensityDesc::Indexed(_) => 0.0,
            DensityDesc::Grid(_) => max_density,
        };
        let mut largest_albedo = 0.0;
        match &self.albedo {
            AlbedoDesc::Constant(rgb) => {
                if !rgb.iter().all(|a| (0.0..=1.0).contains(a)) {
                    return Err(invalid(
                        "medium albedo",
                        "three numbers in [0, 1]",
                        format!("{rgb:?}"),
                    ));
                }
            }
            AlbedoDesc::Grid(grid) => {
                largest_albedo = match checked {
                    Some(data) => data.largest_albedo,
                    None => check_grid(grid, "albedo grid", 1.0, invalid)?,
                };
            }
        }
        let sparse = self.grids().any(|(_, g)| g.layout == SampleLayout::Sparse);
        let plain_reads =
            self.lookup == GridLookup::Trilinear && self.storage == GridStorage::Dense;
        let chromatic_grids = match &self.density {
            DensityDesc::Rgb(_) => self.grids().next().is_some(),
            DensityDesc::Grid(g) => g.channels == 3,
            DensityDesc::Constant(_) | DensityDesc::Indexed(_) => false,
        };
        let chromatic_reads = plain_reads
            || (self.lookup == GridLookup::Nearest && self.storage == GridStorage::Dense);
        if chromatic_grids && (sparse || !chromatic_reads) {
            return Err(invalid(
                "grid lookup",
                "trilinear or nearest lookups of dense grids beside a chromatic extinction",
                format!("{:?} lookups, {:?} storage", self.lookup, self.storage),
            ));
        }
        if sparse && matches!(self.lookup, GridLookup::Texture | GridLookup::TextureHalf) {
            return Err(invalid(
                "grid lookup",
                "trilinear, stochastic or nearest lookups for a sparse grid (textures hold dense grids; \
                 read the VDB dense with sparse = \"never\" to use them)",
                format!("{:?}", self.lookup),
            ));
        }
        Ok((
            max_density,
            CheckedData {
                largest_density,
                largest_albedo,
            },
        ))
    }

    /// The largest extinction of the medium (delta tracking's majorant).
    pub fn max_extinction(&self) -> f32 {
        match &self.density {
            DensityDesc::Constant(density) => self.scale * density,
            DensityDesc::Rgb(rgb) => self.scale * rgb.iter().copied().fold(0.0, f32::max),
            DensityDesc::Indexed(indexed) => self.scale * indexed.max_extinction(),
            DensityDesc::Grid(grid) => self.scale * grid.max_value(),
        }
    }

    /// The largest density and the largest albedo component, each with its name (`"density"`,
    /// `"albedo"`): a constant's own, a grid's as `checked` found it.
    pub fn largest_values(&self, checked: CheckedData) -> [(&'static str, f32); 2] {
        [
            (
                "density",
                match &self.density {
                    DensityDesc::Constant(v) => *v,
                    DensityDesc::Rgb(rgb) => rgb.iter().copied().fold(0.0, f32::max),
                    DensityDesc::Indexed(indexed) => indexed.max_extinction(),
                    DensityDesc::Grid(_) => checked.largest_density,
                },
            ),
            (
                "albedo",
                match &self.albedo {
                    AlbedoDesc::Constant(rgb) => rgb.iter().copied().fold(0.0, f32::max),
                    AlbedoDesc::Grid(_) => checked.largest_albedo,
                },
            ),
        ]
    }

    /// The medium's grids, each with what it holds (`"density"`, `"albedo"`), in that order.
    pub fn grids(&self) -> impl Iterator<Item = (&'static str, &GridDesc)> {
        let density = match &self.density {
            DensityDesc::Grid(g) => Some(("density", g)),
            DensityDesc::Constant(_) | DensityDesc::Rgb(_) | DensityDesc::Indexed(_) => None,
        };
        let albedo = match &self.albedo {
            AlbedoDesc::Grid(g) => Some(("albedo", g)),
            AlbedoDesc::Constant(_) => None,
        };
        density.into_iter().chain(albedo)
    }

    /// The values the description's serialisation leaves out (the grids' samples), the
    /// density's then the albedo's (empty for a constant), which what fingerprints a scene
    /// hashes on their own (the facade's `fingerprint::content`). A material-indexed volume's
    /// are its packed indices (their bits as `f32`s) then its table.
    pub fn unserialised_values(&self) -> [&[f32]; 2] {
        let density = match &self.density {
            DensityDesc::Grid(g) => &g.data[..],
            DensityDesc::Indexed(indexed) => bytemuck::cast_slice(indexed.packed_indices()),
            DensityDesc::Constant(_) | DensityDesc::Rgb(_) => &[],
        };
        let albedo = match (&self.density, &self.albedo) {
            (DensityDesc::Indexed(indexed), _) => indexed.table(),
            (_, AlbedoDesc::Grid(g)) => &g.data[..],
            (_, AlbedoDesc::Constant(_)) => &[],
        };
        [density, albedo]
    }

    /// The `scale` of the medium's Mitsuba 3 `<medium>`: an RGB extinction's largest channel
    /// travels in it.
    pub(crate) fn mitsuba3_scale(&self) -> f32 {
        match &self.density {
            DensityDesc::Rgb(rgb) if rgb.iter().any(|&c| c > 0.0) => {
                self.scale * rgb.iter().copied().fold(0.0, f32::max)
            }
            _ => self.scale,
        }
    }

    /// Whether the extinction differs between channels (the medium renders as
    /// [`volpt_core::ChromaticMedium`]; Mitsuba 3's peer integrator is `volpathmis`).
    pub fn is_chromatic(&self) -> bool {
        match &self.density {
            DensityDesc::Rgb(rgb) => !rgb.iter().all(|&c| c == rgb[0]),
            DensityDesc::Indexed(_) => true,
            DensityDesc::Grid(g) => g.channels == 3,
            DensityDesc::Constant(_) => false,
        }
    }

    /// The `<medium>`'s type, its extinction and its albedo elements in a Mitsuba 3 scene; `grid`
    /// writes a grid's file and returns the `gridvolume` that reads it (its arguments: the grid,
    /// what it holds, Mitsuba's parameter, its `filter_type`).
    pub(crate) fn to_mitsuba3(
        &self,
        grid: &mut GridWriter<'_>,
    ) -> Result<(&'static str, String, String), SceneError> {
        // Nearest lookups are Mitsuba 3's `nearest` filter; the others are written trilinear.
        let filter = match self.lookup {
            GridLookup::Nearest => "nearest",
            _ => "trilinear",
        };
        let (medium_type, sigma_t) = match &self.density {
            DensityDesc::Constant(d) => (
                "homogeneous",
                format!("<float name=\"sigma_t\" value=\"{d}\"/>"),
            ),
            // An RGB value is a reflectance in [0, 1] to Mitsuba 3's parser: the largest channel
            // goes into `scale` ([`MediumDesc::mitsuba3_scale`]), the rest into the RGB.
            DensityDesc::Rgb(rgb) => {
                let max = rgb.iter().copied().fold(0.0, f32::max);
                let unit = if max > 0.0 {
                    rgb.map(|c| c / max)
                } else {
                    *rgb
                };
                ("homogeneous", rgb_element("sigma_t", &unit))
            }
            DensityDesc::Grid(g) => ("heterogeneous", grid(g, "density", "sigma_t", filter)?),
            // Mitsuba 3 reads no material table: the table expanded per voxel, read nearest.
            DensityDesc::Indexed(indexed) => {
                let g = indexed.materials().first().map_or(0.0, |m| m.g);
                if indexed.materials().iter().any(|m| m.g != g) {
                    return Err(SceneError::Export {
                        path: PathBuf::from("medium"),
                        reason: "the materials' Henyey-Greenstein g differ, and a Mitsuba 3 \
                                 medium has one phase function: give them one g to export"
                            .into(),
                    });
                }
                let (sigma_t, albedo) = indexed.expanded_grids();
                return Ok((
                    "heterogeneous",
                    grid(&sigma_t, "sigma_t", "sigma_t", "nearest")?,
                    grid(&albedo, "albedo", "albedo", "nearest")?,
                ));
            }
        };
        let albedo = match &self.albedo {
            AlbedoDesc::Constant(rgb) => rgb_element("albedo", rgb),
            AlbedoDesc::Grid(g) => grid(g, "albedo", "albedo", filter)?,
        };
        Ok((medium_type, sigma_t, albedo))
    }

    /// The facade's `medium.*` parameters: `(key, what it is)`. `medium.scale` is a number,
    /// `medium.albedo` an RGB ([`MediumParam`]).
    pub const PARAMS: &'static [(&'static str, &'static str)] = &[
        (
            "medium.scale",
            "the density's scale (extinction = scale x density), finite and >= 0",
        ),
        (
            "medium.albedo",
            "the constant single-scattering albedo, RGB in [0, 1] (not a grid's)",
        ),
    ];

    /// The keys of a material-indexed volume's coefficients, `materials.<m>.sigma_s` and
    /// `.sigma_a` (RGB per world unit, before `medium.scale`) and `.g` (a number in (-1, 1)) for
    /// every material of its table (none for another medium), `<m>` its name (its index in the
    /// table where another material before it has that name, or it has none), with what each
    /// is: [`MediumDesc::param`] and [`MediumDesc::set_param`] take them beside
    /// [`MediumDesc::PARAMS`], and take a material's index for `<m>` too.
    pub fn material_params(&self) -> Vec<(String, &'static str)> {
        let DensityDesc::Indexed(indexed) = &self.density else {
            return Vec::new();
        };
        let materials = indexed.materials();
        materials
            .iter()
            .enumerate()
            .flat_map(|(k, m)| {
                let named = !m.name.is_empty() && material_index(materials, &m.name) == Some(k);
                let id = if named { m.name.clone() } else { k.to_string() };
                MATERIAL_FIELDS
                    .into_iter()
                    .zip(MATERIAL_FIELDS_ABOUT)
                    .map(move |(field, about)| (format!("materials.{id}.{field}"), about))
            })
            .collect()
    }

    /// The value of parameter `key`, if it is one of [`MediumDesc::PARAMS`] or
    /// [`MediumDesc::material_params`] (the phase's are [`PhaseDesc::param`]'s); `Some(Err(why))`
    /// where this medium has no such value.
    pub fn param(&self, key: &str) -> Option<Result<MediumParam, ParamRefused>> {
        if let Some((id, field)) = material_key(key) {
            let DensityDesc::Indexed(indexed) = &self.density else {
                return Some(Err(NOT_INDEXED));
            };
            let Some(k) = material_index(indexed.materials(), id) else {
                return Some(Err(NO_SUCH_MATERIAL));
            };
            let m = &indexed.materials()[k];
            return Some(Ok(match field {
                "sigma_s" => MediumParam::Rgb(m.sigma_s),
                "sigma_a" => MediumParam::Rgb(m.sigma_a),
                _ => MediumParam::Float(m.g),
            }));
        }
        Some(match key {
            "medium.scale" => Ok(MediumParam::Float(self.scale)),
            "medium.albedo" => match &self.albedo {
                AlbedoDesc::Constant(rgb) => Ok(MediumParam::Rgb(*rgb)),
                AlbedoDesc::Grid(_) => Err(ALBEDO_GRID),
            },
            _ => return None,
        })
    }

    /// Sets parameter `key` to `value`, if it is one of [`MediumDesc::PARAMS`] (`None`: the
    /// medium is left alone). `Some(Err(why))` refuses the value, leaving the medium as it was.
    pub fn set_param(&mut self, key: &str, value: MediumParam) -> Option<Result<(), ParamRefused>> {
        if let Some((id, field)) = material_key(key) {
            return Some(self.set_material_param(id, field, value));
        }
        Some(match key {
            "medium.scale" => match value {
                MediumParam::Float(v) if v.is_finite() && v >= 0.0 => {
                    self.scale = v;
                    Ok(())
                }
                _ => Err(ParamRefused::Value("a finite number >= 0")),
            },
            "medium.albedo" => match &mut self.albedo {
                AlbedoDesc::Constant(rgb) => match value {
                    MediumParam::Rgb(v) if v.iter().all(|c| c.is_finite()) => {
                        if !v.iter().all(|c| (0.0..=1.0).contains(c)) {
                            return Some(Err(ParamRefused::Value("RGB in [0, 1]")));
                        }
                        *rgb = v;
                        Ok(())
                    }
                    _ => Err(ParamRefused::Value("three finite numbers")),
                },
                AlbedoDesc::Grid(_) => Err(ALBEDO_GRID),
            },
            _ => return None,
        })
    }

    /// One medium of each kind (with an isotropic phase, a scale of 3 and dense storage); with
    /// the boundary's, the phase's and the environment's examples, every registry medium part is
    /// selected by some scene (tests cover the registry with them). The grids lie a little inside
    /// and outside the unit cube, so that a grid's own mapping matters; their values differ in
    /// every voxel, so that any change of mapping shows. The fourth and fifth media's
    /// nearest-sample lookups select the any-layout grid media (with a constant albedo and with an
    /// albedo grid); a grid decoded with the other lookup renders a different image, so both
    /// lookups cross the device ABI. The sixth reads textures of half-precision texels: decoded as
    /// f32 texels, its samples would differ. The eighth reads one texel per lookup (stochastic):
    /// decoded as trilinear, it would read eight. The last is material-indexed: three materials
    /// over a 3 x 2 x 2 index grid a little off the unit cube, every voxel's index differing from
    /// its neighbours', so that a swapped axis or table row shows.
    pub fn examples() -> Vec<Self> {
        let bounds = Bounds {
            min: [-0.6, -0.45, -0.5],
            max: [0.55, 0.5, 0.6],
        };
        let grid = |channels: u32, convention| {
            let n = 4 * 3 * 2 * channels as usize;
            GridDesc {
                layout: SampleLayout::Dense,
                resolution: [4, 3, 2],
                channels,
                bounds,
                convention,
                data: (0..n)
                    .map(|i| 0.2 + 0.8 * ((i * 7919) % n) as f32 / n as f32)
                    .collect(),
            }
        };
        let (vertex, cell) = (GridConvention::Vertex, GridConvention::Cell);
        let media = [
            (
                DensityDesc::Constant(2.0),
                AlbedoDesc::Constant([0.9, 0.7, 0.5]),
                GridLookup::Trilinear,
            ),
            (
                DensityDesc::Rgb([1.0, 2.5, 5.0]),
                AlbedoDesc::Constant([0.95, 0.9, 0.85]),
                GridLookup::Trilinear,
            ),
            (
                DensityDesc::Grid(grid(1, vertex)),
                AlbedoDesc::Constant([0.8, 0.9, 0.6]),
                GridLookup::Trilinear,
            ),
            (
                DensityDesc::Grid(grid(1, cell)),
                AlbedoDesc::Grid(grid(3, vertex)),
                GridLookup::Trilinear,
            ),
            (
                DensityDesc::Grid(grid(1, vertex)),
                AlbedoDesc::Constant([0.8, 0.9, 0.6]),
                GridLookup::Nearest,
            ),
            (
                DensityDesc::Grid(grid(1, cell)),
                AlbedoDesc::Grid(grid(3, vertex)),
                GridLookup::Nearest,
            ),
            (
                DensityDesc::Grid(grid(1, cell)),
                AlbedoDesc::Grid(grid(3, vertex)),
                GridLookup::TextureHalf,
            ),
            (
                DensityDesc::Grid(grid(1, vertex)),
                AlbedoDesc::Grid(grid(3, cell)),
                GridLookup::Stochastic,
            ),
        ];
        media
            .into_iter()
            .map(|(density, albedo, lookup)| MediumDesc {
                density,
                scale: 3.0,
                albedo,
                phase: PhaseDesc::Isotropic,
                lookup,
                storage: GridStorage::Dense,
            })
            .chain(std::iter::once(Self::indexed_example(bounds)))
            .collect()
    }

    /// [`MediumDesc::examples`]'s material-indexed medium over `bounds`.
    fn indexed_example(bounds: Bounds) -> Self {
        let materials = [
            ("cyan", [0.6, 1.2, 1.5], [2.5, 0.6, 0.1], 0.4),
            ("magenta", [1.1, 0.5, 1.0], [0.2, 2.0, 0.3], -0.3),
            ("white", [2.0, 2.0, 2.0], [0.05, 0.05, 0.05], 0.0),
        ]
        .map(|(name, sigma_s, sigma_a, g)| MaterialDesc {
            name: name.into(),
            sigma_s,
            sigma_a,
            g,
            colour: None,
        });
        let indices: [u8; 12] = [0, 1, 2, 1, 2, 0, 2, 0, 1, 0, 2, 1];
        let indexed = IndexedDesc::new(
            std::path::Path::new("example"),
            materials.to_vec(),
            [3, 2, 2],
            bounds,
            &indices,
        )
        .expect("a valid example");
        MediumDesc {
            phase: indexed.phase(),
            density: DensityDesc::Indexed(indexed),
            scale: 3.0,
            albedo: AlbedoDesc::Constant([0.0; 3]),
            lookup: GridLookup::Trilinear,
            storage: GridStorage::Dense,
        }
    }
}

/// The fields of a material's parameters ([`MediumDesc::material_params`]).
const MATERIAL_FIELDS: [&str; 3] = ["sigma_s", "sigma_a", "g"];

/// `(k, field)` of a key `materials.<k>.<field>`.
fn material_key(key: &str) -> Option<(&str, &'static str)> {
    let rest = key.strip_prefix("materials.")?;
    let (id, field) = rest.rsplit_once('.')?;
    let field = MATERIAL_FIELDS.into_iter().find(|&f| f == field)?;
    Some((id, field))
}

/// What each of [`MATERIAL_FIELDS`] is.
const MATERIAL_FIELDS_ABOUT: [&str; 3] = [
    "the material's scattering coefficient, RGB per world unit (before medium.scale), finite \
     and >= 0",
    "the material's absorption coefficient, RGB per world unit (before medium.scale), finite \
     and >= 0",
    "the material's Henyey-Greenstein asymmetry, in (-1, 1)",
];

/// The index of the material `id` names in `materials`: the first of that name, else the one at
/// index `id`.
fn material_index(materials: &[MaterialDesc], id: &str) -> Option<usize> {
    materials
        .iter()
        .position(|m| m.name == id)
        .or_else(|| id.parse().ok().filter(|&k: &usize| k < materials.len()))
}

/// A material parameter naming no material of the table.
const NO_SUCH_MATERIAL: ParamRefused = ParamRefused::NotHere {
    needs: "a material of the table (its name or its index)",
    found: "no material of that name or index",
};

/// A material parameter of a medium that is not material-indexed.
const NOT_INDEXED: ParamRefused = ParamRefused::NotHere {
    needs: "a material-indexed volume",
    found: "another medium",
};

impl MediumDesc {
    /// Sets `field` of the material `id` names; the phase variant follows the materials'
    /// asymmetries.
    fn set_material_param(
        &mut self,
        id: &str,
        field: &str,
        value: MediumParam,
    ) -> Result<(), ParamRefused> {
        let DensityDesc::Indexed(indexed) = &mut self.density else {
            return Err(NOT_INDEXED);
        };
        let Some(k) = material_index(indexed.materials(), id) else {
            return Err(NO_SUCH_MATERIAL);
        };
        let mut m = indexed.materials()[k].clone();
        match (field, value) {
            ("sigma_s", MediumParam::Rgb(v)) => m.sigma_s = v,
            ("sigma_a", MediumParam::Rgb(v)) => m.sigma_a = v,
            ("g", MediumParam::Float(g)) => m.g = g,
            ("g", _) => return Err(ParamRefused::Value("a number in (-1, 1)")),
            _ => return Err(ParamRefused::Value("three finite numbers >= 0")),
        }
        indexed
            .set_material(k, m)
            .map_err(|(_, expected, _)| ParamRefused::Value(expected))?;
        self.phase = indexed.phase();
        Ok(())
    }
}

/// A value of a `medium.*` parameter ([`MediumDesc::PARAMS`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MediumParam {
    Float(f32),
    Rgb([f32; 3]),
}

/// Why a medium refuses a parameter ([`MediumDesc::param`], [`MediumDesc::set_param`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamRefused {
    /// This medium has no such value: what the parameter needs, and what the medium has instead.
    NotHere {
        needs: &'static str,
        found: &'static str,
    },
    /// The value is not what the parameter takes: what it takes.
    Value(&'static str),
}

/// `medium.albedo` of a medium whose albedo is a grid: the parameter is a constant's.
const ALBEDO_GRID: ParamRefused = ParamRefused::NotHere {
    needs: "a constant albedo",
    found: "a grid",
};

/// As `volpt info`'s `density` line begins (its scale follows).
impl fmt::Display for DensityDesc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DensityDesc::Constant(d) => write!(f, "constant {d}"),
            DensityDesc::Rgb(rgb) => write!(f, "constant RGB {rgb:?} (chromatic)"),
            DensityDesc::Indexed(indexed) => write!(f, "{}", InfoTable(indexed)),
            DensityDesc::Grid(g) if g.channels == 3 => {
                write!(f, "{} (a density per channel: chromatic)", InfoGrid(g))
            }
            DensityDesc::Grid(g) => write!(f, "{}", InfoGrid(g)),
        }
    }
}

/// As `volpt info`'s `albedo` line prints it.
impl fmt::Display for AlbedoDesc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AlbedoDesc::Constant(rgb) => write!(f, "constant {rgb:?}"),
            AlbedoDesc::Grid(g) => write!(f, "{}", InfoGrid(g)),
        }
    }
}

impl GridLookup {
    /// As `volpt info`'s `lookup` line prints it.
    pub fn info(self) -> &'static str {
        match self {
            GridLookup::Trilinear => {
                "trilinear (without --lookup, a GPU with fast math reads stochastic lookups \
                 instead where the grids fit in its memory)"
            }
            GridLookup::Nearest => "nearest (biased: a blockier field)",
            GridLookup::Texture => "texture (the texture unit's filter, 8-bit weights: biased)",
            GridLookup::TextureHalf => "texture-f16 (half-precision texels, 8-bit weights: biased)",
            GridLookup::Stochastic => {
                "stochastic (one sample chosen by its trilinear weight: unbiased)"
            }
        }
    }
}

/// A grid as `volpt info` prints it: its shape, placement and range of values.
struct InfoGrid<'g>(&'g GridDesc);

impl fmt::Display for InfoGrid<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let g = self.0;
        let (lo, hi) = g
            .samples()
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        write!(
            f,
            "grid {}x{}x{}x{}, {:?}-centred, bounds {:?} .. {:?}, values {lo} .. {hi}",
            g.resolution[0],
            g.resolution[1],
            g.resolution[2],
            g.channels,
            g.convention,
            g.bounds.min,
            g.bounds.max
        )
    }
}

/// What the factory reads for the medium axis: the description's density and albedo, each a
/// constant where the specialised factory found a grid of one value over the box.
pub struct MediumInput<'a> {
    medium: &'a MediumDesc,
    /// The medium's box (the boundary's), which a one-voxel grid covers.
    bounds: &'a Bounds,
    density: Density<'a>,
    albedo: Albedo<'a>,
}

/// Whether samples of so many channels per sample hold one value everywhere.
pub type IsUniform<'u> = dyn Fn(&[f32], usize) -> bool + 'u;

/// A medium's density as the description has it, before it becomes a part.
enum Density<'a> {
    Constant(&'a f32),
    Grid(&'a GridDesc),
    /// Channels that differ (equal ones are `Constant`).
    Rgb(&'a [f32; 3]),
    Indexed(&'a IndexedDesc),
}

impl Density<'_> {
    /// Whether the extinction differs between channels: only [`ChromaticMedium`] renders it.
    fn is_chromatic(&self) -> bool {
        match self {
            Density::Rgb(_) | Density::Indexed(_) => true,
            Density::Grid(g) => g.channels == 3,
            Density::Constant(_) => false,
        }
    }
}

enum Albedo<'a> {
    /// Three channels.
    Constant(&'a [f32]),
    Grid(&'a GridDesc),
}

impl<'a> MediumInput<'a> {
    /// `desc`'s medium. With `is_uniform` (whether samples of so many channels hold one value
    /// everywhere; the factory's, which remembers its answers), a grid of one value covering the
    /// medium's box is that constant, and each such grid is reported to `fired`; without it
    /// (the factory's general parts) every grid stays a grid.
    pub fn of(
        desc: &'a SceneDescription,
        is_uniform: Option<&IsUniform<'_>>,
        fired: &mut dyn FnMut(Simplification),
    ) -> Self {
        let medium = &desc.medium;
        let bounds = &desc.boundary.bounds;
        let uniform = |grid: &'a GridDesc| is_uniform.and_then(|u| uniform(grid, bounds, u));
        let density = match &medium.density {
            DensityDesc::Grid(grid) => match uniform(grid) {
                Some(value) => {
                    fired(Simplification::ConstantDensityGrid);
                    // A density per channel of one value each: an RGB constant.
                    match <&[f32; 3]>::try_from(value) {
                        Ok(rgb) if rgb.iter().any(|&c| c != rgb[0]) => Density::Rgb(rgb),
                        _ => Density::Constant(&value[0]),
                    }
                }
                None => Density::Grid(grid),
            },
            DensityDesc::Constant(sigma) => Density::Constant(sigma),
            DensityDesc::Rgb(rgb) if is_uniform.is_some() && rgb.iter().all(|&c| c == rgb[0]) => {
                fired(Simplification::GreyExtinction);
                Density::Constant(&rgb[0])
            }
            DensityDesc::Rgb(rgb) => Density::Rgb(rgb),
            DensityDesc::Indexed(indexed) => Density::Indexed(indexed),
        };
        let albedo = match &medium.albedo {
            AlbedoDesc::Grid(grid) => match uniform(grid) {
                Some(value) => {
                    fired(Simplification::ConstantAlbedoGrid);
                    Albedo::Constant(value)
                }
                None => Albedo::Grid(grid),
            },
            AlbedoDesc::Constant(rgb) => Albedo::Constant(rgb),
        };
        Self {
            medium,
            bounds,
            density,
            albedo,
        }
    }
}

/// The one value of `grid` per channel, if it has a single value everywhere and covers `bounds`
/// (outside its own box a grid is zero, so a smaller grid is not constant over the medium).
fn uniform<'g>(
    grid: &'g GridDesc,
    bounds: &Bounds,
    is_uniform: &IsUniform<'_>,
) -> Option<&'g [f32]> {
    let covers =
        (0..3).all(|i| grid.bounds.min[i] <= bounds.min[i] && grid.bounds.max[i] >= bounds.max[i]);
    let channels = grid.channels as usize;
    let samples = grid.samples();
    let first = samples.get(..channels)?;
    (covers && is_uniform(samples, channels)).then_some(first)
}

impl<'a> FromDescription<'a> for HomogeneousMedium {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match (&input.density, &input.albedo) {
            (Density::Constant(density), Albedo::Constant(albedo)) => Some(HomogeneousMedium {
                sigma_t: input.medium.scale * **density,
                albedo: Spectrum::new(albedo[0], albedo[1], albedo[2]),
            }),
            _ => None,
        }
    }

    fn general(_: &MediumInput<'a>) -> Option<Self> {
        None
    }
}

/// A constant albedo never reads memory: the specialised part for grids of the reads `R` asks.
impl<'a, R: ReadsRule> FromDescription<'a> for GridMedium<'a, ConstantAlbedo, R> {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        if input.density.is_chromatic() {
            return None;
        }
        match input.albedo {
            Albedo::Constant(albedo) if R::asked_by(input.medium) => Some(grid_medium(
                input,
                ConstantAlbedo(Spectrum::new(albedo[0], albedo[1], albedo[2])),
            )),
            _ => None,
        }
    }

    fn general(_: &MediumInput<'a>) -> Option<Self> {
        None
    }
}

/// The general medium of the reads `R` asks: a constant albedo becomes a one-voxel grid (read
/// only at real collisions, a few per path).
impl<'a, R: ReadsRule> FromDescription<'a> for GridMedium<'a, GridAlbedo<'a, R>, R> {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        Self::general(input)
    }

    fn general(input: &MediumInput<'a>) -> Option<Self> {
        if !R::asked_by(input.medium) || input.density.is_chromatic() {
            return None;
        }
        let albedo = match input.albedo {
            Albedo::Grid(albedo) => grid::<3>(albedo, input.medium.lookup),
            Albedo::Constant(rgb) => one_voxel(input, rgb),
        };
        Some(grid_medium(input, GridAlbedo(albedo, R::default())))
    }
}

/// A chromatic extinction, which only this part renders (read trilinearly from dense grids: a
/// density or albedo grid of other lookups or storage is refused when the scene is checked).
impl<'a> FromDescription<'a> for ChromaticMedium<'a> {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        Self::general(input)
    }

    fn general(input: &MediumInput<'a>) -> Option<Self> {
        let (albedo, albedo_grid) = match input.albedo {
            Albedo::Constant(a) => (Spectrum::new(a[0], a[1], a[2]), None),
            Albedo::Grid(g) => (Spectrum::ZERO, Some(grid::<3>(g, input.medium.lookup))),
        };
        let rgb = match input.density {
            Density::Rgb(rgb) => rgb,
            Density::Grid(g) if g.channels == 3 => {
                return Some(ChromaticMedium::per_channel(
                    Spectrum::splat(input.medium.scale),
                    grid::<3>(g, input.medium.lookup),
                    albedo,
                    albedo_grid,
                ))
            }
            Density::Indexed(indexed) => {
                return Some(ChromaticMedium::indexed(MaterialGrid::new(
                    indexed.packed_indices(),
                    indexed.resolution,
                    aabb(&indexed.bounds),
                    indexed.table(),
                    input.medium.scale,
                )))
            }
            Density::Constant(_) | Density::Grid(_) => return None,
        };
        let extinction = input.medium.scale * Spectrum::from_array(*rgb);
        Some(ChromaticMedium::new(extinction, None, albedo, albedo_grid))
    }
}

/// A grid medium with `albedo`; a constant density becomes a one-voxel grid over the medium's box.
fn grid_medium<'a, A, R: GridReads>(input: &MediumInput<'a>, albedo: A) -> GridMedium<'a, A, R> {
    let medium = input.medium;
    let density = match input.density {
        Density::Grid(density) => grid::<1>(density, medium.lookup),
        Density::Constant(sigma) => one_voxel(input, std::slice::from_ref(sigma)),
        Density::Rgb(_) | Density::Indexed(_) => {
            unreachable!("a chromatic extinction is ChromaticMedium's")
        }
    };
    let max_density = density.samples().iter().copied().fold(0.0, f32::max);
    GridMedium {
        density,
        scale: medium.scale,
        majorant: medium.scale * max_density,
        majorants: None,
        albedo,
        reads: R::default(),
    }
}

/// Which [`GridReads`] a description's lookup and storage ask for: exactly one of them for every
/// medium. A kernel carries the code of its reads alone.
pub trait ReadsRule: GridReads {
    fn asked_by(medium: &MediumDesc) -> bool;
}

/// Every grid that needs neither textures nor the any-layout reads.
impl ReadsRule for DenseTrilinear {
    fn asked_by(medium: &MediumDesc) -> bool {
        !texture_reads(medium) && !any_layout(medium)
    }
}

/// Nearest-sample lookups, bricked storage on a GPU, or a sparse grid, unless read through
/// textures.
impl ReadsRule for AnyLayout {
    fn asked_by(medium: &MediumDesc) -> bool {
        !texture_reads(medium) && any_layout(medium)
    }
}

impl ReadsRule for TextureTrilinear {
    fn asked_by(medium: &MediumDesc) -> bool {
        texture_reads(medium)
    }
}

/// Whether the medium's grids need the any-layout reads ([`AnyLayout`]): nearest-sample lookups,
/// bricked storage on a GPU, or a sparse grid.
fn any_layout(medium: &MediumDesc) -> bool {
    medium.lookup == GridLookup::Nearest
        || medium.storage != GridStorage::Dense
        || sparse_grids(medium)
}

/// Whether a grid of the medium is sparse (read in software: a texture holds dense samples).
fn sparse_grids(medium: &MediumDesc) -> bool {
    let sparse = |g: &GridDesc| g.layout == SampleLayout::Sparse;
    matches!(&medium.density, DensityDesc::Grid(g) if sparse(g))
        || matches!(&medium.albedo, AlbedoDesc::Grid(g) if sparse(g))
}

/// Whether the medium's grids are read through textures ([`TextureTrilinear`]): the texture
/// lookups, and stochastic lookups of dense grids (one unfiltered texel; bricked and sparse grids
/// are read in software by [`AnyLayout`]).
fn texture_reads(medium: &MediumDesc) -> bool {
    match medium.lookup {
        GridLookup::Stochastic => medium.storage == GridStorage::Dense && !sparse_grids(medium),
        lookup => texel(lookup).is_some(),
    }
}

/// What a texture holds per sample, if the lookup reads grids through textures
/// ([`TextureTrilinear`]).
fn texel(lookup: GridLookup) -> Option<TexelFormat> {
    match lookup {
        GridLookup::Texture | GridLookup::Stochastic => Some(TexelFormat::F32),
        GridLookup::TextureHalf => Some(TexelFormat::F16),
        GridLookup::Trilinear | GridLookup::Nearest => None,
    }
}

fn aabb(b: &Bounds) -> Aabb {
    Aabb::new(Vec3::from_array(b.min), Vec3::from_array(b.max))
}

/// A one-voxel grid of `value` (its channels) over the medium's box.
fn one_voxel<'a, const C: usize>(input: &MediumInput<'_>, value: &'a [f32]) -> Grid<'a, C> {
    Grid::new(
        value,
        [1, 1, 1],
        GridMapping::cell_centred(aabb(input.bounds), [1, 1, 1]),
    )
    .with_texel(texel(input.medium.lookup).unwrap_or_default())
}

fn grid<const C: usize>(g: &GridDesc, lookup: GridLookup) -> Grid<'_, C> {
    let bounds = aabb(&g.bounds);
    let mapping = match g.convention {
        GridConvention::Vertex => GridMapping::vertex_centred(bounds, g.resolution),
        GridConvention::Cell => GridMapping::cell_centred(bounds, g.resolution),
    };
    let grid = match g.layout {
        SampleLayout::Dense => Grid::new(&g.data, g.resolution, mapping),
        SampleLayout::Sparse => Grid::sparse(&g.data, g.resolution, mapping),
    }
    .with_texel(texel(lookup).unwrap_or_default());
    match lookup {
        GridLookup::Nearest => grid.with_lookup(CoreLookup::Nearest),
        GridLookup::Stochastic => grid.with_lookup(CoreLookup::Stochastic),
        _ => grid,
    }
}
