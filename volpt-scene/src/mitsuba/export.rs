//! A [`SceneDescription`] written out as a Mitsuba 3 scene: the XML, its grids as `.vol` files and
//! its environment map as OpenEXR, beside each other in one directory.
//!
//! The written scene is the same estimator in Mitsuba 3's `volpath`, whatever source the description
//! came from (a volpt TOML scene with a raw grid and a transfer function, a MetaImage or VTK file, a
//! Mitsuba 0.6 scene): this is how those scenes are compared with Mitsuba 3 (`docs/peers.md`), and how
//! a user takes a volume prepared by volpt to Mitsuba. What Mitsuba 3 spells differently:
//! - **Grids** are placed by `to_world` on cell centres over `[0,1]^3`. A vertex-centred (Mitsuba
//!   0.6) grid is written on its box grown by half a sample spacing `h = extent / (n - 1)` on every
//!   side, which puts the cell centres on the 0.6 sample positions: inside the original box, the
//!   only place the medium is looked up, the trilinear fields are identical.
//! - **No Russian roulette** (`rr_depth` unset) is `rr_depth = 10^9`: Mitsuba 3 refuses values below
//!   1, and no path of a finite render reaches that depth.
//! - **Material-indexed volumes** (Mitsuba 3 reads no material table) are written as their
//!   table expanded per voxel: RGB grids of the extinction and the albedo, read `nearest` as the
//!   table is. Mitsuba 3 has one phase function per medium: a table whose materials' `g` differ
//!   is refused.
//! - **Mesh boundaries** are written as a binary PLY of their world-space triangles
//!   (`<name>-boundary.ply`, vertices shared where their positions are equal, so that volpt reads
//!   it back as the same closed mesh) read with `face_normals`, or with the mesh's vertex normals
//!   (`nx ny nz`; a vertex shared where position and normal are equal: a mesh whose corners at
//!   one position have different normals, a crease, reads back into volpt as open there).
//! - **Environment maps** are written with Mitsuba 3's row convention (rows from pole to pole). A
//!   Mitsuba 0.6 map (cell-centred rows) would move by half a row, so it is refused rather than
//!   silently changed.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::description::{
    Bounds, FovAxis, GridConvention, GridDesc, Matrix4, MeshDesc, Projection, SceneDescription,
};
use crate::error::SceneError;
use crate::output::create_dir;
use crate::vol::{write_vol, VolGrid};

/// `rr_depth` for "no Russian roulette", which Mitsuba 3 cannot spell as -1.
pub const NO_ROULETTE_DEPTH: u32 = 1_000_000_000;

