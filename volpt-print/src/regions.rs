//! Where on a target an error lies: each texel classed by its distance to the target's ink, so
//! a mean CIEDE2000 can be split into the ink itself, the white beside it (which the ink's
//! scattering darkens most), and the white farther away (docs/printing.md, "Where the lines'
//! error is").

use crate::colour::LinearRgb;

/// A texel's region on its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Region {
    /// Not white: some channel below [`WHITE`].
    Ink,
    /// White, at most [`EDGE`] texels from ink (Chebyshev distance).
    Edge,
    /// White, more than [`EDGE`] and at most [`NEAR`] texels from ink.
    Near,
    /// White, farther from ink.
    Far,
}

impl Region {
    /// Every region, in [`Region::index`] order.
    pub const ALL: [Region; 4] = [Region::Ink, Region::Edge, Region::Near, Region::Far];

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn name(self) -> &'static str {
        ["ink", "edge", "near", "far"][self.index()]
    }
}

/// A target texel is white when every channel (linear RGB) is at least this.
pub const WHITE: f64 = 0.99;
/// The widest distance from ink, in texels, of [`Region::Edge`].
pub const EDGE: usize = 2;
/// The widest distance from ink, in texels, of [`Region::Near`].
pub const NEAR: usize = 6;

/// Each texel's region on a `width` x `height` target (row-major).
pub fn regions(target: &[LinearRgb], [width, height]: [u32; 2]) -> Vec<Region> {
    let [w, h] = [width as usize, height as usize];
    assert_eq!(target.len(), w * h, "one colour per texel");
    let ink: Vec<bool> = target
        .iter()
        .map(|c| c.0.iter().any(|&v| v < WHITE))
        .collect();
    (0..w * h)
        .map(|i| {
            if ink[i] {
                return Region::Ink;
            }
            let (x, y) = (i % w, i / w);
            let ys = y.saturating_sub(NEAR)..(y + NEAR + 1).min(h);
            let distance = ys
                .flat_map(|yy| {
                    (x.saturating_sub(NEAR)..(x + NEAR + 1).min(w)).map(move |xx| (xx, yy))
                })
                .filter(|&(xx, yy)| ink[xx + w * yy])
                .map(|(xx, yy)| xx.abs_diff(x).max(yy.abs_diff(y)))
                .min();
            match distance {
                Some(d) if d <= EDGE => Region::Edge,
                Some(_) => Region::Near,
                None => Region::Far,
            }
        })
        .collect()
}

/// Per region, its share of the texels and the mean of `values` over it (`None` where it has
/// none), in [`Region::ALL`]'s order.
pub fn region_means(values: &[f64], regions: &[Region]) -> [(f64, Option<f64>); 4] {
    assert_eq!(values.len(), regions.len(), "one value per texel");
    Region::ALL.map(|r| {
        let (sum, count) = values
            .iter()
            .zip(regions)
            .filter(|(_, &k)| k == r)
            .fold((0.0, 0usize), |(s, n), (v, _)| (s + v, n + 1));
        let share = count as f64 / regions.len().max(1) as f64;
        (share, (count > 0).then(|| sum / count as f64))
    })
}
