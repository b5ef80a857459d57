//! Frames as the page shows them: exposure, sRGB, 8 bits; and the encoders (JPEG for frames, PNG
//! on request and for snapshots, OpenEXR for linear snapshots).
//!
//! JPEG is jpeg-encoder's with its `simd` feature: AVX2 colour conversion and DCT where the CPU
//! has them (detected at run time), 4:2:0 at the frames' quality; pure Rust, no C library. One
//! encoder does ~15 ns a pixel (an H200 host's Xeon, 2026-11-29): a frame is encoded in strips
//! on up to eight threads, joined by restart markers into one baseline JPEG.

use volpt::Image;

use crate::ViewError;

/// The CPU's frames (the CPU backend's, and a GPU's where it cannot tone map itself); one GPU
/// tone maps its own film ([`volpt::Backend::tone_map`]), within one 8-bit level of these.
pub use volpt::tone::tone_map;

/// Baseline JPEG of 8-bit RGB; `quality` from 1 to 100 (4:2:0 below 90, else 4:4:4, as
/// jpeg-encoder chooses). A frame of several MCU rows is encoded in horizontal strips on several
/// threads, joined by restart markers ([`restart_strips`]).
pub fn jpeg(rgb: &[u8], width: u32, height: u32, quality: u8) -> Result<Vec<u8>, ViewError> {
    jpeg_in_strips(rgb, width, height, quality, jpeg_threads())
}

/// Threads a frame's JPEG uses at most: the host's other cores render and send.
const MAX_THREADS: usize = 8;
/// Sets the threads a frame's JPEG uses (1: one encoder, no restart markers), for measurements.
pub const JPEG_THREADS_VARIABLE: &str = "VOLPT_VIEW_JPEG_THREADS";

/// [`JPEG_THREADS_VARIABLE`]'s number where it holds one, else the cores up to [`MAX_THREADS`].
fn jpeg_threads() -> usize {
    static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *THREADS.get_or_init(|| {
        std::env::var(JPEG_THREADS_VARIABLE)
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
            .filter(|&n| n >= 1)
            .unwrap_or_else(|| {
                std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_THREADS))
            })
    })
}
/// Pixels a strip has at least: smaller frames are not worth a thread.
const MIN_STRIP_PIXELS: usize = 1 << 16;

/// [`jpeg`] on at most `threads` threads: strips of whole MCU rows, one a thread.
pub fn jpeg_in_strips(
    rgb: &[u8],
    width: u32,
    height: u32,
    quality: u8,
    threads: usize,
) -> Result<Vec<u8>, ViewError> {
    let (w, h) = dimensions(width, height)?;
    let required = 3 * usize::from(w) * usize::from(h);
    if rgb.len() < required {
        return Err(ViewError::Encode(format!(
            "JPEG: {} bytes of RGB for {width} x {height} pixels; expected {required}",
            rgb.len()
        )));
    }
    // The MCU: 16 x 16 pixels with 4:2:0, 8 x 8 with 4:4:4.
    let (sampling, mcu) = if quality < 90 {
        (jpeg_encoder::SamplingFactor::F_2_2, 16)
    } else {
        (jpeg_encoder::SamplingFactor::F_1_1, 8)
    };
    let columns = usize::from(w).div_ceil(mcu);
    let rows = usize::from(h).div_ceil(mcu);
    let by_pixels = (usize::from(w) * usize::from(h) / MIN_STRIP_PIXELS).max(1);
    // A strip's MCUs are the restart interval, a u16.
    let rows_per_strip = rows
        .div_ceil(threads.min(by_pixels).max(1))
        .min(usize::from(u16::MAX) / columns)
        .max(1);
    let encode = |rgb: &[u8], strip_height: u16, interval: Option<u16>| {
        let mut out = Vec::new();
        let mut encoder = jpeg_encoder::Encoder::new(&mut out, quality);
        encoder.set_sampling_factor(sampling);
        if let Some(interval) = interval {
            encoder.set_restart_interval(interval);
        }
        encoder
            .encode(rgb, w, strip_height, jpeg_encoder::ColorType::Rgb)
            .map_err(|e| ViewError::Encode(format!("JPEG: {e}")))?;
        Ok::<_, ViewError>(out)
    };
    if rows_per_strip >= rows {
        return encode(&rgb[..required], h, None);
    }
    let interval = (rows_per_strip * columns) as u16;
    let strip_bytes = 3 * usize::from(w) * rows_per_strip * mcu;
    let strips: Vec<Result<Vec<u8>, ViewError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = rgb[..required]
            .chunks(strip_bytes)
            .map(|strip| {
                let strip_height = (strip.len() / (3 * usize::from(w))) as u16;
                scope.spawn(move || encode(strip, strip_height, Some(interval)))
            })
            .collect();
        handles
            .into_iter()
            .map(|handle| {
                handle.join().unwrap_or_else(|_| {
                    Err(ViewError::Encode("JPEG: a strip's thread panicked".into()))
                })
            })
            .collect()
    });
    let strips = strips.into_iter().collect::<Result<Vec<_>, _>>()?;
    restart_strips(&strips, h)
}

