//! SVG charts (plotters). Each chart is drawn to a temporary file and renamed into
//! place, so a failed run never leaves a chart that looks complete.

use fem_models::geometry::Fields;
use plotters::prelude::*;
use std::path::Path;

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
}

impl Series {
    /// A curve drawn as a line.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers: false,
            highlight: None,
        }
    }

    /// A curve drawn as a line with markers.
    pub fn marked(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers: true,
            highlight: None,
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
}

type DrawResult<T> = Result<T, Box<dyn std::error::Error>>;

// ten colours before one repeats: a model choice's chart has up to eight curves
const COLORS: [RGBColor; 10] = [
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
];

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

fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if log {
        // within the normal doubles: a log axis up to infinity has no end to its ticks
        ((lo / 1.5).max(1e-300), (hi * 1.5).min(1e300))
    } else if hi - lo < 1e-300 {
        (lo - 1.0, hi + 1.0)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    axes: Axes,
    series: &[Series],
) -> DrawResult<()>
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
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(70);
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(axes.x)
                .y_desc(axes.y)
                .y_label_formatter(&|v| format!("{v:.3e}"))
                .x_label_formatter(&|v| tick(*v))
                .draw()?;
            for (k, s) in series.iter().enumerate() {
                let color = COLORS[k % COLORS.len()];
                let points: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|p| {
                        p.0.is_finite()
                            && p.1.is_finite()
                            && (!axes.log_x || p.0 > 0.0)
                            && (!axes.log_y || p.1 > 0.0)
                    })
                    .collect();
                if let Some(like) = s.highlight {
                    let color = COLORS[like % COLORS.len()];
                    let marker = move |p: (f64, f64)| {
                        EmptyElement::at(p) + TriangleMarker::new((0, 0), 9, color.filled())
                    };
                    chart
                        .draw_series(points.iter().map(|&p| marker(p)))?
                        .label(s.name.clone())
                        .legend(move |(x, y)| {
                            EmptyElement::at((x + 10, y))
                                + TriangleMarker::new((0, 0), 6, color.filled())
                        });
                    continue;
                }
                chart
                    .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                if s.markers {
                    chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }};
    }
    match (axes.log_x, axes.log_y) {
        (false, false) => finish!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
        (true, false) => finish!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
        (false, true) => finish!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
        (true, true) => {
            finish!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
        }
    }
    Ok(())
}

fn write_atomically(
    path: &Path,
    draw: impl FnOnce(&Path) -> DrawResult<()>,
) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let tmp = path.with_extension("svg.partial");
    let result = draw(&tmp).map_err(|e| std::io::Error::other(e.to_string()));
    match result {
        Ok(()) => std::fs::rename(&tmp, path),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// One chart with several curves.
pub fn chart(path: &Path, title: &str, axes: Axes, series: &[Series]) -> std::io::Result<()> {
    write_atomically(path, |tmp| {
        let root = SVGBackend::new(tmp, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        draw_panel(&root, title, axes, series)?;
        root.present()?;
        Ok(())
    })
}

/// Several charts stacked in one file.
pub fn stacked(path: &Path, panels: &[(String, Axes, Vec<Series>)]) -> std::io::Result<()> {
    write_atomically(path, |tmp| {
        let root = SVGBackend::new(tmp, (900, 330 * panels.len() as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        for (area, (title, axes, series)) in root.split_evenly((panels.len(), 1)).iter().zip(panels)
        {
            draw_panel(area, title, *axes, series)?;
        }
        root.present()?;
        Ok(())
    })
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
            let height = (800.0 * h / w).clamp(200.0, 1200.0) as u32 + 60;
            write_atomically(path, |tmp| {
                let root = SVGBackend::new(tmp, (860, height)).into_drawing_area();
                root.fill(&WHITE)?;
                let mut chart = ChartBuilder::on(&root)
                    .caption(title, ("sans-serif", 16))
                    .margin(12)
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
            })
        }
    }
}

/// The length of each cell of an interval mesh from its midpoints and the mesh's left
/// end `x[0]`: each cell's right end is its midpoint mirrored from its left end.
fn cell_lengths(x: &[f64], midpoints: &[f64]) -> Vec<f64> {
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
}
