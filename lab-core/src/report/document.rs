//! A report under construction: headings, paragraphs, tables and plots,
//! made into one self-contained HTML page.

use super::plot::{self, Axes, Series};
use super::text::esc;
use super::verdict::Verdict;
use std::fmt::Write as _;

const CSS: &str =
    "body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222}\
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:0.8em 0}td,th{border:1px solid #bbb;padding:3px 8px;\
text-align:right}th{background:#eee}td:first-child,th:first-child{text-align:left}\
figure{margin:1em 0}figcaption{font-size:0.9em;color:#555}p.note{color:#555;font-size:0.9em}\
p.verdict{background:#f4f7fb;border-left:4px solid #1f77b4;padding:0.6em 0.9em;line-height:1.45}\
p.verdict.warn{border-left-color:#d62728}span.warning{color:#b00}";

/// A report under construction.
pub struct Report {
    title: String,
    body: String,
    figures: usize,
}

impl Report {
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_owned(),
            body: String::new(),
            figures: 0,
        }
    }

    pub fn heading(&mut self, text: &str) {
        let _ = writeln!(self.body, "<h2>{}</h2>", esc(text));
    }

    pub fn paragraph(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p>{}</p>", esc(text));
    }

    pub fn note(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p class=\"note\">{}</p>", esc(text));
    }

    pub fn table(&mut self, header: &[&str], rows: &[Vec<String>]) {
        self.body.push_str("<table>\n<tr>");
        for h in header {
            let _ = write!(self.body, "<th>{}</th>", esc(h));
        }
        self.body.push_str("</tr>\n");
        for r in rows {
            self.body.push_str("<tr>");
            for c in r {
                let _ = write!(self.body, "<td>{}</td>", esc(c));
            }
            self.body.push_str("</tr>\n");
        }
        self.body.push_str("</table>\n");
    }

    /// The report's verdict: one paragraph, its numbers tagged with the
    /// JSON keys they come from (`data-key`), its warnings marked.
    pub fn verdict(&mut self, v: &Verdict) {
        let class = if v.has_warnings() {
            "verdict warn"
        } else {
            "verdict"
        };
        let _ = writeln!(self.body, "<p class=\"{class}\">{}</p>", v.html());
    }

    /// A plot, drawn now as inline SVG. The figure says what it plots:
    /// its axes (`data-x`, `data-y`) and how many data points it draws
    /// (`data-points`).
    pub fn plot(&mut self, axes: &Axes, series: &[Series], caption: &str) {
        self.figures += 1;
        let svg = plot::svg(axes, series);
        let _ = write!(
            self.body,
            "<figure id=\"fig{}\" data-x=\"{}\" data-y=\"{}\" data-points=\"{}\">\n{svg}\n\
             <figcaption>Figure {}. {}</figcaption>\n</figure>\n",
            self.figures,
            esc(&axes.x_label),
            esc(&axes.y_label),
            plot::data_points(series),
            self.figures,
            esc(caption)
        );
    }

    /// A plot whose legend stands beside the data, never on it, with
    /// labelled marks on the curve.
    pub fn plot_annotated(
        &mut self,
        axes: &Axes,
        series: &[Series],
        marks: &[super::annotated::Mark],
        caption: &str,
    ) {
        self.figures += 1;
        let svg = super::annotated::svg(axes, series, marks, 500);
        let _ = write!(
            self.body,
            "<figure id=\"fig{}\">\n{svg}\n<figcaption>Figure {}. {}</figcaption>\n</figure>\n",
            self.figures,
            self.figures,
            esc(caption)
        );
    }

    /// The report as a fragment to place in another page (a notebook's
    /// output cell): the same title, verdict, plots and tables, its style
    /// kept to itself.
    pub fn fragment(&self) -> String {
        format!(
            "<div class=\"gyro-report\">\n<style>{}</style>\n<h1>{}</h1>\n{}</div>\n",
            scoped_css(".gyro-report"),
            esc(&self.title),
            self.body
        )
    }

    pub fn html(&self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{t}</title>\n\
             <style>{CSS}</style>\n</head>\n<body>\n<h1>{t}</h1>\n{}</body>\n</html>\n",
            self.body,
            t = esc(&self.title)
        )
    }
}

/// The report's style with every rule kept inside `scope` (`body` is the
/// scope itself).
fn scoped_css(scope: &str) -> String {
    CSS.split_inclusive('}')
        .filter_map(|rule| {
            let (sel, body) = rule.split_once('{')?;
            let sel: Vec<String> = sel
                .split(',')
                .map(|s| match s.trim() {
                    "body" => scope.to_owned(),
                    s => format!("{scope} {s}"),
                })
                .collect();
            Some(format!("{}{{{body}", sel.join(",")))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fragment_keeps_its_style_to_itself() {
        let css = scoped_css(".r");
        assert!(css.starts_with(".r{font-family:sans-serif"), "{css}");
        assert!(css.contains(".r td,.r th{border"), "{css}");
        assert!(!css.contains("}body") && !css.contains("{body"), "{css}");
        let mut r = Report::new("t");
        r.paragraph("p");
        let f = r.fragment();
        assert!(f.starts_with("<div class=\"gyro-report\">") && f.contains("<p>p</p>"));
    }
}
