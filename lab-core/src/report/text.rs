//! Text in reports and on the terminal: HTML escaping and the number
//! formats the tables use.

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
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

/// A time in seconds, to 0.1 s however far from zero: a device clock's
/// seconds since power-on run to 1e8 and more, where six significant
/// digits would make every span of a record the same.
pub fn time_s(t: f64) -> String {
    if t.is_finite() && t.abs() >= 1e4 {
        format!("{t:.1}")
    } else {
        sig(t)
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
