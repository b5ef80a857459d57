//! Procedural volumes for the thesis' benchmark scenes, generated rather than committed.
//!
//! `cgg-logo` and `ad` are solid blocks of constant density whose albedo is white except for a
//! coloured logo printed a few voxels deep into the face the camera sees (+z), like a full-colour 3D
//! print. The letters come from a 5x7 bitmap font, scaled to span most of the face.

use std::path::{Path, PathBuf};

use crate::description::Bounds;
use crate::error::SceneError;
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
        std::fs::create_dir_all(dir).map_err(|error| SceneError::Io {
            path: dir.to_owned(),
            error,
        })?;
        let (density, albedo) = self.grids(bounds);
        let paths = [dir.join("density.vol"), dir.join("albedo.vol")];
        write_vol(&paths[0], &density)?;
        write_vol(&paths[1], &albedo)?;
        Ok(paths)
    }
}

/// Generates the grids of the included scenes under `scenes_dir` (`cgg-logo/` and `ad/`).
pub fn generate_thesis_grids(scenes_dir: &Path) -> Result<Vec<PathBuf>, SceneError> {
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
    Ok(written)
}
