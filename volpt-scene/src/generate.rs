//! Procedural volumes for the thesis' benchmark scenes, generated rather than committed.
//!
//! `cgg-logo` and `ad` are solid blocks of constant density whose albedo is white except for a
//! coloured logo printed a few voxels deep into the face the camera sees (+z), like a full-colour 3D
//! print. The letters come from a 5x7 bitmap font, scaled to span most of the face.
//!
//! `envmap-cube` is lit by a small procedural sky ([`SKY`]), written as an OpenEXR lat-long map.

use std::path::{Path, PathBuf};

use crate::description::Bounds;
use crate::error::SceneError;
use crate::output::{create_dir, write_rgb_exr};
use crate::vol::{write_vol, VolGrid};

/// One printed block: its voxel resolution, the text printed on it and how deep the ink goes.
#[derive(Clone, Copy, Debug)]
pub struct PrintedBlock {
    pub resolution: [u32; 3],
    pub text: &'static str,
    pub ink_depth: u32,
    pub density: f32,
    /// Albedo of the unprinted material.
    pub white: [f32; 3],
}

/// Inks cycle over the letters: cyan, magenta, yellow, as in a CMY print.
pub const INKS: [[f32; 3]; 3] = [[0.05, 0.55, 0.85], [0.8, 0.08, 0.45], [0.9, 0.75, 0.05]];

/// The `cgg-logo` block: a unit cube of 100^3 voxels.
pub const CGG_LOGO: PrintedBlock = PrintedBlock {
    resolution: [100, 100, 100],
    text: "CGG",
    ink_depth: 10,
    density: 1.0,
    white: [0.9, 0.9, 0.9],
};

/// The `ad` block: a 3.2 x 3.2 x 1 slab of 320 x 320 x 100 voxels.
pub const AD: PrintedBlock = PrintedBlock {
    resolution: [320, 320, 100],
    text: "AD",
    ink_depth: 10,
    density: 1.0,
    white: [0.9, 0.9, 0.9],
};

const GLYPH_WIDTH: usize = 5;
const GLYPH_HEIGHT: usize = 7;

fn glyph(c: char) -> [&'static str; GLYPH_HEIGHT] {
    match c {
        'A' => [
            ".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#",
        ],
        'C' => [
            ".###.", "#...#", "#....", "#....", "#....", "#...#", ".###.",
        ],
        'D' => [
            "####.", "#...#", "#...#", "#...#", "#...#", "#...#", "####.",
        ],
        'G' => [
            ".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".###.",
        ],
        _ => ["....."; GLYPH_HEIGHT],
    }
}

impl PrintedBlock {
    /// Which ink (index into [`INKS`]) covers column `x`, row `y` of the printed face (y up), if any.
    pub fn ink_at(&self, x: u32, y: u32) -> Option<usize> {
        let [w, h, _] = self.resolution;
        let letters = self.text.chars().count();
        // Text cells: each glyph is 5 columns plus one of spacing; the text spans ~80% of the face.
        let columns = letters * (GLYPH_WIDTH + 1) - 1;
        let cell = ((w as usize * 4 / 5) / columns)
            .min((h as usize * 4 / 5) / GLYPH_HEIGHT)
            .max(1);
        let (text_w, text_h) = (columns * cell, GLYPH_HEIGHT * cell);
        let x0 = (w as usize - text_w) / 2;
        let top = (h as usize - text_h) / 2;
        let row_from_top = (h - 1 - y) as usize;
        let (cx, cy) = (
            (x as usize).checked_sub(x0)? / cell,
            row_from_top.checked_sub(top)? / cell,
        );
        if cx >= columns || cy >= GLYPH_HEIGHT {
            return None;
        }
        let (letter, column) = (cx / (GLYPH_WIDTH + 1), cx % (GLYPH_WIDTH + 1));
        if column == GLYPH_WIDTH {
            return None;
        }
        let c = self.text.chars().nth(letter)?;
        (glyph(c)[cy].as_bytes()[column] == b'#').then_some(letter % INKS.len())
    }

    /// The density grid (constant) and the RGB albedo grid, both over `bounds`.
    pub fn grids(&self, bounds: Bounds) -> (VolGrid, VolGrid) {
        let [w, h, d] = self.resolution;
        let n = (w * h * d) as usize;
        let density = VolGrid {
            resolution: self.resolution,
            channels: 1,
            bbox: bounds,
            data: vec![self.density; n],
        };
        let mut albedo = Vec::with_capacity(3 * n);
        for z in 0..d {
            let printed = z >= d - self.ink_depth.min(d);
            for y in 0..h {
                for x in 0..w {
                    let ink = if printed { self.ink_at(x, y) } else { None };
                    albedo.extend_from_slice(&ink.map_or(self.white, |i| INKS[i]));
                }
            }
        }
        let albedo = VolGrid {
            resolution: self.resolution,
            channels: 3,
            bbox: bounds,
            data: albedo,
        };
        (density, albedo)
    }

