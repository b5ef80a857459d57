//! A compensation's target: a PNG (8 or 16 bits, grey, RGB, with or without alpha, or a palette),
//! its values sRGB-encoded as PNGs are unless they say otherwise, read as linear RGB. Alpha is
//! ignored. Sizes are checked against volpt's memory limit from the header, before any pixel is
//! decoded.

use std::io::BufReader;
use std::path::Path;

use volpt_scene::limits::{bytes_of, check_memory, open_regular};

use crate::colour::{LinearRgb, Srgb};
use crate::error::PrintError;

/// The target's texels (row-major, row 0 at the image's top as it is shown) and its size.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    pub texels: Vec<LinearRgb>,
    pub size: [u32; 2],
}

impl Target {
    /// Reads the PNG at `path`.
    pub fn read(path: &Path) -> Result<Target, PrintError> {
        let png_error = |source| PrintError::Png {
            path: path.to_path_buf(),
            source,
        };
        let (file, _) = open_regular(path)?;
        let mut decoder = png::Decoder::new(BufReader::new(file));
        decoder.set_transformations(png::Transformations::EXPAND);
        let mut reader = decoder.read_info().map_err(png_error)?;
        let [w, h] = [reader.info().width, reader.info().height];
        let pixels = u64::from(w) * u64::from(h);
        // The decoded image (at most 8 bytes a pixel) and its texels as three f64s each.
        check_memory(
            path,
            &format!("a target of {w} x {h} pixels"),
            bytes_of(pixels, 8 + 24),
        )?;
        let mut buffer = vec![0; reader.output_buffer_size()];
        let frame = reader.next_frame(&mut buffer).map_err(png_error)?;
        let channels = frame.color_type.samples();
        let bytes = match frame.bit_depth {
            png::BitDepth::Sixteen => 2,
            _ => 1,
        };
        let value = |at: &[u8], c: usize| -> f64 {
            match bytes {
                2 => f64::from(u16::from_be_bytes([at[2 * c], at[2 * c + 1]])) / 65535.0,
                _ => f64::from(at[c]) / 255.0,
            }
        };
        let mut texels = Vec::with_capacity(pixels as usize);
        for y in 0..h as usize {
            let row = &buffer[y * frame.line_size..];
            for x in 0..w as usize {
                let at = &row[x * channels * bytes..];
                let rgb = if channels >= 3 {
                    [0, 1, 2].map(|c| value(at, c))
                } else {
                    [value(at, 0); 3]
                };
                texels.push(Srgb(rgb).to_linear());
            }
        }
        Ok(Target {
            texels,
            size: [w, h],
        })
    }
}
