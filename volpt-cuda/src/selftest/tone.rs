//! The tone-mapping kernel's test film and its check: the GPU's frame against the CPU's
//! (`volpt_film::tone::tone_map` of the film's image), within one 8-bit level.

use volpt_film::{Film, Image};

/// The frame may differ from the CPU's by this many levels: the CPU reads a table of the sRGB
/// curve 2^14 entries fine, the fast kernels approximate `c^(1/2.4)`; each may round a value
/// near a level's boundary to the other side.
pub const TOLERANCE: u8 = 1;

/// The exposures (stops) the check tone maps at: none, brighter, darker, far brighter.
pub const EXPOSURES: [f32; 4] = [0.0, 1.5, -2.0, 10.0];

/// A film of `pixels` pixels (one row) holding `spp` samples' sums: the corner values (zero,
/// -0, negative, NaN, infinity, the sRGB curve's knee, 1, far above 1) then sums whose means
/// span 2^-16 to 4 logarithmically, so that every level of every exposure is crossed.
pub fn film(pixels: u32, spp: u32) -> Film {
    let corners = [
        0.0,
        -0.0,
        -1.0,
        f64::NAN,
        f64::INFINITY,
        0.003_130_8,
        1.0,
        1e30,
    ];
    let n = 3 * pixels as usize;
    let random = (0..n as u64).map(|i| {
        let u = f64::from(super::unit(i + 9_000_000));
        (18.0 * u - 16.0).exp2()
    });
    let means: Vec<f64> = corners.into_iter().chain(random).take(n).collect();
    let mut film = Film::new(pixels, 1);
    for (sum, mean) in film.flat_sums_mut().iter_mut().zip(means) {
        *sum = mean * f64::from(spp);
    }
    film
}

/// The CPU's frame of `film`'s image over `spp` samples at `exposure`: what the viewer sends
/// when it renders on the CPU.
pub fn cpu_frame(film: &Film, spp: u32, exposure: f32) -> Vec<u8> {
    let image: Image = film.image(spp);
    volpt_film::tone::tone_map(&image, exposure)
}

/// The bytes of `got` that differ from `expected` by more than [`TOLERANCE`], described, and
/// what was measured (the largest difference, how many bytes differ at all).
pub fn check(expected: &[u8], got: &[u8], label: &str) -> (Vec<String>, String) {
    let mut failures = Vec::new();
    if expected.len() != got.len() {
        failures.push(format!(
            "{label}: {} bytes, expected {}",
            got.len(),
            expected.len()
        ));
    }
    let (mut largest, mut differ) = (0u8, 0usize);
    for (i, (&e, &g)) in expected.iter().zip(got).enumerate() {
        let d = e.abs_diff(g);
        largest = largest.max(d);
        differ += usize::from(d > 0);
        if d > TOLERANCE {
            failures.push(format!("{label}: byte {i} is {g}, the CPU's {e}"));
        }
    }
    let measured = format!(
        "{label}: largest difference {largest} level(s), {differ} of {} bytes differ",
        expected.len()
    );
    (failures, measured)
}
