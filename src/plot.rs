//! SVG charts. plotters draws each panel's frame (grid, ticks, axis labels); the title,
//! the curves and the legend are written here as SVG elements, so that
//! - the legend sits in a column of its own beside the plot and never covers data;
//! - a title too long for one line wraps instead of being clipped;
//! - a pair has the same colour on every chart ([`pair_names`]), and curves that share
//!   a colour differ in dash and every curve in marker shape, so that curves lying on
//!   one another (errors at a solver's floor) stay distinguishable;
//! - every curve is a `<g class="series" data-name="…">` holding a `<polyline
//!   class="data">` of its points in pixels, inside a `<g class="panel">` whose
//!   `data-box`, `data-x` and `data-y` give the axes' mapping, so that a reader (and the
//!   report's test) can take the numbers back off the drawing.
//!
//! Each chart `<stem>.svg` is written with its data `<stem>.chart.csv` beside it (columns
//! `panel,series,x,y`: every point drawn), each through a temporary file renamed into
//! place, so that a failed run never leaves a chart that looks complete.

use fem_models::geometry::Fields;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A named curve.
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points.
    pub points: Vec<(f64, f64)>,
    /// Draw markers at the points as well as the line.
    pub markers: bool,
    /// Draw large triangles at the points and no line (a point singled out on
    /// the curves, such as a choice made), in the colour of the series with this index.
    pub highlight: Option<usize>,
    /// Draw a line through the points.
    pub line: bool,
}

impl Series {
    /// A curve drawn as a line.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers: false,
            highlight: None,
            line: true,
        }
    }

    /// A curve drawn as a line with markers.
    pub fn marked(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers: true,
            highlight: None,
            line: true,
        }
    }

    /// Points without a line (runs that failed, drawn where the chart says).
    pub fn points(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers: true,
            highlight: None,
            line: false,
        }
    }

    /// Points singled out: large triangles, no line, in the colour of the
    /// series with index `like` (the curve they sit on).
    pub fn highlighted(name: impl Into<String>, points: Vec<(f64, f64)>, like: usize) -> Self {
        Self {
            name: name.into(),
            points,
            markers: false,
            highlight: Some(like),
            line: false,
        }
    }
}

/// Axis options of a chart.
#[derive(Clone, Copy, Debug, Default)]
pub struct Axes<'a> {
    /// x label
    pub x: &'a str,
    /// y label
    pub y: &'a str,
    /// logarithmic x
    pub log_x: bool,
    /// logarithmic y
    pub log_y: bool,
    /// Rate triangles under each curve's finest segment (log–log convergence charts).
    pub rates: bool,
}

type DrawResult<T> = Result<T, Box<dyn std::error::Error>>;

/// Width of every chart in pixels: the plot and, on its right, the legend's column.
pub const WIDTH: u32 = 1000;
const LEGEND_WIDTH: u32 = 280;
const TITLE_FONT: f64 = 17.0;
const LEGEND_FONT: f64 = 13.0;

// sixteen colours: one for each pair of every family (so that a pair keeps its colour
// across charts), the rest for curves that are not a pair's
const COLORS: [RGBColor; 16] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(80, 80, 80),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 128),
    RGBColor(128, 0, 0),
    RGBColor(0, 100, 0),
    RGBColor(184, 134, 11),
    RGBColor(75, 0, 130),
    RGBColor(0, 128, 128),
];

// curves of one colour differ in dash
const DASHES: [&str; 4] = ["", "7 4", "2 3", "9 3 2 3"];

/// The marker shapes, one per curve of a chart in turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Marker {
    Circle,
    Square,
    Diamond,
    TriangleUp,
    TriangleDown,
}

const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::Diamond,
    Marker::TriangleUp,
    Marker::TriangleDown,
];

/// How one curve is drawn.
#[derive(Clone, Copy, Debug)]
struct Style {
    color: RGBColor,
    dash: &'static str,
    marker: Marker,
    /// Markers at the points.
    markers: bool,
    /// A line through the points.
    line: bool,
    /// Marker radius in pixels.
    size: f64,
}

/// Every pair name of every family, in the registry's order: a pair's index here is its
/// colour on every chart.
pub fn pair_names() -> &'static [&'static str] {
    static NAMES: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    NAMES.get_or_init(|| {
        let mut names: Vec<&'static str> = Vec::new();
        for family in fem_models::families::families() {
            for pair in family.pairs() {
                if !names.contains(&pair.name) {
                    names.push(pair.name);
                }
            }
        }
        names
    })
}

/// The pair a curve's legend names: its first word (split at spaces, `:`, `,` and
/// brackets) that is a pair's name.
fn pair_of(name: &str) -> Option<usize> {
    name.split(|c: char| c.is_whitespace() || ":,()[]".contains(c))
        .find_map(|word| pair_names().iter().position(|p| *p == word))
}

