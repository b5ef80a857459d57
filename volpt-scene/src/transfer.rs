//! Transfer functions: RGB albedo as a function of density, piecewise linear between control
//! points and clamped beyond the first and last.
//!
//! A scanned or simulated volume usually carries one number per voxel. A transfer function colours
//! it: [`TransferFunction::apply`] turns a 1-channel density grid into the 3-channel albedo grid
//! of the same shape, so that, say, dense material scatters white and thin material red.
//!
//! The text file format (documented for users in `docs/guide.md` ("Transfer functions")): one control point
//! `density r g b` per line, numbers separated by whitespace; `#` starts a comment that runs to the
//! end of the line; blank lines are ignored. Densities must be finite and strictly increasing,
//! albedo components in `[0, 1]`, and there must be at least one point (one point is a constant
//! albedo). Errors name the file and line.

use std::path::Path;

use crate::description::GridDesc;
use crate::error::SceneError;

/// One control point: at `density`, the albedo is `albedo`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlPoint {
    pub density: f32,
    pub albedo: [f32; 3],
}

/// A piecewise-linear map from density to RGB albedo; its points are validated (strictly
/// increasing finite densities, albedos in `[0, 1]`, at least one point).
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    points: Vec<ControlPoint>,
}

impl TransferFunction {
    /// Reads a transfer-function file (format in the module docs).
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let text = crate::limits::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses the text of a transfer-function file; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, SceneError> {
        let invalid =
            |line: usize, field: &str, expected: String, found: &str| SceneError::InvalidValue {
                path: path.to_path_buf(),
                line,
                field: field.to_string(),
                expected,
                found: found.to_string(),
            };
        let mut points: Vec<ControlPoint> = Vec::new();
        let mut lines = 0;
        for (index, raw_line) in text.lines().enumerate() {
            let line = index + 1;
            lines = line;
            let content = raw_line.split('#').next().unwrap_or_default().trim();
            if content.is_empty() {
                continue;
            }
            let tokens: Vec<&str> = content.split_whitespace().collect();
            let &[density, r, g, b] = tokens.as_slice() else {
                return Err(invalid(
                    line,
                    "control point",
                    "four numbers `density r g b`".into(),
                    content,
                ));
            };
            let density_value = density
                .parse::<f32>()
                .ok()
                .filter(|d| d.is_finite())
                .ok_or_else(|| invalid(line, "density", "a finite number".into(), density))?;
            if let Some(previous) = points.last() {
                if density_value <= previous.density {
                    return Err(invalid(
                        line,
                        "density",
                        format!(
                            "a density above the previous control point's ({}): densities \
                             must increase strictly",
                            previous.density
                        ),
                        density,
                    ));
                }
            }
            let mut albedo = [0.0; 3];
            for ((slot, token), name) in
                albedo
                    .iter_mut()
                    .zip([r, g, b])
                    .zip(["albedo red", "albedo green", "albedo blue"])
            {
                *slot = token
                    .parse::<f32>()
                    .ok()
                    .filter(|v| (0.0..=1.0).contains(v))
                    .ok_or_else(|| invalid(line, name, "a number in [0, 1]".into(), token))?;
            }
            points.push(ControlPoint {
                density: density_value,
                albedo,
            });
        }
        if points.is_empty() {
            return Err(SceneError::Missing {
                path: path.to_path_buf(),
                line: lines.max(1),
                element: "transfer function".into(),
                what: "control points (lines `density r g b`)".into(),
            });
        }
        Ok(Self { points })
    }

    /// The control points, by increasing density.
    pub fn points(&self) -> &[ControlPoint] {
        &self.points
    }

    /// The albedo at `density`: linear between the neighbouring control points, the first
    /// point's albedo at or below the first density (and for NaN), the last point's at or above
    /// the last.
    pub fn eval(&self, density: f32) -> [f32; 3] {
        let above = self.points.partition_point(|p| p.density <= density);
        let (Some(low), Some(high)) = (
            self.points.get(above.wrapping_sub(1)),
            self.points.get(above),
        ) else {
            // Below the first point (or NaN), or at/above the last: clamp.
            let end = if above == 0 {
                self.points.first()
            } else {
                self.points.last()
            };
            return end.map_or([0.0; 3], |p| p.albedo);
        };
        let t = (density - low.density) / (high.density - low.density);
        std::array::from_fn(|c| low.albedo[c] + t * (high.albedo[c] - low.albedo[c]))
    }

    /// The 3-channel albedo grid of a density grid: same resolution, bounds and convention, each
    /// voxel's albedo [`Self::eval`] of its density. A density grid has one channel; of a grid
    /// with more, each voxel's first channel is taken as its density.
    pub fn apply(&self, density: &GridDesc) -> GridDesc {
        let channels = density.channels.max(1) as usize;
        let samples = density.samples();
        let table: Vec<f32> = density.data[samples.len()..].to_vec();
        let mut data = Vec::with_capacity(samples.len() / channels * 3 + table.len());
        for voxel in samples.chunks_exact(channels) {
            data.extend_from_slice(&self.eval(voxel[0]));
        }
        // A sparse density's albedo is sparse too, with the same bricks: the same table.
        data.extend(table);
        GridDesc {
            layout: density.layout,
            resolution: density.resolution,
            channels: 3,
            bounds: density.bounds,
            convention: density.convention,
            data,
        }
    }
}
