//! How to read a user's file as one of the lab's kinds: which of its
//! columns is which of ours (`--columns rate_dps=gyro_z`), the units its
//! rates, temperatures and times are in, and the stretch of the record
//! to take (`--from-s`, `--to-s`). The file kinds turn this into a rule
//! per column (scale, offset and physical range); the table readers apply
//! those rules cell by cell.

use super::units::{RateUnit, TempUnit, TimeUnit};
use crate::error::LabError;

/// What the user said about their file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReadSpec {
    /// (our name, theirs) pairs.
    pub rename: Vec<(String, String)>,
    /// The rate columns' unit, where given.
    pub rate_unit: Option<RateUnit>,
    /// The reference rate's unit, where it differs from the rate's (a
    /// table's log in deg/s beside a gyro's in rad/s).
    pub ref_rate_unit: Option<RateUnit>,
    /// The temperature columns' unit, where given.
    pub temp_unit: Option<TempUnit>,
    /// The time column's unit (seconds unless given).
    pub time_unit: Option<TimeUnit>,
    /// The stretch of the record to read, s (on the time column's scale,
    /// or since the first row for clock timestamps).
    pub from_s: Option<f64>,
    pub to_s: Option<f64>,
}

impl ReadSpec {
    /// The file's name of our column `ours`.
    pub fn theirs<'a>(&'a self, ours: &'a str) -> &'a str {
        self.rename
            .iter()
            .find(|(o, _)| o == ours)
            .map_or(ours, |(_, t)| t.as_str())
    }

    /// Whether our column `ours` was mapped onto another of the file's.
    pub fn is_mapped(&self, ours: &str) -> bool {
        self.rename.iter().any(|(o, _)| o == ours)
    }

    /// Parses `--columns ours=theirs,ours=theirs`.
    pub fn parse_rename(s: &str) -> Result<Vec<(String, String)>, LabError> {
        let mut out: Vec<(String, String)> = vec![];
        for pair in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let Some((ours, theirs)) = pair.split_once('=') else {
                return Err(LabError::Usage(format!(
                    "`{pair}` is not ours=theirs (our column name, =, the file's)"
                )));
            };
            let (ours, theirs) = (ours.trim(), theirs.trim());
            if ours.is_empty() || theirs.is_empty() {
                return Err(LabError::Usage(format!(
                    "`{pair}`: a name on each side of `=`"
                )));
            }
            if out.iter().any(|(o, _)| o == ours) {
                return Err(LabError::Usage(format!("`{ours}` is mapped twice")));
            }
            out.push((ours.to_owned(), theirs.to_owned()));
        }
        Ok(out)
    }

    /// The stretch asked for checked: finite times, the end after the
    /// start; `names` are what the caller calls the two (`--from-s` and
    /// `--to-s` on the command line).
    pub fn check_stretch(&self, names: [&str; 2]) -> Result<(), LabError> {
        for (name, v) in names.iter().zip([self.from_s, self.to_s]) {
            if v.is_some_and(|v| !v.is_finite()) {
                return Err(LabError::Usage(format!("{name}: not a finite time")));
            }
        }
        if let (Some(f), Some(t)) = (self.from_s, self.to_s) {
            if t <= f {
                return Err(LabError::Usage(format!(
                    "{} {f} {} {t}: the stretch is empty",
                    names[0], names[1]
                )));
            }
        }
        Ok(())
    }

    /// Whether a time `t` (s) is inside the stretch asked for.
    pub fn keeps(&self, t: f64) -> bool {
        self.from_s.is_none_or(|f| t >= f) && self.to_s.is_none_or(|e| t <= e)
    }

    /// The stretch asked for, as words (None for the whole record).
    pub fn stretch(&self) -> Option<String> {
        match (self.from_s, self.to_s) {
            (None, None) => None,
            (Some(f), None) => Some(format!("from {f} s")),
            (None, Some(e)) => Some(format!("up to {e} s")),
            (Some(f), Some(e)) => Some(format!("{f} .. {e} s")),
        }
    }
}

/// What a file kind does with one of its columns' cells: the value read
/// is `scale * cell + offset`, then checked against the column's range.
pub struct ColumnRule {
    pub scale: f64,
    pub offset: f64,
    /// Converted values in this closed range are inside the column's
    /// physical range without asking `check` (the common case, read at
    /// the cost of two comparisons).
    pub valid: (f64, f64),
    /// The message for a converted value outside the column's physical
    /// range (None inside it).
    pub check: Option<Box<dyn Fn(f64) -> Option<String>>>,
}

impl ColumnRule {
    /// Read as written, unchecked.
    pub fn plain() -> Self {
        Self {
            scale: 1.0,
            offset: 0.0,
            valid: (f64::NEG_INFINITY, f64::INFINITY),
            check: None,
        }
    }

    /// What is wrong with the converted value `v`, if anything.
    pub fn problem(&self, v: f64) -> Option<String> {
        if v >= self.valid.0 && v <= self.valid.1 {
            return None;
        }
        self.check.as_ref().and_then(|c| c(v))
    }
}

/// A file kind's rule for each of its column names.
pub type Rules<'a> = &'a dyn Fn(&str) -> ColumnRule;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mapping_reads_and_refuses_what_is_not_one() {
        let r = ReadSpec::parse_rename("omega=gyro_z, clock=time").unwrap();
        assert_eq!(r[1], ("clock".to_owned(), "time".to_owned()));
        let s = ReadSpec {
            rename: r,
            ..Default::default()
        };
        assert_eq!(s.theirs("omega"), "gyro_z");
        assert_eq!(s.theirs("heat"), "heat");
        assert!(ReadSpec::parse_rename("omega").is_err());
        assert!(ReadSpec::parse_rename("omega=a,omega=b").is_err());
        assert!(ReadSpec::parse_rename("=a").is_err());
    }

    #[test]
    fn a_stretch_keeps_its_ends() {
        let s = ReadSpec {
            from_s: Some(10.0),
            to_s: Some(20.0),
            ..Default::default()
        };
        assert!(s.keeps(10.0) && s.keeps(20.0) && !s.keeps(9.99) && !s.keeps(20.01));
        assert!(ReadSpec::default().keeps(-1e9));
    }
}
