//! Log-log line plots as SVG and PNG, drawn with `plotters`: one layout, written by its SVG backend
//! and by its bitmap backend (encoded with `png`).
//!
//! The bitmap backend rasterises text itself (`ab_glyph`) from a font embedded in the binary,
//! `assets/DejaVuSans.ttf` (licence beside it), so a PNG needs no font, fontconfig or font files
//! on the machine. The SVG names the family `sans-serif` and leaves the glyphs to its viewer; its
//! layout is measured with the same embedded font.
//!
//! The legend sits below the axes, one entry a row, and the picture grows to hold it: it is never
//! cut off and never covers a curve, however many settings or however long their names.

use std::sync::OnceLock;

use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One curve: its name and `(x, y)` points, both positive.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// The SVG's least width (a legend name too long for it widens the picture), and the height of
/// its axes part; the legend adds rows below.
const WIDTH: u32 = 720;
const AXES_HEIGHT: u32 = 480;
/// The axes' margin, and the heights of the x axis' labels and widths of the y axis' labels.
const MARGIN: u32 = 12;
const X_LABEL_AREA: u32 = 40;
const Y_LABEL_AREA: u32 = 64;
/// Height of one legend row, and the legend's margins above and below its rows.
const LEGEND_ROW: u32 = 20;
const LEGEND_PAD: u32 = 8;
/// A legend entry's line length, and where its name starts, from the entry's left edge.
const LEGEND_LINE: u32 = 24;
const LEGEND_TEXT: u32 = 32;
/// The size of every label and legend name, and of the axes' descriptions and the title.
const LABEL_SIZE: u32 = 12;
const DESC_SIZE: u32 = 13;
const TITLE_SIZE: u32 = 15;
/// Distinguishable on white, in the order curves are drawn.
const COLOURS: [RGBColor; 8] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x17, 0xbe, 0xcf),
];
/// PNG pixels per SVG unit: the PNG is twice the SVG's size, so that lines and text stay crisp.
const PNG_SCALE: u32 = 2;
/// The family every text of a plot asks for; the embedded font is registered under it.
const FAMILY: &str = "sans-serif";

/// DejaVu Sans (Bitstream Vera licence with DejaVu's public-domain changes:
/// `assets/LICENSE-DejaVu`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font with `plotters` once per process; every later call returns the
/// first call's outcome.
fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).map_err(|_| {
                "the embedded font assets/DejaVuSans.ttf: expected a TrueType font, found bytes \
                 ab_glyph cannot parse"
                    .to_owned()
            })
        })
        .clone()
        .map_err(|e| anyhow!(e))
}

/// A font of `size` pixels (at `k` times the SVG's scale) in the embedded family. `plotters` sizes
/// a font by its line height, 1.24 em (the SVG's `font-size` is the size over 1.24).
fn font(size: u32, k: u32) -> FontDesc<'static> {
    (FAMILY, f64::from(size * k) * 1.24).into_font()
}

/// The picture's size in SVG units: the axes and a legend row per series, at least [`WIDTH`] wide
/// and wide enough for the longest legend name (measured with the embedded font, which must be
/// registered).
fn size(series: &[Series]) -> (u32, u32) {
    let legend = if series.is_empty() {
        0
    } else {
        2 * LEGEND_PAD + LEGEND_ROW * series.len() as u32
    };
    let label = font(LABEL_SIZE, 1);
    let longest = series
        .iter()
        .map(|s| label.box_size(&s.name).map_or(0, |(w, _)| w))
        .max()
        .unwrap_or(0);
    let width = WIDTH.max(MARGIN + Y_LABEL_AREA + LEGEND_TEXT + longest + MARGIN);
    (width, AXES_HEIGHT + legend)
}

/// The decades `10^lo ..= 10^hi` that hold every value `f` picks from `points`, at least one
/// decade wide; `(0, 1)` when there is no value.
fn decades(points: &[(f64, f64)], f: fn(&(f64, f64)) -> f64) -> (i32, i32) {
    let lo = points.iter().map(f).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
    if lo.is_finite() && hi.is_finite() {
        let lo = lo.log10().floor();
        (lo as i32, hi.log10().ceil().max(lo + 1.0) as i32)
    } else {
        (0, 1)
    }
}

/// Widen the axes by these factors beyond their outer decades: `plotters` labels the decades from
/// `10^ceil(log10(start))`, whose floating-point logarithm can land just above the first decade
/// and drop its label.
const LOWER: f64 = 1.0 - 1e-9;
const UPPER: f64 = 1.0 + 1e-9;

/// `10^d`, times `widen`.
fn decade(d: i32, widen: f64) -> f64 {
    10f64.powi(d) * widen
}

