//! Frames as the viewer shows them, on the CPU: the image scaled by 2^exposure, in sRGB, 8 bits
//! per channel. The GPU computes the same frame beside its film (`volpt_device::tone`); the two
//! agree within one 8-bit level (volpt-cuda's tests, and `volpt selftest --backend cuda`).

use std::sync::LazyLock;

use crate::image::srgb_encode;
use crate::Image;

/// Entries of the sRGB table over linear [0, 1]. 2^14 entries keep the table's step below a
/// fifth of an 8-bit level even in the darks, where sRGB's slope is steepest (12.92).
const LUT_SIZE: usize = 1 << 14;

static SRGB: LazyLock<Vec<u8>> = LazyLock::new(|| {
    (0..LUT_SIZE)
        .map(|i| (srgb_encode(i as f32 / (LUT_SIZE - 1) as f32) * 255.0 + 0.5) as u8)
        .collect()
});

/// 8-bit sRGB RGB of `image` scaled by 2^`exposure` and clipped to [0, 1]; NaN is black.
pub fn tone_map(image: &Image, exposure: f32) -> Vec<u8> {
    let gain = exposure.exp2();
    let scale = gain * (LUT_SIZE - 1) as f32;
    let lut = &*SRGB;
    let mut out = Vec::with_capacity(image.pixels.len() * 3);
    for rgb in &image.pixels {
        for c in rgb {
            // `as usize` maps NaN to 0 and saturates; `min` keeps the index in the table.
            let i = ((c * scale + 0.5) as usize).min(LUT_SIZE - 1);
            out.push(lut[i]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_mapping_is_srgb_of_the_exposed_value_and_clips() {
        let image = Image {
            width: 4,
            height: 1,
            pixels: vec![
                [0.0, 0.25, 1.0],
                [f32::NAN, -1.0, 1e30],
                [0.5, 0.5, 0.5],
                [0.214; 3],
            ],
        };
        let rgb = tone_map(&image, 1.0);
        // 0.25 * 2 = 0.5 linear is sRGB 188; 0.214 * 2 = 0.428 is 175.
        assert_eq!(&rgb[..3], &[0, 188, 255]);
        assert_eq!(&rgb[3..6], &[0, 0, 255]);
        assert_eq!(&rgb[6..9], &[255, 255, 255]);
        assert_eq!(rgb[9], 175);
    }
}
