//! Tone mapping on the GPU, beside the film it reads: the viewer's frame as 8-bit sRGB RGB, so
//! that a frame's bytes, not its `f64` sums, are what comes back to the host. One kernel for
//! every scene (it reads the film, which every variant writes alike).
//!
//! The per-pixel function is plain code, run by the kernel and by the CPU's tests alike: the CPU's
//! frames (`volpt_film::tone`, a table of the same curve) must equal it within one 8-bit level.

/// The tone-mapping kernels' entry points, as [`export_tone_map!`](crate::export_tone_map)
/// exports them (their pack group is `film`).
pub const ENTRIES: [&str; 1] = ["film__tone_map"];

/// Exports the tone-mapping kernel (the workspace's kernels crate invokes it once).
#[macro_export]
macro_rules! export_tone_map {
    () => {
        const _: () = {
            /// # Safety
            /// As [`volpt_device::tone::tone_map`].
            #[export_name = "film__tone_map"]
            pub unsafe extern "ptx-kernel" fn tone_map(
                film: *const f64,
                out: *mut u8,
                pixels: u32,
                inv_spp: f64,
                gain: f32,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::tone::tone_map(film, out, pixels, inv_spp, gain) }
            }
        };
    };
}

/// 8-bit sRGB (IEC 61966-2-1) of the linear value `linear` clipped to [0, 1], rounded to the
/// nearest level; NaN is black. `c^(1/2.4)` is `exp(ln c / 2.4)` through `volpt_core::math`:
/// libm's bits on the CPU and in the exact kernels, `lg2`/`ex2` in the fast ones (relative error
/// ~2^-22, far below the half level that rounding to 8 bits leaves).
#[inline(always)]
pub fn srgb8(linear: f32) -> u8 {
    use volpt_core::math::{exp, ln};
    // `>` is false for NaN: NaN is black, as below 0.
    let c = if linear > 0.0 { linear.min(1.0) } else { 0.0 };
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * exp(ln(c) * (1.0 / 2.4)) - 0.055
    };
    // `as u8` saturates; `s` is in [0, 1] up to rounding.
    (s * 255.0 + 0.5) as u8
}

/// The frame's pixel of the film sums `sum` over `1 / inv_spp` samples at `gain` (2^exposure):
/// the image's value as `volpt_film::Film::image` rounds it to `f32`, times `gain`, in sRGB.
#[inline(always)]
pub fn tone_map_pixel(sum: [f64; 3], inv_spp: f64, gain: f32) -> [u8; 3] {
    sum.map(|c| srgb8((c * inv_spp) as f32 * gain))
}

/// Thread `i < pixels` writes pixel `i`'s frame bytes ([`tone_map_pixel`] of `film[3i..3i + 3]`)
/// to `out[3i..3i + 3]`.
///
/// # Safety
/// `film` must hold `3 pixels` sums and `out` `3 pixels` bytes, both device memory alive for the
/// launch.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
pub unsafe fn tone_map(film: *const f64, out: *mut u8, pixels: u32, inv_spp: f64, gain: f32) {
    let i = crate::nvptx::global_thread_index();
    if i >= pixels {
        return;
    }
    let i = 3 * i as usize;
    // SAFETY: the caller's contract; `i + 2 < 3 pixels`.
    unsafe {
        let sum = [*film.add(i), *film.add(i + 1), *film.add(i + 2)];
        let [r, g, b] = tone_map_pixel(sum, inv_spp, gain);
        *out.add(i) = r;
        *out.add(i + 1) = g;
        *out.add(i + 2) = b;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb8_is_the_srgb_curve_clipped_with_nan_black() {
        assert_eq!(srgb8(0.0), 0);
        assert_eq!(srgb8(-1.0), 0);
        assert_eq!(srgb8(f32::NAN), 0);
        assert_eq!(srgb8(1.0), 255);
        assert_eq!(srgb8(f32::INFINITY), 255);
        // 0.5 linear is sRGB 0.7354, 187.5 levels: 188; 0.428 is 175 (as the viewer's table).
        assert_eq!(srgb8(0.5), 188);
        assert_eq!(srgb8(0.428), 175);
        // The linear segment: 12.92 * 0.001 * 255 = 3.29.
        assert_eq!(srgb8(0.001), 3);
    }

    #[test]
    fn a_pixel_is_its_mean_times_the_gain() {
        // Sums of 4 samples: means 0.25, 0.125, NaN; gain 2.
        assert_eq!(
            tone_map_pixel([1.0, 0.5, f64::NAN], 0.25, 2.0),
            [srgb8(0.5), srgb8(0.25), 0]
        );
    }
}
