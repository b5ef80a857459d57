//! The one `<shape>`: the closed surface that bounds the medium, its surface bsdf and interior
//! medium.
//!
//! - `cube` ([-1, 1]^3 mapped by `toWorld`): the box itself when `toWorld` only scales and
//!   translates it (or rotates it by multiples of 90 degrees); under any other transform, its 12
//!   triangles placed by it.
//! - `obj`, `ply`: a closed triangle mesh file placed by `toWorld`; the box itself when its
//!   vertices (after `toWorld`) are the 8 corners of an axis-aligned box. As in Mitsuba 3, a
//!   dielectric surface scatters about interpolated vertex normals unless `face_normals` is
//!   true: the file's (OBJ `vn`, PLY `nx ny nz`), or where it has none, smooth ones computed as
//!   Mitsuba computes them ([`TriangleSoup::smooth_normals`]). An index-matched (`null`)
//!   surface has no normals to shade with.
//! - `sphere` (`center`, `radius`, `toWorld`): Mitsuba's sphere is analytic; volpt's is a
//!   latitude-longitude mesh inscribed in it ([`SPHERE_RINGS`] x [`SPHERE_SEGMENTS`], 16,128
//!   triangles), whose surface lies within 3.1e-4 radii (1 - cos(pi / 128)) inside the sphere's.
//!
//! A box boundary is traced with one slab test; a mesh with a ray cast through its BVH.

use std::path::Path;
use std::sync::Arc;

use super::boxes::{box_from_corners, transformed_box};
use super::plugin::{invalid, Ctx, Plugin};
use super::transform::{apply_point, mul, transform, Transform, IDENTITY_F64};
use super::xml::Element;
use crate::boundary::MITSUBA_KINDS;
use crate::description::{BoundaryDesc, BsdfDesc, MediumDesc};
use crate::error::SceneError;
use crate::mesh::{read_mesh, MeshDesc, TriangleSoup};

const KINDS: &str = "volpt's boundary is a closed surface: a cube, a sphere, or an obj or ply \
                     mesh (closed and consistently oriented)";

/// Bands from pole to pole of the mesh that stands for Mitsuba's `sphere`.
pub const SPHERE_RINGS: u32 = 64;
/// Steps around the axis of the mesh that stands for Mitsuba's `sphere`.
pub const SPHERE_SEGMENTS: u32 = 128;

/// The boundary's geometry before its surface: a box, or a mesh (its bounding box follows).
enum Geometry {
    Box(crate::description::Bounds),
    Mesh(Arc<MeshDesc>),
}

/// A shape's geometry as read: placed, or a mesh file's triangles, placed once the surface says
/// whether they need vertex normals.
enum Read {
    Placed(Geometry),
    File(std::path::PathBuf, TriangleSoup),
}

