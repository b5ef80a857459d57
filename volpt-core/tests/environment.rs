//! The environments on their own, against an independent f64 reference of the documented
//! conventions: the lat-long lookup (`u = atan2(v.x, -v.z) / 2 pi`, `v = acos(v.y) / pi` in the
//! map's frame, bilinear, wrapping in `u`, both row conventions), the sampling distribution's layout
//! (3x3 brightest texel times `sin(theta)`, running sums), the solid-angle density built from it,
//! and the sampler drawing directions with that density. The whole-renderer tests see these only
//! through next-event estimation, where a consistently wrong density stays unbiased (MIS) and only
//! the noise changes.
//!
//! Tolerances: the lookups are f32 with texels of size <= 4 and maps of <= 9 texels a side, so
//! 1e-4 of the largest texel is tens of ulps of the interpolation; densities are compared to 1e-3
//! relative away from cell edges (within 1e-4 of an edge a direction may fall either side).

mod common;

use std::f64::consts::PI;

use common::*;
use volpt_core::{ConstantEnvironment, Environment, LatLongEnvironment, LatLongRows, Vec2, Vec3};

/// A `width x height` map with a bright spot, dim texels and black regions more than one texel
/// from anything lit (cells of zero weight), different per channel.
fn texels(width: u32, height: u32, seed: u64) -> Vec<f32> {
    let mut rng = TestRng::new(seed);
    let mut rgb = Vec::new();
    for j in 0..height {
        for i in 0..width {
            // Lit: a band of columns 0..3 and the rows of the upper half.
            let lit = i < 3 && j < height.div_ceil(2);
            for c in 0..3 {
                let v = if lit {
                    0.05 + 3.0 * rng.f32() * (1.0 + c as f32) / 3.0
                } else {
                    0.0
                };
                rgb.push(v);
            }
        }
    }
    // One bright texel, so that 3x3 maxima differ from the texels themselves.
    let k = 3 * (width as usize + 1);
    rgb[k..k + 3].copy_from_slice(&[4.0, 1.0, 2.0]);
    rgb
}

/// A rotation (rows of world-to-map) that is neither the identity nor a permutation.
fn rotation() -> [Vec3; 3] {
    let m = glam::Mat3::from_euler(glam::EulerRot::YXZ, 0.7, -0.4, 0.25);
    let t = m.transpose();
    [t.x_axis, t.y_axis, t.z_axis]
}

struct Reference<'a> {
    rgb: &'a [f32],
    width: u32,
    height: u32,
    rows: LatLongRows,
    world_to_map: [Vec3; 3],
    scale: f64,
}

impl Reference<'_> {
    fn texel(&self, x: i64, y: i64, c: usize) -> f64 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.rgb[3 * (y * self.width as usize + x) + c] as f64
    }

    /// `(u, v)` of a world look direction.
    fn uv(&self, dir: Vec3) -> (f64, f64) {
        let d = [dir.x as f64, dir.y as f64, dir.z as f64];
        let m: Vec<f64> = self
            .world_to_map
            .iter()
            .map(|r| r.x as f64 * d[0] + r.y as f64 * d[1] + r.z as f64 * d[2])
            .collect();
        let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        let u = m[0].atan2(-m[2]) / (2.0 * PI);
        (u - u.floor(), (m[1] / len).clamp(-1.0, 1.0).acos() / PI)
    }

    fn radiance(&self, dir: Vec3) -> [f64; 3] {
        let (u, v) = self.uv(dir);
        let h = self.height as f64;
        let row = match self.rows {
            LatLongRows::CellCentred => v * h - 0.5,
            LatLongRows::PoleToPole => v * (h - 1.0),
        }
        .clamp(0.0, h - 1.0);
        let x = u * self.width as f64 - 0.5;
        let (x0, y0) = (x.floor(), row.floor());
        let (fx, fy) = (x - x0, row - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        std::array::from_fn(|c| {
            let top = self.texel(x0, y0, c) * (1.0 - fx) + self.texel(x0 + 1, y0, c) * fx;
            let bottom =
                self.texel(x0, y0 + 1, c) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1, c) * fx;
            (top * (1.0 - fy) + bottom * fy) * self.scale
        })
    }

    /// Cell `(i, j)`'s weight: the brightest channel of the 3x3 texels around it times
    /// `sin(theta)` at the cell's centre.
    fn weight(&self, i: u32, j: u32) -> f64 {
        let mut brightest: f64 = 0.0;
        for dj in -1..=1 {
            for di in -1..=1 {
                for c in 0..3 {
                    brightest = brightest.max(self.texel(i as i64 + di, j as i64 + dj, c));
                }
            }
        }
        brightest * (PI * (j as f64 + 0.5) / self.height as f64).sin()
    }

    fn total(&self) -> f64 {
        (0..self.height)
            .flat_map(|j| (0..self.width).map(move |i| (i, j)))
            .map(|(i, j)| self.weight(i, j))
            .sum()
    }

    /// The solid-angle density of `dir`: its cell's probability spread uniformly over the cell's
    /// `(u, v)` area, `d omega = 2 pi^2 sin(theta) du dv`.
    fn pdf(&self, dir: Vec3) -> f64 {
        let (u, v) = self.uv(dir);
        let (w, h) = (self.width as f64, self.height as f64);
        let i = ((u * w) as u32).min(self.width - 1);
        let j = ((v * h) as u32).min(self.height - 1);
        self.weight(i, j) / self.total() * w * h / (2.0 * PI * PI * (PI * v).sin())
    }

    /// Whether `dir` lies within `eps` (in cells) of a cell edge, where f32 and f64 may disagree
    /// about its cell, or within 0.05 rad of a pole, where f32's `acos` of a rotated direction
    /// (rounded by ~6e-8) moves `theta` by ~6e-8 / theta and the density `1 / sin(theta)` by more
    /// than 1e-3 relative.
    fn near_cell_edge(&self, dir: Vec3, eps: f64) -> bool {
        let (u, v) = self.uv(dir);
        let near = |x: f64| (x - x.round()).abs() < eps;
        near(u * self.width as f64) || near(v * self.height as f64) || (PI * v).sin() < 0.05
    }
}

