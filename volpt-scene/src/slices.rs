//! Voxel-print slice stacks: a folder of PNG images, one per layer (the format full-colour voxel
//! printers take), each pixel's colour naming a material through the palette of the scene's
//! `[[materials]]` (`colour`). Files are read in the natural order of their names (hidden files
//! skipped): the first is layer z = 0. Within a slice, column `x` is voxel `x` and row `y` voxel
//! `y` (the image's top row at the box's minimum y). 8-bit RGB, RGBA (alpha ignored), grey and
//! palette PNGs are read; 16-bit ones are reduced to 8 bits.
//!
//! Every slice's header is read and checked (same size, the expected count, and the expected
//! resolution where the caller knows one: [`StackShape`]) and the volume's size and one slice's
//! decoded pixels checked against the memory limit before any pixel is decoded.

use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use crate::error::{MaterialProblem, SceneError};
use crate::limits::{bytes_of, check_memory, open_regular};
use crate::material::{MaterialDesc, MaterialIndex};
use volpt_core::material::wide_indices;

/// The PNG files of a folder, in the natural order of their names (hidden files skipped). A PNG
/// name that is not a regular file (a folder, a device) is refused, not skipped: it is a layer.
pub fn slice_files(dir: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let png = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    };
    let mut files = crate::dicom::folder_files(dir)?;
    files.retain(|p| png(p));
    let io = |error| SceneError::Io {
        path: dir.to_path_buf(),
        error,
    };
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        let hidden = path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if png(&path) && !hidden && !path.is_file() {
            open_regular(&path)?;
        }
    }
    Ok(files)
}

/// A slice stack's material indices, one per voxel, x fastest.
pub enum SliceIndices {
    /// For a table of at most 256 materials.
    Bytes(Vec<u8>),
    /// For a larger table.
    Wide(Vec<u16>),
}

/// The resolution a caller expects of a stack (width, height, slices), and what says so (named in
/// the errors: `volume.resolution`, a print's `materials.toml`).
#[derive(Clone, Copy, Debug)]
pub struct StackShape<'a> {
    pub resolution: [u32; 3],
    pub source: &'a str,
}

/// The material indices of the slice stack in `dir` (bytes, or `u16`s for a table of more than
/// 256 materials) and its resolution; `expected`, if given, is the resolution the caller expects.
pub fn read_slices(
    dir: &Path,
    materials: &[MaterialDesc],
    expected: Option<StackShape>,
) -> Result<(SliceIndices, [u32; 3]), SceneError> {
    Ok(if wide_indices(materials.len()) {
        let (indices, res) = read_slices_as(dir, materials, expected)?;
        (SliceIndices::Wide(indices), res)
    } else {
        let (indices, res) = read_slices_as(dir, materials, expected)?;
        (SliceIndices::Bytes(indices), res)
    })
}

fn read_slices_as<I: MaterialIndex>(
    dir: &Path,
    materials: &[MaterialDesc],
    expected: Option<StackShape>,
) -> Result<(Vec<I>, [u32; 3]), SceneError> {
    let error = |problem| SceneError::Material {
        path: dir.to_owned(),
        problem,
    };
    let palette = palette(dir, materials)?;
    let files = slice_files(dir)?;
    let found = u32::try_from(files.len()).unwrap_or(u32::MAX);
    if files.is_empty() || expected.is_some_and(|e| e.resolution[2] != found) {
        return Err(error(MaterialProblem::SliceCount {
            expected: expected.map_or(1, |e| e.resolution[2]),
            found,
            source: expected.map_or_else(|| "at least one".into(), |e| e.source.into()),
        }));
    }
    let name = |p: &Path| {
        p.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into())
    };
    // Headers first: sizes agree and the volume fits before a pixel is decoded.
    let mut size = expected.map(|e| ([e.resolution[0], e.resolution[1]], e.source.to_owned()));
    for file in &files {
        let (w, h) = header(file, &name(file))?;
        match &size {
            None => size = Some(([w, h], "the first slice's".into())),
            Some((s, source)) if *s != [w, h] => {
                return Err(error(MaterialProblem::SliceSize {
                    slice: name(file),
                    expected: *s,
                    found: [w, h],
                    source: source.clone(),
                }))
            }
            Some(_) => {}
        }
    }
    let [w, h] = size.expect("at least one slice").0;
    let voxels = (w as u64) * (h as u64) * files.len() as u64;
    check_memory(
        dir,
        &format!("the index grid of {w} x {h} x {found} voxels"),
        bytes_of(voxels, std::mem::size_of::<I>() as u64),
    )?;
    // A slice's decoded pixels: at most 8 bytes each (16-bit RGBA before reduction).
    check_memory(
        dir,
        &format!("a slice of {w} x {h} pixels"),
        bytes_of(w as u64 * h as u64, 8),
    )?;
    let palette_text = materials
        .iter()
        .filter_map(|m| {
            let [r, g, b] = m.colour?;
            Some(format!("#{r:02x}{g:02x}{b:02x} {}", m.name))
        })
        .collect::<Vec<_>>()
        .join(", ");
    let mut indices = Vec::with_capacity(voxels as usize);
    for file in &files {
        decode(file, &name(file), &palette, &palette_text, &mut indices)?;
    }
    Ok((indices, [w, h, found]))
}

