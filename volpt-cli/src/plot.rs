//! Log-log line plots as SVG and PNG, drawn by hand: a few polylines, decade ticks and a legend
//! need no plotting library. The layout is computed once, as a list of [`Mark`]s, and written by
//! both outputs; the PNG draws its text with the public-domain 8x8 bitmap font of `font8x8`, so it
//! needs no font on the machine.

use std::fmt::Write;

use anyhow::{Context, Result};
use font8x8::legacy::BASIC_LEGACY;

/// One curve: its name and `(x, y)` points, both positive.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

const WIDTH: f64 = 720.0;
const HEIGHT: f64 = 480.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 220.0;
const TOP: f64 = 30.0;
const BOTTOM: f64 = 60.0;
/// Distinguishable on white, in the order curves are drawn.
const COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];
const GRID: &str = "#dddddd";
const BLACK: &str = "#000000";
/// PNG pixels per SVG unit: the PNG is twice the SVG's size, so that lines and text stay crisp.
const PNG_SCALE: f64 = 2.0;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Anchor {
    Start,
    Middle,
    End,
}

/// What a plot is made of, in SVG units (y down).
#[derive(Debug, PartialEq)]
enum Mark {
    /// A rectangle's outline.
    Frame { x: f64, y: f64, w: f64, h: f64 },
    Line {
        from: (f64, f64),
        to: (f64, f64),
        colour: &'static str,
        width: f64,
    },
    Polyline {
        points: Vec<(f64, f64)>,
        colour: &'static str,
    },
    /// Text whose baseline starts, centres or ends at `at`; `vertical` turns it 90 degrees
    /// anticlockwise about `at`.
    Text {
        at: (f64, f64),
        text: String,
        anchor: Anchor,
        size: f64,
        vertical: bool,
    },
}

/// The marks of a log-log plot of `series` (points with a non-positive or non-finite coordinate
/// are skipped).
fn log_log(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Vec<Mark> {
    let finite = |(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0;
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied().filter(finite))
        .collect();
    let range = |f: fn(&(f64, f64)) -> f64| {
        let lo = all.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = all.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi.is_finite() {
            (
                lo.log10().floor(),
                hi.log10().ceil().max(lo.log10().floor() + 1.0),
            )
        } else {
            (0.0, 1.0)
        }
    };
    let (x0, x1) = range(|p| p.0);
    let (y0, y1) = range(|p| p.1);
    let plot_w = WIDTH - LEFT - RIGHT;
    let plot_h = HEIGHT - TOP - BOTTOM;
    let sx = |x: f64| LEFT + (x.log10() - x0) / (x1 - x0) * plot_w;
    let sy = |y: f64| TOP + (y1 - y.log10()) / (y1 - y0) * plot_h;
    let text = |at, text: &str, anchor, size, vertical| Mark::Text {
        at,
        text: text.to_owned(),
        anchor,
        size,
        vertical,
    };
    let line = |from, to, colour, width| Mark::Line {
        from,
        to,
        colour,
        width,
    };

    let mut marks = vec![text(
        (LEFT + plot_w / 2.0, 18.0),
        title,
        Anchor::Middle,
        14.0,
        false,
    )];
    for d in (x0 as i32)..=(x1 as i32) {
        let x = sx(10f64.powi(d));
        marks.push(line((x, TOP), (x, TOP + plot_h), GRID, 1.0));
        let at = (x, TOP + plot_h + 16.0);
        marks.push(text(at, &format!("1e{d}"), Anchor::Middle, 12.0, false));
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let y = sy(10f64.powi(d));
        marks.push(line((LEFT, y), (LEFT + plot_w, y), GRID, 1.0));
        let at = (LEFT - 6.0, y + 4.0);
        marks.push(text(at, &format!("1e{d}"), Anchor::End, 12.0, false));
    }
    marks.push(Mark::Frame {
        x: LEFT,
        y: TOP,
        w: plot_w,
        h: plot_h,
    });
    let at = (LEFT + plot_w / 2.0, HEIGHT - 20.0);
    marks.push(text(at, x_label, Anchor::Middle, 12.0, false));
    let at = (20.0, TOP + plot_h / 2.0);
    marks.push(text(at, y_label, Anchor::Middle, 12.0, true));
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        marks.push(Mark::Polyline {
            points: s
                .points
                .iter()
                .filter(|p| finite(p))
                .map(|&(x, y)| (sx(x), sy(y)))
                .collect(),
            colour,
        });
        let ly = TOP + 10.0 + 18.0 * i as f64;
        let lx = LEFT + plot_w + 12.0;
        marks.push(line((lx, ly), (lx + 20.0, ly), colour, 2.0));
        let at = (lx + 26.0, ly + 4.0);
        marks.push(text(at, &s.name, Anchor::Start, 12.0, false));
    }
    marks
}

