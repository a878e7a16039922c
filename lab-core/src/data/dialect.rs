//! The CSV dialects users' files come in: a byte-order mark before the
//! first line (Excel's UTF-8), a comma, semicolon or tab between cells,
//! and with a semicolon or a tab, the decimal comma of the locales that
//! use one (`-0,0123`). The separator is read off the header line, so no
//! option is needed for it.

/// The UTF-8 byte-order mark.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// `text` without a leading byte-order mark, and its length.
pub fn strip_bom(text: &[u8]) -> (&[u8], usize) {
    match text.strip_prefix(BOM) {
        Some(rest) => (rest, BOM.len()),
        None => (text, 0),
    }
}

/// How a file separates its cells and writes its decimals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dialect {
    pub delimiter: u8,
    /// A cell that does not read as a number with a decimal point is read
    /// again with its one comma as the point (only where commas cannot
    /// separate cells).
    pub decimal_comma: bool,
}

impl Default for Dialect {
    fn default() -> Self {
        Self {
            delimiter: b',',
            decimal_comma: false,
        }
    }
}

impl Dialect {
    /// The dialect of a header line: the separator among `,` `;` and tab
    /// that splits it into the most cells outside quotes (a one-column
    /// header is a comma file).
    pub fn of_header(line: &[u8]) -> Self {
        let mut counts = [0usize; 3];
        let mut quoted = false;
        for &b in line {
            match b {
                b'"' => quoted = !quoted,
                b',' if !quoted => counts[0] += 1,
                b';' if !quoted => counts[1] += 1,
                b'\t' if !quoted => counts[2] += 1,
                _ => {}
            }
        }
        let seps = [b',', b';', b'\t'];
        let best = (0..3).max_by_key(|&i| (counts[i], 3 - i)).unwrap_or(0);
        if counts[best] == 0 {
            return Self::default();
        }
        Self {
            delimiter: seps[best],
            decimal_comma: seps[best] != b',',
        }
    }

    /// A cell as a number: with a decimal point, or in a decimal-comma
    /// file with its one comma as the point.
    pub fn parse(&self, cell: &str) -> Result<f64, std::num::ParseFloatError> {
        match cell.parse::<f64>() {
            Ok(v) => Ok(v),
            Err(e) if self.decimal_comma && cell.bytes().filter(|&b| b == b',').count() == 1 => {
                cell.replacen(',', ".", 1).parse::<f64>().map_err(|_| e)
            }
            Err(e) => Err(e),
        }
    }

    pub fn name(&self) -> &'static str {
        match self.delimiter {
            b';' => "semicolon",
            b'\t' => "tab",
            _ => "comma",
        }
    }
}

/// The first line of `text` that is neither blank nor a `#` comment.
pub fn header_line(text: &[u8]) -> &[u8] {
    text.split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .find(|l| {
            let t = l.trim_ascii();
            !t.is_empty() && !t.starts_with(b"#")
        })
        .unwrap_or(b"")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_separator_is_read_off_the_header() {
        assert_eq!(Dialect::of_header(b"time,gyro,table").delimiter, b',');
        let s = Dialect::of_header(b"time;gyro;table");
        assert_eq!((s.delimiter, s.decimal_comma), (b';', true));
        assert_eq!(Dialect::of_header(b"time\tgyro").delimiter, b'\t');
        // A comma inside a quoted name does not separate.
        assert_eq!(Dialect::of_header(b"\"gyro, deg/s\";time").delimiter, b';');
        assert_eq!(Dialect::of_header(b"time").delimiter, b',');
    }

    #[test]
    fn a_decimal_comma_reads_only_where_commas_do_not_separate() {
        let semi = Dialect::of_header(b"a;b");
        assert_eq!(semi.parse("-0,0125").unwrap(), -0.0125);
        assert_eq!(semi.parse("1.5").unwrap(), 1.5);
        assert!(semi.parse("1,2,3").is_err());
        assert!(Dialect::default().parse("0,5").is_err());
    }

    #[test]
    fn a_bom_and_comments_come_off() {
        let text = b"\xEF\xBB\xBF# made by a logger\n\ntime;x\n1;2\n";
        let (rest, n) = strip_bom(text);
        assert_eq!(n, 3);
        assert_eq!(header_line(rest), b"time;x");
    }
}
