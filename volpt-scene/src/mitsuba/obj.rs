//! Vertex positions from a Wavefront OBJ file: the only part of a mesh volpt's box boundary needs.

use std::path::Path;

use super::plugin::parse_f64;
use crate::error::SceneError;

/// The `v x y z [w]` positions of an OBJ file, in file order.
pub(crate) fn obj_vertices(path: &Path) -> Result<Vec<[f64; 3]>, SceneError> {
    let bytes = crate::limits::read_file(path)?;
    // OBJ is ASCII in practice; comments in other encodings should not stop us.
    let text = String::from_utf8_lossy(&bytes);
    let mut vertices = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let coords: Option<Vec<f64>> = words.map(parse_f64).collect();
        match coords.as_deref() {
            Some(&[x, y, z]) | Some(&[x, y, z, _]) => vertices.push([x, y, z]),
            _ => {
                return Err(SceneError::InvalidValue {
                    path: path.to_path_buf(),
                    line: i + 1,
                    field: "vertex (v)".into(),
                    expected: "three finite numbers \"v x y z\"".into(),
                    found: format!("\"{}\"", line.trim()),
                })
            }
        }
    }
    Ok(vertices)
}
