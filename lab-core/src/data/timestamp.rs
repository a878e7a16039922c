//! Clock timestamps in a time column (a PC logger's `2026-03-01
//! 14:02:07.125` or `14:02:07.125`), read as seconds: a date and time as
//! seconds since 1970 (UTC, or the offset it states), a time of day as
//! seconds since midnight. The reader makes them seconds since the
//! record's first row.

/// Days from 1970-01-01 to the civil date (proleptic Gregorian).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = if y >= 0 { y } else { y - 399 } / 400;
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Digits of `s` from `at`, exactly `n` of them.
fn digits(s: &[u8], at: usize, n: usize) -> Option<i64> {
    let d = s.get(at..at + n)?;
    d.iter()
        .all(u8::is_ascii_digit)
        .then(|| d.iter().fold(0i64, |a, &b| a * 10 + i64::from(b - b'0')))
}

/// `HH:MM:SS[.frac]` from `at`: seconds and the index after it.
fn time_of_day(s: &[u8], at: usize) -> Option<(f64, usize)> {
    let h = digits(s, at, 2)?;
    let m = digits(s, at + 3, 2)?;
    let sec = digits(s, at + 6, 2)?;
    if s[at + 2] != b':' || s[at + 5] != b':' || h > 23 || m > 59 || sec > 60 {
        return None;
    }
    let mut end = at + 8;
    let mut frac = 0.0;
    if matches!(s.get(end), Some(b'.' | b',')) {
        let start = end + 1;
        end = start;
        while s.get(end).is_some_and(u8::is_ascii_digit) {
            end += 1;
        }
        if end == start {
            return None;
        }
        let text = std::str::from_utf8(&s[start..end]).ok()?;
        frac = format!("0.{text}").parse::<f64>().ok()?;
    }
    Some(((h * 3600 + m * 60 + sec) as f64 + frac, end))
}

/// A timestamp as seconds: `YYYY-MM-DD[T or space]HH:MM:SS[.frac][Z or
/// +HH:MM or -HH:MM]` since 1970, or `HH:MM:SS[.frac]` since midnight.
/// None for anything else (a plain number is the caller's).
pub fn parse(cell: &str) -> Option<f64> {
    let s = cell.trim().as_bytes();
    if s.len() >= 8 && s[2] == b':' {
        let (t, end) = time_of_day(s, 0)?;
        return (end == s.len()).then_some(t);
    }
    if s.len() < 19 || s[4] != b'-' || s[7] != b'-' || !matches!(s[10], b'T' | b' ') {
        return None;
    }
    let (y, mo, d) = (digits(s, 0, 4)?, digits(s, 5, 2)?, digits(s, 8, 2)?);
    if !(1..=12).contains(&mo) || !(1..=31).contains(&d) {
        return None;
    }
    let (tod, mut end) = time_of_day(s, 11)?;
    let mut offset = 0i64;
    match s.get(end) {
        None => {}
        Some(b'Z') => end += 1,
        Some(&c @ (b'+' | b'-')) => {
            let oh = digits(s, end + 1, 2)?;
            let colon = usize::from(s.get(end + 3) == Some(&b':'));
            let om = digits(s, end + 3 + colon, 2)?;
            offset = (oh * 3600 + om * 60) * if c == b'+' { 1 } else { -1 };
            end += 5 + colon;
        }
        _ => return None,
    }
    (end == s.len()).then(|| (days_from_civil(y, mo, d) * 86_400 - offset) as f64 + tod)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_and_times_read_as_seconds() {
        assert_eq!(parse("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(parse("2000-03-01 00:00:00"), Some(951_868_800.0));
        assert_eq!(parse("2026-11-28T18:59:19.25Z"), Some(1_795_892_359.25));
        assert_eq!(
            parse("2026-11-28T19:59:19+01:00"),
            parse("2026-11-28T18:59:19Z")
        );
        assert_eq!(parse("14:02:07.125"), Some(50_527.125));
        assert_eq!(parse("14:02:07,5"), Some(50_527.5));
        for bad in [
            "12.5",
            "2026-13-01 00:00:00",
            "25:00:00",
            "14:02",
            "2026-11-28",
            "x",
        ] {
            assert_eq!(parse(bad), None, "{bad}");
        }
    }
}
