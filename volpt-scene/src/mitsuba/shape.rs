//! The one `<shape>`: the box that bounds the medium, its surface bsdf and interior medium.
//!
//! volpt's boundary is an axis-aligned box. Mitsuba writes one as a `cube` ([-1, 1]^3 mapped by
//! `toWorld`) or as an `obj` mesh; either is accepted when the result is exactly such a box.

use super::boxes::{box_from_corners, transformed_box};
use super::obj::obj_vertices;
use super::plugin::{invalid, Ctx, Plugin};
use super::transform::{apply_point, transform, IDENTITY_F64};
use super::xml::Element;
use crate::boundary::MITSUBA_KINDS;
use crate::description::{BoundaryDesc, BsdfDesc, MediumDesc};
use crate::error::SceneError;

const NOT_A_BOX: &str = "volpt's boundary must be an axis-aligned box: a cube whose toWorld only \
                         scales and translates it (or rotates it by multiples of 90 degrees), or \
                         an obj whose vertices are the 8 corners of such a box";

pub(crate) fn boundary(
    el: &Element,
    ctx: &Ctx<'_>,
) -> Result<(BoundaryDesc, MediumDesc), SceneError> {
    let p = Plugin::new(el, ctx);
    let kind = p.kind()?;
    if kind != "cube" && kind != "obj" {
        return Err(p.unsupported(NOT_A_BOX));
    }
    let to_world = match p.find(&["toWorld", "to_world"])? {
        Some(arg) => transform(&arg)?,
        None => IDENTITY_F64,
    };
    let bounds = if kind == "cube" {
        transformed_box(&to_world, [-1.0; 3], [1.0; 3]).ok_or_else(|| p.unsupported(NOT_A_BOX))?
    } else {
        let filename = p
            .find(&["filename"])?
            .ok_or_else(|| p.missing("<string name=\"filename\">"))?;
        let path = el.dir().join(filename.string()?);
        let vertices = obj_vertices(&path).map_err(|error| SceneError::Referenced {
            path: el.file.to_path_buf(),
            line: el.line,
            element: el.describe(),
            error: Box::new(error),
        })?;
        let world: Vec<[f64; 3]> = vertices
            .iter()
            .map(|&v| apply_point(&to_world, v))
            .collect();
        box_from_corners(&world).ok_or_else(|| {
            p.unsupported(format!(
                "the {} vertices of {} (after toWorld) are not the 8 corners of an axis-aligned \
                 box; {NOT_A_BOX}",
                vertices.len(),
                path.display()
            ))
        })?
    };
    // Shading details that do not change a box's geometry.
    p.ignore(&[
        "flipNormals",
        "flip_normals",
        "faceNormals",
        "face_normals",
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
    Ok((
        BoundaryDesc {
            bounds,
            bsdf: surface,
        },
        medium,
    ))
}