/// One JPEG of the strips' JPEGs, each a baseline JPEG of the same width, tables and restart
/// interval (its MCU count: none has a restart marker of its own), stacked top to bottom into an
/// image `height` pixels high: the first strip's headers with the frame's height, then each
/// strip's entropy-coded data, the restart markers RST0..RST7 in turn between them (a restart
/// resets the DC predictions, as a strip's own start does), then EOI. The bytes are those of one
/// encoder run over the whole image with that restart interval.
fn restart_strips(strips: &[Vec<u8>], height: u16) -> Result<Vec<u8>, ViewError> {
    let bad = |why: &str| ViewError::Encode(format!("JPEG strips: {why}"));
    let mut out = Vec::with_capacity(strips.iter().map(Vec::len).sum());
    for (i, strip) in strips.iter().enumerate() {
        let (sof_height_at, scan_at) = scan_start(strip).ok_or_else(|| bad("no scan"))?;
        let entropy = strip
            .get(scan_at..strip.len().saturating_sub(2))
            .filter(|_| strip.ends_with(&[0xFF, 0xD9]))
            .ok_or_else(|| bad("no end of image"))?;
        if i == 0 {
            out.extend_from_slice(&strip[..scan_at]);
            out[sof_height_at..sof_height_at + 2].copy_from_slice(&height.to_be_bytes());
        } else {
            out.extend_from_slice(&[0xFF, 0xD0 + ((i - 1) % 8) as u8]);
        }
        out.extend_from_slice(entropy);
    }
    out.extend_from_slice(&[0xFF, 0xD9]);
    Ok(out)
}

/// Where a baseline JPEG's frame header keeps the height, and where its (first) scan's
/// entropy-coded data starts: its marker segments walked from SOI to SOS.
fn scan_start(jpeg: &[u8]) -> Option<(usize, usize)> {
    if !jpeg.starts_with(&[0xFF, 0xD8]) {
        return None;
    }
    let mut at = 2;
    let mut sof_height = None;
    loop {
        let (&[0xFF, marker], rest) = jpeg.get(at..)?.split_first_chunk::<2>()? else {
            return None;
        };
        let length = usize::from(u16::from_be_bytes(*rest.first_chunk::<2>()?));
        let end = at + 2 + length;
        match marker {
            // SOF0: length, precision, then the height.
            0xC0 => sof_height = Some(at + 5),
            0xDA => return Some((sof_height?, end)).filter(|_| end <= jpeg.len()),
            _ => {}
        }
        at = end;
    }
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

    /// A frame encoded in strips on several threads is, byte for byte, what one encoder writes
    /// over the whole frame with the strips' restart interval: the same headers (the frame's
    /// height), entropy data and restart markers (RST0..7 wrapping round past eight strips). Sizes
    /// whose last strip or MCU is partial, 4:2:0 and 4:4:4.
    #[test]
    fn a_frame_in_strips_is_one_encoders_frame_with_restarts() {
        for (width, height, quality, threads) in [
            (800u32, 800u32, 85u8, 8usize),
            (1000, 563, 85, 3),
            (517, 1301, 85, 12),
            (640, 480, 95, 4),
        ] {
            let rgb: Vec<u8> = (0..3 * width * height)
                .map(|i| {
                    let (p, c) = (i / 3, i % 3);
                    let (x, y) = (p % width, p / width);
                    ((x * (c + 1) + y * 3 + (x * y) % 7) % 256) as u8
                })
                .collect();
            let strips = jpeg_in_strips(&rgb, width, height, quality, threads).unwrap();
            let mcu = if quality < 90 { 16 } else { 8 };
            let rows = height.div_ceil(mcu) as usize;
            let by_pixels = (width * height) as usize / MIN_STRIP_PIXELS;
            let rows_per_strip = rows.div_ceil(threads.min(by_pixels).max(1));
            assert!(rows_per_strip < rows, "{width}x{height}: in strips");
            let mut whole = Vec::new();
            let mut encoder = jpeg_encoder::Encoder::new(&mut whole, quality);
            encoder.set_restart_interval((rows_per_strip * width.div_ceil(mcu) as usize) as u16);
            encoder
                .encode(
                    &rgb,
                    width as u16,
                    height as u16,
                    jpeg_encoder::ColorType::Rgb,
                )
                .unwrap();
            assert!(
                strips == whole,
                "{width}x{height} q{quality} on {threads} threads"
            );
        }
        // One thread, or a small frame: one encoder, no restarts.
        let rgb = vec![7u8; 3 * 64 * 64];
        let mut plain = Vec::new();
        jpeg_encoder::Encoder::new(&mut plain, 85)
            .encode(&rgb, 64, 64, jpeg_encoder::ColorType::Rgb)
            .unwrap();
        assert_eq!(jpeg_in_strips(&rgb, 64, 64, 85, 8).unwrap(), plain);
    }
}
