//! A compensation's record, written to a folder: what a user looks at and what a printer takes.
//!
//! - `target.png`: the target (sRGB); `prediction.png`: the kept (best) iteration's prediction
//!   (and `prediction.exr`: its linear RGB, 32-bit float),
//!   and `comparison.png`: side by side, the target, the naive prediction and its ΔE map, the
//!   kept prediction and its ΔE map (enlarged to at least [`COMPARISON_HEIGHT`] pixels);
//! - `iteration_NN/prediction.png`: the iteration's predicted top view (sRGB, 8-bit);
//! - `iteration_NN/delta_e.png`: its per-texel CIEDE2000, grey, 0 black to [`DELTA_E_WHITE`] white;
//! - `iterations.csv`: per iteration, the mean and 95th-percentile CIEDE2000, the prediction's
//!   noise (the mean CIEDE2000 of one standard error), its samples per texel, and whether its
//!   print is the one kept (`iteration,mean_delta_e,p95_delta_e,noise_delta_e,spp,best`);
//! - `delta_e.svg`: the mean and 95th-percentile CIEDE2000 (and the noise) per iteration;
//! - `slices/`: the best iteration's print as a slice stack ([`crate::slices`]).

use std::fmt::Write as _;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::colour::LinearRgb;
use crate::compensate::Compensation;
use crate::error::PrintError;
use crate::slices::write_slices;

/// The least height of `comparison.png`'s panels: smaller targets are enlarged by a whole factor.
pub const COMPARISON_HEIGHT: u32 = 192;

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
    let mut csv = String::from("iteration,mean_delta_e,p95_delta_e,noise_delta_e,spp,best\n");
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
        write_png(
            &sub.join("delta_e.png"),
            [width, height],
            png::ColorType::Grayscale,
            &grey(&it.delta_e),
        )?;
        let best = u8::from(k == compensation.best);
        let spp = it.samples.map_or(String::new(), |s| s.to_string());
        writeln!(
            csv,
            "{k},{:.6},{:.6},{:.6},{spp},{best}",
            it.mean, it.p95, it.noise
        )
        .expect("a String takes text");
    }
    let csv_path = dir.join("iterations.csv");
    std::fs::write(&csv_path, csv).map_err(io(&csv_path))?;
    let kept = &compensation.iterations[compensation.best];
    write_png(
        &dir.join("prediction.png"),
        [width, height],
        png::ColorType::Rgb,
        &srgb(&kept.prediction),
    )?;
    // Its linear RGB values, unrounded (L*a*b* is `colour::LinearRgb::to_lab` of these).
    let exr_path = dir.join("prediction.exr");
    volpt::Image {
        width,
        height,
        pixels: kept
            .prediction
            .iter()
            .map(|c| c.0.map(|v| v as f32))
            .collect(),
    }
    .write_exr(&exr_path)
    .map_err(|e| PrintError::Io {
        path: exr_path.clone(),
        source: std::io::Error::other(e),
    })?;
    // Side by side, a column of white between, each panel enlarged to at least
    // COMPARISON_HEIGHT pixels (nearest): target, naive prediction and its ΔE map, kept
    // prediction and its ΔE map.
    let naive = &compensation.iterations[0];
    let grey_rgb = |d: &[f64]| -> Vec<u8> { grey(d).iter().flat_map(|&g| [g; 3]).collect() };
    let panels = [
        srgb(target),
        srgb(&naive.prediction),
        grey_rgb(&naive.delta_e),
        srgb(&kept.prediction),
        grey_rgb(&kept.delta_e),
    ];
    let k = (COMPARISON_HEIGHT / height).max(1) as usize;
    let (w, h) = (width as usize, height as usize);
    let gap = 2 * k;
    let wide = panels.len() * w * k + (panels.len() - 1) * gap;
    let mut side = vec![255u8; wide * h * k * 3];
    for y in 0..h * k {
        for (p, panel) in panels.iter().enumerate() {
            for x in 0..w * k {
                let from = ((y / k) * w + x / k) * 3;
                let to = (y * wide + p * (w * k + gap) + x) * 3;
                side[to..to + 3].copy_from_slice(&panel[from..from + 3]);
            }
        }
    }
    write_png(
        &dir.join("comparison.png"),
        [wide as u32, (h * k) as u32],
        png::ColorType::Rgb,
        &side,
    )?;
    let svg_path = dir.join("delta_e.svg");
    std::fs::write(&svg_path, plot_svg(compensation)).map_err(io(&svg_path))?;
    write_slices(&compensation.print, &dir.join("slices"))
}

