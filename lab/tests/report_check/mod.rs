//! Checks of a calibration report (report.html), shared by the tests of
//! the commands that write one: nothing external, every plot with its
//! axes, their units and data, the verdict's numbers those of the JSON,
//! the verdict's warnings those of the JSON.
#![allow(dead_code)]

/// One figure of a report.
pub struct Figure {
    pub x: String,
    pub y: String,
    pub points: usize,
    pub svg: String,
}

/// The value of attribute `name` in the tag text `tag`.
fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!("{name}=\"");
    let i = tag.find(&key)? + key.len();
    let j = tag[i..].find('"')? + i;
    Some(unescape(&tag[i..j]))
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&amp;", "&")
}

/// Nothing fetched: no scripts, links, sources or URLs but the SVG
/// namespace's name (an identifier, never fetched).
pub fn assert_self_contained(html: &str) {
    let stripped = html.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
    for bad in [
        "<script", "<link", "<img", "<iframe", "src=", "href=", "url(", "@import", "http:",
        "https:",
    ] {
        assert!(!stripped.contains(bad), "report holds `{bad}`");
    }
}

/// The figures of a report.
pub fn figures(html: &str) -> Vec<Figure> {
    let mut out = vec![];
    let mut rest = html;
    while let Some(i) = rest.find("<figure") {
        let end_tag = rest[i..].find('>').unwrap() + i;
        let tag = &rest[i..end_tag];
        let close = rest[end_tag..].find("</figure>").unwrap() + end_tag;
        out.push(Figure {
            x: attr(tag, "data-x").unwrap_or_default(),
            y: attr(tag, "data-y").unwrap_or_default(),
            points: attr(tag, "data-points")
                .and_then(|p| p.parse().ok())
                .unwrap_or(0),
            svg: rest[end_tag..close].to_owned(),
        });
        rest = &rest[close..];
    }
    out
}

/// Every plot has both axes labelled "quantity, unit", drawn in its SVG,
/// and data drawn (lines or points).
pub fn assert_plots_complete(html: &str, at_least: usize) {
    let figs = figures(html);
    assert!(figs.len() >= at_least, "{} figures", figs.len());
    for f in &figs {
        for label in [&f.x, &f.y] {
            let (q, unit) = label
                .rsplit_once(", ")
                .unwrap_or_else(|| panic!("axis `{label}` has no unit"));
            assert!(
                !q.trim().is_empty() && !unit.trim().is_empty(),
                "axis `{label}`"
            );
            assert!(f.svg.contains(&esc(label)), "axis `{label}` not drawn");
        }
        assert!(f.points > 0, "figure {} / {} has no data", f.x, f.y);
        assert!(
            f.svg.contains("<polyline") || f.svg.contains("<circle"),
            "figure {} / {} draws no data",
            f.x,
            f.y
        );
        assert!(
            f.svg.contains("<svg"),
            "figure {} / {} is not SVG",
            f.x,
            f.y
        );
    }
}

pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The verdict paragraph (its inner HTML).
pub fn verdict(html: &str) -> String {
    let i = html.find("<p class=\"verdict").expect("a verdict");
    let j = html[i..].find('>').unwrap() + i + 1;
    let k = html[j..].find("</p>").unwrap() + j;
    html[j..k].to_owned()
}

/// The value at a JSON path `a.b.0` (`.length`: an array's length).
fn at(v: &serde_json::Value, path: &str) -> serde_json::Value {
    let mut cur = v.clone();
    for seg in path.split('.') {
        cur = match (seg, &cur) {
            ("length", serde_json::Value::Array(a)) => serde_json::Value::from(a.len()),
            (s, serde_json::Value::Array(a)) => a[s.parse::<usize>().unwrap()].clone(),
            (s, o) => o[s].clone(),
        };
    }
    cur
}

/// Every tagged number of the verdict is the JSON's value at its key, to
/// the digits shown; every tagged word the JSON's string. Returns how many
/// were checked.
pub fn assert_verdict_matches(html: &str, json: &serde_json::Value) -> usize {
    let v = verdict(html);
    let mut n = 0;
    let mut rest = v.as_str();
    while let Some(i) = rest.find("data-key=\"") {
        let s = &rest[i + 10..];
        let key_end = s.find('"').unwrap();
        let key = &s[..key_end];
        let text_start = s.find('>').unwrap() + 1;
        let text_end = s.find("</span>").unwrap();
        let shown = unescape(&s[text_start..text_end]);
        let want = at(json, key);
        match want {
            serde_json::Value::String(w) => assert_eq!(shown, w, "{key}"),
            serde_json::Value::Number(w) => {
                let w = w.as_f64().unwrap();
                let x: f64 = shown.parse().unwrap_or_else(|_| panic!("{key}: `{shown}`"));
                let decimals = shown.split('.').nth(1).map_or(0, |d| d.len());
                let tol = 0.5 * 10f64.powi(-(decimals as i32)) * (1.0 + 1e-9) + 1e-12 * w.abs();
                assert!((x - w).abs() <= tol, "{key}: verdict {shown}, JSON {w}");
            }
            other => panic!("{key}: JSON holds {other}"),
        }
        n += 1;
        rest = &s[text_end..];
    }
    n
}

/// The warning kinds of the verdict, which must be those of the JSON's
/// `warnings`.
pub fn assert_warnings_match(html: &str, json: &serde_json::Value) -> Vec<String> {
    let v = verdict(html);
    let shown: Vec<String> = v
        .split("data-warning=\"")
        .skip(1)
        .map(|s| s[..s.find('"').unwrap()].to_owned())
        .collect();
    let want: Vec<String> = json["warnings"]
        .as_array()
        .expect("warnings in the JSON")
        .iter()
        .map(|w| w["kind"].as_str().unwrap().to_owned())
        .collect();
    assert_eq!(shown, want, "verdict against JSON warnings");
    shown
}

/// All of the above.
pub fn check(html: &str, json: &serde_json::Value, min_figures: usize, min_numbers: usize) {
    assert_self_contained(html);
    assert_plots_complete(html, min_figures);
    let n = assert_verdict_matches(html, json);
    assert!(n >= min_numbers, "{n} numbers in the verdict");
    assert_warnings_match(html, json);
}

/// Wall time of the command `args` (gyro-lab's arguments, in-process), the
/// least of `rounds` runs with the report and of as many without
/// (`--no-report`, or `without` in place of the report's arguments),
/// alternated so that both see the same machine.
pub fn report_overhead(args: &[&str], without: &[&str], rounds: usize) -> (f64, f64) {
    use clap::Parser;
    let run = |a: &[&str]| {
        let mut v = vec!["gyro-lab"];
        v.extend_from_slice(a);
        let cli = gyro_lab::cli::Cli::parse_from(v);
        let t0 = std::time::Instant::now();
        gyro_lab::cli::run(&cli).expect("command");
        t0.elapsed().as_secs_f64()
    };
    let (mut with, mut bare) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..rounds {
        bare = bare.min(run(without));
        with = with.min(run(args));
    }
    (with, bare)
}