/// The maps every test uses: odd and even sizes, width != height, both row conventions, a rotation
/// and a scale.
fn cases() -> Vec<(Vec<f32>, u32, u32, LatLongRows)> {
    vec![
        (texels(7, 5, 1), 7, 5, LatLongRows::PoleToPole),
        (texels(9, 4, 2), 9, 4, LatLongRows::CellCentred),
        (texels(6, 8, 3), 6, 8, LatLongRows::CellCentred),
    ]
}

const SCALE: f32 = 1.5;

fn map(rgb: &[f32], width: u32, height: u32, rows: LatLongRows) -> LatLongEnvironment<'_> {
    LatLongEnvironment::new(rgb, width, height, rows, rotation(), SCALE)
}

fn reference(rgb: &[f32], width: u32, height: u32, rows: LatLongRows) -> Reference<'_> {
    Reference {
        rgb,
        width,
        height,
        rows,
        world_to_map: rotation(),
        scale: SCALE as f64,
    }
}

fn distribution(map: &LatLongEnvironment<'_>) -> Vec<f32> {
    let mut out = vec![f32::NAN; LatLongEnvironment::distribution_len(map.width, map.height)];
    map.fill_distribution(&mut out);
    out
}

#[test]
fn lat_long_radiance_is_the_bilinear_lookup_of_the_documented_uv() {
    for (rgb, width, height, rows) in cases() {
        let map = map(&rgb, width, height, rows);
        let reference = reference(&rgb, width, height, rows);
        let tolerance = 1e-4 * 4.0 * SCALE as f64;
        let mut rng = TestRng::new(11);
        for k in 0..4000 {
            let dir = rng.unit_vector();
            let got = map.radiance(dir);
            let want = reference.radiance(dir);
            for c in 0..3 {
                assert!(
                    (got[c] as f64 - want[c]).abs() <= tolerance,
                    "{width}x{height} {rows:?}, direction {k} {dir}: channel {c} is {}, the \
                     reference {}",
                    got[c],
                    want[c]
                );
            }
        }
    }
}

#[test]
fn lat_long_distribution_is_the_documented_running_sums() {
    for (rgb, width, height, rows) in cases() {
        let (w, h) = (width as usize, height as usize);
        assert_eq!(
            LatLongEnvironment::distribution_len(width, height),
            h * (w + 1) + h + 1,
            "{width}x{height}: each row's w + 1 running sums, then the rows' h + 1"
        );
        let reference = reference(&rgb, width, height, rows);
        let distribution = distribution(&map(&rgb, width, height, rows));
        let close = |got: f32, want: f64, what: &str| {
            assert!(
                (got as f64 - want).abs() <= 1e-6 * want.abs().max(1e-3),
                "{width}x{height}: {what} is {got}, the reference {want}"
            );
        };
        let mut total = 0.0;
        for j in 0..h {
            let mut sum = 0.0;
            close(distribution[j * (w + 1)], 0.0, &format!("row {j}'s sum 0"));
            for i in 0..w {
                sum += reference.weight(i as u32, j as u32);
                close(
                    distribution[j * (w + 1) + i + 1],
                    sum,
                    &format!("row {j}'s running sum {}", i + 1),
                );
            }
            total += sum;
            close(
                distribution[h * (w + 1) + j + 1],
                total,
                &format!("the rows' running sum {}", j + 1),
            );
        }
        close(distribution[h * (w + 1)], 0.0, "the rows' sum 0");
    }
}

