//! Frames as the page shows them: exposure, sRGB, 8 bits; and the encoders (JPEG for frames, PNG
//! on request and for snapshots, OpenEXR for linear snapshots).

use std::sync::LazyLock;

use volpt::Image;

use crate::ViewError;

/// Entries of the sRGB table over linear [0, 1]. 2^14 entries keep the table's step below a
/// fifth of an 8-bit level even in the darks, where sRGB's slope is steepest (12.92).
const LUT_SIZE: usize = 1 << 14;

static SRGB: LazyLock<Vec<u8>> = LazyLock::new(|| {
    (0..LUT_SIZE)
        .map(|i| {
            let c = i as f32 / (LUT_SIZE - 1) as f32;
            let s = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0 + 0.5) as u8
        })
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

/// Baseline JPEG of 8-bit RGB; `quality` from 1 to 100.
pub fn jpeg(rgb: &[u8], width: u32, height: u32, quality: u8) -> Result<Vec<u8>, ViewError> {
    let (w, h) = dimensions(width, height)?;
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, quality)
        .encode(rgb, w, h, jpeg_encoder::ColorType::Rgb)
        .map_err(|e| ViewError::Encode(format!("JPEG: {e}")))?;
    Ok(out)
}

/// JPEG's sides end at 65535 pixels.
fn dimensions(width: u32, height: u32) -> Result<(u16, u16), ViewError> {
    match (u16::try_from(width), u16::try_from(height)) {
        (Ok(w), Ok(h)) => Ok((w, h)),
        _ => Err(ViewError::Encode(format!(
            "JPEG: {width} x {height} pixels; each side must be at most 65535"
        ))),
    }
}

/// PNG of 8-bit RGB, fast compression (frames are sent, not archived).
pub fn png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, ViewError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let error = |e: png::EncodingError| ViewError::Encode(format!("PNG: {e}"));
    let mut writer = encoder.write_header().map_err(error)?;
    writer.write_image_data(rgb).map_err(error)?;
    writer.finish().map_err(error)?;
    Ok(out)
}

/// OpenEXR of the linear image (32-bit float RGB), as `volpt render` writes it.
pub fn exr(image: &Image) -> Result<Vec<u8>, ViewError> {
    use exr::prelude::*;
    let (w, h) = (image.width as usize, image.height as usize);
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = image.pixels[p.y() * w + p.x()];
        (r, g, b)
    });
    let mut out = std::io::Cursor::new(Vec::new());
    exr::prelude::Image::from_channels((w, h), channels)
        .write()
        .to_buffered(&mut out)
        .map_err(|e| ViewError::Encode(format!("OpenEXR: {e}")))?;
    Ok(out.into_inner())
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

    #[test]
    fn encoders_write_their_formats() {
        let rgb = vec![128u8; 3 * 8 * 4];
        assert!(jpeg(&rgb, 8, 4, 85).unwrap().starts_with(&[0xFF, 0xD8]));
        assert!(png(&rgb, 8, 4).unwrap().starts_with(b"\x89PNG"));
        let image = Image {
            width: 2,
            height: 1,
            pixels: vec![[1.0, 2.0, 3.0]; 2],
        };
        assert!(exr(&image).unwrap().starts_with(&[0x76, 0x2f, 0x31, 0x01]));
        assert!(jpeg(&[], 70000, 1, 85).is_err());
    }
}