/// A ΔE map as grey levels: 0 black, [`DELTA_E_WHITE`] and above white.
fn grey(delta_e: &[f64]) -> Vec<u8> {
    delta_e
        .iter()
        .map(|d| (d / DELTA_E_WHITE * 255.0).clamp(0.0, 255.0).round() as u8)
        .collect()
}

/// The plot of CIEDE2000 per iteration: mean, 95th percentile and noise against the iteration, on
/// linear axes from 0, the kept iteration circled. Plain SVG (no fonts embedded: the viewer's
/// sans-serif).
pub fn plot_svg(compensation: &Compensation) -> String {
    // The picture's size and the plot area's margins (the legend on the right).
    let [width, height, left, right, top_margin, bottom] =
        [640.0, 400.0, 56.0, 150.0, 36.0, 44.0f64];
    let its = &compensation.iterations;
    let series: [(&str, &str, Vec<f64>); 3] = [
        ("mean", "#1f77b4", its.iter().map(|i| i.mean).collect()),
        (
            "95th percentile",
            "#d62728",
            its.iter().map(|i| i.p95).collect(),
        ),
        (
            "noise (mean)",
            "#7f7f7f",
            its.iter().map(|i| i.noise).collect(),
        ),
    ];
    let top = series
        .iter()
        .flat_map(|s| s.2.iter().copied())
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    // A round axis top: 1, 2 or 5 times a power of ten, and five ticks below it.
    let tick = {
        let raw = (top / 5.0).max(1e-6);
        let decade = 10f64.powf(raw.log10().floor());
        [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * decade)
            .find(|&t| t >= raw)
            .unwrap_or(10.0 * decade)
    };
    let y_max = (top / tick).ceil().max(1.0) * tick;
    let n = its.len().max(2) - 1;
    let (pw, ph) = (width - left - right, height - top_margin - bottom);
    let x = |k: usize| left + pw * k as f64 / n as f64;
    let y = |v: f64| top_margin + ph * (1.0 - v / y_max);
    let mut svg = String::new();
    let mut w = |text: String| svg.push_str(&text);
    w(format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"{width}\" height=\"{height}\" \
         fill=\"white\"/>\n<text x=\"{}\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">\
         CIEDE2000 per iteration</text>\n",
        left + pw / 2.0
    ));
    let mut v = 0.0;
    while v <= y_max + tick / 2.0 {
        w(format!(
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{v}</text>\n",
            left + pw,
            left - 6.0,
            y(v) + 4.0,
            y = y(v),
        ));
        v = ((v + tick) / tick).round() * tick;
    }
    let every = its.len().div_ceil(10).max(1);
    for k in (0..its.len()).step_by(every) {
        w(format!(
            "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">{k}</text>\n",
            x(k),
            top_margin + ph + 16.0
        ));
    }
    w(format!(
        "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">iteration (0: the naive \
         assignment)</text>\n<text transform=\"translate(16 {:.1}) rotate(-90)\" \
         text-anchor=\"middle\">CIEDE2000</text>\n<rect x=\"{left}\" y=\"{top_margin}\" \
         width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"black\"/>\n",
        left + pw / 2.0,
        height - 8.0,
        top_margin + ph / 2.0
    ));
    for (row, (name, colour, values)) in series.iter().enumerate() {
        let points: Vec<String> = values
            .iter()
            .enumerate()
            .map(|(k, &v)| format!("{:.1},{:.1}", x(k), y(v)))
            .collect();
        w(format!(
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\" points=\"{}\"/>\n",
            points.join(" ")
        ));
        for (k, &v) in values.iter().enumerate() {
            w(format!(
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{colour}\"/>\n",
                x(k),
                y(v)
            ));
        }
        let ly = top_margin + 10.0 + 20.0 * row as f64;
        w(format!(
            "<line x1=\"{}\" x2=\"{}\" y1=\"{ly}\" y2=\"{ly}\" stroke=\"{colour}\" \
             stroke-width=\"2\"/><text x=\"{}\" y=\"{}\">{name}</text>\n",
            width - right + 12.0,
            width - right + 36.0,
            width - right + 42.0,
            ly + 4.0
        ));
    }
    let best = compensation.best;
    w(format!(
        "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"7\" fill=\"none\" stroke=\"black\"/>\
         <text x=\"{}\" y=\"{}\">kept: iteration {best}</text>\n</svg>\n",
        x(best),
        y(its[best].mean),
        width - right + 12.0,
        top_margin + 74.0
    ));
    svg
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
