//! `<transform>`: Mitsuba's affine transforms, composed in double precision.
//!
//! The children of a `<transform>` apply in the order written: each new one acts after the ones
//! before it, so the result is `M = T_last * ... * T_first`.

use super::plugin::{invalid, numbers, quoted, xyz, Arg};
use super::xml::Element;
use crate::description::{Matrix4, IDENTITY};
use crate::error::SceneError;

/// Row-major 4x4: `p' = m * [p, 1]`.
pub(crate) type Transform = [[f64; 4]; 4];

pub(crate) const IDENTITY_F64: Transform = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Parses a `<transform>` parameter.
pub(crate) fn transform(arg: &Arg<'_>) -> Result<Transform, SceneError> {
    if arg.target.tag != "transform" {
        return Err(arg.wrong_type("a <transform>"));
    }
    let mut m = IDENTITY_F64;
    for step in &arg.target.children {
        let t = match step.tag.as_str() {
            "translate" => translate(xyz(step, 0.0)?),
            "scale" => scale(scale_factors(step)?),
            "rotate" => rotate(step)?,
            "matrix" => matrix(step)?,
            "lookat" => lookat(step)?,
            _ => {
                return Err(SceneError::Unsupported {
                    path: step.file.to_path_buf(),
                    line: step.line,
                    what: format!("<{}> in a <transform>", step.tag),
                    reason: "expected translate, scale, rotate, matrix or lookat".into(),
                })
            }
        };
        m = mul(&t, &m);
    }
    Ok(m)
}

