//! Plots as SVG text (plotters' SVG backend: text is SVG text in the
//! browser's sans-serif, no font files).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Line,
    Dashed,
    Points,
    /// Shaded vertical bands across the plot, each point one band's
    /// (x_lo, x_hi) (an interval on the x axis: a knee's 95 % band, a span
    /// outside a range); drawn behind the data, outlined so that a narrow
    /// band still shows.
    Bands,
}

pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Vertical error bars (lo, hi) per point, drawn with `Points`.
    pub errors: Option<Vec<(f64, f64)>>,
    pub style: Style,
    /// Index into the palette.
    pub color: usize,
}

impl Series {
    /// Vertical bands over the x intervals `spans` (lo, hi).
    pub fn bands(label: &str, spans: Vec<(f64, f64)>, color: usize) -> Self {
        Self {
            style: Style::Bands,
            ..Self::line(label, spans, color)
        }
    }

    pub fn line(label: &str, points: Vec<(f64, f64)>, color: usize) -> Self {
        Self {
            label: label.into(),
            points,
            errors: None,
            style: Style::Line,
            color,
        }
    }
    pub fn dashed(label: &str, points: Vec<(f64, f64)>, color: usize) -> Self {
        Self {
            style: Style::Dashed,
            ..Self::line(label, points, color)
        }
    }
    pub fn points(
        label: &str,
        points: Vec<(f64, f64)>,
        errors: Option<Vec<(f64, f64)>>,
        color: usize,
    ) -> Self {
        Self {
            errors,
            style: Style::Points,
            ..Self::line(label, points, color)
        }
    }
}

pub struct Axes {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
}

impl Axes {
    /// Linear axes; the labels carry their units ("time, h").
    pub fn linear(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
        }
    }
}

/// At most `max` of `points`, evenly thinned (every k-th).
pub fn thin(points: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    let step = points.len().div_ceil(max.max(1)).max(1);
    if step == 1 {
        return points;
    }
    points.into_iter().step_by(step).collect()
}

pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Data range of all series (error bars included), padded; positive only
/// on log axes.
pub(crate) fn range(series: &[Series], y: bool, log: bool) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut take = |v: f64| {
        if v.is_finite() && (!log || v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    };
    for s in series {
        if s.style == Style::Bands {
            // (lo, hi) on the x axis; nothing on the y axis.
            if !y {
                for &(a, b) in &s.points {
                    take(a);
                    take(b);
                }
            }
            continue;
        }
        for (i, &(x, yv)) in s.points.iter().enumerate() {
            take(if y { yv } else { x });
            if let (true, Some(e)) = (y, &s.errors) {
                if let Some(&(a, b)) = e.get(i) {
                    take(a);
                    take(b);
                }
            }
        }
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (-1.0, 1.0) };
    }
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        let pad = ((b - a) * 0.05).max(0.1);
        (10f64.powf(a - pad), 10f64.powf(b + pad))
    } else {
        let pad = ((hi - lo) * 0.05)
            .max(hi.abs().max(lo.abs()) * 1e-6)
            .max(1e-12);
        (lo - pad, hi + pad)
    }
}

/// Data points a plot draws (bands not counted): finite points of its
/// lines and point series.
pub fn data_points(series: &[Series]) -> usize {
    series
        .iter()
        .filter(|s| s.style != Style::Bands)
        .map(|s| {
            s.points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .count()
        })
        .sum()
}

/// A tick label: as many decimals as the axis's tick step needs (about a
/// tenth of `span`), no "-0"; on a log axis, significant digits.
fn tick(v: f64, span: f64, log: bool) -> String {
    if log {
        return if v != 0.0 && !(1e-3..1e5).contains(&v.abs()) {
            format!("{v:.0e}")
        } else {
            let d = (2 - v.abs().log10().floor() as i32).clamp(0, 4) as usize;
            let t = format!("{v:.d$}");
            if t.contains('.') {
                t.trim_end_matches('0').trim_end_matches('.').to_owned()
            } else {
                t
            }
        };
    }
    let step = (span / 10.0).abs();
    let d = if step > 0.0 && step.is_finite() {
        (-step.log10().floor()).clamp(0.0, 8.0) as usize
    } else {
        1
    };
    let t = format!("{v:.d$}");
    if t.trim_start_matches('-')
        .trim_matches(|c| c == '0' || c == '.')
        .is_empty()
    {
        format!("{:.d$}", 0.0)
    } else {
        t
    }
}

/// The corner of the plot where the legend covers the fewest data points
/// (upper right on a tie). `u` maps x to 0..1 across the plot, `v` y.
fn legend_corner(
    series: &[Series],
    u: impl Fn(f64) -> f64,
    v: impl Fn(f64) -> f64,
) -> (SeriesLabelPosition, usize, f64) {
    let longest = series.iter().map(|s| s.label.len()).max().unwrap_or(0) as f64;
    // The legend's size as a share of the plot (about 7 px a character,
    // 17 px a line on a 790 x 390 px plot).
    let w = ((longest * 7.0 + 45.0) / 790.0).min(0.9);
    let h = ((series.len() as f64 * 17.0 + 12.0) / 390.0).min(0.9);
    let corners = [
        (
            SeriesLabelPosition::UpperRight,
            (1.0 - w, 1.0),
            (1.0 - h, 1.0),
        ),
        (SeriesLabelPosition::UpperLeft, (0.0, w), (1.0 - h, 1.0)),
        (SeriesLabelPosition::LowerRight, (1.0 - w, 1.0), (0.0, h)),
        (SeriesLabelPosition::LowerLeft, (0.0, w), (0.0, h)),
    ];
    let mut best = (SeriesLabelPosition::UpperRight, usize::MAX);
    for (pos, (ua, ub), (va, vb)) in corners {
        let mut n = 0;
        for s in series.iter().filter(|s| s.style != Style::Bands) {
            for &(x, y) in &s.points {
                let (a, b) = (u(x), v(y));
                if a >= ua && a <= ub && b >= va && b <= vb {
                    n += 1;
                }
            }
        }
        if n < best.1 {
            best = (pos, n);
        }
    }
    (best.0, best.1, h)
}

