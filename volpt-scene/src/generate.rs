//! Procedural volumes for the thesis' benchmark scenes, generated rather than committed.
//!
//! `cgg-logo` and `ad` are solid blocks of constant density whose albedo is white except for a
//! coloured logo printed a few voxels deep into the face the camera sees (+z), like a full-colour 3D
//! print. The letters come from a 5x7 bitmap font, scaled to span most of the face.
//!
//! `envmap-cube` is lit by a small procedural sky ([`SKY`]), written as an OpenEXR lat-long map.
//!
//! `smoke` reads a procedural plume ([`SMOKE`]) of the shape, box and density statistics of Mitsuba's
//! `smoke.vol`, which may not be redistributed: a widening column of fractal noise rising through
//! the box. The real grid stays usable with `-D data=DIR`.

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
/// `ad/`, the sky map of `envmap-cube/` and the stand-in density grid of `smoke/`.
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
    written.push(SMOKE.write(&scenes_dir.join("smoke"))?);
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

/// A smoke plume on a vertex-centred grid: density is fractal value noise inside a column that
/// rises along +y from a fifth of the box's height, bending in x and z and widening as it rises,
/// squared above a threshold so that most of the plume is thin wisps with a few dense cores
/// (clamped at 1).
///
/// Only `+`, `*`, `/`, `floor` and integer hashing go into a value, all exact or correctly rounded
/// in IEEE arithmetic, so the grid is the same bit for bit on every machine.
#[derive(Clone, Copy, Debug)]
pub struct Plume {
    pub resolution: [u32; 3],
    pub bounds: Bounds,
}

/// The stand-in for Mitsuba's `smoke.vol` in `scenes/smoke`: the same 128 x 128 x 50 samples and
/// box, density 0..1; about 13% of its samples are non-zero (the real grid: 38%), 4% exceed 0.1
/// (3.5%) and its mean is about 0.014 (0.012).
pub const SMOKE: Plume = Plume {
    resolution: [128, 128, 50],
    bounds: Bounds {
        min: [-0.5, -0.5, -0.1953125],
        max: [0.5, 0.5, 0.1953125],
    },
};

/// A well-mixed 32-bit hash of a lattice point and an octave, uniform on `[0, 1]`.
fn lattice_value(p: [i64; 3], octave: u32) -> f64 {
    let mut h = (p[0] as u32)
        .wrapping_mul(0x8da6_b343)
        .wrapping_add((p[1] as u32).wrapping_mul(0xd816_3841))
        .wrapping_add((p[2] as u32).wrapping_mul(0xcb1a_b31f))
        .wrapping_add(octave.wrapping_mul(0x1656_67b1));
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    f64::from(h) / f64::from(u32::MAX)
}

/// Value noise: the lattice values around `p` blended with smoothstep weights; in `[0, 1]`.
fn value_noise(p: [f64; 3], octave: u32) -> f64 {
    let cell = p.map(f64::floor);
    let t = [0, 1, 2].map(|a| {
        let f = p[a] - cell[a];
        f * f * (3.0 - 2.0 * f)
    });
    let mut sum = 0.0;
    for corner in 0..8 {
        let mut weight = 1.0;
        let mut lattice = [0i64; 3];
        for a in 0..3 {
            let up = corner >> a & 1 == 1;
            lattice[a] = cell[a] as i64 + i64::from(up);
            weight *= if up { t[a] } else { 1.0 - t[a] };
        }
        sum += weight * lattice_value(lattice, octave);
    }
    sum
}

/// Four octaves of value noise, 6 cells per unit length at the first, normalised to `[0, 1]`.
fn fractal_noise(p: [f64; 3]) -> f64 {
    let (mut sum, mut amplitude, mut frequency) = (0.0, 0.5, 6.0);
    for octave in 0..4 {
        sum += amplitude * value_noise(p.map(|c| c * frequency), octave);
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    sum / 0.9375
}

impl Plume {
    /// The density at world position `p` in the unit-sized box's frame (`y` in `[-0.5, 0.5]`).
    fn density(p: [f64; 3]) -> f64 {
        // Height from the box's floor, 0..1; the plume starts at 0.2 and fades in over 0.08.
        let height = p[1] + 0.5;
        if height < 0.2 {
            return 0.0;
        }
        let u = (height - 0.2) / 0.8;
        let centre_x = 0.25 - 0.55 * u + 0.7 * u * u * (1.0 - u);
        let centre_z = 0.16 * (1.0 - 2.0 * u) * u;
        let radius = 0.06 + 0.22 * u;
        let (dx, dz) = (p[0] - centre_x, p[2] - centre_z);
        let r2 = (dx * dx + dz * dz) / (radius * radius);
        if r2 >= 1.0 {
            return 0.0;
        }
        let envelope = (1.0 - r2) * (1.0 - r2);
        let fade = ((height - 0.2) / 0.08).min(1.0);
        let wisp = (fractal_noise(p) - 0.42).max(0.0);
        (12.0 * envelope * fade * wisp * wisp).min(1.0)
    }

    /// The density grid: sample `(i, j, k)` at the box's corner plus `(i, j, k) / (resolution - 1)`
    /// of its size (vertex-centred, as Mitsuba 0.6 reads `smoke.vol`).
    pub fn grid(&self) -> VolGrid {
        let [w, h, d] = self.resolution;
        let (min, max) = (self.bounds.min, self.bounds.max);
        let at = |i: u32, n: u32, a: usize| {
            f64::from(min[a])
                + f64::from(max[a] - min[a]) * f64::from(i) / f64::from(n.saturating_sub(1).max(1))
        };
        let mut data = Vec::with_capacity((w * h * d) as usize);
        for k in 0..d {
            for j in 0..h {
                for i in 0..w {
                    let p = [at(i, w, 0), at(j, h, 1), at(k, d, 2)];
                    data.push(Self::density(p) as f32);
                }
            }
        }
        VolGrid {
            resolution: self.resolution,
            channels: 1,
            bbox: self.bounds,
            data,
        }
    }

    /// Writes `smoke.vol` into `dir`, returning its path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf, SceneError> {
        create_dir(dir)?;
        let path = dir.join("smoke.vol");
        write_vol(&path, &self.grid())?;
        Ok(path)
    }
}
