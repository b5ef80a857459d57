//! Slice stacks: a voxel print as full-colour voxel printers take it, one PNG per layer
//! (`slice_0000.png` is the bottom layer, printed first), each pixel's colour naming a material
//! through the palette of `materials.toml` beside them:
//!
//! ```toml
//! voxel_size = [0.0846, 0.0423, 0.027] # x, y, layer height (the unit the coefficients are per)
//! width = 320                          # pixels per slice
//! height = 320
//! layers = 100                         # slices: slice_0000.png .. slice_0099.png
//! [[materials]]
//! name = "cyan"
//! colour = [0, 255, 255]               # its palette colour in the slices (8-bit RGB)
//! sigma_s = [9.0, 9.5, 9.9]
//! sigma_a = [2.9, 0.1, 0.05]
//! g = 0.0
//! ```
//!
//! Slice names have four digits, more where `layers` needs them. Within a slice, column `x` is voxel
//! `x` and row `y` voxel `y`. Slices are 8-bit RGB.
//!
//! The slices are read by volpt-scene's slice-stack reader ([`volpt_scene::slices`], the one a
//! TOML scene's `format = "png"` volume uses: RGBA, grey and palette PNGs too; every slice's size
//! against `materials.toml`'s from its header and one slice's pixels against the memory limit
//! before a pixel is decoded, regular files only, a pixel whose colour names no material an
//! error naming the slice and pixel). What is a print's own is checked here first: the table
//! (`materials.toml`, its materials read by volpt-scene's `[[materials]]` reader), the index grid
//! that `materials.toml` claims against the memory limit, and the numbering (no slice missing,
//! none extra). The whole stack is read or none of it.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use volpt_scene::limits::{bytes_of, check_memory, read_text};
use volpt_scene::material::{MaterialDesc, MaterialSpec};
use volpt_scene::slices::{SliceIndices, StackShape};

use crate::error::PrintError;
use crate::print::VoxelPrint;

/// The name of a stack's material table, beside its slices.
pub const MATERIALS_FILE: &str = "materials.toml";

/// `materials.toml`, as written (its materials as volpt-scene writes a [`MaterialDesc`]) and as
/// read (as volpt-scene reads `[[materials]]`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header<M> {
    voxel_size: [f64; 3],
    width: u32,
    height: u32,
    layers: u32,
    materials: Vec<M>,
}

/// The file name of slice `z` of a stack of `layers`: four digits, or as many as the last needs.
pub fn slice_name(z: u32, layers: u32) -> String {
    let digits = layers.saturating_sub(1).max(1).ilog10() as usize + 1;
    format!("slice_{z:0width$}.png", width = digits.max(4))
}

/// Writes `print` into `dir` (created if absent) as `materials.toml` and one PNG per layer.
/// Refuses a folder that already holds a stack's files, whose stale slices would be read with the
/// new ones.
pub fn write_slices(print: &VoxelPrint, dir: &Path) -> Result<(), PrintError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| PrintError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    if let Some(stale) = stack_files(dir)?.first() {
        return Err(PrintError::Invalid {
            path: dir.to_path_buf(),
            field: "the output folder".into(),
            expected: "a folder without slice_*.png or materials.toml".into(),
            found: stale.display().to_string(),
        });
    }
    let [width, height, layers] = print.resolution();
    let header = Header {
        voxel_size: print.voxel_size(),
        width,
        height,
        layers,
        materials: print.materials().to_vec(),
    };
    let toml_path = dir.join(MATERIALS_FILE);
    let text = toml::to_string(&header).expect("a material table serialises");
    std::fs::write(&toml_path, text).map_err(io(&toml_path))?;
    // A print's table has a colour for every material (`check_table`).
    let palette: Vec<[u8; 3]> = print
        .materials()
        .iter()
        .map(|m| m.colour.unwrap_or_default())
        .collect();
    for z in 0..layers {
        let path = dir.join(slice_name(z, layers));
        let pixels: Vec<u8> = print
            .layer(z)
            .iter()
            .flat_map(|&k| palette[usize::from(k)])
            .collect();
        let file = File::create(&path).map_err(io(&path))?;
        let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let encoding = |e: png::EncodingError| PrintError::Io {
            path: path.clone(),
            source: std::io::Error::other(e),
        };
        let mut writer = encoder.write_header().map_err(encoding)?;
        writer.write_image_data(&pixels).map_err(encoding)?;
        writer.finish().map_err(encoding)?;
    }
    Ok(())
}