/// The styles of a chart's curves: a pair's own colour, other curves the colours no
/// pair of the chart has, in turn; a curve that shares its colour with earlier ones gets
/// the next dash; markers cycle through the shapes.
fn styles(series: &[Series]) -> Vec<Style> {
    let pairs: Vec<Option<usize>> = series.iter().map(|s| pair_of(&s.name)).collect();
    let taken: Vec<usize> = pairs.iter().flatten().map(|p| p % COLORS.len()).collect();
    let mut free = (0..COLORS.len()).filter(|c| !taken.contains(c)).cycle();
    let mut colors: Vec<usize> = Vec::with_capacity(series.len());
    for (s, pair) in series.iter().zip(&pairs) {
        let color = match (s.highlight, pair) {
            (Some(like), _) => colors.get(like).copied().unwrap_or(0),
            (None, Some(p)) => p % COLORS.len(),
            (None, None) => free.next().unwrap_or(0),
        };
        colors.push(color);
    }
    series
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let same = (0..k)
                .filter(|&j| colors[j] == colors[k] && series[j].highlight.is_none())
                .count();
            let highlight = s.highlight.is_some();
            Style {
                color: COLORS[colors[k]],
                dash: DASHES[same % DASHES.len()],
                marker: if highlight {
                    Marker::TriangleUp
                } else {
                    MARKERS[k % MARKERS.len()]
                },
                markers: s.markers || highlight,
                line: s.line && !highlight,
                size: if highlight { 9.0 } else { 3.5 },
            }
        })
        .collect()
}

/// A short axis label with four significant digits, trailing zeros dropped: plain for
/// moderate magnitudes (`0.0125`, `250`), `1.5e-5` style otherwise. Neighbouring ticks
/// stay distinct: one significant digit made 1.5e-3 and 2e-3 both `2e-3`, and three
/// decimals made 0.0125 `0.013` (loads below 0.1 had repeated labels).
fn tick(v: f64) -> String {
    let trim = |text: &str| -> String {
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text.to_string()
        }
    };
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if (1e-2..1e4).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        trim(&format!("{v:.decimals$}"))
    } else {
        let text = format!("{v:.3e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        format!("{}e{exponent}", trim(mantissa))
    }
}

/// [`tick`] on a linear axis spanning `span`: a tick within rounding of zero (the
/// `-2.22e-16` an axis through zero computes) is `0`.
fn linear_tick(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span.abs() {
        "0".into()
    } else {
        tick(v)
    }
}

/// The ticks of a logarithmic axis from `lo` to `hi`: powers of ten (every second or
/// third where there are many decades), with 2 and 5 times them within two decades and
/// every digit within one, so that an axis shows at least two labels a reader can place.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let decades = (hi / lo).log10();
    let mantissas: &[f64] = if decades > 2.5 {
        &[1.0]
    } else if decades > 1.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    };
    let step = (decades / 8.0).ceil().max(1.0) as i32;
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mut ticks = Vec::new();
    for e in first..=last {
        if mantissas.len() == 1 && e.rem_euclid(step) != 0 {
            continue;
        }
        for m in mantissas {
            let v = m * 10f64.powi(e);
            if v >= lo && v <= hi {
                ticks.push(v);
            }
        }
    }
    ticks
}

/// Grid lines and labels of a logarithmic axis, drawn here because plotters labels only
/// some decades (an axis within one decade had one label, or none).
fn log_axis(svg: &mut String, scale: Scale, horizontal: bool, plot_box: [f64; 4]) {
    let [left, top, right, bottom] = plot_box;
    let along = |v: f64| {
        let f = scale.fraction(v);
        if horizontal {
            left + f * (right - left)
        } else {
            bottom - f * (bottom - top)
        }
    };
    // labels no closer than a label's extent: powers of ten first, then the others
    // where they fit
    let gap = if horizontal { 44.0 } else { 20.0 };
    let ticks = log_ticks(scale.lo, scale.hi);
    let decade = |v: f64| (v.log10() - v.log10().round()).abs() < 1e-9;
    let mut labelled: Vec<f64> = Vec::new();
    for pass in [true, false] {
        for &v in ticks.iter().filter(|&&v| decade(v) == pass) {
            if labelled.iter().all(|&u| (along(u) - along(v)).abs() >= gap) {
                labelled.push(v);
            }
        }
    }
    for v in ticks {
        let f = scale.fraction(v);
        let label = if labelled.contains(&v) {
            escape(&tick(v))
        } else {
            String::new()
        };
        let _ = if horizontal {
            let x = left + f * (right - left);
            writeln!(
                svg,
                r#"<line class="grid" x1="{x:.2}" y1="{top}" x2="{x:.2}" y2="{bottom}" stroke="black" stroke-opacity="0.12"/><line x1="{x:.2}" y1="{bottom}" x2="{x:.2}" y2="{:.1}" stroke="black"/><text x="{x:.2}" y="{:.1}" text-anchor="middle" font-family="sans-serif" font-size="14" fill="black">{label}</text>"#,
                bottom + 5.0,
                bottom + 20.0
            )
        } else {
            let y = bottom - f * (bottom - top);
            writeln!(
                svg,
                r#"<line class="grid" x1="{left}" y1="{y:.2}" x2="{right}" y2="{y:.2}" stroke="black" stroke-opacity="0.12"/><line x1="{:.1}" y1="{y:.2}" x2="{left}" y2="{y:.2}" stroke="black"/><text x="{:.1}" y="{y:.2}" dy="0.35em" text-anchor="end" font-family="sans-serif" font-size="14" fill="black">{label}</text>"#,
                left - 5.0,
                left - 8.0
            )
        };
    }
}

