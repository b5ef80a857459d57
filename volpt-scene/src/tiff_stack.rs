//! TIFF stacks (microscopes, industrial CT, ImageJ/Fiji, tifffile): a multi-page `.tif`/`.tiff`,
//! one slice per page, or a folder of TIFF files, one slice each (or several pages each), in the
//! natural order of their names (`slice2` before `slice10`), read.
//!
//! Decoded by the `tiff` crate (image-rs's TIFF decoder, the one the `image` crate uses:
//! maintained, pure Rust, every sample type and the usual compressions), built with only its
//! deflate and LZW codecs (flate2 is already volpt's, LZW is `weezl`, a small crate).
//!
//! - Pages: greyscale (one sample per pixel), 8, 16, 32 or 64-bit integers (signed or unsigned) or
//!   32/64-bit floats, every page the size of the first. Column `x`, row `y` (the first row is
//!   `y = 0`), page `z`.
//! - Spacing: `1 / XResolution` and `1 / YResolution` where the first page has them, else 1; between
//!   slices ImageJ's `spacing=` (in the first page's `ImageDescription`, as ImageJ and tifffile's
//!   `imagej=True` write it), else the x spacing (square voxels, as stack viewers assume). The
//!   first voxel is centred at the origin; each voxel is a cell. A TOML scene's `volume.bounds`
//!   places a stack whose spacing the file does not say.
//! - Limits: each page's size and the stack so far are checked against [`crate::raw::MAX_VALUES`]
//!   and the memory limit before the page is decoded (the decoder's own buffer limit is the
//!   memory limit too); every value finite and >= 0; only regular files are read.

use std::cmp::Ordering;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use tiff::decoder::ifd::Value;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::ColorType;

use crate::description::{GridConvention, GridDesc, SampleLayout};
use crate::error::{GridProblem, SceneError};
use crate::raw::{centred_bounds, checked_value, grid_error, ByteOrder, RawLayout, ScalarType};

/// Whether `path` names a TIFF file by its extension (`.tif`, `.tiff`).
pub fn is_tiff(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tif") || e.eq_ignore_ascii_case("tiff"))
}

/// The TIFF files of a folder, in the natural order of their names (hidden files skipped).
pub fn stack_files(dir: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let mut files = crate::dicom::folder_files(dir)?;
    files.retain(|p| is_tiff(p));
    Ok(files)
}

/// Reads a multi-page TIFF file, or a folder of TIFF files (see the module docs).
pub fn read_tiff_stack(path: &Path) -> Result<GridDesc, SceneError> {
    let files = if path.is_dir() {
        let files = stack_files(path)?;
        if files.is_empty() {
            return Err(grid_error(
                path,
                GridProblem::MissingField {
                    field: "slices",
                    expected: "a folder holding .tif or .tiff files",
                },
            ));
        }
        files
    } else {
        vec![path.to_path_buf()]
    };
    let mut stack = Stack::default();
    for file in &files {
        stack.read_pages(file)?;
    }
    let [w, h] = stack.size.expect("every file has a first page");
    let spacing = stack.spacing;
    let resolution = [w, h, stack.pages];
    let bounds = centred_bounds([0.0; 3], spacing, resolution).ok_or_else(|| {
        grid_error(
            path,
            GridProblem::BadField {
                line: None,
                field: "XResolution, YResolution and ImageJ's spacing".into(),
                expected: "spacings giving a box with finite f32 bounds".into(),
                found: format!("{spacing:?}"),
            },
        )
    })?;
    Ok(GridDesc {
        layout: SampleLayout::Dense,
        resolution,
        channels: 1,
        bounds,
        convention: GridConvention::Cell,
        data: stack.data,
    })
}

/// The slices read so far.
#[derive(Default)]
struct Stack {
    /// Width and height, from the first page.
    size: Option<[u32; 2]>,
    spacing: [f64; 3],
    pages: u32,
    data: Vec<f32>,
}