/// Every sampled direction carries the map's radiance and the density `pdf` gives it, and that
/// density is the documented one (so it integrates to 1 over the sphere).
#[test]
fn lat_long_samples_carry_their_radiance_and_the_documented_density() {
    for (rgb, width, height, rows) in cases() {
        let reference = reference(&rgb, width, height, rows);
        let map = map(&rgb, width, height, rows);
        let distribution = distribution(&map);
        let map = LatLongEnvironment {
            distribution: &distribution,
            ..map
        };
        let mut rng = TestRng::new(5);
        let mut compared = 0;
        for k in 0..4000 {
            let sample = map
                .sample(rng.vec2())
                .unwrap_or_else(|| panic!("{width}x{height}: sample {k} is None"));
            let dir = sample.dir;
            assert!(
                (dir.length() - 1.0).abs() < 1e-5,
                "sample {k}: |{dir}| != 1"
            );
            let radiance = map.radiance(dir);
            assert!(
                (sample.radiance - radiance).abs().max_element() <= 1e-6 * radiance.max_element(),
                "{width}x{height}, sample {k}: radiance {} but the map has {radiance} there",
                sample.radiance
            );
            if reference.near_cell_edge(dir, 1e-4) {
                continue;
            }
            compared += 1;
            let want = reference.pdf(dir);
            for (what, got) in [("sample's pdf", sample.pdf), ("pdf(dir)", map.pdf(dir))] {
                assert!(
                    (got as f64 - want).abs() <= 1e-3 * want,
                    "{width}x{height} {rows:?}, sample {k} {dir}: {what} {got}, the reference \
                     {want}"
                );
            }
        }
        assert!(
            compared > 3500,
            "only {compared} samples away from cell edges"
        );
        // Directions anywhere, including cells of zero weight.
        for _ in 0..4000 {
            let dir = rng.unit_vector();
            if reference.near_cell_edge(dir, 1e-4) {
                continue;
            }
            let (got, want) = (map.pdf(dir) as f64, reference.pdf(dir));
            assert!(
                (got - want).abs() <= 1e-3 * want,
                "{width}x{height}: pdf({dir}) {got}, the reference {want}"
            );
        }
    }
}

/// The sampler draws cells in proportion to their weights (chi-square; cells of zero weight never)
/// and positions uniformly in `(u, v)` within a cell (Kolmogorov-Smirnov on the fractional cell
/// coordinates).
#[test]
fn lat_long_samples_follow_the_distribution() {
    const N: usize = 40_000;
    let cases = cases();
    let alpha = ALPHA / (3.0 * cases.len() as f64);
    for (rgb, width, height, rows) in &cases {
        let (width, height) = (*width, *height);
        let reference = reference(rgb, width, height, *rows);
        let map = map(rgb, width, height, *rows);
        let distribution = distribution(&map);
        let map = LatLongEnvironment {
            distribution: &distribution,
            ..map
        };
        let total = reference.total();
        let expected: Vec<f64> = (0..height)
            .flat_map(|j| (0..width).map(move |i| (i, j)))
            .map(|(i, j)| N as f64 * reference.weight(i, j) / total)
            .collect();
        let mut observed = vec![0.0; expected.len()];
        let (mut fu, mut fv) = (Vec::new(), Vec::new());
        let mut rng = TestRng::new(17);
        for _ in 0..N {
            let dir = map.sample(rng.vec2()).expect("a lit map samples").dir;
            let (u, v) = reference.uv(dir);
            let (x, y) = (u * width as f64, v * height as f64);
            let (i, j) = ((x as u32).min(width - 1), (y as u32).min(height - 1));
            observed[(j * width + i) as usize] += 1.0;
            fu.push(x - x.floor());
            fv.push(y - y.floor());
        }
        let chi2 = chi2_test(&observed, &expected);
        assert!(
            chi2.p_value > alpha,
            "{width}x{height}: cells drawn against their weights: {chi2:?}"
        );
        for (what, fractions) in [("u", &fu), ("v", &fv)] {
            let ks = ks_test(fractions, |x| x.clamp(0.0, 1.0));
            assert!(
                ks.p_value > alpha,
                "{width}x{height}: {what} within a cell is not uniform: {ks:?}"
            );
        }
    }
}

#[test]
fn lat_long_without_distribution_or_light_is_not_sampled() {
    let (width, height) = (5, 3);
    let rgb = texels(width, height, 4);
    let unsampled = map(&rgb, width, height, LatLongRows::CellCentred);
    assert!(
        unsampled.sample(Vec2::new(0.3, 0.6)).is_none(),
        "no distribution"
    );
    assert_eq!(unsampled.pdf(Vec3::Y), 0.0, "no distribution");

    let black = vec![0.0; rgb.len()];
    let black_map = map(&black, width, height, LatLongRows::CellCentred);
    let distribution = distribution(&black_map);
    let black_map = LatLongEnvironment {
        distribution: &distribution,
        ..black_map
    };
    assert!(
        black_map.sample(Vec2::new(0.3, 0.6)).is_none(),
        "a black map"
    );
    assert_eq!(black_map.pdf(Vec3::Y), 0.0, "a black map");
}

