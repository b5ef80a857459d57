//! volpt's own scene files (`.toml`): one volume from any grid file volpt reads (raw, MetaImage,
//! VTK, Mitsuba `.vol`), with a transfer function or a constant albedo, and the rest of the scene
//! in a few keys. Everything but `[volume]` has a default: the thesis setup (camera at (0, 0, 100),
//! fov 0.7, GGX alpha 0.1, IORs 1.05/1.01, 400x400 at 100 spp), so a CT volume needs four lines. The format is documented in `docs/guide.md` ("volpt TOML scenes").
//!
//! Paths are relative to the scene file. `$name` in a path is replaced by a parameter: the
//! `[defaults]` table gives values, and `-D name=value` overrides them, as in Mitsuba XML.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::Deserialize;

use crate::description::*;
use crate::error::SceneError;
use crate::material::{IndexedDesc, MaterialSpec};
use crate::raw::{read_raw, ByteOrder, RawLayout, ScalarType};
use crate::{normalise, read_metaimage, read_vol, read_vtk};

pub use crate::boundary::{BoundarySpec, BsdfKind, Ior};
pub use crate::environment::EnvironmentSpec;
pub use crate::light::LightSpec;
pub use crate::medium::AlbedoSpec;
pub use crate::phase::PhaseSpec;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub defaults: BTreeMap<String, String>,
    pub volume: VolumeSpec,
    #[serde(default)]
    pub albedo: AlbedoSpec,
    #[serde(default)]
    pub phase: PhaseSpec,
    #[serde(default)]
    pub boundary: BoundarySpec,
    #[serde(default)]
    pub camera: CameraSpec,
    #[serde(default)]
    pub film: FilmSpec,
    #[serde(default)]
    pub sampler: SamplerSpec,
    #[serde(default)]
    pub integrator: IntegratorSpec,
    #[serde(default)]
    pub environment: EnvironmentSpec,
    /// Lights besides the environment: a sun, a point or a spot light ([`LightSpec`]).
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// A material-indexed volume's table: `[volume]` is then its index grid (or PNG slices).
    #[serde(default)]
    pub materials: Vec<MaterialSpec>,
}

/// The density grid.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VolumeSpec {
    pub file: String,
    /// `raw`, `metaimage`, `vtk`, `vol`, `vdb`, `nrrd`, `tiff` or `dicom`; by default from the
    /// extension (`.raw` needs it said), and for a folder from its files (TIFFs, else DICOM).
    pub format: Option<VolumeFormat>,
    /// Raw files: voxels per axis.
    pub resolution: Option<[u32; 3]>,
    /// Raw files: `u8`, `i8`, `u16`, `i16`, `u32`, `i32`, `u64`, `i64`, `f32`, `f64`.
    #[serde(rename = "type")]
    pub scalar: Option<ScalarType>,
    /// Raw files: `little` (default) or `big`.
    #[serde(default)]
    pub byte_order: ByteOrder,
    /// Raw files: bytes to skip before the data.
    #[serde(default)]
    pub header_bytes: u64,
    /// World box `[[min], [max]]`: required for raw files; for other formats it replaces the
    /// file's own box.
    pub bounds: Option<[[f32; 3]; 2]>,
    /// VTK files: the point-data array to read (default: the first scalar array).
    pub array: Option<String>,
    /// VDB files: the float grid to read (default: `density`, or the file's only float grid).
    pub grid: Option<String>,
    /// VDB files: keep the grid sparse, `auto` (default: when that takes at most half the
    /// memory, or the dense box would not fit the memory limit), `always` or `never`.
    pub sparse: Option<String>,
    /// Map the grid's `[0, max]` linearly onto `[0, normalise]` before scaling.
    pub normalise: Option<f32>,
    /// Extinction per unit density (of a material-indexed volume: a factor of every
    /// material's extinction).
    #[serde(default = "one")]
    pub scale: f32,
    /// PNG slice stacks: the voxel's size `[x, y, z]` in world units (the box is then centred on
    /// the origin), instead of `bounds`.
    pub voxel_size: Option<[f32; 3]>,
}