pub(crate) fn mul(a: &Transform, b: &Transform) -> Transform {
    let mut out = [[0.0; 4]; 4];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

pub(crate) fn apply_point(m: &Transform, p: [f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (i, v) in out.iter_mut().enumerate() {
        *v = m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3];
    }
    out
}

pub(crate) fn to_f32(m: &Transform) -> Matrix4 {
    let mut out = IDENTITY;
    for (row, src) in out.iter_mut().zip(m) {
        for (v, s) in row.iter_mut().zip(src) {
            *v = *s as f32;
        }
    }
    out
}

fn translate([x, y, z]: [f64; 3]) -> Transform {
    [
        [1.0, 0.0, 0.0, x],
        [0.0, 1.0, 0.0, y],
        [0.0, 0.0, 1.0, z],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

fn scale([x, y, z]: [f64; 3]) -> Transform {
    [
        [x, 0.0, 0.0, 0.0],
        [0.0, y, 0.0, 0.0],
        [0.0, 0.0, z, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// `<scale value="s">` is uniform, `value="x, y, z"` or `x`/`y`/`z` attributes per axis (a
/// missing axis keeps its size).
fn scale_factors(step: &Element) -> Result<[f64; 3], SceneError> {
    if let Some(raw) = step.attr("value") {
        if let Some(&[s]) = numbers(raw).as_deref() {
            return Ok([s; 3]);
        }
    }
    xyz(step, 1.0)
}

/// Rotation by `angle` degrees about the axis (`x`/`y`/`z` or `value`), counter-clockwise when
/// the axis points at the viewer (Mitsuba's `Transform::rotate`).
fn rotate(step: &Element) -> Result<Transform, SceneError> {
    let axis = xyz(step, 0.0)?;
    let raw_angle = step.attr("angle").unwrap_or("0");
    let angle = super::plugin::parse_f64(raw_angle).ok_or_else(|| {
        invalid(
            step,
            &format!("{} angle", step.describe()),
            "an angle in degrees",
            quoted(raw_angle),
        )
    })?;
    let Some([x, y, z]) = normalize(axis) else {
        return Err(invalid(
            step,
            "<rotate> axis",
            "a non-zero rotation axis",
            format!("{axis:?}"),
        ));
    };
    let (s, c) = angle.to_radians().sin_cos();
    Ok([
        [
            x * x + (1.0 - x * x) * c,
            x * y * (1.0 - c) - z * s,
            x * z * (1.0 - c) + y * s,
            0.0,
        ],
        [
            x * y * (1.0 - c) + z * s,
            y * y + (1.0 - y * y) * c,
            y * z * (1.0 - c) - x * s,
            0.0,
        ],
        [
            x * z * (1.0 - c) - y * s,
            y * z * (1.0 - c) + x * s,
            z * z + (1.0 - z * z) * c,
            0.0,
        ],
        [0.0, 0.0, 0.0, 1.0],
    ])
}

/// `value` holds 16 numbers (4x4, row-major) or 9 (the linear part).
fn matrix(step: &Element) -> Result<Transform, SceneError> {
    let raw = step.attr("value").unwrap_or("");
    let bad = || {
        invalid(
            step,
            "<matrix value>",
            "16 numbers (an affine 4x4 row-major matrix, last row 0 0 0 1) or 9 (3x3)",
            quoted(raw),
        )
    };
    let v = numbers(raw).ok_or_else(bad)?;
    let mut m = IDENTITY_F64;
    match v.len() {
        // volpt's transforms are affine: a projective last row would be silently dropped.
        16 if v[12..] == [0.0, 0.0, 0.0, 1.0] => {
            for (i, row) in m.iter_mut().enumerate() {
                row.copy_from_slice(&v[4 * i..4 * i + 4]);
            }
        }
        9 => {
            for (i, row) in m.iter_mut().take(3).enumerate() {
                row[..3].copy_from_slice(&v[3 * i..3 * i + 3]);
            }
        }
        _ => return Err(bad()),
    }
    Ok(m)
}

/// Mitsuba's look-at: the camera sits at `origin`, looks along `dir = target - origin`, with
/// `left = up x dir` and the columns (left, up', dir, origin).
fn lookat(step: &Element) -> Result<Transform, SceneError> {
    let point = |key: &str| -> Result<[f64; 3], SceneError> {
        let raw = step.attr(key).ok_or_else(|| {
            super::plugin::missing(step, &format!("the {key} attribute (\"x, y, z\")"))
        })?;
        match numbers(raw).as_deref() {
            Some(&[x, y, z]) => Ok([x, y, z]),
            _ => Err(invalid(
                step,
                &format!("<lookat {key}>"),
                "three numbers \"x, y, z\"",
                quoted(raw),
            )),
        }
    };
    let origin = point("origin")?;
    let target = point("target")?;
    let up = point("up")?;
    let dir = normalize(sub(target, origin)).ok_or_else(|| {
        invalid(
            step,
            "<lookat target>",
            "a target different from the origin",
            quoted(step.attr("target").unwrap_or("")),
        )
    })?;
    let parallel = crate::toml_scene::parallel(up, dir);
    let left = normalize(cross(up, dir))
        .filter(|_| !parallel)
        .ok_or_else(|| {
            invalid(
                step,
                "<lookat up>",
                "an up vector not parallel to the viewing direction",
                quoted(step.attr("up").unwrap_or("")),
            )
        })?;
    let new_up = cross(dir, left);
    Ok([
        [left[0], new_up[0], dir[0], origin[0]],
        [left[1], new_up[1], dir[1], origin[1]],
        [left[2], new_up[2], dir[2], origin[2]],
        [0.0, 0.0, 0.0, 1.0],
    ])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (len > 0.0 && len.is_finite()).then(|| v.map(|c| c / len))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn rotation_is_counter_clockwise() {
        let el = Element {
            tag: "rotate".into(),
            attrs: vec![("z".into(), "1".into()), ("angle".into(), "90".into())],
            children: vec![],
            file: std::rc::Rc::from(std::path::Path::new("t.xml")),
            line: 1,
        };
        let m = rotate(&el).unwrap();
        assert!(close(apply_point(&m, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
    }

    #[test]
    fn later_steps_apply_after_earlier_ones() {
        let m = mul(&translate([1.0, 0.0, 0.0]), &scale([2.0, 2.0, 2.0]));
        assert!(close(apply_point(&m, [1.0, 1.0, 1.0]), [3.0, 2.0, 2.0]));
    }

    fn lookat_of(target: &str, up: &str) -> Result<Transform, SceneError> {
        lookat(&Element {
            tag: "lookat".into(),
            attrs: vec![
                ("origin".into(), "0, 0, 0".into()),
                ("target".into(), target.into()),
                ("up".into(), up.into()),
            ],
            children: vec![],
            file: std::rc::Rc::from(std::path::Path::new("t.xml")),
            line: 1,
        })
    }

    /// Parallel means parallel relative to the vectors' lengths: a look direction within float
    /// rounding of the up is refused (its left would be rounding noise), a tiny up at right
    /// angles to the view is accepted, in Mitsuba's `lookat` and in the facade's `look_at` alike.
    #[test]
    fn an_up_parallel_to_the_view_within_rounding_is_refused_whatever_its_length() {
        for (target, up) in [("1e-7, 1, 0", "0, 1, 0"), ("0, 3, 0", "1e-6, -2, 0")] {
            assert!(lookat_of(target, up).is_err(), "target {target}, up {up}");
        }
        for (target, up) in [("1, 0, 0", "0, 1e-13, 1e-13"), ("0.01, 1, 0", "0, 1, 0")] {
            assert!(lookat_of(target, up).is_ok(), "target {target}, up {up}");
        }
        use crate::toml_scene::look_at;
        assert!(look_at([0.0; 3], [1e-7, 1.0, 0.0], [0.0, 1.0, 0.0]).is_none());
        assert!(look_at([1e4, 0.0, 0.0], [1e4, 1.0, 1e-5], [0.0, 1.0, 0.0]).is_none());
        assert!(look_at([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1e-13, 0.0]).is_some());
    }
}