/// Writes `desc` as `dir/<name>.xml`, with `<name>-density.vol`, `<name>-albedo.vol` and
/// `<name>-envmap.exr` beside it where the scene has grids or a map. Returns every path written,
/// the XML first.
pub fn write_mitsuba3(
    desc: &SceneDescription,
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, SceneError> {
    // The name becomes part of file names inside `dir`: it must not lead out of it.
    let plain = matches!(
        Path::new(name).components().collect::<Vec<_>>().as_slice(),
        [std::path::Component::Normal(n)] if *n == std::ffi::OsStr::new(name)
    );
    if !plain || name.contains(['/', '\\']) {
        return Err(SceneError::Export {
            path: dir.to_path_buf(),
            reason: format!(
                "the name {:?} must be a plain file name (no directories, no `..`), so that \
                 every file is written inside {}",
                crate::error::excerpt(name),
                dir.display()
            ),
        });
    }
    create_dir(dir)?;
    let xml_path = dir.join(format!("{name}.xml"));
    let mut written = vec![xml_path.clone()];
    // Writes `<name>-<what>.vol` and returns the `gridvolume` that reads it as Mitsuba's `param`.
    let mut grid =
        |grid: &GridDesc, what: &str, param: &str, filter: &str| -> Result<String, SceneError> {
            let file = format!("{name}-{what}.vol");
            // Mitsuba's .vol is dense: a sparse grid is written densified, within the memory limit.
            let [x, y, z] = grid.resolution;
            crate::limits::check_grid_memory(
                &dir.join(&file),
                [x, y, z],
                grid.channels,
                grid.dense_bytes().unwrap_or(u64::MAX) / 4,
            )?;
            let dense = grid.densified();
            let grid = &dense;
            let (bbox, to_world) = cell_centred_box(grid);
            let path = dir.join(&file);
            write_vol(
                &path,
                &VolGrid {
                    resolution: grid.resolution,
                    channels: grid.channels,
                    bbox,
                    data: grid.data.clone(),
                },
            )?;
            written.push(path);
            Ok(grid_volume(param, &file, filter, &to_world))
        };

    let medium = &desc.medium;
    let (medium_type, sigma_t, albedo) = medium.to_mitsuba3(&mut grid)?;
    let phase = medium.phase.to_mitsuba3();
    let bsdf = desc.boundary.bsdf.to_mitsuba3();
    let emitter = desc
        .environment
        .to_mitsuba3(dir, name, &xml_path, &mut written)?
        + &desc.lights.to_mitsuba3(&xml_path)?;
    let depth = |d: Option<u32>, none: i64| d.map_or(none, i64::from);
    let fov_axis = match desc.camera.fov_axis {
        FovAxis::X => "x",
        FovAxis::Y => "y",
        FovAxis::Smaller => "smaller",
        FovAxis::Larger => "larger",
        FovAxis::Diagonal => "diagonal",
    };
    let shape = match &desc.boundary.mesh {
        None => {
            // Mitsuba's `cube` is [-1,1]^3.
            let cube = Bounds {
                min: [-1.0; 3],
                max: [1.0; 3],
            };
            let cube_to_world = box_transform(&cube, &desc.boundary.bounds);
            format!(
                "<shape type=\"cube\">\n        {}",
                matrix_transform(&cube_to_world, "        ")
            )
        }
        Some(mesh) => {
            let file = format!("{name}-boundary.ply");
            let path = dir.join(&file);
            write_ply(&path, mesh)?;
            written.push(path);
            let face_normals = if mesh.buffers.normals.is_empty() {
                "\n        <boolean name=\"face_normals\" value=\"true\"/>"
            } else {
                ""
            };
            format!(
                "<shape type=\"ply\">\n        <string name=\"filename\" value=\"{file}\"/>{face_normals}"
            )
        }
    };

    let mut xml = String::new();
    let _ = write!(
        xml,
        r#"<?xml version="1.0" encoding="utf-8"?>
<!-- Written by volpt (`volpt scene export`): the scene volpt renders, in Mitsuba 3 spelling. -->
<scene version="3.0.0">
    <integrator type="{integrator}">
        <integer name="max_depth" value="{max_depth}"/>
        <integer name="rr_depth" value="{rr_depth}"/>
    </integrator>

    <sensor type="{sensor}">
        {fov}{camera}
        <sampler type="independent">
            <integer name="sample_count" value="{spp}"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{width}"/>
            <integer name="height" value="{height}"/>
            <rfilter type="box"/>
        </film>
    </sensor>

    {emitter}

    {shape}
        {bsdf}
        <medium type="{medium_type}" name="interior">
            {sigma_t}
            <float name="scale" value="{scale}"/>
            {albedo}
            {phase}
        </medium>
    </shape>
</scene>
"#,
        max_depth = depth(desc.integrator.max_depth, -1),
        rr_depth = depth(desc.integrator.rr_depth, i64::from(NO_ROULETTE_DEPTH)),
        sensor = match desc.camera.projection {
            Projection::Perspective => "perspective",
            Projection::Orthographic => "orthographic",
        },
        // An orthographic sensor has no field of view.
        fov = match desc.camera.projection {
            Projection::Perspective => format!(
                "<float name=\"fov\" value=\"{}\"/>\n        <string name=\"fov_axis\" \
                 value=\"{fov_axis}\"/>\n        ",
                desc.camera.fov_degrees
            ),
            Projection::Orthographic => String::new(),
        },
        camera = matrix_transform(&desc.camera.to_world, "        "),
        spp = desc.spp,
        width = desc.film.width,
        height = desc.film.height,
        scale = medium.mitsuba3_scale(),
        // Mitsuba 3's `volpath` samples one channel without MIS: very noisy on chromatic media.
        integrator = if medium.is_chromatic() {
            "volpathmis"
        } else {
            "volpath"
        },
    );
    std::fs::write(&xml_path, xml).map_err(|error| SceneError::Io {
        path: xml_path,
        error,
    })?;
    Ok(written)
}

/// Writes `mesh`'s triangles as a binary little-endian PLY, each position (with its vertex
/// normal, where the mesh has them) once.
fn write_ply(path: &Path, mesh: &MeshDesc) -> Result<(), SceneError> {
    let buffers = &mesh.buffers;
    let shaded = !buffers.normals.is_empty();
    let mut index: HashMap<[u32; 6], u32> = HashMap::new();
    let mut vertices: Vec<[f32; 6]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangle_count());
    for (i, t) in buffers.triangles.iter().enumerate() {
        let normals = buffers.normals.get(i).copied().unwrap_or([[0.0; 3]; 3]);
        faces.push(core::array::from_fn(|k| {
            let [x, y, z] = t.v[k];
            let [nx, ny, nz] = normals[k];
            let vertex = [x, y, z, nx, ny, nz];
            *index.entry(vertex.map(f32::to_bits)).or_insert_with(|| {
                vertices.push(vertex);
                (vertices.len() - 1) as u32
            })
        }));
    }
    let normal_properties = if shaded {
        "property float nx\nproperty float ny\nproperty float nz\n"
    } else {
        ""
    };
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by volpt: a closed mesh boundary\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         {normal_properties}element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .into_bytes();
    let components = if shaded { 6 } else { 3 };
    for v in &vertices {
        for c in &v[..components] {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in &faces {
        bytes.push(3);
        for i in f {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).map_err(|error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    })
}

/// The box whose cells' centres are the grid's samples, and the transform that takes `[0,1]^3` to it.
fn cell_centred_box(grid: &GridDesc) -> (Bounds, Matrix4) {
    let b = grid.bounds;
    let bounds = match grid.convention {
        GridConvention::Cell => b,
        GridConvention::Vertex => {
            let mut grown = b;
            for axis in 0..3 {
                let extent = b.max[axis] - b.min[axis];
                // One sample along an axis is constant along it: any cell around it will do.
                let h = extent / (grid.resolution[axis].max(2) - 1) as f32;
                grown.min[axis] = b.min[axis] - 0.5 * h;
                grown.max[axis] = b.max[axis] + 0.5 * h;
            }
            grown
        }
    };
    let unit = Bounds {
        min: [0.0; 3],
        max: [1.0; 3],
    };
    (bounds, box_transform(&unit, &bounds))
}

/// The axis-aligned affine map taking the box `from` onto the box `to`.
fn box_transform(from: &Bounds, to: &Bounds) -> Matrix4 {
    let mut m = [[0.0; 4]; 4];
    for (axis, row) in m.iter_mut().take(3).enumerate() {
        let s = (to.max[axis] - to.min[axis]) / (from.max[axis] - from.min[axis]);
        row[axis] = s;
        row[3] = to.min[axis] - from.min[axis] * s;
    }
    m[3][3] = 1.0;
    m
}

/// `<transform name="to_world">` holding `m`, for an element whose children are indented by
/// `indent`.
pub(crate) fn matrix_transform(m: &Matrix4, indent: &str) -> String {
    let values: Vec<String> = m.iter().flatten().map(|v| v.to_string()).collect();
    format!(
        "<transform name=\"to_world\">\n{indent}    <matrix value=\"{}\"/>\n{indent}</transform>",
        values.join(" ")
    )
}

pub(crate) fn rgb_element(name: &str, rgb: &[f32; 3]) -> String {
    format!(
        "<rgb name=\"{name}\" value=\"{}, {}, {}\"/>",
        rgb[0], rgb[1], rgb[2]
    )
}

fn grid_volume(param: &str, file: &str, filter: &str, to_world: &Matrix4) -> String {
    format!(
        "<volume type=\"gridvolume\" name=\"{param}\">\n                <string name=\"filename\" value=\"{file}\"/>\n                \
         <string name=\"filter_type\" value=\"{filter}\"/>\n                {}\n            </volume>",
        matrix_transform(to_world, "                ")
    )
}
