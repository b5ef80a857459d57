//! A compensation's record, written to a folder: what a user looks at and what a printer takes.
//!
//! - `target.png`: the target (sRGB);
//! - `iteration_NN/prediction.png`: the iteration's predicted top view (sRGB, 8-bit);
//! - `iteration_NN/delta_e.png`: its per-texel CIEDE2000, grey, 0 black to [`DELTA_E_WHITE`] white;
//! - `iterations.csv`: per iteration, the mean and 95th-percentile CIEDE2000 and the update step
//!   (`iteration,mean_delta_e,p95_delta_e,best`: 1 on the iteration whose print is kept);
//! - `slices/`: the best iteration's print as a slice stack ([`crate::slices`]).

use std::fmt::Write as _;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::colour::LinearRgb;
use crate::compensate::Compensation;
use crate::error::PrintError;
use crate::slices::write_slices;

/// The CIEDE2000 a ΔE map shows as white (and above): 10 is a clearly visible difference.
pub const DELTA_E_WHITE: f64 = 10.0;

/// Writes `compensation`'s record for `target` (`width` x `height`) into `dir` (see the module
/// docs); refuses a folder that already holds a slice stack.
pub fn write_record(
    compensation: &Compensation,
    target: &[LinearRgb],
    [width, height]: [u32; 2],
    dir: &Path,
) -> Result<(), PrintError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| PrintError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let srgb = |colours: &[LinearRgb]| -> Vec<u8> {
        colours.iter().flat_map(|c| c.to_srgb().to_u8()).collect()
    };
    write_png(
        &dir.join("target.png"),
        [width, height],
        png::ColorType::Rgb,
        &srgb(target),
    )?;
    let mut csv = String::from("iteration,mean_delta_e,p95_delta_e,best\n");
    let digits = compensation
        .iterations
        .len()
        .max(2)
        .to_string()
        .len()
        .max(2);
    for (k, it) in compensation.iterations.iter().enumerate() {
        let sub = dir.join(format!("iteration_{k:0digits$}"));
        std::fs::create_dir_all(&sub).map_err(io(&sub))?;
        write_png(
            &sub.join("prediction.png"),
            [width, height],
            png::ColorType::Rgb,
            &srgb(&it.prediction),
        )?;
        let grey: Vec<u8> = it
            .delta_e
            .iter()
            .map(|d| (d / DELTA_E_WHITE * 255.0).clamp(0.0, 255.0).round() as u8)
            .collect();
        write_png(
            &sub.join("delta_e.png"),
            [width, height],
            png::ColorType::Grayscale,
            &grey,
        )?;
        let best = u8::from(k == compensation.best);
        writeln!(csv, "{k},{:.6},{:.6},{best}", it.mean, it.p95).expect("a String takes text");
    }
    let csv_path = dir.join("iterations.csv");
    std::fs::write(&csv_path, csv).map_err(io(&csv_path))?;
    write_slices(&compensation.print, &dir.join("slices"))
}

fn write_png(
    path: &Path,
    [width, height]: [u32; 2],
    colour: png::ColorType,
    data: &[u8],
) -> Result<(), PrintError> {
    let failed = |source| PrintError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = File::create(path).map_err(failed)?;
    let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
    encoder.set_color(colour);
    encoder.set_depth(png::BitDepth::Eight);
    let encoding = |e: png::EncodingError| failed(std::io::Error::other(e));
    let mut writer = encoder.write_header().map_err(encoding)?;
    writer.write_image_data(data).map_err(encoding)?;
    writer.finish().map_err(encoding)
}
