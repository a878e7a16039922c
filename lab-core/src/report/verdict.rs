//! A report's verdict: one paragraph that says what was fitted, from how
//! much data, how good the fit is against its noise, and what to beware of.
//! Its numbers are tagged with the JSON keys they come from, so a reader
//! (or a test) can hold the paragraph against the command's JSON.

use super::text::esc;
use std::fmt::Write as _;

/// A verdict under construction.
#[derive(Default)]
pub struct Verdict {
    html: String,
    warnings: usize,
}

impl Verdict {
    pub fn new() -> Self {
        Self::default()
    }

    /// Plain text.
    pub fn text(&mut self, t: &str) -> &mut Self {
        self.html.push_str(&esc(t));
        self
    }

    /// A value shown as `shown`, tagged with the JSON key `key`.
    fn tagged(&mut self, key: &str, shown: &str) -> &mut Self {
        let _ = write!(
            self.html,
            "<span class=\"v\" data-key=\"{}\">{}</span>",
            esc(key),
            esc(shown)
        );
        self
    }

    /// A number from the JSON key `key` (a path: `a.b`, `knees_c.0`),
    /// printed with `decimals` decimals.
    pub fn num(&mut self, key: &str, value: f64, decimals: usize) -> &mut Self {
        let shown = if value.is_finite() {
            format!("{value:.decimals$}")
        } else {
            "n/a".to_owned()
        };
        self.tagged(key, &shown)
    }

    /// A pair from the JSON array `key` (`key.0 .. key.1`): a range or an
    /// interval.
    pub fn range(&mut self, key: &str, pair: [f64; 2], decimals: usize) -> &mut Self {
        self.num(&format!("{key}.0"), pair[0], decimals)
            .text(" .. ")
            .num(&format!("{key}.1"), pair[1], decimals)
    }

    /// A word from the JSON key `key` (a string value).
    pub fn word(&mut self, key: &str, value: &str) -> &mut Self {
        self.tagged(key, value)
    }

    /// A count from the JSON key `key`.
    pub fn count(&mut self, key: &str, value: usize) -> &mut Self {
        self.tagged(key, &value.to_string())
    }

    /// A warning sentence (its kind, as the JSON's `warnings` names it).
    pub fn warning(&mut self, kind: &str, message: &str) -> &mut Self {
        self.warnings += 1;
        let _ = write!(
            self.html,
            " <span class=\"warning\" data-warning=\"{}\">Warning: {}.</span>",
            esc(kind),
            esc(message)
        );
        self
    }

    pub fn has_warnings(&self) -> bool {
        self.warnings > 0
    }

    /// The paragraph's inner HTML.
    pub fn html(&self) -> &str {
        &self.html
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_tagged_and_text_escaped() {
        let mut v = Verdict::new();
        v.text("a < b: ")
            .num("residual_ppm", 0.24871, 3)
            .text(" ppm over ")
            .count("rows", 25)
            .warning("knee_near_edge", "close to 60 degC");
        let h = v.html();
        assert!(h.starts_with("a &lt; b: "));
        assert!(h.contains("data-key=\"residual_ppm\">0.249</span>"));
        assert!(h.contains("data-key=\"rows\">25</span>"));
        assert!(h.contains("data-warning=\"knee_near_edge\""));
        assert!(v.has_warnings());
    }
}