/// The grid file's format (`volume.format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VolumeFormat {
    Raw,
    MetaImage,
    Vtk,
    Vol,
    Vdb,
    Nrrd,
    /// A multi-page TIFF, or a folder of TIFFs.
    Tiff,
    /// A folder of DICOM slices (one series), or one slice.
    Dicom,
    /// A folder of PNG slices whose colours name `[[materials]]` (a voxel print's layers).
    Png,
}

/// The image axis the field of view spans (`camera.fov_axis`), as Mitsuba names it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FovAxisName {
    #[default]
    X,
    Y,
    Smaller,
    Larger,
    Diagonal,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum OneOrThree {
    One(f32),
    Three([f32; 3]),
}

impl OneOrThree {
    pub(crate) fn rgb(self) -> [f32; 3] {
        match self {
            OneOrThree::One(v) => [v; 3],
            OneOrThree::Three(rgb) => rgb,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    #[serde(default = "thesis_origin")]
    pub origin: [f32; 3],
    #[serde(default)]
    pub target: [f32; 3],
    #[serde(default = "y_up")]
    pub up: [f32; 3],
    /// Full field of view in degrees along `fov_axis` (perspective; default 0.7).
    pub fov: Option<f32>,
    /// `x` (default), `y`, `smaller`, `larger` or `diagonal`, as in Mitsuba.
    #[serde(default)]
    pub fov_axis: FovAxisName,
    /// `perspective` (default) or `orthographic` (Mitsuba 3's sensors).
    #[serde(default)]
    pub projection: ProjectionName,
    /// Orthographic: the film's size in world units, `width` or `[width, height]` (the height
    /// defaults to the width times the film's aspect, height / width).
    pub extent: Option<OneOrTwo>,
}

/// `camera.projection`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProjectionName {
    #[default]
    Perspective,
    Orthographic,
}

/// One number or two.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum OneOrTwo {
    One(f64),
    Two([f64; 2]),
}

