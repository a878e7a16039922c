//! Plots whose legend never covers data (it has its own column to the
//! right of the plotting area) and that carry labelled marks: points the
//! reader should find on the curve (a reading, a floor), each a hollow
//! diamond on the curve with its label in the legend column (no text on
//! the data).

use super::plot::{Axes, Series, Style, PALETTE};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

/// A labelled point on the plot.
pub struct Mark {
    pub x: f64,
    pub y: f64,
    pub label: String,
    /// Index into the palette.
    pub color: usize,
}

/// Width of the SVG, and of its legend column.
const WIDTH: u32 = 960;
const LEGEND: u32 = 250;

fn chart<X, Y>(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    axes: &Axes,
    xs: X,
    ys: Y,
    series: &[Series],
    marks: &[Mark],
) -> Result<(), DrawingAreaErrorKind<std::io::Error>>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut ch = ChartBuilder::on(area)
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
        match s.style {
            Style::Bands => {
                // Full height: each point is a band's (x_lo, x_hi).
                let yr = ch.y_range();
                ch.draw_series(pts.iter().map(|&(a, b)| {
                    Rectangle::new([(a, yr.start), (b, yr.end)], c.mix(0.18).filled())
                }))?;
            }
            Style::Line => {
                ch.draw_series(LineSeries::new(pts, c.stroke_width(2)))?;
            }
            Style::Dashed => {
                ch.draw_series(DashedLineSeries::new(pts, 6, 4, c.stroke_width(1)))?;
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
                ch.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
            }
        }
    }
    for m in marks {
        let c = PALETTE[m.color % PALETTE.len()];
        let p = (m.x, m.y);
        ch.draw_series(std::iter::once(
            EmptyElement::at(p)
                + Polygon::new(vec![(0, -7), (7, 0), (0, 7), (-7, 0)], c.filled())
                + Polygon::new(vec![(0, -4), (4, 0), (0, 4), (-4, 0)], WHITE.filled()),
        ))?;
    }
    Ok(())
}

/// The legend column: one row per series (its line or marker, its label)
/// and one per mark.
fn legend(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    series: &[Series],
    marks: &[Mark],
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let font = ("sans-serif", 13).into_font();
    let mut y = 50;
    for s in series.iter().filter(|s| !s.label.is_empty()) {
        let c = PALETTE[s.color % PALETTE.len()];
        match s.style {
            Style::Line => {
                area.draw(&PathElement::new(vec![(8, y), (30, y)], c.stroke_width(2)))?
            }
            Style::Dashed => area
                .draw(&PathElement::new(vec![(8, y), (14, y)], c.stroke_width(1)))
                .and_then(|_| {
                    area.draw(&PathElement::new(vec![(19, y), (25, y)], c.stroke_width(1)))
                })?,
            Style::Points => area.draw(&Circle::new((19, y), 3, c.filled()))?,
            Style::Bands => area.draw(&Rectangle::new(
                [(8, y - 5), (30, y + 5)],
                c.mix(0.4).filled(),
            ))?,
        }
        area.draw(&Text::new(s.label.clone(), (38, y - 7), font.clone()))?;
        y += 20;
    }
    for m in marks {
        let c = PALETTE[m.color % PALETTE.len()];
        area.draw(&Polygon::new(
            vec![(19, y - 7), (26, y), (19, y + 7), (12, y)],
            c.filled(),
        ))?;
        area.draw(&Polygon::new(
            vec![(19, y - 4), (23, y), (19, y + 4), (15, y)],
            WHITE.filled(),
        ))?;
        area.draw(&Text::new(m.label.clone(), (38, y - 7), font.clone()))?;
        y += 20;
    }
    Ok(())
}

/// One plot as an SVG element, the legend in a column of its own.
pub fn svg(axes: &Axes, series: &[Series], marks: &[Mark], height: u32) -> String {
    let mut out = String::new();
    let result = {
        let root = SVGBackend::with_string(&mut out, (WIDTH, height)).into_drawing_area();
        let _ = root.fill(&WHITE);
        let (left, right) = root.split_horizontally(WIDTH - LEGEND);
        let mut all: Vec<Series> = series
            .iter()
            .map(|s| Series {
                label: String::new(),
                points: s.points.clone(),
                errors: s.errors.clone(),
                style: s.style,
                color: s.color,
            })
            .collect();
        // The marks count in the ranges too.
        all.push(Series::points(
            "",
            marks.iter().map(|m| (m.x, m.y)).collect(),
            None,
            0,
        ));
        let (x0, x1) = super::plot::range(&all, false, axes.log_x);
        let (y0, y1) = super::plot::range(&all, true, axes.log_y);
        let drawn = match (axes.log_x, axes.log_y) {
            (true, true) => chart(
                &left,
                axes,
                (x0..x1).log_scale(),
                (y0..y1).log_scale(),
                series,
                marks,
            ),
            (true, false) => chart(&left, axes, (x0..x1).log_scale(), y0..y1, series, marks),
            (false, true) => chart(&left, axes, x0..x1, (y0..y1).log_scale(), series, marks),
            (false, false) => chart(&left, axes, x0..x1, y0..y1, series, marks),
        };
        drawn
            .and_then(|_| legend(&right, series, marks))
            .and_then(|_| root.present())
    };
    match result {
        Ok(()) => out,
        Err(e) => format!(
            "<p>(plot not drawn: {})</p>",
            super::text::esc(&e.to_string())
        ),
    }
}