/// Share of an axis from `a` to `b` at `x` (log: in log space).
fn share(x: f64, a: f64, b: f64, log: bool) -> f64 {
    if log {
        (x.max(1e-300).ln() - a.ln()) / (b.ln() - a.ln())
    } else {
        (x - a) / (b - a)
    }
}

/// The y range raised at the top by the legend's height when every corner
/// of the plot holds data, so that the legend covers none.
fn room_for_legend(series: &[Series], axes: &Axes, x: (f64, f64), y: (f64, f64)) -> (f64, f64) {
    let (_, n, h) = legend_corner(
        series,
        |v| share(v, x.0, x.1, axes.log_x),
        |v| share(v, y.0, y.1, axes.log_y),
    );
    if n == 0 {
        return y;
    }
    let grow = h / (1.0 - h).max(0.1) * 1.05;
    if axes.log_y {
        let (a, b) = (y.0.ln(), y.1.ln());
        (y.0, (b + (b - a) * grow).exp())
    } else {
        (y.0, y.1 + (y.1 - y.0) * grow)
    }
}

fn draw<X, Y>(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    axes: &Axes,
    (xs, ys): (X, Y),
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    series: &[Series],
) -> Result<(), DrawingAreaErrorKind<std::io::Error>>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut ch = ChartBuilder::on(root)
        .margin(12)
        .caption(&axes.title, ("sans-serif", 18))
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(xs, ys)?;
    let (lx, ly) = (axes.log_x, axes.log_y);
    let x_fmt = move |v: &f64| tick(*v, x1 - x0, lx);
    let y_fmt = move |v: &f64| tick(*v, y1 - y0, ly);
    ch.configure_mesh()
        .x_desc(axes.x_label.as_str())
        .y_desc(axes.y_label.as_str())
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 13))
        .draw()?;
    // Bands first, behind the data.
    for s in series.iter().filter(|s| s.style == Style::Bands) {
        let c = PALETTE[s.color % PALETTE.len()];
        let spans: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        ch.draw_series(
            spans
                .iter()
                .map(|&(a, b)| Rectangle::new([(a, y0), (b, y1)], c.mix(0.18).filled())),
        )?
        .label(s.label.as_str())
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], c.mix(0.4).filled()));
        ch.draw_series(
            spans
                .iter()
                .map(|&(a, b)| Rectangle::new([(a, y0), (b, y1)], c.mix(0.7).stroke_width(1))),
        )?;
    }
    for s in series.iter().filter(|s| s.style != Style::Bands) {
        let c = PALETTE[s.color % PALETTE.len()];
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let legend = |c: RGBColor| {
            move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
        };
        match s.style {
            Style::Line => {
                ch.draw_series(LineSeries::new(pts, c.stroke_width(2)))?
                    .label(s.label.as_str())
                    .legend(legend(c));
            }
            Style::Dashed => {
                ch.draw_series(DashedLineSeries::new(pts, 6, 4, c.stroke_width(2)))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        // Dashed in the legend too: two dashes.
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (7, 0)], c.stroke_width(2))
                            + PathElement::new(vec![(11, 0), (18, 0)], c.stroke_width(2))
                    });
            }
            Style::Bands => {}
            Style::Points => {
                if let Some(errs) = &s.errors {
                    ch.draw_series(
                        s.points
                            .iter()
                            .zip(errs)
                            .filter(|(p, _)| p.1.is_finite())
                            .map(|(&(x, y), &(lo, hi))| {
                                ErrorBar::new_vertical(x, lo, y, hi, c.stroke_width(1), 6)
                            }),
                    )?;
                }
                ch.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 9, y), 3, c.filled()));
            }
        }
    }
    let (corner, _, _) = legend_corner(series, |x| share(x, x0, x1, lx), |y| share(y, y0, y1, ly));
    ch.configure_series_labels()
        .position(corner)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()?;
    root.present()
}

/// One plot as an SVG element.
pub fn svg(axes: &Axes, series: &[Series]) -> String {
    let mut out = String::new();
    let result = {
        let root = SVGBackend::with_string(&mut out, (900, 480)).into_drawing_area();
        let _ = root.fill(&WHITE);
        let (x0, x1) = range(series, false, axes.log_x);
        let (y0, y1) = range(series, true, axes.log_y);
        let (y0, y1) = room_for_legend(series, axes, (x0, x1), (y0, y1));
        let yr = ((x0, x1), (y0, y1));
        match (axes.log_x, axes.log_y) {
            (true, true) => draw(
                &root,
                axes,
                ((x0..x1).log_scale(), (y0..y1).log_scale()),
                yr,
                series,
            ),
            (true, false) => draw(&root, axes, ((x0..x1).log_scale(), y0..y1), yr, series),
            (false, true) => draw(&root, axes, (x0..x1, (y0..y1).log_scale()), yr, series),
            (false, false) => draw(&root, axes, (x0..x1, y0..y1), yr, series),
        }
    };
    match result {
        Ok(()) => out,
        Err(e) => format!(
            "<p>(plot not drawn: {})</p>",
            super::text::esc(&e.to_string())
        ),
    }
}