impl Stack {
    /// Appends every page of `path`.
    fn read_pages(&mut self, path: &Path) -> Result<(), SceneError> {
        let (file, _) = crate::limits::open_regular(path)?;
        let decode = |e: tiff::TiffError| {
            grid_error(
                path,
                GridProblem::Decode {
                    what: "the TIFF image".into(),
                    message: e.to_string(),
                },
            )
        };
        let mut limits = Limits::default();
        limits.decoding_buffer_size =
            usize::try_from(crate::limits::memory_limit()).unwrap_or(usize::MAX);
        let mut decoder = Decoder::new(BufReader::new(file))
            .map_err(decode)?
            .with_limits(limits);
        loop {
            let (w, h) = decoder.dimensions().map_err(decode)?;
            let colour = decoder.colortype().map_err(decode)?;
            let page = self.pages;
            let ColorType::Gray(_) = colour else {
                return Err(bad(
                    path,
                    page,
                    "colour type",
                    "greyscale (one sample per pixel: volpt reads a density; RGB, palette and \
                     multi-sample pages are not read, convert the stack to one channel first, \
                     e.g. ImageJ's Image > Type > 8-bit or 32-bit)",
                    format!("{colour:?}"),
                ));
            };
            match self.size {
                None => {
                    self.size = Some([w, h]);
                    self.spacing = first_page_spacing(&mut decoder);
                }
                Some(size) if size != [w, h] => {
                    return Err(bad(
                        path,
                        page,
                        "width x height",
                        &format!("{} x {}, as the first page", size[0], size[1]),
                        format!("{w} x {h}"),
                    ))
                }
                Some(_) => {}
            }
            // The stack with this page, checked before the page is decoded.
            let layout = RawLayout {
                resolution: [w, h, page + 1],
                channels: 1,
                scalar: ScalarType::F32,
                byte_order: ByteOrder::Little,
                header_bytes: 0,
            };
            if page == u32::MAX {
                return Err(bad(path, page, "pages", "fewer than 2^32", "more".into()));
            }
            let (count, _) = layout.checked_size(path)?;
            let values = decoder.read_image().map_err(decode)?;
            let start = self.data.len();
            if self.data.try_reserve_exact(count - start).is_err() {
                return Err(crate::limits::check_memory(path, "the TIFF stack", None).unwrap_err());
            }
            // Index in the whole stack, for errors naming the voxel.
            let mut push = |i: usize, v: f64| -> Result<(), SceneError> {
                self.data.push(checked_value(path, &layout, start + i, v)?);
                Ok(())
            };
            let pixels = (w as usize) * (h as usize);
            macro_rules! each {
                ($v:expr) => {{
                    if $v.len() != pixels {
                        return Err(bad(
                            path,
                            page,
                            "samples",
                            &pixels.to_string(),
                            $v.len().to_string(),
                        ));
                    }
                    for (i, &x) in $v.iter().enumerate() {
                        push(i, x as f64)?;
                    }
                }};
            }
            match values {
                DecodingResult::U8(v) => each!(v),
                DecodingResult::U16(v) => each!(v),
                DecodingResult::U32(v) => each!(v),
                DecodingResult::U64(v) => each!(v),
                DecodingResult::I8(v) => each!(v),
                DecodingResult::I16(v) => each!(v),
                DecodingResult::I32(v) => each!(v),
                DecodingResult::I64(v) => each!(v),
                DecodingResult::F16(v) => each!(v.iter().map(|h| h.to_f32()).collect::<Vec<_>>()),
                DecodingResult::F32(v) => each!(v),
                DecodingResult::F64(v) => each!(v),
            }
            self.pages += 1;
            if !decoder.more_images() {
                return Ok(());
            }
            decoder.next_image().map_err(decode)?;
        }
    }
}

/// The first page's voxel spacing (module docs): from its resolution tags and ImageJ description.
fn first_page_spacing(decoder: &mut Decoder<BufReader<File>>) -> [f64; 3] {
    let mut per_pixel = |tag| {
        let resolution = match decoder.get_tag(tag).ok()? {
            Value::Rational(n, d) => f64::from(n) / f64::from(d),
            other => other.into_f64().ok()?,
        };
        Some(resolution)
            .filter(|r| r.is_finite() && *r > 0.0)
            .map(|r| 1.0 / r)
            .filter(|s| s.is_finite())
    };
    let x = per_pixel(Tag::XResolution);
    let y = per_pixel(Tag::YResolution);
    let description = decoder.get_tag_ascii_string(Tag::ImageDescription).ok();
    let z = description.as_deref().and_then(imagej_spacing);
    let x = x.unwrap_or(1.0);
    [x, y.unwrap_or(x), z.unwrap_or(x)]
}

/// ImageJ's `spacing=` line, in a description starting `ImageJ=`.
fn imagej_spacing(description: &str) -> Option<f64> {
    if !description.starts_with("ImageJ=") {
        return None;
    }
    description
        .lines()
        .find_map(|l| l.trim().strip_prefix("spacing="))
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
}

fn bad(path: &Path, page: u32, field: &str, expected: &str, found: String) -> SceneError {
    grid_error(
        path,
        GridProblem::BadField {
            line: None,
            field: format!("page {page}: {field}"),
            expected: expected.into(),
            found,
        },
    )
}

/// Natural order of file names: digit runs compare as numbers (`2` before `10`), the rest as text.
pub(crate) fn natural_order(a: &str, b: &str) -> Ordering {
    let (mut a, mut b) = (a, b);
    loop {
        match (a.chars().next(), b.chars().next()) {
            (None, None) => return Ordering::Equal,
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(x), Some(y)) if x.is_ascii_digit() && y.is_ascii_digit() => {
                let split = |s: &str| {
                    let end = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
                    (s[..end].to_string(), end)
                };
                let ((da, ea), (db, eb)) = (split(a), split(b));
                let (ta, tb) = (da.trim_start_matches('0'), db.trim_start_matches('0'));
                let order = ta.len().cmp(&tb.len()).then_with(|| ta.cmp(tb));
                if order != Ordering::Equal {
                    return order;
                }
                (a, b) = (&a[ea..], &b[eb..]);
            }
            (Some(x), Some(y)) => {
                if x != y {
                    return x.cmp(&y);
                }
                (a, b) = (&a[x.len_utf8()..], &b[y.len_utf8()..]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_sort_by_their_numbers() {
        let mut names = vec!["s10.tif", "s2.tif", "s1.tif", "s02b.tif"];
        names.sort_by(|a, b| natural_order(a, b));
        assert_eq!(names, vec!["s1.tif", "s2.tif", "s02b.tif", "s10.tif"]);
    }

    #[test]
    fn imagej_spacing_is_read_from_its_description() {
        assert_eq!(
            imagej_spacing("ImageJ=1.11a\nimages=4\nslices=4\nspacing=2.5\nunit=um\n"),
            Some(2.5)
        );
        assert_eq!(imagej_spacing("spacing=2.5"), None);
    }
}
