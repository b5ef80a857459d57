//! The generated inputs of the included scenes (`volpt scene generate`), read back: the printed
//! text's letters centred and upright on the face the camera sees, the ink only in the front
//! layers, the sky's sun where its elevation puts it over a zenith, horizon and ground of the
//! documented colours, the smoke plume in smoke.vol's box with its documented statistics, and every
//! file written holding what the generator made.

use std::path::Path;

use volpt_scene::generate::{generate_scene_inputs, PrintedBlock, AD, CGG_LOGO, INKS, SKY, SMOKE};
use volpt_scene::read_vol;

/// The test's own copy of the 5x7 letters the blocks print (row 0 at the top).
fn letter(c: char) -> [&'static str; 7] {
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
        other => panic!("no test glyph for {other:?}"),
    }
}

/// The inked texels' bounding box on the printed face: `[x_min, x_max, y_min, y_max]`.
fn ink_box(block: &PrintedBlock) -> [u32; 4] {
    let [w, h, _] = block.resolution;
    let mut b = [u32::MAX, 0, u32::MAX, 0];
    for y in 0..h {
        for x in 0..w {
            if block.ink_at(x, y).is_some() {
                b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
            }
        }
    }
    assert!(b[0] <= b[1], "{}: no ink at all", block.text);
    b
}

#[test]
fn printed_text_reads_back_centred_and_upright() {
    for block in [CGG_LOGO, AD] {
        let [w, h, _] = block.resolution;
        let [x0, x1, y0, y1] = ink_box(&block);
        let name = block.text;
        // Centred: the margins on either side differ by one texel at most.
        assert!(
            (x0 as i64 - (w - 1 - x1) as i64).abs() <= 1,
            "{name}: x {x0}..{x1} of {w}"
        );
        assert!(
            (y0 as i64 - (h - 1 - y1) as i64).abs() <= 1,
            "{name}: y {y0}..{y1} of {h}"
        );
        // The letters are cells of 5 columns and a spacing column (none after the last), 7 rows,
        // of one square cell size, spanning at most 80% of the face and at least half of it.
        let columns = 6 * name.len() as u32 - 1;
        let (text_w, text_h) = (x1 - x0 + 1, y1 - y0 + 1);
        assert_eq!(
            text_w % columns,
            0,
            "{name}: {text_w} texels for {columns} columns"
        );
        let cell = text_w / columns;
        assert_eq!(text_h, 7 * cell, "{name}: cells of {cell} texels");
        assert!(
            5 * text_w <= 4 * w && 5 * text_h <= 4 * h,
            "{name}: {text_w}x{text_h}"
        );
        assert!(
            2 * text_w >= w || 2 * text_h >= h,
            "{name}: {text_w}x{text_h}"
        );
        // Each cell's centre holds its letter's ink (cycling over the inks) or none; row 0 of a
        // letter is its top, at the largest y: the face is printed the right way up.
        for (i, c) in name.chars().enumerate() {
            for (row, line) in letter(c).iter().enumerate() {
                for col in 0..6 {
                    if i == name.len() - 1 && col == 5 {
                        continue;
                    }
                    let x = x0 + (6 * i as u32 + col) * cell + cell / 2;
                    let y = y1 - (row as u32 * cell + cell / 2);
                    let inked = col < 5 && line.as_bytes()[col as usize] == b'#';
                    assert_eq!(
                        block.ink_at(x, y),
                        inked.then_some(i % INKS.len()),
                        "{name}: letter {c} row {row} column {col} at ({x}, {y})"
                    );
                }
            }
        }
    }
}

#[test]
fn grids_are_white_with_ink_in_the_front_layers_only() {
    let bounds = volpt_scene::Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    for block in [CGG_LOGO, AD] {
        let [w, h, d] = block.resolution;
        let (density, albedo) = block.grids(bounds);
        let n = (w * h * d) as usize;
        assert_eq!(density.data.len(), n);
        assert!(density.data.iter().all(|&v| v == block.density));
        assert_eq!((albedo.channels, albedo.data.len()), (3, 3 * n));
        let [x0, x1, y0, y1] = ink_box(&block);
        let at = |x: u32, y: u32, z: u32| {
            let i = 3 * ((z * h + y) * w + x) as usize;
            [albedo.data[i], albedo.data[i + 1], albedo.data[i + 2]]
        };
        for y in y0..=y1 {
            for x in x0..=x1 {
                let Some(ink) = block.ink_at(x, y) else {
                    continue;
                };
                // Inked through the front `ink_depth` layers (+z, the camera's side), white behind.
                assert_eq!(at(x, y, d - 1), INKS[ink]);
                assert_eq!(at(x, y, d - block.ink_depth), INKS[ink]);
                assert_eq!(at(x, y, d - block.ink_depth - 1), block.white);
                assert_eq!(at(x, y, 0), block.white);
            }
        }
        assert_eq!(at(0, 0, d - 1), block.white);
    }
}

