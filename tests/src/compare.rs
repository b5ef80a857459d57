//! Rendered images against the independent references of [`crate::reference`], pixel by pixel,
//! with windows derived from the renderer's own standard error and the reference's quadrature error.

use glam::DVec3;
use volpt_render::Image;
use volpt_scene::description::SceneDescription;

use crate::reference::{gauss_legendre, RefBox, RefCamera, RefEnvironment, RefMedium};

/// Per-pixel windows in standard errors: a false alarm among the ~1000 pixel channels of a test
/// has probability below 1e-3.
pub const Z_PIXEL: f64 = 5.0;

/// What a pixel should be: its expectation, the variance of the renderer's estimate of it, and
/// the quadrature error of the expectation (the difference between two quadrature orders).
#[derive(Clone, Copy, Debug, Default)]
pub struct Expected {
    pub mean: DVec3,
    pub variance: DVec3,
    pub quadrature: DVec3,
}

/// How much of a pixel sees the boundary's box. The box is convex, so a pixel whose four corners
/// see it sees it all over; a pixel none of whose 5x5 lattice points (corners included) sees it is
/// background unless a sliver of the box's outline fits between the points, which the exact
/// check on background pixels would report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    Medium,
    Background,
    Silhouette,
}

pub fn coverage(camera: &RefCamera, bounds: &RefBox) -> Vec<Coverage> {
    const LATTICE: usize = 5;
    let mut out = Vec::new();
    for y in 0..camera.height {
        for x in 0..camera.width {
            let sees = |i: usize, j: usize| {
                let f = |k: usize| k as f64 / (LATTICE - 1) as f64;
                let d = camera.direction(x as f64 + f(i), y as f64 + f(j));
                bounds.interval(camera.origin, d).is_some()
            };
            let corners = [
                (0, 0),
                (LATTICE - 1, 0),
                (0, LATTICE - 1),
                (LATTICE - 1, LATTICE - 1),
            ];
            out.push(if corners.iter().all(|&(i, j)| sees(i, j)) {
                Coverage::Medium
            } else if (0..LATTICE).all(|i| (0..LATTICE).all(|j| !sees(i, j))) {
                Coverage::Background
            } else {
                Coverage::Silhouette
            });
        }
    }
    out
}

/// The first two moments of a radiance sample, so that one quadrature gives the mean and variance.
#[derive(Clone, Copy, Debug, Default)]
pub struct Moments {
    pub first: DVec3,
    pub second: DVec3,
}

impl std::ops::AddAssign for Moments {
    fn add_assign(&mut self, o: Self) {
        self.first += o.first;
        self.second += o.second;
    }
}

impl std::ops::Mul<f64> for Moments {
    type Output = Self;
    fn mul(self, w: f64) -> Self {
        Self {
            first: self.first * w,
            second: self.second * w,
        }
    }
}

/// Per pixel, `f` integrated over the pixel with a `fine`- and a `coarse`-point Gauss rule per
/// axis (`f`'s flag says which), on all available threads.
pub fn per_pixel<F>(
    camera: &RefCamera,
    (fine, coarse): (usize, usize),
    f: F,
) -> Vec<(Moments, Moments)>
where
    F: Fn(DVec3, bool) -> Moments + Sync,
{
    let (fine, coarse) = (gauss_legendre(fine), gauss_legendre(coarse));
    let pixels: Vec<(u32, u32)> = (0..camera.height)
        .flat_map(|y| (0..camera.width).map(move |x| (x, y)))
        .collect();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = pixels.len().div_ceil(threads);
    std::thread::scope(|s| {
        let workers: Vec<_> = pixels
            .chunks(chunk)
            .map(|part| {
                let (f, fine, coarse) = (&f, &fine, &coarse);
                s.spawn(move || {
                    part.iter()
                        .map(|&(x, y)| {
                            (
                                camera.pixel_mean(x, y, fine, |d| f(d, true)),
                                camera.pixel_mean(x, y, coarse, |d| f(d, false)),
                            )
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("reference worker"))
            .collect()
    })
}

/// A pure absorber behind an index-matched boundary: a camera sample escapes unscattered with the
/// radiance `L(d)` of its direction with probability `T(d)` or is absorbed, so the pixel's mean is
/// `E[L T]` over the pixel and the variance of one sample `E[L^2 T] - E[L T]^2`.
pub fn absorber_expectation(desc: &SceneDescription, spp: u32, steps: u32) -> Vec<Expected> {
    let camera = RefCamera::new(&desc.camera, &desc.film);
    let medium = RefMedium::new(desc);
    let env = RefEnvironment::new(&desc.environment);
    let moments = per_pixel(&camera, (4, 3), |d, fine| {
        let steps = if fine { steps } else { steps / 2 };
        let t = medium.transmittance_to_exit(camera.origin, d, steps);
        let l = env.radiance(d);
        Moments {
            first: l * t,
            second: l * l * t,
        }
    });
    moments
        .into_iter()
        .map(|(fine, coarse)| Expected {
            mean: fine.first,
            variance: (fine.second - fine.first * fine.first).max(DVec3::ZERO) / spp as f64,
            quadrature: (fine.first - coarse.first).abs(),
        })
        .collect()
}

/// Per checked pixel and channel `|image - mean| <= 5 se + quadrature error`, and per channel the
/// difference summed over the checked pixels within 5 of its standard errors (plus the summed
/// quadrature errors). The channels of one path are correlated, so each is summed on its own.
/// Returns each channel's image-wide z.
pub fn assert_matches(
    what: &str,
    image: &Image,
    expected: &[Expected],
    checked: impl Fn(usize) -> bool,
) -> [f64; 3] {
    assert_eq!(image.pixels.len(), expected.len(), "{what}: image size");
    let (mut sum_diff, mut sum_var, mut sum_quadrature) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    let mut count = 0;
    for (i, (px, e)) in image.pixels.iter().zip(expected).enumerate() {
        if !checked(i) {
            continue;
        }
        count += 1;
        for c in 0..3 {
            let diff = px[c] as f64 - e.mean[c];
            let se = e.variance[c].sqrt();
            let bound = Z_PIXEL * se + e.quadrature[c] + 1e-6 * e.mean[c].abs().max(1e-3);
            assert!(
                diff.abs() <= bound,
                "{what}: pixel {i} channel {c}: {} vs reference {} (se {se}, quadrature {})",
                px[c],
                e.mean[c],
                e.quadrature[c]
            );
            sum_diff[c] += diff;
            sum_var[c] += e.variance[c];
            sum_quadrature[c] += e.quadrature[c];
        }
    }
    assert!(count > 0, "{what}: no pixel checked");
    std::array::from_fn(|c| {
        let z = sum_diff[c] / sum_var[c].sqrt();
        assert!(
            sum_diff[c].abs() <= 5.0 * sum_var[c].sqrt() + sum_quadrature[c],
            "{what}: channel {c}: summed difference {} (z = {z}) over {count} pixels",
            sum_diff[c]
        );
        z
    })
}

/// The relative difference between the image and the expectation, summed over the checked pixels'
/// first channel: a bias a whole-image average would dilute with background.
pub fn relative_bias(image: &Image, expected: &[Expected], checked: impl Fn(usize) -> bool) -> f64 {
    let (rendered, reference) = (0..expected.len())
        .filter(|&i| checked(i))
        .fold((0.0, 0.0), |(r, e), i| {
            (r + image.pixels[i][0] as f64, e + expected[i].mean.x)
        });
    rendered / reference - 1.0
}