#[test]
fn constant_environment_samples_the_sphere_uniformly() {
    let radiance = Vec3::new(0.5, 1.0, 2.0);
    let env = ConstantEnvironment(radiance);
    let mut rng = TestRng::new(3);
    let mut z = Vec::new();
    for _ in 0..10_000 {
        let sample = env
            .sample(rng.vec2())
            .expect("a constant environment samples");
        assert_eq!(sample.radiance, radiance);
        assert!((sample.pdf as f64 - 1.0 / (4.0 * PI)).abs() < 1e-7);
        assert!((sample.dir.length() - 1.0).abs() < 1e-5);
        assert!((env.pdf(sample.dir) as f64 - 1.0 / (4.0 * PI)).abs() < 1e-7);
        assert_eq!(env.radiance(sample.dir), radiance);
        z.push(sample.dir.z as f64);
    }
    // Archimedes: z of a uniform direction is uniform in [-1, 1].
    let ks = ks_test(&z, |z| (0.5 * (z + 1.0)).clamp(0.0, 1.0));
    assert!(ks.p_value > ALPHA, "z of the samples: {ks:?}");
}

/// The sampler's numbers include 0 exactly (the renderer's `next_f32` returns it once in 2^24),
/// which lands on a pole, where the solid-angle density has no finite value: such a sample must be
/// refused (`None`), never returned with a density of 0 or infinity (next-event estimation divides
/// by it, and one NaN spoils a pixel).
#[test]
fn lat_long_samples_on_the_edges_of_the_unit_square_have_positive_densities() {
    let last = 1.0 - f32::EPSILON / 2.0;
    for (rgb, width, height, rows) in cases() {
        // A map lit at both poles, so that the edge rows have weight.
        let mut rgb = rgb;
        let lit: Vec<f32> = (0..3 * width).map(|k| 0.5 + (k % 3) as f32).collect();
        rgb[..3 * width as usize].copy_from_slice(&lit);
        let n = rgb.len();
        rgb[n - 3 * width as usize..].copy_from_slice(&lit);
        let map = map(&rgb, width, height, rows);
        let distribution = distribution(&map);
        let map = LatLongEnvironment {
            distribution: &distribution,
            ..map
        };
        let mut refused = 0;
        for x in [0.0, 0.3, 0.5, last] {
            for y in [0.0, 0.3, 0.5, last] {
                match map.sample(Vec2::new(x, y)) {
                    Some(sample) => assert!(
                        sample.pdf.is_finite() && sample.pdf > 0.0,
                        "{width}x{height}: u = ({x}, {y}) gives density {}",
                        sample.pdf
                    ),
                    None => refused += 1,
                }
            }
        }
        assert!(refused <= 8, "{width}x{height}: {refused} of 16 refused");
    }
}

/// `pdf` is asked about any direction an escaping path takes, including those that round onto the
/// edges of the `(u, v)` square: a direction a hair below `u = 0` gives `u = 1 - 1e-31`, which is
/// 1.0 in f32, and the south pole gives `v >= 1`. Both must read the last cell (or density 0 at the
/// pole), never the next row's values or past the table.
#[test]
fn lat_long_pdf_on_the_seam_and_at_the_poles() {
    let identity = [Vec3::X, Vec3::Y, Vec3::Z];
    for (rgb, width, height, rows) in cases() {
        let map = LatLongEnvironment::new(&rgb, width, height, rows, identity, 1.0);
        let distribution = distribution(&map);
        let map = LatLongEnvironment {
            distribution: &distribution,
            ..map
        };
        // Row 0 is lit (`texels`), so the seam's cells there have weight.
        for y in [0.9f32, 0.3, -0.4] {
            let r = (1.0 - y * y).sqrt();
            let seam = Vec3::new(-1e-30, y, -r);
            // The same cell, with a polar angle (and so a density) within ~1e-6 of the seam's.
            let before = Vec3::new(-1e-3, y, -r).normalize();
            let (got, want) = (map.pdf(seam), map.pdf(before));
            assert!(
                (got - want).abs() <= 1e-4 * want && got.is_finite(),
                "{width}x{height}: pdf on the seam {got}, just before it {want}"
            );
        }
        for pole in [Vec3::Y, Vec3::NEG_Y] {
            let pdf = map.pdf(pole);
            assert!(pdf.is_finite() && pdf >= 0.0, "pdf({pole}) = {pdf}");
        }
    }
}