pub(crate) fn boundary(
    el: &Element,
    ctx: &Ctx<'_>,
) -> Result<(BoundaryDesc, MediumDesc), SceneError> {
    let p = Plugin::new(el, ctx);
    let kind = p.kind()?;
    if !matches!(kind, "cube" | "obj" | "ply" | "sphere") {
        return Err(p.unsupported(KINDS));
    }
    let to_world = match p.find(&["toWorld", "to_world"])? {
        Some(arg) => transform(&arg)?,
        None => IDENTITY_F64,
    };
    // Errors in a file the shape names name the shape's element too.
    let referenced = |error: SceneError| SceneError::Referenced {
        path: el.file.to_path_buf(),
        line: el.line,
        element: el.describe(),
        error: Box::new(error),
    };
    let read = match kind {
        "cube" => match transformed_box(&to_world, [-1.0; 3], [1.0; 3]) {
            Some(bounds) => Read::Placed(Geometry::Box(bounds)),
            None => {
                let (vertices, triangles) =
                    volpt_core::mesh::primitives::cuboid(volpt_core::Aabb::new(
                        volpt_core::Vec3::splat(-1.0),
                        volpt_core::Vec3::splat(1.0),
                    ));
                let soup = TriangleSoup::new(vertices, triangles);
                Read::Placed(Geometry::Mesh(
                    MeshDesc::placed(Path::new("cube"), &soup, &to_world).map_err(referenced)?,
                ))
            }
        },
        "sphere" => {
            let center = match p.find(&["center"])? {
                Some(arg) => arg.point()?,
                None => [0.0; 3],
            };
            let radius = match p.find(&["radius"])? {
                Some(arg) => {
                    let r = arg.float()?;
                    // `float` is finite.
                    if r <= 0.0 {
                        return Err(arg.invalid("a positive radius", r.to_string()));
                    }
                    f64::from(r)
                }
                None => 1.0,
            };
            // Mitsuba places the sphere of `center` and `radius`, then applies `to_world`.
            let mut local = IDENTITY_F64;
            for a in 0..3 {
                local[a][a] = radius;
                local[a][3] = center[a];
            }
            let (vertices, triangles) =
                volpt_core::mesh::primitives::sphere([0.0; 3], 1.0, SPHERE_RINGS, SPHERE_SEGMENTS);
            let soup = TriangleSoup::new(vertices, triangles);
            Read::Placed(Geometry::Mesh(
                MeshDesc::placed(Path::new("sphere"), &soup, &mul(&to_world, &local))
                    .map_err(referenced)?,
            ))
        }
        _ => {
            let filename = p
                .find(&["filename"])?
                .ok_or_else(|| p.missing("<string name=\"filename\">"))?;
            let path = el.dir().join(filename.string()?);
            let soup = read_mesh(&path).map_err(referenced)?;
            Read::File(path, soup)
        }
    };
    if let Some(arg) = p.find(&["flipNormals", "flip_normals"])? {
        if arg.boolean()? {
            return Err(arg.invalid(
                "false: the medium is inside, where the normals point away from",
                "true",
            ));
        }
    }
    let face_normals = match p.find(&["faceNormals", "face_normals"])? {
        Some(arg) => arg.boolean()?,
        None => false,
    };
    // Shading details that do not change the geometry.
    p.ignore(&[
        "maxSmoothAngle",
        "flipTexCoords",
        "flip_tex_coords",
        "collapse",
    ]);

    let mut interior = None;
    for arg in p.objects("medium")? {
        match arg.written.attr("name") {
            Some("interior") if interior.is_none() => interior = Some(arg),
            Some("interior") => {
                return Err(invalid(
                    arg.written,
                    &arg.written.describe(),
                    "one interior medium",
                    "a second one".into(),
                ))
            }
            Some("exterior") => {
                return Err(SceneError::Unsupported {
                    path: arg.written.file.to_path_buf(),
                    line: arg.written.line,
                    what: arg.written.describe(),
                    reason: "volpt's exterior is vacuum: only an interior medium is rendered"
                        .into(),
                })
            }
            other => {
                return Err(invalid(
                    arg.written,
                    &arg.written.describe(),
                    "name=\"interior\"",
                    other.map_or("no name".into(), |n| format!("name=\"{n}\"")),
                ))
            }
        }
    }
    let interior = interior.ok_or_else(|| {
        p.missing("an interior medium (<medium name=\"interior\" ...> or <ref name=\"interior\" id=\"...\"/>)")
    })?;
    let Some(surface) = p.object("bsdf")? else {
        // A `<ref>` to the wrong kind of object is the likelier mistake: report it first.
        let el = p.el;
        p.finish()?;
        return Err(super::plugin::missing(
            el,
            &format!(
                "a <bsdf>: volpt needs the boundary's surface to be {MITSUBA_KINDS} (Mitsuba \
                 would make it diffuse)"
            ),
        ));
    };
    let surface = BsdfDesc::from_mitsuba(surface.target, ctx)?;
    let medium = MediumDesc::from_mitsuba(interior.target, ctx)?;
    p.finish()?;
    let geometry = match read {
        Read::File(path, mut soup) => {
            if face_normals || surface == BsdfDesc::Null {
                soup.normals.clear();
            } else if soup.normals.is_empty() {
                soup.normals = soup.smooth_normals();
            }
            if soup.normals.is_empty() {
                mesh_or_box(&path, &soup, &to_world)
            } else {
                MeshDesc::placed(&path, &soup, &to_world).map(Geometry::Mesh)
            }
            .map_err(referenced)?
        }
        Read::Placed(geometry) => geometry,
    };
    let boundary = match geometry {
        Geometry::Box(bounds) => BoundaryDesc::box_(bounds, surface),
        Geometry::Mesh(mesh) => BoundaryDesc::mesh(mesh, surface),
    };
    Ok((boundary, medium))
}

/// A mesh file's triangles placed by `to_world`: the box itself if its vertices are a box's 8
/// corners (one slab test instead of a ray cast), else the mesh.
fn mesh_or_box(
    path: &Path,
    soup: &TriangleSoup,
    to_world: &Transform,
) -> Result<Geometry, SceneError> {
    if soup.vertices.len() == 8 {
        let world: Vec<[f64; 3]> = soup
            .vertices
            .iter()
            .map(|&v| apply_point(to_world, v.map(f64::from)))
            .collect();
        if let Some(bounds) = box_from_corners(&world) {
            return Ok(Geometry::Box(bounds));
        }
    }
    MeshDesc::placed(path, soup, to_world).map(Geometry::Mesh)
}
