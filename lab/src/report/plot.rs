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

const PALETTE: [RGBColor; 8] = [
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
fn range(series: &[Series], y: bool, log: bool) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut take = |v: f64| {
        if v.is_finite() && (!log || v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    };
    for s in series {
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

fn draw<X, Y>(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    axes: &Axes,
    xs: X,
    ys: Y,
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
    ch.configure_mesh()
        .x_desc(axes.x_label.as_str())
        .y_desc(axes.y_label.as_str())
        .label_style(("sans-serif", 13))
        .draw()?;
    for s in series {
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
                ch.draw_series(DashedLineSeries::new(pts, 6, 4, c.stroke_width(1)))?
                    .label(s.label.as_str())
                    .legend(legend(c));
            }
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
    ch.configure_series_labels()
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
        match (axes.log_x, axes.log_y) {
            (true, true) => draw(
                &root,
                axes,
                (x0..x1).log_scale(),
                (y0..y1).log_scale(),
                series,
            ),
            (true, false) => draw(&root, axes, (x0..x1).log_scale(), y0..y1, series),
            (false, true) => draw(&root, axes, x0..x1, (y0..y1).log_scale(), series),
            (false, false) => draw(&root, axes, x0..x1, y0..y1, series),
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