/// The direction of texel `(i, j)` of the sky by the mapping its documentation gives.
fn sky_direction(i: u32, j: u32) -> [f64; 3] {
    use std::f64::consts::PI;
    let theta = PI * j as f64 / (SKY.height - 1) as f64;
    let phi = 2.0 * PI * (i as f64 + 0.5) / SKY.width as f64;
    [
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    ]
}

#[test]
fn sky_has_its_sun_at_its_elevation_over_zenith_horizon_and_ground() {
    let rgb = SKY.texels();
    let (w, h) = (SKY.width, SKY.height);
    assert_eq!(rgb.len(), (3 * w * h) as usize);
    let texel = |i: u32, j: u32| {
        let k = 3 * (j * w + i) as usize;
        [rgb[k], rgb[k + 1], rgb[k + 2]]
    };
    // The brightest texel looks within a texel's angle of the sun: 30 degrees up, towards +x.
    let (mut best, mut at) = (f32::MIN, (0, 0));
    for j in 0..h {
        for i in 0..w {
            if texel(i, j)[0] > best {
                (best, at) = (texel(i, j)[0], (i, j));
            }
        }
    }
    let e = SKY.sun_elevation.to_radians() as f64;
    let sun = [e.cos(), e.sin(), 0.0];
    let d = sky_direction(at.0, at.1);
    let angle = (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2])
        .min(1.0)
        .acos();
    let texel_angle = std::f64::consts::PI / (h - 1) as f64;
    assert!(
        angle <= texel_angle,
        "brightest texel {at:?} is {angle} rad from the sun"
    );
    assert!(best > SKY.sun[0] * 0.5, "the sun's peak {best}");
    // Far from the sun (more than 10 of its radii) the sky is its plain colours: the zenith
    // on the top row, the ground on the bottom row, and between them a gradient that brightens
    // monotonically towards the horizon in the red channel (horizon 0.85, zenith 0.25).
    for i in 0..w {
        let top = texel(i, 0);
        let bottom = texel(i, h - 1);
        for c in 0..3 {
            assert!(
                (top[c] - SKY.zenith[c]).abs() < 1e-6,
                "top row {i}: {top:?}"
            );
            assert!(
                (bottom[c] - SKY.ground[c]).abs() < 1e-6,
                "bottom row {i}: {bottom:?}"
            );
        }
    }
    let far = (0..w)
        .filter(|&i| {
            (0..h).all(|j| {
                let d = sky_direction(i, j);
                let cos = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
                cos.min(1.0).acos() > 10.0 * SKY.sun_radius as f64
            })
        })
        .collect::<Vec<_>>();
    assert!(!far.is_empty());
    for i in far {
        let mut previous = f32::MIN;
        for j in 0..h {
            let t = texel(i, j);
            if sky_direction(i, j)[1] >= 0.0 {
                assert!(t[0] > previous, "column {i}: not brightening at row {j}");
                assert!(t[0] <= SKY.horizon[0] + 1e-6);
                previous = t[0];
            } else {
                assert_eq!(t, SKY.ground, "column {i} row {j} below the horizon");
            }
        }
    }
}

/// Reads an RGB OpenEXR file as `f32` texels, row-major from the top-left.
fn read_exr(path: &Path) -> (usize, usize, Vec<f32>) {
    use exr::prelude::read_first_rgba_layer_from_file;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0.0f32; 3 * size.width() * size.height()]),
        |(width, rgb), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let k = 3 * (pos.y() * *width + pos.x());
            rgb[k..k + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .expect("sky.exr reads");
    let size = image.layer_data.size;
    (
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    )
}