/// Colour to material index; every material of a slice stack's table needs a distinct colour.
fn palette<I: MaterialIndex>(
    dir: &Path,
    materials: &[MaterialDesc],
) -> Result<HashMap<[u8; 3], I>, SceneError> {
    let mut palette = HashMap::new();
    for (k, m) in materials.iter().enumerate() {
        let invalid = |expected: &str, found: String| SceneError::InvalidScene {
            source_name: dir.display().to_string(),
            field: format!("materials[{k}].colour"),
            expected: expected.into(),
            found,
        };
        let Some(colour) = m.colour else {
            return Err(invalid(
                "a colour for every material of a slice stack",
                "none".into(),
            ));
        };
        if palette.insert(colour, I::narrow(k)).is_some() {
            return Err(invalid(
                "a colour no other material has",
                format!("{colour:?} twice"),
            ));
        }
    }
    Ok(palette)
}

fn decoder(file: &Path, slice: &str) -> Result<png::Reader<BufReader<std::fs::File>>, SceneError> {
    let (f, _) = open_regular(file)?;
    let mut decoder = png::Decoder::new(BufReader::new(f));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    decoder.read_info().map_err(|e| SceneError::Material {
        path: file.to_owned(),
        problem: MaterialProblem::Slice {
            slice: slice.into(),
            message: e.to_string(),
        },
    })
}

/// A slice's width and height, from its header alone.
fn header(file: &Path, slice: &str) -> Result<(u32, u32), SceneError> {
    let reader = decoder(file, slice)?;
    let info = reader.info();
    Ok((info.width, info.height))
}

/// Appends a slice's material indices to `out`; `palette_text` lists the palette for errors.
fn decode<I: MaterialIndex>(
    file: &Path,
    slice: &str,
    palette: &HashMap<[u8; 3], I>,
    palette_text: &str,
    out: &mut Vec<I>,
) -> Result<(), SceneError> {
    let error = |problem| SceneError::Material {
        path: file.to_owned(),
        problem,
    };
    let mut reader = decoder(file, slice)?;
    let (w, h) = (reader.info().width, reader.info().height);
    let mut buffer = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buffer).map_err(|e| {
        error(MaterialProblem::Slice {
            slice: slice.into(),
            message: e.to_string(),
        })
    })?;
    let channels = match frame.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => {
            return Err(error(MaterialProblem::Slice {
                slice: slice.into(),
                message: "a palette image that did not expand to RGB".into(),
            }))
        }
    };
    let row_bytes = frame.line_size;
    for y in 0..h as usize {
        let row = &buffer[y * row_bytes..];
        for x in 0..w as usize {
            let px = &row[x * channels..];
            let colour = if channels >= 3 {
                [px[0], px[1], px[2]]
            } else {
                [px[0]; 3]
            };
            match palette.get(&colour) {
                Some(&k) => out.push(k),
                None => {
                    return Err(error(MaterialProblem::PaletteColour {
                        slice: slice.into(),
                        pixel: [x as u32, y as u32],
                        colour,
                        palette: palette_text.into(),
                    }))
                }
            }
        }
    }
    Ok(())
}