/// A log-log plot of `series` as SVG.
pub fn log_log_svg(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> String {
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for mark in log_log(title, x_label, y_label, series) {
        let _ = match mark {
            Mark::Frame { x, y, w, h } => writeln!(
                svg,
                r#"<rect x="{x}" y="{y}" width="{w}" height="{h}" fill="none" stroke="black"/>"#
            ),
            Mark::Line {
                from,
                to,
                colour,
                width,
            } => writeln!(
                svg,
                r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{colour}" stroke-width="{width}"/>"#,
                from.0, from.1, to.0, to.1
            ),
            Mark::Polyline { points, colour } => {
                let points: Vec<String> = points
                    .iter()
                    .map(|(x, y)| format!("{x:.1},{y:.1}"))
                    .collect();
                writeln!(
                    svg,
                    r#"<polyline fill="none" stroke="{colour}" stroke-width="2" points="{}"/>"#,
                    points.join(" ")
                )
            }
            Mark::Text {
                at: (x, y),
                text,
                anchor,
                size,
                vertical,
            } => {
                let anchor = match anchor {
                    Anchor::Start => "start",
                    Anchor::Middle => "middle",
                    Anchor::End => "end",
                };
                let place = if vertical {
                    format!(r#"transform="translate({x:.1} {y:.1}) rotate(-90)""#)
                } else {
                    format!(r#"x="{x:.1}" y="{y:.1}""#)
                };
                writeln!(
                    svg,
                    r#"<text {place} text-anchor="{anchor}" font-size="{size}">{}</text>"#,
                    escape(&text)
                )
            }
        };
    }
    svg.push_str("</svg>\n");
    svg
}

/// The same plot as [`log_log_svg`], as a PNG at twice its size.
pub fn log_log_png(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<Vec<u8>> {
    let mut canvas = Canvas::new((WIDTH * PNG_SCALE) as usize, (HEIGHT * PNG_SCALE) as usize);
    let s = PNG_SCALE;
    for mark in log_log(title, x_label, y_label, series) {
        match mark {
            Mark::Frame { x, y, w, h } => {
                let corners = [(x, y), (x + w, y), (x + w, y + h), (x, y + h), (x, y)];
                for pair in corners.windows(2) {
                    canvas.line(scaled(pair[0]), scaled(pair[1]), rgb(BLACK), s);
                }
            }
            Mark::Line {
                from,
                to,
                colour,
                width,
            } => canvas.line(scaled(from), scaled(to), rgb(colour), width * s),
            Mark::Polyline { points, colour } => {
                for pair in points.windows(2) {
                    canvas.line(scaled(pair[0]), scaled(pair[1]), rgb(colour), 2.0 * s);
                }
            }
            Mark::Text {
                at,
                text,
                anchor,
                size,
                vertical,
            } => canvas.text(scaled(at), &text, anchor, size * s, vertical),
        }
    }
    canvas.png()
}

fn scaled((x, y): (f64, f64)) -> (f64, f64) {
    (x * PNG_SCALE, y * PNG_SCALE)
}

/// `#rrggbb` as bytes (the colours above are all of that form).
fn rgb(hex: &str) -> [u8; 3] {
    let channel = |i: usize| u8::from_str_radix(&hex[1 + 2 * i..3 + 2 * i], 16).unwrap_or(0);
    [channel(0), channel(1), channel(2)]
}

/// An RGB raster, white to begin with.
struct Canvas {
    width: usize,
    height: usize,
    pixels: Vec<[u8; 3]>,
}

impl Canvas {
    fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            pixels: vec![[255; 3]; width * height],
        }
    }

    /// Fills the pixels of the square of side `side` centred at `(x, y)` (clipped to the canvas).
    fn square(&mut self, (x, y): (f64, f64), side: f64, colour: [u8; 3]) {
        let half = 0.5 * side.max(1.0);
        let span = |c: f64, n: usize| {
            let lo = (c - half).round().max(0.0) as usize;
            let hi = ((c + half).round().max(0.0) as usize).min(n);
            lo..hi.max(lo)
        };
        for py in span(y, self.height) {
            for px in span(x, self.width) {
                self.pixels[py * self.width + px] = colour;
            }
        }
    }

    /// A line `width` pixels wide: squares stamped every half pixel along it.
    fn line(&mut self, from: (f64, f64), to: (f64, f64), colour: [u8; 3], width: f64) {
        let length = (to.0 - from.0).hypot(to.1 - from.1);
        let steps = (2.0 * length).ceil().max(1.0) as usize;
        for i in 0..=steps {
            let t = i as f64 / steps as f64;
            let p = (from.0 + (to.0 - from.0) * t, from.1 + (to.1 - from.1) * t);
            self.square(p, width, colour);
        }
    }

    /// `text` in the 8x8 font, its baseline at `at`, scaled by a whole factor so that a glyph's
    /// advance (8 font pixels) is about 2/3 of `size`, the width of a sans-serif character.
    fn text(&mut self, at: (f64, f64), text: &str, anchor: Anchor, size: f64, vertical: bool) {
        let k = (size / 12.0).round().max(1.0);
        let advance = 8.0 * k;
        let length = advance * text.chars().count() as f64;
        let start = match anchor {
            Anchor::Start => 0.0,
            Anchor::Middle => -0.5 * length,
            Anchor::End => -length,
        };
        // Glyph rows 0-6 stand on the baseline; row 7 holds descenders.
        let top = -7.0 * k;
        for (i, c) in text.chars().enumerate() {
            let glyph = BASIC_LEGACY[if c.is_ascii() {
                c as usize
            } else {
                b'?' as usize
            }];
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits >> col & 1 == 0 {
                        continue;
                    }
                    // Along the text and down from the baseline, in pixels.
                    let u = start + advance * i as f64 + k * col as f64 + 0.5 * k;
                    let v = top + k * row as f64 + 0.5 * k;
                    let p = if vertical {
                        (at.0 + v, at.1 - u)
                    } else {
                        (at.0 + u, at.1 + v)
                    };
                    self.square(p, k, [0; 3]);
                }
            }
        }
    }

    fn png(&self) -> Result<Vec<u8>> {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, self.width as u32, self.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        encoder
            .write_header()
            .and_then(|mut writer| writer.write_image_data(&data))
            .context("encoding a plot as PNG")?;
        Ok(bytes)
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series() -> Vec<Series> {
        vec![Series {
            name: "rr_depth=5".to_owned(),
            points: vec![(0.1, 1.0), (1.0, 0.3), (10.0, 0.1)],
        }]
    }

    /// The PNG decodes to the SVG's size times two, with the curve's colour on it and black text
    /// in the title's row.
    #[test]
    fn png_draws_curves_and_text() {
        let bytes = log_log_png("title", "time", "RMSE", &series()).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut data = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut data).unwrap();
        assert_eq!((info.width, info.height), (1440, 960));
        let pixels: Vec<&[u8]> = data.chunks_exact(3).collect();
        assert!(pixels.iter().any(|p| *p == rgb(COLOURS[0])));
        let title_rows = &pixels[20 * 1440..36 * 1440];
        assert!(title_rows.iter().any(|p| *p == [0, 0, 0]));
    }

    #[test]
    fn svg_and_png_share_one_layout() {
        let marks = log_log("t", "x", "y", &series());
        let texts = marks
            .iter()
            .filter(|m| matches!(m, Mark::Text { .. }))
            .count();
        let svg = log_log_svg("t", "x", "y", &series());
        assert_eq!(svg.matches("<text").count(), texts);
        assert_eq!(svg.matches("<polyline").count(), 1);
    }
}