/// A rate triangle under a curve on log–log axes: legs in the ratio of the slope of its
/// segment at the accurate end (the two points of smallest y's end), labelled with that
/// slope (the observed rate), in the curve's colour.
fn rate_triangle(
    svg: &mut String,
    points: &[(f64, f64)],
    color: &str,
    to_pixel: &dyn Fn((f64, f64)) -> (f64, f64),
) {
    let mut sorted: Vec<(f64, f64)> = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    // the segment at the accurate end: small h, or many unknowns
    if sorted.len() >= 2 && sorted[sorted.len() - 1].1 < sorted[0].1 {
        sorted.reverse();
    }
    let [(xf, yf), (xn, yn), ..] = sorted[..] else {
        return;
    };
    let ((x1, y1), (x2, y2)) = if xf < xn {
        ((xf, yf), (xn, yn))
    } else {
        ((xn, yn), (xf, yf))
    };
    if x2 <= x1 || y1 <= 0.0 || y2 <= 0.0 {
        return;
    }
    let slope = (y2 / y1).ln() / (x2 / x1).ln();
    if !slope.is_finite() {
        return;
    }
    // a third of the segment's length in log x, set off below the curve
    let xa = x1 * (x2 / x1).powf(0.35);
    let xb = x1 * (x2 / x1).powf(0.7);
    let ya = y1 * (xa / x1).powf(slope);
    let yb = ya * (xb / xa).powf(slope);
    let (pa, pb) = (to_pixel((xa, ya)), to_pixel((xb, yb)));
    let offset = 14.0;
    let (ax, ay) = (pa.0, pa.1 + offset);
    let (bx, by) = (pb.0, pb.1 + offset);
    let (cx, cy) = if slope >= 0.0 { (bx, ay) } else { (ax, by) };
    let _ = writeln!(
        svg,
        r#"<g class="rate"><polygon points="{ax:.2},{ay:.2} {bx:.2},{by:.2} {cx:.2},{cy:.2}" fill="none" stroke="{color}" stroke-width="1.2"/><text x="{:.2}" y="{:.2}" dy="0.35em" font-family="sans-serif" font-size="13" fill="{color}">{slope:.2}</text></g>"#,
        bx.max(ax) + 4.0,
        0.5 * (ay + by)
    );
}

fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        // within the normal doubles: a log axis up to infinity has no end to its ticks
        ((lo / 1.5).max(1e-300), (hi * 1.5).min(1e300))
    } else if hi - lo <= 1e-12 * lo.abs().max(hi.abs()) {
        // one value: a tenth of it either side (±1 made 0.0039 look like 0)
        let pad = if hi == 0.0 { 1.0 } else { 0.1 * hi.abs() };
        (lo - pad, hi + pad)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

/// One axis of a panel: its range and whether it is logarithmic.
#[derive(Clone, Copy, Debug)]
struct Scale {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Scale {
    /// Where `v` lies between the ends, 0 at `lo` and 1 at `hi`.
    fn fraction(self, v: f64) -> f64 {
        if self.log {
            (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    /// Whether `v` can be drawn on this axis.
    fn drawable(self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0)
    }
}

/// `text` with the characters XML reserves escaped.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `text` broken at spaces into lines of at most `width` characters (a longer word
/// stands alone).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// Characters of a sans-serif font of `size` pixels that fit in `pixels` (the average
/// advance of such a font is about 0.55 of its size).
fn characters_in(pixels: f64, size: f64) -> usize {
    ((pixels / (0.55 * size)).floor() as usize).max(8)
}

/// A marker of `style` at (x, y), in pixels.
fn marker(out: &mut String, style: &Style, x: f64, y: f64) {
    let r = style.size;
    let fill = color_hex(style.color);
    let _ = match style.marker {
        Marker::Circle => writeln!(
            out,
            r#"<circle class="marker" cx="{x:.3}" cy="{y:.3}" r="{r}" fill="{fill}"/>"#
        ),
        Marker::Square => writeln!(
            out,
            r#"<rect class="marker" x="{:.3}" y="{:.3}" width="{:.3}" height="{:.3}" fill="{fill}"/>"#,
            x - 0.9 * r,
            y - 0.9 * r,
            1.8 * r,
            1.8 * r
        ),
        Marker::Diamond => writeln!(
            out,
            r#"<polygon class="marker" points="{:.3},{:.3} {:.3},{:.3} {:.3},{:.3} {:.3},{:.3}" fill="{fill}"/>"#,
            x,
            y - 1.2 * r,
            x + 1.2 * r,
            y,
            x,
            y + 1.2 * r,
            x - 1.2 * r,
            y
        ),
        Marker::TriangleUp | Marker::TriangleDown => {
            let s = if style.marker == Marker::TriangleUp {
                1.0
            } else {
                -1.0
            };
            writeln!(
                out,
                r#"<polygon class="marker" points="{:.3},{:.3} {:.3},{:.3} {:.3},{:.3}" fill="{fill}"/>"#,
                x,
                y - s * 1.2 * r,
                x + 1.1 * r,
                y + s * 0.7 * r,
                x - 1.1 * r,
                y + s * 0.7 * r
            )
        }
    };
}

fn color_hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// One panel as drawn: its title, the points of each curve that could be drawn, and the
/// SVG of its title, curves and legend.
struct Panel {
    /// The points drawn, by curve name.
    drawn: Vec<(String, Vec<(f64, f64)>)>,
    /// The SVG elements written here (title, curves, legend).
    svg: String,
}

/// Draws one panel into `area`: plotters' frame, then the title (wrapped to the
/// panel's width), the curves in the plot's box and the legend in a column beside it.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    axes: Axes,
    series: &[Series],
) -> DrawResult<Panel>
where
    DB::ErrorType: 'static,
{
    let (x0, x1) = range(
        series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
        axes.log_x,
    );
    let (y0, y1) = range(
        series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
        axes.log_y,
    );
    let (xs, ys) = (
        Scale {
            lo: x0,
            hi: x1,
            log: axes.log_x,
        },
        Scale {
            lo: y0,
            hi: y1,
            log: axes.log_y,
        },
    );
    let (left, top) = area.get_base_pixel();
    let (width, _) = area.dim_in_pixel();
    let title_lines = wrap(title, characters_in(f64::from(width) - 24.0, TITLE_FONT));
    let title_height = 10 + 21 * title_lines.len() as u32;
    let (plot_area, _) = area.split_horizontally(width.saturating_sub(LEGEND_WIDTH));
    let plot_area = plot_area.margin(title_height, 4, 4, 8);
    let mut builder = ChartBuilder::on(&plot_area);
    builder.x_label_area_size(44).y_label_area_size(78);
    let (x_span, y_span) = (x1 - x0, y1 - y0);
    let x_ticks = move |v: &f64| {
        if axes.log_x {
            String::new()
        } else {
            linear_tick(*v, x_span)
        }
    };
    let y_ticks = move |v: &f64| {
        if axes.log_y {
            String::new()
        } else {
            linear_tick(*v, y_span)
        }
    };
    macro_rules! frame {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            mesh.x_desc(axes.x)
                .y_desc(axes.y)
                .label_style(("sans-serif", 14))
                .axis_desc_style(("sans-serif", 16))
                .x_label_formatter(&x_ticks)
                .y_label_formatter(&y_ticks);
            // a log axis's grid and labels are drawn below (log_axis)
            if axes.log_x {
                mesh.disable_x_mesh()
                    .set_tick_mark_size(LabelAreaPosition::Bottom, 0);
            }
            if axes.log_y {
                mesh.disable_y_mesh()
                    .set_tick_mark_size(LabelAreaPosition::Left, 0);
            }
            mesh.draw()?;
            chart.plotting_area().get_pixel_range()
        }};
    }
    let (px, py) = match (axes.log_x, axes.log_y) {
        (false, false) => frame!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
        (true, false) => frame!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
        (false, true) => frame!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
        (true, true) => {
            frame!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
        }
    };
    let (bl, br) = (f64::from(px.start), f64::from(px.end));
    let (bt, bb) = (f64::from(py.start), f64::from(py.end));
    let to_pixel = |(x, y): (f64, f64)| {
        (
            bl + xs.fraction(x) * (br - bl),
            bb - ys.fraction(y) * (bb - bt),
        )
    };

    let mut svg = String::new();
    let centre = f64::from(left) + f64::from(width) / 2.0;
    for (k, line) in title_lines.iter().enumerate() {
        let _ = writeln!(
            svg,
            r#"<text class="title" x="{centre:.1}" y="{:.1}" text-anchor="middle" font-family="sans-serif" font-size="{TITLE_FONT}" fill="black">{}</text>"#,
            f64::from(top) + 24.0 + 21.0 * k as f64,
            escape(line)
        );
    }
    if axes.log_x {
        log_axis(&mut svg, xs, true, [bl, bt, br, bb]);
    }
    if axes.log_y {
        log_axis(&mut svg, ys, false, [bl, bt, br, bb]);
    }
    let styles = styles(series);
    let _ = writeln!(
        svg,
        r#"<g class="panel" data-title="{}" data-box="{bl} {bt} {br} {bb}" data-x="{x0:e} {x1:e} {}" data-y="{y0:e} {y1:e} {}">"#,
        escape(title),
        if axes.log_x { "log" } else { "linear" },
        if axes.log_y { "log" } else { "linear" },
    );
    let mut drawn = Vec::with_capacity(series.len());
    let mut hidden = Vec::with_capacity(series.len());
    for (s, style) in series.iter().zip(&styles) {
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| xs.drawable(p.0) && ys.drawable(p.1))
            .collect();
        hidden.push(s.points.len() - points.len());
        let pixels: Vec<(f64, f64)> = points.iter().map(|&p| to_pixel(p)).collect();
        let color = color_hex(style.color);
        let _ = writeln!(svg, r#"<g class="series" data-name="{}">"#, escape(&s.name));
        let list = pixels.iter().fold(String::new(), |mut text, (x, y)| {
            let _ = write!(text, "{x:.3},{y:.3} ");
            text
        });
        let (stroke, dash) = if style.line {
            (color.as_str(), style.dash)
        } else {
            ("none", "")
        };
        let dash = if dash.is_empty() {
            String::new()
        } else {
            format!(r#" stroke-dasharray="{dash}""#)
        };
        let _ = writeln!(
            svg,
            r#"<polyline class="data" fill="none" stroke="{stroke}" stroke-width="2"{dash} points="{}"/>"#,
            list.trim_end()
        );
        if style.markers {
            for &(x, y) in &pixels {
                marker(&mut svg, style, x, y);
            }
        }
        svg.push_str("</g>\n");
        if axes.rates && axes.log_x && axes.log_y && style.line {
            rate_triangle(&mut svg, &points, &color, &to_pixel);
        }
        drawn.push((s.name.clone(), pixels, points));
    }
    svg.push_str("</g>\n");
    let covered = coinciding(&drawn);
    let drawn: Vec<(String, Vec<(f64, f64)>)> = drawn
        .into_iter()
        .map(|(name, _, points)| (name, points))
        .collect();

    // the legend, in its own column
    let legend_left = f64::from(left) + f64::from(width.saturating_sub(LEGEND_WIDTH)) + 6.0;
    let chars = characters_in(f64::from(LEGEND_WIDTH) - 48.0, LEGEND_FONT);
    let mut y = bt + 8.0;
    svg.push_str("<g class=\"legend\">\n");
    for (k, ((s, style), hidden)) in series.iter().zip(&styles).zip(&hidden).enumerate() {
        let mut text = s.name.clone();
        if *hidden > 0 {
            let why = if axes.log_x || axes.log_y {
                "not finite or ≤ 0 on a log axis"
            } else {
                "not finite"
            };
            let points = if *hidden == 1 { "point" } else { "points" };
            let _ = write!(text, " ({hidden} {points} {why}, not drawn)");
        }
        if let Some(under) = covered[k] {
            let _ = write!(text, " (on the same points as {})", series[under].name);
        }
        let lines = wrap(&text, chars);
        let color = color_hex(style.color);
        if style.line {
            let dash = if style.dash.is_empty() {
                String::new()
            } else {
                format!(r#" stroke-dasharray="{}""#, style.dash)
            };
            let _ = writeln!(
                svg,
                r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{color}" stroke-width="2"{dash}/>"#,
                legend_left,
                legend_left + 30.0
            );
        }
        if style.markers || style.line {
            let sample = Style {
                size: style.size.min(6.0),
                ..*style
            };
            marker(&mut svg, &sample, legend_left + 15.0, y);
        }
        for (k, line) in lines.iter().enumerate() {
            let _ = writeln!(
                svg,
                r#"<text x="{:.1}" y="{:.1}" dy="0.35em" font-family="sans-serif" font-size="{LEGEND_FONT}" fill="black">{}</text>"#,
                legend_left + 38.0,
                y + 16.0 * k as f64,
                escape(line)
            );
        }
        y += 16.0 * lines.len() as f64 + 6.0;
    }
    svg.push_str("</g>\n");
    Ok(Panel { drawn, svg })
}

/// For each curve, an earlier one it lies on (every point within two pixels of the
/// other's, point for point), which it hides: the legend says so.
#[allow(clippy::type_complexity)]
fn coinciding(drawn: &[(String, Vec<(f64, f64)>, Vec<(f64, f64)>)]) -> Vec<Option<usize>> {
    drawn
        .iter()
        .enumerate()
        .map(|(k, (_, pixels, _))| {
            (0..k).find(|&j| {
                let other = &drawn[j].1;
                !pixels.is_empty()
                    && other.len() == pixels.len()
                    && other
                        .iter()
                        .zip(pixels)
                        .all(|(a, b)| (a.0 - b.0).hypot(a.1 - b.1) <= 2.0)
            })
        })
        .collect()
}

/// Writes `text` to `path` through a temporary file renamed into place.
fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".partial");
    let tmp = path.with_file_name(name);
    let result = std::fs::write(&tmp, text);
    match result {
        Ok(()) => std::fs::rename(&tmp, path),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// The data file beside chart `path`: `<stem>.chart.csv`.
pub fn data_path(path: &Path) -> PathBuf {
    path.with_extension("chart.csv")
}

/// A CSV field: quoted where it holds a comma, a quote or a line break.
pub fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// Draws `panels` stacked in one file of height `panel_height` each, and writes the
/// points drawn beside it ([`data_path`]).
fn write_panels(
    path: &Path,
    panel_height: u32,
    panels: &[(&str, Axes, &[Series])],
) -> std::io::Result<()> {
    let to_io = |e: Box<dyn std::error::Error>| std::io::Error::other(e.to_string());
    // tall enough for the longest legend (drawn from the plot's top, 16 px a line)
    let chars = characters_in(f64::from(LEGEND_WIDTH) - 48.0, LEGEND_FONT);
    let legend = panels
        .iter()
        .map(|(title, _, series)| {
            let lines: usize = series
                .iter()
                .map(|s| {
                    wrap(
                        &format!("{} (on the same points as {})", s.name, s.name),
                        chars,
                    )
                    .len()
                })
                .sum();
            let title_lines = wrap(title, characters_in(f64::from(WIDTH) - 24.0, TITLE_FONT)).len();
            (16 * lines + 6 * series.len() + 21 * title_lines + 40) as u32
        })
        .max()
        .unwrap_or(0);
    let panel_height = panel_height.max(legend);
    let height = panel_height * panels.len().max(1) as u32;
    let mut frame = String::new();
    let mut drawn = Vec::with_capacity(panels.len());
    {
        let root = SVGBackend::with_string(&mut frame, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| to_io(e.into()))?;
        let areas = root.split_evenly((panels.len().max(1), 1));
        for (area, (title, axes, series)) in areas.iter().zip(panels) {
            drawn.push(draw_panel(area, title, *axes, series).map_err(to_io)?);
        }
        root.present().map_err(|e| to_io(e.into()))?;
    }
    let end = frame.rfind("</svg>").unwrap_or(frame.len());
    let mut svg = frame[..end].to_string();
    for panel in &drawn {
        svg.push_str(&panel.svg);
    }
    svg.push_str("</svg>\n");
    let mut csv = String::from("panel,series,x,y\n");
    for (k, panel) in drawn.iter().enumerate() {
        for (name, points) in &panel.drawn {
            for (x, y) in points {
                let _ = writeln!(csv, "{},{},{x:e},{y:e}", k + 1, csv_field(name));
            }
        }
    }
    write_atomically(&data_path(path), &csv)?;
    write_atomically(path, &svg)
}

/// One chart with several curves.
pub fn chart(path: &Path, title: &str, axes: Axes, series: &[Series]) -> std::io::Result<()> {
    write_panels(path, 620, &[(title, axes, series)])
}

/// Several charts stacked in one file.
pub fn stacked(path: &Path, panels: &[(String, Axes, Vec<Series>)]) -> std::io::Result<()> {
    let panels: Vec<(&str, Axes, &[Series])> = panels
        .iter()
        .map(|(title, axes, series)| (title.as_str(), *axes, series.as_slice()))
        .collect();
    write_panels(path, 360, &panels)
}

/// The primal fields with ψ, and λ, of a scene solved on an interval (w with ψ, θ of a
/// Timoshenko beam, λ_h as steps); other fields draw nothing.
pub fn profiles(path: &Path, title: &str, fields: &Fields) -> std::io::Result<()> {
    let Fields::Interval {
        x,
        fields,
        psi,
        cell_x,
        lambda,
    } = fields
    else {
        return Ok(());
    };
    let zip = |y: &[f64]| x.iter().copied().zip(y.iter().copied()).collect::<Vec<_>>();
    let mut panels = Vec::new();
    for (k, (name, values)) in fields.iter().enumerate() {
        let mut series = vec![Series::line(format!("{name}_h"), zip(values))];
        // the constrained field comes first; ψ beside it
        if k == 0 {
            series.push(Series::line("obstacle ψ", zip(psi)));
        }
        panels.push((
            format!("{title}: {name}"),
            Axes {
                x: "x",
                y: name,
                ..Axes::default()
            },
            series,
        ));
    }
    // λ is piecewise constant: draw it as steps.
    let half = if cell_x.len() > 1 {
        0.5 * (cell_x[1] - cell_x[0])
    } else {
        0.5
    };
    let steps: Vec<(f64, f64)> = cell_x
        .iter()
        .zip(lambda)
        .flat_map(|(&c, &l)| [(c - half, l), (c + half, l)])
        .collect();
    panels.push((
        format!("{title}: contact multiplier"),
        Axes {
            x: "x",
            y: "λ",
            ..Axes::default()
        },
        vec![Series::line("λ_h (P0)", steps)],
    ));
    stacked(path, &panels)
}

/// A mesh as a picture: on triangles every cell's outline, the cells in contact (cell
/// field `contact` positive) shaded; on an interval the cell lengths against x (log
/// scale), the cells in contact (λ_h > 0) marked.
pub fn mesh(path: &Path, title: &str, fields: &Fields) -> std::io::Result<()> {
    match fields {
        Fields::Interval {
            cell_x, lambda, x, ..
        } => {
            let lengths: Vec<(f64, f64)> = cell_x
                .iter()
                .copied()
                .zip(cell_lengths(x, cell_x))
                .collect();
            let touching: Vec<(f64, f64)> = lengths
                .iter()
                .zip(lambda)
                .filter(|(_, &l)| l > 0.0)
                .map(|(p, _)| *p)
                .collect();
            chart(
                path,
                title,
                Axes {
                    x: "x",
                    y: "cell length h",
                    log_x: false,
                    log_y: true,
                    rates: false,
                },
                &[
                    Series::marked("cell length", lengths),
                    Series::marked("cells in contact (λ_h > 0)", touching),
                ],
            )
        }
        Fields::Triangles { mesh, cell, .. } => {
            let contact = cell.iter().find(|c| c.0 == "contact").map(|c| &c.1);
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for v in mesh.vertices() {
                for k in 0..2 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            let (w, h) = ((hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300));
            let title_lines = wrap(title, characters_in(836.0, 16.0));
            let title_height = 12 + 20 * title_lines.len() as u32;
            let height = (800.0 * h / w).clamp(200.0, 1200.0) as u32 + 40 + title_height;
            let mut svg = String::new();
            let drawn = (|| -> DrawResult<()> {
                let root = SVGBackend::with_string(&mut svg, (860, height)).into_drawing_area();
                root.fill(&WHITE)?;
                let mut chart = ChartBuilder::on(&root.margin(title_height, 12, 12, 12))
                    .x_label_area_size(30)
                    .y_label_area_size(50)
                    .build_cartesian_2d(lo[0]..hi[0], lo[1]..hi[1])?;
                chart
                    .configure_mesh()
                    .disable_mesh()
                    .x_desc("x")
                    .y_desc("y")
                    .x_label_formatter(&|v| tick(*v))
                    .y_label_formatter(&|v| tick(*v))
                    .draw()?;
                let shade = RGBColor(250, 170, 160);
                let grey = RGBColor(90, 90, 90);
                let corners = |c: usize| -> Vec<(f64, f64)> {
                    let x = mesh.cell_coordinates(c);
                    vec![(x[0], x[1]), (x[2], x[3]), (x[4], x[5])]
                };
                chart.draw_series(
                    (0..mesh.cell_count())
                        .filter(|&c| contact.is_some_and(|s| s[c] > 0.0))
                        .map(|c| Polygon::new(corners(c), shade.filled())),
                )?;
                chart.draw_series((0..mesh.cell_count()).map(|c| {
                    let mut outline = corners(c);
                    outline.push(outline[0]);
                    PathElement::new(outline, grey.stroke_width(1))
                }))?;
                root.present()?;
                Ok(())
            })();
            drawn.map_err(|e| std::io::Error::other(e.to_string()))?;
            let end = svg.rfind("</svg>").unwrap_or(svg.len());
            svg.truncate(end);
            for (k, line) in title_lines.iter().enumerate() {
                let _ = writeln!(
                    svg,
                    r#"<text class="title" x="430" y="{}" text-anchor="middle" font-family="sans-serif" font-size="16" fill="black">{}</text>"#,
                    24 + 20 * k,
                    escape(line)
                );
            }
            svg.push_str("</svg>\n");
            write_atomically(path, &svg)
        }
    }
}

/// The length of each cell of an interval mesh from its midpoints and the mesh's left
/// end `x[0]`: each cell's right end is its midpoint mirrored from its left end.
pub fn cell_lengths(x: &[f64], midpoints: &[f64]) -> Vec<f64> {
    let mut left = x.first().copied().unwrap_or(0.0);
    midpoints
        .iter()
        .map(|&m| {
            let length = 2.0 * (m - left);
            left += length;
            length
        })
        .collect()
}

#[cfg(test)]
mod tick_tests {
    use super::tick;

    /// Cells of lengths 0.5, 0.25, 0.25 on [1, 2] from their midpoints.
    #[test]
    fn cell_lengths_come_back_from_the_midpoints() {
        let lengths = super::cell_lengths(&[1.0, 2.0], &[1.25, 1.625, 1.875]);
        assert_eq!(lengths, vec![0.5, 0.25, 0.25]);
    }

    #[test]
    fn ticks_keep_four_significant_digits_and_stay_distinct() {
        for (v, text) in [
            (0.0, "0"),
            (1.0, "1"),
            (250.0, "250"),
            (0.0125, "0.0125"),
            (0.5, "0.5"),
            (1234.5, "1234"),
            (-3.25, "-3.25"),
            (1.5e-3, "1.5e-3"),
            (2e-3, "2e-3"),
            (1.25e5, "1.25e5"),
            (-7e-9, "-7e-9"),
        ] {
            assert_eq!(tick(v), text, "{v}");
        }
        let labels: Vec<String> = (1..=10).map(|k| tick(k as f64 * 5e-4)).collect();
        for pair in labels.windows(2) {
            assert_ne!(pair[0], pair[1]);
        }
    }

    #[test]
    fn a_tick_at_rounding_of_zero_is_zero() {
        assert_eq!(super::linear_tick(-2.220446049250313e-16, 2.0), "0");
        assert_eq!(super::linear_tick(0.25, 2.0), "0.25");
        // on an axis of tiny values the same magnitude is a real tick
        assert_eq!(super::linear_tick(-2.5e-16, 1e-15), "-2.5e-16");
    }

    #[test]
    fn log_axes_get_labels_a_reader_can_place() {
        // within one decade: the digits
        let ticks = super::log_ticks(0.06, 0.5);
        assert_eq!(ticks.first(), Some(&0.06));
        assert!(ticks.contains(&0.1) && ticks.contains(&0.5));
        // two decades: 1, 2, 5
        let ticks = super::log_ticks(1e-3, 0.1);
        for v in [1e-3, 2e-3, 5e-3, 0.01, 0.02, 0.05, 0.1] {
            assert!(ticks.iter().any(|t| (t / v - 1.0).abs() < 1e-12), "{v}");
        }
        // sixteen decades: every second power of ten, at most nine labels
        let ticks = super::log_ticks(1e-16, 1.0);
        assert!(ticks.len() <= 9 && ticks.len() >= 8, "{ticks:?}");
    }

    #[test]
    fn long_titles_wrap_at_spaces() {
        let lines = super::wrap("one two three four five", 9);
        assert_eq!(lines, vec!["one two", "three", "four five"]);
        assert_eq!(super::wrap("", 9), vec![""]);
    }

    /// A pair keeps its colour whatever else a chart holds, curves of one pair differ
    /// in dash, and a highlighted point takes the colour of the curve it marks.
    #[test]
    fn a_pair_has_one_colour_on_every_chart() {
        use super::{styles, Series};
        let line = |name: &str| Series::line(name, vec![(1.0, 1.0)]);
        let one = styles(&[line("p2-p0 L²"), line("exact λ"), line("p2-p0 H¹")]);
        let other = styles(&[
            line("p1-p0 L²"),
            line("uniform"),
            line("p2-p0 against seconds"),
        ]);
        assert_eq!(one[0].color, other[2].color);
        assert_ne!(one[0].color, other[0].color);
        assert_eq!(one[0].color, one[2].color);
        assert_ne!(one[0].dash, one[2].dash);
        // a curve that is no pair's takes a colour no pair of the chart has
        assert_ne!(one[1].color, one[0].color);
        let marked = styles(&[
            line("p1-p0 L²"),
            line("p2-p0 L²"),
            Series::highlighted("choice", vec![(1.0, 1.0)], 1),
        ]);
        assert_eq!(marked[2].color, marked[1].color);
        assert!(!marked[2].line && marked[2].markers);
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(super::csv_field("plain, α = 0"), "\"plain, α = 0\"");
        assert_eq!(super::csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(super::csv_field("p2-p0 L²"), "p2-p0 L²");
    }

    /// A chart's data file lists every point drawn, and a point a log axis cannot show
    /// is left out of both and counted in the legend.
    #[test]
    fn a_chart_writes_the_points_it_draws_beside_it() {
        let dir = std::env::temp_dir().join(format!("fem-forms-plot-{}", std::process::id()));
        let path = dir.join("c.svg");
        let axes = super::Axes {
            x: "h",
            y: "error",
            log_x: true,
            log_y: true,
            rates: true,
        };
        let series = [super::Series::marked(
            "p1-p0 L², with a comma",
            vec![
                (0.5, 0.25),
                (0.25, 0.0625),
                (0.125, 0.0),
                (0.0625, 0.00390625),
            ],
        )];
        super::chart(&path, "a chart", axes, &series).unwrap();
        let data = std::fs::read_to_string(super::data_path(&path)).unwrap();
        assert_eq!(
            data,
            "panel,series,x,y\n1,\"p1-p0 L², with a comma\",5e-1,2.5e-1\n1,\"p1-p0 L², with a comma\",2.5e-1,6.25e-2\n1,\"p1-p0 L², with a comma\",6.25e-2,3.90625e-3\n"
        );
        let svg = std::fs::read_to_string(&path).unwrap();
        // the legend's words, its lines joined
        let words: Vec<&str> = svg
            .split("</text>")
            .filter_map(|t| t.rsplit_once('>').map(|(_, w)| w.trim()))
            .collect();
        let words = words.join(" ");
        assert!(
            words.contains("(1 point not finite or ≤ 0 on a log axis, not drawn)"),
            "{words}"
        );
        // the rate triangle of the finest segment: slope 2 between h = 1/16 and 1/4
        assert!(svg.contains(">2.00</text>"), "no rate 2.00");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A single value spans a tenth of itself either side (not ±1, which drew 0.0039
    /// as 0), and failed runs drawn as points have no line through them.
    #[test]
    fn a_constant_curve_keeps_its_scale_and_points_stay_points() {
        assert_eq!(
            super::range([0.004, 0.004].into_iter(), false),
            (0.0036, 0.0044)
        );
        assert_eq!(super::range([0.0].into_iter(), false), (-1.0, 1.0));
        let styles = super::styles(&[super::Series::points("failed", vec![(1.0, 1.0)])]);
        assert!(!styles[0].line && styles[0].markers);
    }
}