impl Default for CameraSpec {
    fn default() -> Self {
        Self {
            origin: thesis_origin(),
            target: [0.0; 3],
            up: y_up(),
            fov: None,
            fov_axis: FovAxisName::default(),
            projection: ProjectionName::default(),
            extent: None,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilmSpec {
    #[serde(default = "thesis_resolution")]
    pub width: u32,
    #[serde(default = "thesis_resolution")]
    pub height: u32,
}

impl Default for FilmSpec {
    fn default() -> Self {
        Self {
            width: thesis_resolution(),
            height: thesis_resolution(),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SamplerSpec {
    #[serde(default = "thesis_spp")]
    pub spp: u32,
}

impl Default for SamplerSpec {
    fn default() -> Self {
        Self { spp: thesis_spp() }
    }
}

/// Mitsuba's semantics: -1 is unlimited.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    #[serde(default = "unlimited")]
    pub max_depth: i64,
    #[serde(default = "unlimited")]
    pub rr_depth: i64,
}

impl Default for IntegratorSpec {
    fn default() -> Self {
        Self {
            max_depth: unlimited(),
            rr_depth: unlimited(),
        }
    }
}

fn one() -> f32 {
    1.0
}
fn thesis_origin() -> [f32; 3] {
    [0.0, 0.0, 100.0]
}
fn y_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn thesis_fov() -> f32 {
    0.7
}
fn thesis_resolution() -> u32 {
    400
}
fn thesis_spp() -> u32 {
    100
}
fn unlimited() -> i64 {
    -1
}
/// Reads and parses a TOML scene file (without loading the files it names).
pub fn parse(path: &Path) -> Result<SceneFile, SceneError> {
    parse_with_text(path).map(|(file, _)| file)
}

fn parse_with_text(path: &Path) -> Result<(SceneFile, String), SceneError> {
    let text = crate::limits::read_text(path)?;
    let file = toml::from_str(&text).map_err(|e| {
        let start = e.span().map(|span| span.start);
        SceneError::Toml {
            path: path.to_owned(),
            line: start.map_or(1, |start| text[..start].matches('\n').count() + 1),
            // serde names the wrong value (an unknown variant, a wrong type) but not its key.
            message: match start.and_then(|start| field_at(&text, start)) {
                Some(field) => format!("{field}: {}", e.message()),
                None => e.message().to_owned(),
            },
        }
    })?;
    Ok((file, text))
}

/// The `table.key` whose value stands at byte `offset` of a TOML text: the key on that line, in
/// the last `[table]` above it.
fn field_at(text: &str, offset: usize) -> Option<String> {
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = &text[line_start..];
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    let table = text[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find_map(|l| l.strip_prefix('[')?.strip_suffix(']'));
    Some(match table {
        Some(table) => format!("{}.{key}", table.trim()),
        None => key.to_owned(),
    })
}

/// The file being loaded, for error messages: value errors point at the line of their key.
pub(crate) struct Cx<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Cx<'_> {
    /// The line of `field` (`table.key`): the key's line inside its table, else the table's.
    fn line_of(&self, field: &str) -> usize {
        let (table, key) = field.split_once('.').unwrap_or((field, ""));
        let header = format!("[{table}]");
        let lines: Vec<&str> = self.text.lines().map(str::trim_start).collect();
        let Some(start) = lines.iter().position(|l| l.starts_with(&header)) else {
            return 1;
        };
        let in_table = lines[start + 1..]
            .iter()
            .take_while(|l| !l.starts_with('['))
            .position(|l| {
                !key.is_empty()
                    && l.strip_prefix(key)
                        .is_some_and(|rest| rest.trim_start().starts_with('='))
            });
        in_table.map_or(start + 1, |i| start + 2 + i)
    }

    pub(crate) fn invalid(
        &self,
        field: &str,
        expected: &str,
        found: impl std::fmt::Display,
    ) -> SceneError {
        SceneError::InvalidValue {
            path: self.path.to_owned(),
            line: self.line_of(field),
            field: field.to_owned(),
            expected: expected.to_owned(),
            found: found.to_string(),
        }
    }

    fn missing(&self, what: &str) -> SceneError {
        SceneError::Missing {
            path: self.path.to_owned(),
            line: self.line_of("volume"),
            element: "[volume] of a raw file".into(),
            what: what.into(),
        }
    }
}

/// Loads a TOML scene file and the volume and transfer function it names.
pub fn load(path: &Path, params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
    let (file, text) = parse_with_text(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    assemble(&Cx { path, text: &text }, dir, file, params)
}

/// The scene of a TOML file whose only entry is `[volume] file = path`: a grid file rendered with
/// every default.
pub fn load_volume_only(
    path: &Path,
    params: &[(String, String)],
) -> Result<SceneDescription, SceneError> {
    let file = SceneFile {
        defaults: BTreeMap::new(),
        volume: VolumeSpec {
            file: path.display().to_string(),
            format: None,
            resolution: None,
            scalar: None,
            byte_order: ByteOrder::Little,
            header_bytes: 0,
            bounds: None,
            array: None,
            grid: None,
            sparse: None,
            normalise: None,
            scale: 1.0,
            voxel_size: None,
        },
        albedo: AlbedoSpec::default(),
        phase: PhaseSpec::default(),
        boundary: BoundarySpec::default(),
        camera: CameraSpec::default(),
        film: FilmSpec::default(),
        sampler: SamplerSpec::default(),
        integrator: IntegratorSpec::default(),
        environment: EnvironmentSpec::default(),
        lights: Vec::new(),
        materials: Vec::new(),
    };
    assemble(&Cx { path, text: "" }, Path::new(""), file, params)
}

fn assemble(
    cx: &Cx<'_>,
    dir: &Path,
    file: SceneFile,
    params: &[(String, String)],
) -> Result<SceneDescription, SceneError> {
    let resolve = |value: &str, field: &str| resolve_path(cx, dir, value, field, &file, params);
    let v = &file.volume;

    let volume_path = resolve(&v.file, "volume.file")?;
    if !file.materials.is_empty() {
        return assemble_indexed(cx, &file, &volume_path, dir, params);
    }
    if v.format == Some(VolumeFormat::Png) {
        return Err(cx.invalid(
            "volume.format",
            "png only with [[materials]] (a slice stack's colours name materials)",
            "no [[materials]]",
        ));
    }
    let mesh_path = match &file.boundary.mesh {
        Some(m) => Some(resolve(m, "boundary.mesh")?),
        None => None,
    };
    let mesh = file.boundary.mesh(cx, mesh_path.as_deref())?;
    // The grids lie over the mesh's bounding box unless `volume.bounds` places them.
    let mesh_box = match (&mesh, v.bounds) {
        (Some(m), None) => Some(crate::BoundaryDesc::mesh(m.clone(), BsdfDesc::Null).bounds),
        _ => None,
    };
    let (mut grid, file_box) = read_volume(cx, &volume_path, v)?;
    if let Some(b) = mesh_box {
        grid.bounds = b;
    }
    if let Some(target) = v.normalise {
        if !(target.is_finite() && target > 0.0) {
            return Err(cx.invalid("volume.normalise", "a positive density", target));
        }
        grid = normalise(grid, target);
    }
    let grid = crate::medium::grey_if_equal(grid);
    if grid.channels == 3 && file.albedo.transfer_function.is_some() {
        return Err(cx.invalid(
            "albedo.transfer_function",
            "a one-channel density to apply it to (or an albedo value)",
            "a density grid of three channels",
        ));
    }
    if !(v.scale.is_finite() && v.scale >= 0.0) {
        return Err(cx.invalid("volume.scale", "a finite scale >= 0", v.scale));
    }

    let albedo_grid = match &file.albedo.grid {
        Some(_) if file.albedo.transfer_function.is_some() || file.albedo.value.is_some() => {
            return Err(cx.invalid(
                "albedo",
                "one of grid, transfer_function or value",
                "grid and another",
            ))
        }
        Some(name) if crate::vdb::is_vdb(&volume_path) => {
            let options = crate::vdb::VdbOptions {
                grid: Some(name.clone()),
                vector: true,
                sparsity: sparsity(cx, v)?,
            };
            let mut albedo = crate::vdb::read_vdb(&volume_path, &options)?;
            let placed = match (v.bounds, mesh_box) {
                (Some(b), _) => Some(checked_box(cx, "volume.bounds", b)?),
                (None, mesh_box) => mesh_box,
            };
            if let Some(b) = placed {
                // The albedo moves with the density's box.
                albedo.bounds = remap(albedo.bounds, file_box, b);
            }
            Some(albedo)
        }
        Some(_) => {
            return Err(cx.invalid(
                "albedo.grid",
                "a volume.file that is a .vdb (the grid is read from it)",
                volume_path.display(),
            ))
        }
        None => None,
    };
    let albedo = file.albedo.albedo(cx, albedo_grid, &grid, &resolve)?;
    let phase = file.phase.phase(cx)?;
    let grid_bounds = grid.bounds;
    let medium = MediumDesc {
        density: DensityDesc::Grid(grid),
        scale: v.scale,
        albedo,
        phase,
        lookup: Default::default(),
        storage: Default::default(),
    };
    finish(cx, &file, grid_bounds, medium, mesh)
}

/// A material-indexed volume's scene: `[[materials]]` and `[volume]`'s index grid or slices;
/// the medium's albedo and phase are the materials'.
fn assemble_indexed(
    cx: &Cx<'_>,
    file: &SceneFile,
    volume_path: &Path,
    dir: &Path,
    params: &[(String, String)],
) -> Result<SceneDescription, SceneError> {
    let v = &file.volume;
    if file.albedo.value.is_some()
        || file.albedo.transfer_function.is_some()
        || file.albedo.grid.is_some()
    {
        return Err(cx.invalid(
            "albedo",
            "no [albedo] beside [[materials]] (each material has its own)",
            "an [albedo] table",
        ));
    }
    if file.phase.g.is_some() {
        return Err(cx.invalid(
            "phase.g",
            "no [phase] beside [[materials]] (each material has its own g)",
            "a phase.g",
        ));
    }
    if v.normalise.is_some() {
        return Err(cx.invalid(
            "volume.normalise",
            "no normalise for an index grid (its values name materials)",
            "a normalise",
        ));
    }
    if !(v.scale.is_finite() && v.scale >= 0.0) {
        return Err(cx.invalid("volume.scale", "a finite scale >= 0", v.scale));
    }
    let materials = file
        .materials
        .iter()
        .enumerate()
        .map(|(k, m)| {
            m.material(&|field, expected, found| {
                let field = if field.is_empty() {
                    format!("materials[{k}]")
                } else {
                    format!("materials[{k}].{field}")
                };
                cx.invalid(&field, expected, found)
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let slices = v.format == Some(VolumeFormat::Png)
        || (v.format.is_none() && volume_path.is_dir() && {
            let files = crate::slices::slice_files(volume_path)?;
            !files.is_empty()
        });
    let indexed = if slices {
        use crate::slices::SliceIndices;
        let expected = v.resolution.map(|resolution| crate::slices::StackShape {
            resolution,
            source: "volume.resolution",
        });
        let (indices, resolution) = crate::slices::read_slices(volume_path, &materials, expected)?;
        let bounds = match (v.bounds, v.voxel_size) {
            (Some(b), None) => checked_box(cx, "volume.bounds", b)?,
            (None, Some(size)) => {
                if !size.iter().all(|s| s.is_finite() && *s > 0.0) {
                    return Err(cx.invalid(
                        "volume.voxel_size",
                        "three sizes > 0",
                        format!("{size:?}"),
                    ));
                }
                let half = [0, 1, 2].map(|a| 0.5 * size[a] * resolution[a] as f32);
                Bounds {
                    min: half.map(|h| -h),
                    max: half,
                }
            }
            _ => {
                return Err(cx.invalid(
                    "volume",
                    "voxel_size = [x, y, z] or bounds = [[min], [max]] for a slice stack",
                    "both or neither",
                ))
            }
        };
        match indices {
            SliceIndices::Bytes(i) => {
                IndexedDesc::new(volume_path, materials, resolution, bounds, &i)?
            }
            SliceIndices::Wide(i) => {
                IndexedDesc::new(volume_path, materials, resolution, bounds, &i)?
            }
        }
    } else {
        let (grid, _) = read_volume(cx, volume_path, v)?;
        IndexedDesc::from_grid(volume_path, materials, &grid)?
    };
    let bounds = indexed.bounds;
    let phase = indexed.phase();
    let medium = MediumDesc {
        density: DensityDesc::Indexed(indexed),
        scale: v.scale,
        albedo: AlbedoDesc::Constant([0.0; 3]),
        phase,
        lookup: Default::default(),
        storage: Default::default(),
    };
    // An indexed volume keeps its own placement (its slices' or its file's voxel size).
    let mesh = match &file.boundary.mesh {
        Some(m) => {
            let path = resolve_path(cx, dir, m, "boundary.mesh", file, params)?;
            file.boundary.mesh(cx, Some(&path))?
        }
        None => file.boundary.mesh(cx, None)?,
    };
    finish(cx, file, bounds, medium, mesh)
}

/// The scene around `medium`, whose grid's box is `grid_bounds`: boundary, camera, film,
/// sampler, integrator and environment.
fn finish(
    cx: &Cx<'_>,
    file: &SceneFile,
    grid_bounds: Bounds,
    medium: MediumDesc,
    mesh: Option<Arc<MeshDesc>>,
) -> Result<SceneDescription, SceneError> {
    let bsdf = file.boundary.bsdf(cx)?;
    let boundary = match (mesh, file.boundary.bounds) {
        (Some(mesh), _) => BoundaryDesc::mesh(mesh, bsdf),
        (None, Some(box_)) => BoundaryDesc::box_(checked_box(cx, "boundary.bounds", box_)?, bsdf),
        (None, None) => BoundaryDesc::box_(grid_bounds, bsdf),
    };

    let c = &file.camera;
    let fov_axis = match c.fov_axis {
        FovAxisName::X => FovAxis::X,
        FovAxisName::Y => FovAxis::Y,
        FovAxisName::Smaller => FovAxis::Smaller,
        FovAxisName::Larger => FovAxis::Larger,
        FovAxisName::Diagonal => FovAxis::Diagonal,
    };
    let fov = c.fov.unwrap_or_else(thesis_fov);
    let mut to_world = look_at(c.origin, c.target, c.up).ok_or_else(|| {
        cx.invalid(
            "camera",
            "an origin apart from the target and an up vector not along the view",
            format!(
                "origin {:?}, target {:?}, up {:?}",
                c.origin, c.target, c.up
            ),
        )
    })?;
    if file.film.width == 0 || file.film.height == 0 {
        return Err(cx.invalid(
            "film",
            "a width and height of at least 1",
            format!("{}x{}", file.film.width, file.film.height),
        ));
    }
    let projection = match c.projection {
        ProjectionName::Perspective => {
            if c.extent.is_some() {
                return Err(cx.invalid(
                    "camera.extent",
                    "no extent on a perspective camera (its field of view is `fov`)",
                    "an extent",
                ));
            }
            if !(fov > 0.0 && fov < 180.0) {
                return Err(cx.invalid("camera.fov", "degrees in (0, 180)", fov));
            }
            Projection::Perspective
        }
        ProjectionName::Orthographic => {
            if let Some(fov) = c.fov {
                return Err(cx.invalid(
                    "camera.fov",
                    "no field of view on an orthographic camera (its film's size is `extent`)",
                    fov,
                ));
            }
            // Mitsuba 3's orthographic film spans camera-space x in [-1, 1] and y in
            // [-h/w, h/w], scaled by the frame: half the width on x, and on y half the height
            // times w/h.
            let aspect = f64::from(file.film.width) / f64::from(file.film.height);
            let [w, h] = match c.extent {
                Some(OneOrTwo::One(w)) => [w, w / aspect],
                Some(OneOrTwo::Two(size)) => size,
                None => {
                    return Err(cx.invalid(
                        "camera.extent",
                        "the film's size in world units on an orthographic camera",
                        "none",
                    ))
                }
            };
            if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0) {
                return Err(cx.invalid(
                    "camera.extent",
                    "a width and height above 0",
                    format!("{w}, {h}"),
                ));
            }
            let scale = [0.5 * w, 0.5 * h * aspect];
            for row in to_world.iter_mut().take(3) {
                row[0] = (f64::from(row[0]) * scale[0]) as f32;
                row[1] = (f64::from(row[1]) * scale[1]) as f32;
            }
            Projection::Orthographic
        }
    };
    let depth = |d: i64, field: &str| match d {
        -1 => Ok(None),
        d if d >= 0 && d <= u32::MAX as i64 => Ok(Some(d as u32)),
        d => Err(cx.invalid(field, "-1 (unlimited) or a depth >= 0", d)),
    };
    let environment = file.environment.environment(cx)?;
    Ok(SceneDescription {
        camera: CameraDesc {
            to_world,
            fov_degrees: fov,
            fov_axis,
            projection,
        },
        film: FilmDesc {
            width: file.film.width,
            height: file.film.height,
        },
        spp: file.sampler.spp,
        integrator: IntegratorDesc {
            max_depth: depth(file.integrator.max_depth, "integrator.max_depth")?,
            rr_depth: depth(file.integrator.rr_depth, "integrator.rr_depth")?,
        },
        boundary,
        medium,
        environment,
        lights: LightSpec::lights(&file.lights, cx)?,
    })
}

/// `value` with `$name`s replaced (from `params`, then `[defaults]`), relative to `dir`.
fn resolve_path(
    cx: &Cx<'_>,
    dir: &Path,
    value: &str,
    field: &str,
    file: &SceneFile,
    params: &[(String, String)],
) -> Result<PathBuf, SceneError> {
    let mut out = String::new();
    let mut rest = value;
    while let Some(at) = rest.find('$') {
        out.push_str(&rest[..at]);
        let after = &rest[at + 1..];
        let len = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        let name = &after[..len];
        let found = params
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
            .or_else(|| file.defaults.get(name).map(String::as_str));
        match found {
            Some(v) if !name.is_empty() => out.push_str(v),
            _ => {
                return Err(cx.invalid(
                    field,
                    "parameters defined in [defaults] or by -D name=value",
                    format!("undefined ${name} in {value:?}"),
                ))
            }
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    Ok(dir.join(out))
}

fn checked_box(cx: &Cx<'_>, field: &str, [min, max]: [[f32; 3]; 2]) -> Result<Bounds, SceneError> {
    let ok = (0..3).all(|i| min[i].is_finite() && max[i].is_finite() && min[i] < max[i]);
    if !ok {
        return Err(cx.invalid(
            field,
            "[[min x, y, z], [max x, y, z]] with min < max on every axis",
            format!("{min:?} .. {max:?}"),
        ));
    }
    Ok(Bounds { min, max })
}

/// The `volume.sparse` setting.
fn sparsity(cx: &Cx<'_>, v: &VolumeSpec) -> Result<crate::vdb::Sparsity, SceneError> {
    match &v.sparse {
        None => Ok(crate::vdb::Sparsity::Auto),
        Some(s) => crate::vdb::Sparsity::parse(s)
            .ok_or_else(|| cx.invalid("volume.sparse", "auto, always or never", s)),
    }
}

/// `b` moved and scaled as the box `from` is onto `to`.
fn remap(b: Bounds, from: Bounds, to: Bounds) -> Bounds {
    let map = |i: usize, v: f32| {
        let t = (f64::from(v) - f64::from(from.min[i])) / f64::from(from.max[i] - from.min[i]);
        (f64::from(to.min[i]) + t * f64::from(to.max[i] - to.min[i])) as f32
    };
    Bounds {
        min: [0, 1, 2].map(|i| map(i, b.min[i])),
        max: [0, 1, 2].map(|i| map(i, b.max[i])),
    }
}

/// The density grid and the box its file gave it (before `volume.bounds` replaced it).
fn read_volume(cx: &Cx<'_>, file: &Path, v: &VolumeSpec) -> Result<(GridDesc, Bounds), SceneError> {
    let extension = file
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let format = match (v.format, extension.as_deref()) {
        (Some(f), _) => f,
        (None, Some("mha" | "mhd")) => VolumeFormat::MetaImage,
        (None, Some("vtk" | "vti")) => VolumeFormat::Vtk,
        (None, Some("vol")) => VolumeFormat::Vol,
        (None, Some("vdb")) => VolumeFormat::Vdb,
        (None, _) if crate::scanner::scanner_format(file)?.is_some() => {
            crate::scanner::scanner_format(file)?.expect("checked")
        }
        (None, _) => {
            return Err(cx.invalid(
                "volume.format",
                "raw, metaimage, vtk, vol, vdb, nrrd, tiff or dicom (needed when the extension does not say)",
                file.display(),
            ))
        }
    };
    let bounds = v
        .bounds
        .map(|b| checked_box(cx, "volume.bounds", b))
        .transpose()?;
    let mut grid = match format {
        VolumeFormat::Raw => {
            let resolution = v
                .resolution
                .ok_or_else(|| cx.missing("resolution = [x, y, z]"))?;
            let scalar = match v.scalar {
                Some(scalar) => scalar,
                None => return Err(cx.missing("type (e.g. \"u8\")")),
            };
            let bounds = bounds.ok_or_else(|| cx.missing("bounds = [[min], [max]]"))?;
            let layout = RawLayout {
                resolution,
                channels: 1,
                scalar,
                byte_order: v.byte_order,
                header_bytes: v.header_bytes,
            };
            let grid = read_raw(file, &layout, bounds)?;
            return Ok((grid, bounds));
        }
        VolumeFormat::Vdb => {
            let options = crate::vdb::VdbOptions {
                grid: v.grid.clone(),
                vector: false,
                sparsity: sparsity(cx, v)?,
            };
            crate::vdb::read_vdb(file, &options)?
        }
        VolumeFormat::MetaImage => read_metaimage(file)?,
        VolumeFormat::Nrrd | VolumeFormat::Tiff | VolumeFormat::Dicom => {
            crate::scanner::read_scanned(file, format).expect("a scanner format")?
        }
        VolumeFormat::Vtk => read_vtk(file, v.array.as_deref())?,
        VolumeFormat::Png => {
            return Err(cx.invalid(
                "volume.format",
                "a grid format (PNG slices are read with [[materials]] alone)",
                "png",
            ))
        }
        VolumeFormat::Vol => {
            let vol = read_vol(file)?;
            vol.check_density(file)?;
            GridDesc {
                layout: crate::description::SampleLayout::Dense,
                resolution: vol.resolution,
                channels: vol.channels,
                bounds: vol.bbox,
                // Mitsuba 0.6's convention for its own format.
                convention: GridConvention::Vertex,
                data: vol.data,
            }
        }
    };
    if grid.channels != 1 && grid.channels != 3 {
        return Err(cx.invalid(
            "volume.file",
            "a density grid of one channel (grey) or three (a density per channel)",
            format!("{} channels in {}", grid.channels, file.display()),
        ));
    }
    let file_box = grid.bounds;
    if let Some(bounds) = bounds {
        grid.bounds = bounds;
    }
    Ok((grid, file_box))
}

/// The smallest sine of the angle between a camera's up and its viewing direction: below it the
/// camera's left (their cross product, normalised) is mostly `f32` rounding (an error of about
/// 2.4e-7 / sine), so the up counts as parallel. Relative: the vectors' lengths do not matter.
pub const MIN_UP_SINE: f64 = 1e-4;

/// Whether `up` and `dir` are parallel within [`MIN_UP_SINE`] (or either is zero or not finite).
pub fn parallel(up: [f64; 3], dir: [f64; 3]) -> bool {
    let cross = [
        up[1] * dir[2] - up[2] * dir[1],
        up[2] * dir[0] - up[0] * dir[2],
        up[0] * dir[1] - up[1] * dir[0],
    ];
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let scale = len(up) * len(dir);
    !(scale > 0.0 && scale.is_finite() && len(cross) > MIN_UP_SINE * scale)
}

/// Mitsuba's `lookat`: camera +z towards the target, +y up, +x to the left of the image. `None`
/// where the target is the origin or the up is [`parallel`] to the direction.
pub fn look_at(origin: [f32; 3], target: [f32; 3], up: [f32; 3]) -> Option<Matrix4> {
    let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f32; 3], b: [f32; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let normalize = |v: [f32; 3]| {
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (len > 0.0 && len.is_finite()).then(|| v.map(|c| c / len))
    };
    let dir = normalize(sub(target, origin))?;
    if parallel(up.map(f64::from), dir.map(f64::from)) {
        return None;
    }
    let left = normalize(cross(normalize(up)?, dir))?;
    let new_up = cross(dir, left);
    Some([
        [left[0], new_up[0], dir[0], origin[0]],
        [left[1], new_up[1], dir[1], origin[1]],
        [left[2], new_up[2], dir[2], origin[2]],
        [0.0, 0.0, 0.0, 1.0],
    ])
}