/// A tick's label: `1e-3` for a power of ten, else three significant digits (`2.5e-3`).
fn tick(v: f64) -> String {
    let d = v.log10();
    if (d - d.round()).abs() < 1e-9 {
        format!("1e{}", d.round() as i32)
    } else {
        let s = format!("{v:.2e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{exponent}")
    }
}

/// Draws the log-log plot of `series` on `root`, every length multiplied by `k` (points with a
/// non-positive or non-finite coordinate are skipped).
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    k: u32,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing the plot {title:?}: {e}");
    let finite = |(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0;
    let curves: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| s.points.iter().copied().filter(finite).collect())
        .collect();
    let all: Vec<(f64, f64)> = curves.iter().flatten().copied().collect();
    let (x0, x1) = decades(&all, |p| p.0);
    let (y0, y1) = decades(&all, |p| p.1);
    let text = |size: u32| font(size, k);

    root.fill(&WHITE).map_err(fail)?;
    let (axes, legend) = root.split_vertically(AXES_HEIGHT * k);
    let mut chart = ChartBuilder::on(&axes)
        .caption(title, text(TITLE_SIZE))
        .margin(MARGIN * k)
        .x_label_area_size(X_LABEL_AREA * k)
        .y_label_area_size(Y_LABEL_AREA * k)
        .build_cartesian_2d(
            (decade(x0, LOWER)..decade(x1, UPPER)).log_scale(),
            (decade(y0, LOWER)..decade(y1, UPPER)).log_scale(),
        )
        .map_err(fail)?;
    // One label a decade: the hint is the decade count plus one, below which `plotters` adds no
    // labels between decades.
    chart
        .configure_mesh()
        .x_labels((x1 - x0) as usize + 1)
        .y_labels((y1 - y0) as usize + 1)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style(text(LABEL_SIZE))
        .axis_desc_style(text(DESC_SIZE))
        .axis_style(BLACK.stroke_width(k))
        .bold_line_style(RGBColor(0xcc, 0xcc, 0xcc).stroke_width(k))
        .light_line_style(RGBColor(0xf0, 0xf0, 0xf0).stroke_width(k))
        .draw()
        .map_err(fail)?;
    for (i, points) in curves.into_iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(2 * k)))
            .map_err(fail)?;
    }

    // The legend: a line in the curve's colour and its name, a row each, left-aligned under the
    // axes' plotting area.
    let left = ((MARGIN + Y_LABEL_AREA) * k) as i32;
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let y = ((LEGEND_PAD + LEGEND_ROW * i as u32 + LEGEND_ROW / 2) * k) as i32;
        legend
            .draw(&PathElement::new(
                vec![(left, y), (left + (LEGEND_LINE * k) as i32, y)],
                colour.stroke_width(2 * k),
            ))
            .map_err(fail)?;
        let style = TextStyle::from(text(LABEL_SIZE)).pos(Pos::new(HPos::Left, VPos::Center));
        legend
            .draw(&Text::new(
                s.name.clone(),
                (left + (LEGEND_TEXT * k) as i32, y),
                style,
            ))
            .map_err(fail)?;
    }
    root.present().map_err(fail)
}

