//! The rendered image and its files: OpenEXR (linear, 32-bit float) and a tone-mapped PNG preview.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use thiserror::Error;

#[derive(Debug, Error)]
pub enum ImageError {
    #[error("{path}: cannot read or write OpenEXR: {source}")]
    Exr {
        path: PathBuf,
        source: exr::error::Error,
    },
    #[error("{path}: cannot write PNG: {source}")]
    Png {
        path: PathBuf,
        source: png::EncodingError,
    },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Linear RGB, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Writes the image as its file name's extension says: OpenEXR (`.exr`) or the PNG preview
    /// (`.png`); another name is refused.
    pub fn write(&self, path: &Path) -> Result<(), ImageError> {
        let extension = path.extension().and_then(|e| e.to_str());
        match extension.map(str::to_ascii_lowercase).as_deref() {
            Some("exr") => self.write_exr(path),
            Some("png") => self.write_png(path),
            _ => Err(ImageError::Io {
                path: path.to_owned(),
                source: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "expected a file name ending in .exr or .png",
                ),
            }),
        }
    }

    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        exr::prelude::write_rgb_file(path, self.width as usize, self.height as usize, |x, y| {
            let [r, g, b] = self.pixels[y * self.width as usize + x];
            (r, g, b)
        })
        .map_err(|source| ImageError::Exr {
            path: path.to_owned(),
            source,
        })
    }

    /// Reads the first RGB layer of an OpenEXR file (as [`Image::write_exr`] writes it).
    pub fn read_exr(path: &Path) -> Result<Self, ImageError> {
        use exr::prelude::{read_first_rgba_layer_from_file, Vec2};
        let image = read_first_rgba_layer_from_file(
            path,
            |resolution: Vec2<usize>, _| {
                let (w, h) = (resolution.width(), resolution.height());
                (w, vec![[0.0f32; 3]; w * h])
            },
            |(w, pixels): &mut (usize, Vec<[f32; 3]>),
             p: Vec2<usize>,
             (r, g, b, _a): (f32, f32, f32, f32)| {
                pixels[p.y() * *w + p.x()] = [r, g, b];
            },
        )
        .map_err(|source| ImageError::Exr {
            path: path.to_owned(),
            source,
        })?;
        let size = image.layer_data.size;
        Ok(Image {
            width: size.width() as u32,
            height: size.height() as u32,
            pixels: image.layer_data.channel_data.pixels.1,
        })
    }

    /// 8-bit sRGB of the linear values clipped to [0, 1]: a preview, not a tone-mapping operator.
    pub fn write_png(&self, path: &Path) -> Result<(), ImageError> {
        let io_error = |source| ImageError::Io {
            path: path.to_owned(),
            source,
        };
        let png_error = |source| ImageError::Png {
            path: path.to_owned(),
            source,
        };
        let file = File::create(path).map_err(io_error)?;
        let mut encoder = png::Encoder::new(BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let bytes: Vec<u8> = self
            .pixels
            .iter()
            .flat_map(|rgb| rgb.map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8))
            .collect();
        let mut writer = encoder.write_header().map_err(png_error)?;
        writer.write_image_data(&bytes).map_err(png_error)?;
        writer.finish().map_err(png_error)
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value clipped to [0, 1]; NaN maps to 0.
pub(crate) fn srgb_encode(linear: f32) -> f32 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The PNG preview written next to an image file: `out.exr` -> `out.png`.
pub fn preview_path(path: &Path) -> PathBuf {
    path.with_extension("png")
}
