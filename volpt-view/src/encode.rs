//! Frames as the page shows them: exposure, sRGB, 8 bits; and the encoders (JPEG for frames, PNG
//! on request and for snapshots, OpenEXR for linear snapshots).
//!
//! JPEG is jpeg-encoder's with its `simd` feature: AVX2 colour conversion and DCT where the CPU
//! has them (detected at run time), 4:2:0 at the frames' quality; pure Rust, no C library.

use volpt::Image;

use crate::ViewError;

/// The CPU's frames (the CPU backend's, and a GPU's where it cannot tone map itself); one GPU
/// tone maps its own film ([`volpt::Backend::tone_map`]), within one 8-bit level of these.
pub use volpt::tone::tone_map;

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