    /// Writes `density.vol` and `albedo.vol` into `dir`, returning their paths.
    pub fn write(&self, dir: &Path, bounds: Bounds) -> Result<[PathBuf; 2], SceneError> {
        create_dir(dir)?;
        let (density, albedo) = self.grids(bounds);
        let paths = [dir.join("density.vol"), dir.join("albedo.vol")];
        write_vol(&paths[0], &density)?;
        write_vol(&paths[1], &albedo)?;
        Ok(paths)
    }
}

/// Generates the inputs of the included scenes under `scenes_dir`: the grids of `cgg-logo/` and
/// `ad/`, and the sky map of `envmap-cube/`.
pub fn generate_scene_inputs(scenes_dir: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let unit = Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    let slab = Bounds {
        min: [-1.6, -1.6, -0.5],
        max: [1.6, 1.6, 0.5],
    };
    let mut written = Vec::new();
    written.extend(CGG_LOGO.write(&scenes_dir.join("cgg-logo"), unit)?);
    written.extend(AD.write(&scenes_dir.join("ad"), slab)?);
    written.push(SKY.write(&scenes_dir.join("envmap-cube"))?);
    Ok(written)
}

/// A lat-long sky for Mitsuba 3's `envmap` (rows pole to pole: row `j` at polar angle
/// `pi j / (height - 1)`, column `i` at azimuth `2 pi (i + 0.5) / width`, with the map's look
/// direction `(sin t sin p, cos t, -sin t cos p)`): a blue sky brightening towards the horizon,
/// dark warm ground, and a small warm sun `sun_elevation` degrees above the horizon towards +x.
#[derive(Clone, Copy, Debug)]
pub struct Sky {
    pub width: u32,
    pub height: u32,
    pub zenith: [f32; 3],
    pub horizon: [f32; 3],
    pub ground: [f32; 3],
    pub sun: [f32; 3],
    pub sun_elevation: f32,
    /// Angular radius (radians) at which the sun has fallen to `1/e` of its peak.
    pub sun_radius: f32,
}

/// The sky of `scenes/envmap-cube`: 64x32 texels.
pub const SKY: Sky = Sky {
    width: 64,
    height: 32,
    zenith: [0.25, 0.45, 0.9],
    horizon: [0.85, 0.9, 1.0],
    ground: [0.12, 0.09, 0.06],
    sun: [60.0, 50.0, 35.0],
    sun_elevation: 30.0,
    sun_radius: 0.08,
};

impl Sky {
    /// Linear RGB, row-major from the top-left texel.
    pub fn texels(&self) -> Vec<f32> {
        use std::f32::consts::PI;
        let (sin_e, cos_e) = self.sun_elevation.to_radians().sin_cos();
        let sun_dir = [cos_e, sin_e, 0.0];
        let mut rgb = Vec::with_capacity(3 * (self.width * self.height) as usize);
        for j in 0..self.height {
            let theta = PI * j as f32 / (self.height - 1) as f32;
            for i in 0..self.width {
                let phi = 2.0 * PI * (i as f32 + 0.5) / self.width as f32;
                let d = [
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                ];
                let base = if d[1] >= 0.0 {
                    let t = d[1].sqrt();
                    [0, 1, 2].map(|c| self.horizon[c] + (self.zenith[c] - self.horizon[c]) * t)
                } else {
                    self.ground
                };
                let cos_angle = d[0] * sun_dir[0] + d[1] * sun_dir[1] + d[2] * sun_dir[2];
                let angle = cos_angle.clamp(-1.0, 1.0).acos();
                let glow = (-(angle / self.sun_radius).powi(2)).exp();
                rgb.extend([0, 1, 2].map(|c| base[c] + self.sun[c] * glow));
            }
        }
        rgb
    }

    /// Writes `sky.exr` (half-float RGB) into `dir`, returning its path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf, SceneError> {
        use exr::prelude::f16;
        create_dir(dir)?;
        let path = dir.join("sky.exr");
        let rgb = self.texels();
        let width = self.width as usize;
        write_rgb_exr(&path, width, self.height as usize, |x, y| {
            let i = 3 * (y * width + x);
            (
                f16::from_f32(rgb[i]),
                f16::from_f32(rgb[i + 1]),
                f16::from_f32(rgb[i + 2]),
            )
        })?;
        Ok(path)
    }
}