/// Reads the slice stack in `dir` (see the module docs).
pub fn read_slices(dir: &Path) -> Result<VoxelPrint, PrintError> {
    let toml_path = dir.join(MATERIALS_FILE);
    let header: Header<MaterialSpec> =
        toml::from_str(&read_text(&toml_path)?).map_err(|e| PrintError::Toml {
            path: toml_path.clone(),
            source: Box::new(e),
        })?;
    let invalid = |field: &str, expected: &str, found: String| PrintError::Invalid {
        path: toml_path.clone(),
        field: field.into(),
        expected: expected.into(),
        found,
    };
    let materials: Vec<MaterialDesc> = crate::material::read_table(&toml_path, &header.materials)?;
    let Header {
        voxel_size,
        width,
        height,
        layers,
        ..
    } = header;
    if width == 0 || height == 0 || layers == 0 {
        return Err(invalid(
            "width, height, layers",
            "each at least 1",
            format!("{width}, {height}, {layers}"),
        ));
    }
    // The grid materials.toml claims, before a slice is listed or opened.
    check_memory(
        dir,
        &format!("the index grid of {width} x {height} x {layers} voxels"),
        bytes_of(u64::from(width) * u64::from(height), u64::from(layers)),
    )?;
    check_numbering(dir, layers)?;
    let shape = StackShape {
        resolution: [width, height, layers],
        source: "materials.toml's width, height and layers",
    };
    let (indices, resolution) = volpt_scene::slices::read_slices(dir, &materials, Some(shape))?;
    let SliceIndices::Bytes(indices) = indices else {
        unreachable!("a print's table has at most 256 materials (check_table): byte indices")
    };
    VoxelPrint::new(materials, voxel_size, resolution, indices)
        .map_err(|(field, expected, found)| invalid(field, &expected, found))
}

/// Whether a file name is a stack's (`slice_*.png` or `materials.toml`).
fn stack_files(dir: &Path) -> Result<Vec<PathBuf>, PrintError> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|source| PrintError::Io {
        path: dir.to_path_buf(),
        source,
    })? {
        let entry = entry.map_err(|source| PrintError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name == MATERIALS_FILE || slice_number(&name).is_some() {
            found.push(entry.path());
        }
    }
    found.sort();
    Ok(found)
}

/// The number of a slice file name, `slice_<digits>.png`.
fn slice_number(name: &str) -> Option<&str> {
    let digits = name.strip_prefix("slice_")?.strip_suffix(".png")?;
    (!digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())).then_some(digits)
}

/// Checks the folder holds exactly slices `0 .. layers`. Works from the names present (a folder's
/// real files), never from `layers` alone, which a file may inflate.
fn check_numbering(dir: &Path, layers: u32) -> Result<(), PrintError> {
    let numbering = |found: String| PrintError::SliceNumbering {
        path: dir.to_path_buf(),
        expected: format!(
            "{layers} slices {} .. {} (materials.toml's layers)",
            slice_name(0, layers),
            slice_name(layers - 1, layers)
        ),
        found,
    };
    let mut numbers = Vec::new();
    for path in stack_files(dir)? {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let Some(name) = name.filter(|n| n != MATERIALS_FILE) else {
            continue;
        };
        // A number in range, spelt as the writer spells it (no second spelling of a slice).
        let number = slice_number(&name)
            .and_then(|d| d.parse::<u32>().ok())
            .filter(|&z| z < layers && slice_name(z, layers) == name);
        match number {
            Some(z) => numbers.push(z),
            None => return Err(numbering(format!("an extra slice {name}"))),
        }
    }
    numbers.sort_unstable();
    if let Some(missing) = (0..layers)
        .zip(numbers.iter().chain(std::iter::repeat(&layers)))
        .find(|(z, n)| z != *n)
    {
        return Err(numbering(format!("no {}", slice_name(missing.0, layers))));
    }
    Ok(())
}