/// A log-log plot of `series` as SVG.
pub fn log_log_svg(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<String> {
    register_font()?;
    let mut svg = String::new();
    let root = SVGBackend::with_string(&mut svg, size(series)).into_drawing_area();
    draw(root, 1, title, x_label, y_label, series)?;
    Ok(svg)
}

/// The same plot as [`log_log_svg`], as a PNG at twice its size.
pub fn log_log_png(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<Vec<u8>> {
    register_font()?;
    let (w, h) = size(series);
    let (w, h) = (w * PNG_SCALE, h * PNG_SCALE);
    let mut rgb = vec![0u8; 3 * w as usize * h as usize];
    let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
    draw(root, PNG_SCALE, title, x_label, y_label, series)?;
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // Committed plots (docs/accuracy) stay small: the best deflate level and per-row filters.
    encoder.set_compression(png::Compression::Best);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    encoder
        .write_header()
        .and_then(|mut writer| writer.write_image_data(&rgb))
        .map_err(|e| anyhow!("encoding the plot {title:?} as PNG: {e}"))?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(names: &[&str]) -> Vec<Series> {
        names
            .iter()
            .map(|name| Series {
                name: (*name).to_owned(),
                points: vec![(0.1, 1.0), (1.0, 0.3), (10.0, 0.1)],
            })
            .collect()
    }

    /// The PNG's pixels, its width and height.
    fn decode(bytes: &[u8]) -> (Vec<[u8; 3]>, usize, usize) {
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut data = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut data).unwrap();
        let pixels = data[..info.buffer_size()]
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        (pixels, info.width as usize, info.height as usize)
    }

    fn is_dark(p: &[u8; 3]) -> bool {
        p.iter().all(|&c| c < 96)
    }

    /// The PNG is twice the SVG's size, shows the first curve's colour, and has glyphs (dark
    /// pixels) in the title's rows and in the legend's rows: the embedded font rasterises text
    /// with no font on the machine.
    #[test]
    fn png_draws_curves_title_and_legend_text() {
        let names = ["rr_depth=5", "rr_depth=1"];
        let bytes = log_log_png("title", "time", "RMSE", &series(&names)).unwrap();
        let (pixels, w, h) = decode(&bytes);
        let (sw, sh) = size(&series(&names));
        assert_eq!((w, h), (2 * sw as usize, 2 * sh as usize));
        let c = COLOURS[0];
        assert!(pixels.contains(&[c.0, c.1, c.2]));
        let rows = |from: u32, to: u32| &pixels[(from * 2) as usize * w..(to * 2) as usize * w];
        assert!(rows(0, 28).iter().any(is_dark), "no title text");
        let legend = rows(AXES_HEIGHT, sh);
        assert!(legend.iter().any(is_dark), "no legend text");
        assert!(legend.contains(&[c.0, c.1, c.2]), "no legend line");
    }

    /// Legend names end inside the picture: one of 41 characters (the longest in docs/accuracy) in
    /// the default width, and one of 200 characters in a picture widened for it. The rightmost
    /// dark pixel of the legend's rows is left of the right edge.
    #[test]
    fn long_legend_names_fit_inside_the_png() {
        let typical = "strategy=regeneration-sk lookup=trilinear";
        let huge = "estimator=pt max_depth=2 ".repeat(8);
        for (names, widened) in [(vec![typical; 3], false), (vec![typical, &huge], true)] {
            let bytes = log_log_png("t", "x", "y", &series(&names)).unwrap();
            let (pixels, w, _) = decode(&bytes);
            assert_eq!(w > (WIDTH * PNG_SCALE) as usize, widened, "width {w}");
            let legend = &pixels[(AXES_HEIGHT * PNG_SCALE) as usize * w..];
            let rightmost = legend
                .chunks_exact(w)
                .filter_map(|row| row.iter().rposition(is_dark))
                .max()
                .expect("legend text");
            assert!(
                rightmost < w - 10,
                "legend text reaches column {rightmost} of {w}"
            );
        }
    }

    /// The SVG draws each series' colour twice (its curve and its legend line), holds each legend
    /// name as text, labels the outer decades, and grows a legend row per series.
    #[test]
    fn svg_has_a_curve_and_a_legend_entry_per_series() {
        let svg = log_log_svg("t", "x", "y", &series(&["a=1", "b=2", "c=3"])).unwrap();
        for (i, name) in ["a=1", "b=2", "c=3"].iter().enumerate() {
            let RGBColor(r, g, b) = COLOURS[i];
            let stroke = format!("stroke=\"#{r:02X}{g:02X}{b:02X}\"");
            assert_eq!(svg.matches(&stroke).count(), 2, "{stroke}: {svg}");
            assert!(svg.contains(&format!("\n{name}\n</text>")), "{name}: {svg}");
        }
        // x from 0.1 to 10, y from 0.1 to 1: every decade labelled, the first ones included.
        for tick in ["1e-1", "1e0", "1e1"] {
            assert!(svg.contains(&format!("\n{tick}\n</text>")), "{tick}: {svg}");
        }
        let (_, h) = size(&series(&["a=1", "b=2", "c=3"]));
        assert!(svg.contains(&format!("height=\"{h}\"")), "{svg}");
    }

    #[test]
    fn ticks_name_decades_and_three_significant_digits() {
        assert_eq!(tick(1e-3), "1e-3");
        assert_eq!(tick(10.000000000000002), "1e1");
        assert_eq!(tick(1.0), "1e0");
        assert_eq!(tick(2.5e-3), "2.5e-3");
    }

    /// Points that a log axis cannot show are dropped, not drawn at infinity, and a plot with no
    /// drawable point is still a plot.
    #[test]
    fn non_positive_and_non_finite_points_are_skipped() {
        let bad = vec![Series {
            name: "bad".to_owned(),
            points: vec![
                (0.0, 1.0),
                (1.0, -1.0),
                (f64::NAN, 1.0),
                (1.0, f64::INFINITY),
            ],
        }];
        assert!(log_log_png("t", "x", "y", &bad).is_ok());
        assert!(log_log_svg("t", "x", "y", &bad).is_ok());
    }
}