#[test]
fn generated_files_hold_what_the_generator_made() {
    let dir = tempfile::tempdir().unwrap();
    let written = generate_scene_inputs(dir.path()).expect("inputs generate");
    let names: Vec<String> = written
        .iter()
        .map(|p| p.strip_prefix(dir.path()).unwrap().display().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "cgg-logo/density.vol",
            "cgg-logo/albedo.vol",
            "ad/density.vol",
            "ad/albedo.vol",
            "envmap-cube/sky.exr",
            "smoke/smoke.vol"
        ]
    );
    let unit = volpt_scene::Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    let slab = volpt_scene::Bounds {
        min: [-1.6, -1.6, -0.5],
        max: [1.6, 1.6, 0.5],
    };
    for (block, bounds, k) in [(CGG_LOGO, unit, 0), (AD, slab, 2)] {
        let (density, albedo) = block.grids(bounds);
        for (grid, path) in [(density, &written[k]), (albedo, &written[k + 1])] {
            let read = read_vol(path).expect("generated grid reads");
            assert_eq!(read.resolution, grid.resolution, "{}", path.display());
            assert_eq!(read.channels, grid.channels);
            assert_eq!(read.bbox, bounds);
            assert!(read.data == grid.data, "{}: texels differ", path.display());
        }
    }
    let (width, height, rgb) = read_exr(&written[4]);
    assert_eq!((width, height), (SKY.width as usize, SKY.height as usize));
    // Written as half floats: each texel within half's rounding (2^-11 relative).
    for (k, (&read, &made)) in rgb.iter().zip(&SKY.texels()).enumerate() {
        assert!(
            (read - made).abs() <= made.abs() * 1e-3 + 1e-6,
            "sky texel {} channel {}: {read} written for {made}",
            k / 3,
            k % 3
        );
    }
    let read = read_vol(&written[5]).expect("smoke.vol reads");
    let made = SMOKE.grid();
    assert_eq!((read.resolution, read.channels), (made.resolution, 1));
    assert_eq!(read.bbox, SMOKE.bounds);
    assert!(read.data == made.data, "smoke.vol: samples differ");
}

/// The smoke stand-in has Mitsuba's `smoke.vol` shape and box and resembles its density: values in
/// 0..1 with the maximum reached, mostly empty, a thin plume (the fractions its documentation
/// states, within a third), nothing below a fifth of the box's height, and denser above the middle
/// than at the bottom of the plume, as smoke rises and spreads.
#[test]
fn smoke_plume_has_smoke_vol_box_and_statistics() {
    let grid = SMOKE.grid();
    let [w, h, d] = grid.resolution;
    assert_eq!(grid.resolution, [128, 128, 50]);
    assert_eq!(
        grid.bbox,
        volpt_scene::Bounds {
            min: [-0.5, -0.5, -0.1953125],
            max: [0.5, 0.5, 0.1953125]
        }
    );
    let n = grid.data.len();
    assert_eq!(n, (w * h * d) as usize);
    assert!(grid.data.iter().all(|&v| (0.0..=1.0).contains(&v)));
    assert_eq!(grid.data.iter().fold(0.0f32, |m, &v| m.max(v)), 1.0);
    let fraction =
        |f: &dyn Fn(f32) -> bool| grid.data.iter().filter(|&&v| f(v)).count() as f64 / n as f64;
    let mean = grid.data.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    let near = |found: f64, stated: f64| (found - stated).abs() <= stated / 3.0;
    assert!(
        near(fraction(&|v| v > 0.0), 0.13),
        "non-zero {}",
        fraction(&|v| v > 0.0)
    );
    assert!(
        near(fraction(&|v| v > 0.1), 0.04),
        "above 0.1 {}",
        fraction(&|v| v > 0.1)
    );
    assert!(near(mean, 0.014), "mean {mean}");
    let layer = |y: u32| -> f64 {
        (0..d)
            .flat_map(|z| (0..w).map(move |x| ((z * h + y) * w + x) as usize))
            .map(|i| grid.data[i] as f64)
            .sum()
    };
    let floor = (0..h).find(|&y| layer(y) > 0.0).expect("a plume");
    assert!(
        floor as f64 >= 0.2 * (h - 1) as f64,
        "smoke from row {floor}"
    );
    let lower: f64 = (floor..h / 2).map(layer).sum();
    let upper: f64 = (h / 2..h).map(layer).sum();
    assert!(upper > lower, "upper half {upper}, lower {lower}");
    // The same grid every time (no state, no clock, no platform maths).
    assert!(SMOKE.grid().data == grid.data);
}
