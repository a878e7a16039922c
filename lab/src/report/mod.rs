//! The lab's HTML reports: one self-contained file (inline CSS, inline SVG
//! plots drawn by plotters, no scripts, nothing fetched), so it reads the
//! same offline and in any browser. Every subcommand that writes a report
//! builds it here.

pub mod plot;

use std::fmt::Write as _;
use std::path::Path;

pub use plot::{Axes, Series, Style};

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const CSS: &str = "body{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}\
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:0.8em 0}td,th{border:1px solid #bbb;padding:3px 8px;\
text-align:right}th{background:#eee}td:first-child,th:first-child{text-align:left}\
figure{margin:1em 0}figcaption{font-size:0.9em;color:#555}p.note{color:#555;font-size:0.9em}";

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

    /// A plot, drawn now as inline SVG.
    pub fn plot(&mut self, axes: &Axes, series: &[Series], caption: &str) {
        self.figures += 1;
        let svg = plot::svg(axes, series);
        let _ = write!(
            self.body,
            "<figure id=\"fig{}\">\n{svg}\n<figcaption>Figure {}. {}</figcaption>\n</figure>\n",
            self.figures,
            self.figures,
            esc(caption)
        );
    }

    pub fn html(&self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{t}</title>\n\
             <style>{CSS}</style>\n</head>\n<body>\n<h1>{t}</h1>\n{}</body>\n</html>\n",
            self.body,
            t = esc(&self.title)
        )
    }

    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        std::fs::write(path, self.html())
    }
}

/// Formats a number for a table: 4 significant digits, exponent when far
/// from 1.
pub fn num(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

/// A measured quantity to 6 significant digits, trailing zeros dropped
/// (0.0020000000000000018 s prints as 0.002).
pub fn sig(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    if !(1e-4..1e7).contains(&x.abs()) {
        return format!("{x:.5e}");
    }
    let e = x.abs().log10().floor() as i32;
    let d = (5 - e).max(0) as usize;
    let s = format!("{x:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}
