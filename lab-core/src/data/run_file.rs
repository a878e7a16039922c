//! The run file (docs/interfaces.md "Run file"): a test-rig or simulation
//! record. Its columns are a type, [`Column`]; it is read and written here
//! and nowhere else, so no other module spells a column's name.

use super::csv_writer::{CellFormat, CsvWriter};
use super::header::Places;
use super::read_spec::{ColumnRule, ReadSpec};
use super::source::{Origin, Source};
use super::table::{ColumnStream, Plan, TextTable};
use super::units::{TempUnit, ZERO_C_IN_K};
use crate::error::LabError;
use std::path::Path;

/// A column of a run file: those of the interface, then the lab's own
/// diagnostic and truth columns (kept and ignored by every reader).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Column {
    /// Time since power-on, s.
    Time,
    /// Reference rate about the sensitive axis (table rate plus Earth-rate
    /// component), deg/s.
    RefRate,
    /// Gyro output with the nominal scale factor, deg/s.
    Rate,
    /// The gyro's main temperature sensor (FOG coil), degC.
    Temp,
    /// RLG monoblock sensors at two places, degC.
    MonoA,
    MonoB,
    /// Case sensor, degC.
    Case,
    /// Reference angular acceleration, deg/s^2.
    RefAcc,
    /// Cumulative output angle since the record's start, deg.
    Angle,
    /// `simulate fog`: the output without the eps^2 correction, deg/s.
    RawRate,
    /// `simulate fog`: the loop's phase residual, rad.
    LoopResidual,
    /// `simulate fog`: the 2*pi loop's DAC codes per turn.
    CodesPerTurn,
    /// `simulate fog`: the frame's fault flags.
    Faults,
    /// Simulated chambers: the air temperature, degC.
    AirTemp,
    /// `simulate chamber`: the bias the simulated RLG holds, deg/h.
    TrueBias,
    /// `simulate scale-factor`: the coil's true temperature, degC.
    TrueCoilTemp,
    /// `simulate scale-factor`: the true scale-factor error, ppm.
    TrueScaleFactor,
    /// `compensate`: the compensated rate, deg/s.
    CompensatedRate,
}

impl Column {
    pub const ALL: [Column; 18] = [
        Column::Time,
        Column::RefRate,
        Column::Rate,
        Column::Temp,
        Column::MonoA,
        Column::MonoB,
        Column::Case,
        Column::RefAcc,
        Column::Angle,
        Column::RawRate,
        Column::LoopResidual,
        Column::CodesPerTurn,
        Column::Faults,
        Column::AirTemp,
        Column::TrueBias,
        Column::TrueCoilTemp,
        Column::TrueScaleFactor,
        Column::CompensatedRate,
    ];

    /// The column's name in the header.
    pub const fn name(self) -> &'static str {
        match self {
            Column::Time => "t_s",
            Column::RefRate => "ref_rate_dps",
            Column::Rate => "rate_dps",
            Column::Temp => "temp_c",
            Column::MonoA => "t_mono_a_c",
            Column::MonoB => "t_mono_b_c",
            Column::Case => "t_case_c",
            Column::RefAcc => "ref_acc_dps2",
            Column::Angle => "angle_deg",
            Column::RawRate => "rate_raw_dps",
            Column::LoopResidual => "residual_rad",
            Column::CodesPerTurn => "codes_per_turn",
            Column::Faults => "faults",
            Column::AirTemp => "t_air_c",
            Column::TrueBias => "bias_true_dph",
            Column::TrueCoilTemp => "t_coil_true_c",
            Column::TrueScaleFactor => "sf_true_ppm",
            Column::CompensatedRate => "rate_comp_dps",
        }
    }

    pub const fn unit(self) -> &'static str {
        match self {
            Column::Time => "s",
            Column::RefRate | Column::Rate | Column::RawRate | Column::CompensatedRate => "deg/s",
            Column::Temp
            | Column::MonoA
            | Column::MonoB
            | Column::Case
            | Column::AirTemp
            | Column::TrueCoilTemp => "degC",
            Column::RefAcc => "deg/s^2",
            Column::Angle => "deg",
            Column::LoopResidual => "rad",
            Column::CodesPerTurn | Column::Faults => "-",
            Column::TrueBias => "deg/h",
            Column::TrueScaleFactor => "ppm",
        }
    }

    /// Whether every run file holds it.
    pub const fn required(self) -> bool {
        matches!(self, Column::Time | Column::RefRate | Column::Rate)
    }
}

/// The temperatures a gyro's sensors read, degC: the firmware refuses a
/// sensor outside them (dsp/src/sensor.rs), and so does every reader.
pub const TEMP_RANGE_C: (f64, f64) = (-60.0, 150.0);

/// The physical range of a run file's column, by the unit its name ends
/// in, and what to say of a value outside it (with the unit the user gave,
/// or the likely one): a value outside it is no gyro's, rate table's or
/// sensor's (1e300 deg/s would turn every sum into infinity and every
/// answer into nothing). Time is judged by its increase instead.
pub fn rule(name: &str, spec: &ReadSpec) -> ColumnRule {
    let rate = match name == Column::RefRate.name() {
        true => spec.ref_rate_unit.or(spec.rate_unit),
        false => spec.rate_unit,
    }
    .unwrap_or_default();
    let range =
        |lo: f64, hi: f64, what: &'static str| -> Option<Box<dyn Fn(f64) -> Option<String>>> {
            Some(Box::new(move |v: f64| {
                (!(lo..=hi).contains(&v)).then(|| format!("is outside {what}"))
            }))
        };
    if name.ends_with("_dps2") {
        ColumnRule {
            scale: rate.angle_to_deg(),
            offset: 0.0,
            valid: (-1e8, 1e8),
            check: range(
                -1e8,
                1e8,
                "the angular accelerations a rig gives (|x| <= 1e8 deg/s^2)",
            ),
        }
    } else if name.ends_with("_dps") {
        let given = spec.rate_unit.is_some();
        ColumnRule {
            scale: rate.to_dps(),
            offset: 0.0,
            valid: (-1e5, 1e5),
            check: Some(Box::new(move |v: f64| {
                const MAX: f64 = 1e5;
                (v.abs() > MAX).then(|| {
                    let hint = if !given && (v / 3600.0).abs() <= MAX {
                        format!(
                            "; as deg/h it is {} deg/s: is the file in deg/h? (--rate-unit deg/h)",
                            v / 3600.0
                        )
                    } else {
                        String::new()
                    };
                    format!("is outside the rates a gyro or a rate table gives (|x| <= 1e5 deg/s){hint}")
                })
            })),
        }
    } else if name.ends_with("_deg") {
        ColumnRule {
            scale: rate.angle_to_deg(),
            offset: 0.0,
            valid: (f64::NEG_INFINITY, f64::INFINITY),
            check: None,
        }
    } else if name.ends_with("_c") {
        let unit = spec.temp_unit;
        let given = unit.is_some();
        let unit = unit.unwrap_or_default();
        let (lo, hi) = TEMP_RANGE_C;
        ColumnRule {
            scale: unit.scale(),
            offset: unit.to_c(0.0),
            valid: (lo, hi),
            check: Some(Box::new(move |v: f64| {
                if (lo..=hi).contains(&v) {
                    return None;
                }
                let raw = (v - unit.to_c(0.0)) / unit.scale();
                let as_k = raw - ZERO_C_IN_K;
                Some(if unit == TempUnit::Celsius && (lo..=hi).contains(&as_k) {
                    format!(
                        "is outside the {lo}..+{hi} degC a gyro's sensors read; as kelvin it is {as_k:.2} degC: give --temp-unit K"
                    )
                } else if unit != TempUnit::Celsius && (lo..=hi).contains(&raw) {
                    format!(
                        "is {v:.2} degC with --temp-unit {}, outside the {lo}..+{hi} degC a gyro's sensors read; as degC it is {raw}: drop --temp-unit",
                        unit.name()
                    )
                } else {
                    format!(
                        "is {v:.2} degC, outside the {lo}..+{hi} degC a gyro's sensors read{}",
                        if given {
                            ""
                        } else {
                            " (read as degC: --temp-unit K for kelvin)"
                        }
                    )
                })
            })),
        }
    } else {
        ColumnRule::plain()
    }
}

/// The user's `--columns` name only run-file columns.
fn check_names(spec: &ReadSpec) -> Result<(), LabError> {
    for (ours, _) in &spec.rename {
        if !Column::ALL.iter().any(|c| c.name() == ours) {
            let names: Vec<&str> = Column::ALL.iter().map(|c| c.name()).collect();
            return Err(LabError::Usage(format!(
                "--columns: `{ours}` is not a run-file column ({})",
                names.join(", ")
            )));
        }
    }
    Ok(())
}

/// Whether a command needs the reference rate, or takes a run without one
/// as a static record (reference 0, said in the run's notes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    Required,
    ZeroIfAbsent,
}

/// The interface's columns of a run, as read: the required three, and of
/// the others those the reader asked for and the file has.
#[derive(Debug)]
pub struct RunFile {
    pub t_s: Vec<f64>,
    pub ref_rate_dps: Vec<f64>,
    pub rate_dps: Vec<f64>,
    pub temp_c: Option<Vec<f64>>,
    pub t_mono_a_c: Option<Vec<f64>>,
    pub t_mono_b_c: Option<Vec<f64>>,
    pub t_case_c: Option<Vec<f64>>,
    pub ref_acc_dps2: Option<Vec<f64>>,
    pub angle_deg: Option<Vec<f64>>,
    /// Whether the file had `ref_rate_dps` (else it is zeros: a static
    /// record).
    pub has_reference: bool,
    /// Where the columns are in the file: its path, the header's line,
    /// and per column read its field and the name the file gives it.
    pub places: Places,
}

impl RunFile {
    fn slot(&mut self, c: Column) -> Option<&mut Option<Vec<f64>>> {
        match c {
            Column::Temp => Some(&mut self.temp_c),
            Column::MonoA => Some(&mut self.t_mono_a_c),
            Column::MonoB => Some(&mut self.t_mono_b_c),
            Column::Case => Some(&mut self.t_case_c),
            Column::RefAcc => Some(&mut self.ref_acc_dps2),
            Column::Angle => Some(&mut self.angle_deg),
            _ => None,
        }
    }

    fn new(t_s: Vec<f64>, ref_rate_dps: Vec<f64>, rate_dps: Vec<f64>) -> Self {
        Self {
            t_s,
            ref_rate_dps,
            rate_dps,
            temp_c: None,
            t_mono_a_c: None,
            t_mono_b_c: None,
            t_case_c: None,
            ref_acc_dps2: None,
            angle_deg: None,
            has_reference: true,
            places: Places::default(),
        }
    }

    /// A column read, if it was.
    pub fn column(&self, c: Column) -> Option<&[f64]> {
        match c {
            Column::Time => Some(&self.t_s),
            Column::RefRate => Some(&self.ref_rate_dps),
            Column::Rate => Some(&self.rate_dps),
            Column::Temp => self.temp_c.as_deref(),
            Column::MonoA => self.t_mono_a_c.as_deref(),
            Column::MonoB => self.t_mono_b_c.as_deref(),
            Column::Case => self.t_case_c.as_deref(),
            Column::RefAcc => self.ref_acc_dps2.as_deref(),
            Column::Angle => self.angle_deg.as_deref(),
            _ => None,
        }
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Reads a run file whole, as text (its cells are kept for
    /// [`RunText::text_with`]), checking in this order: the columns (all
    /// missing ones named at once), `t_s` (increasing, at least
    /// `min_rows` rows in the stretch asked for), `ref_rate_dps`,
    /// `rate_dps`, then each column of `need`: they come back in the order
    /// asked (and in the run's fields).
    pub fn read<'a, const N: usize>(
        source: Source<'a>,
        spec: &ReadSpec,
        reference: Reference,
        min_rows: usize,
        need: [Column; N],
    ) -> Result<(RunText<'a>, [Vec<f64>; N]), LabError> {
        check_names(spec)?;
        let owned = spec.clone();
        let rules = Box::new(move |name: &str| rule(name, &owned));
        let table = TextTable::read_source(source, spec, Some(Column::Time.name()), Some(rules))?;
        let mut names = vec![Column::Time.name(), Column::Rate.name()];
        if reference == Reference::Required {
            names.push(Column::RefRate.name());
        }
        names.extend(need.iter().map(|c| c.name()));
        table.require(&names)?;
        let t = table.time(Column::Time.name(), min_rows)?;
        let has_reference = table.has(Column::RefRate.name());
        let w = match has_reference {
            true => table.column(Column::RefRate.name())?,
            false => vec![0.0; t.len()],
        };
        let y = table.column(Column::Rate.name())?;
        let mut run = RunFile::new(t, w, y);
        run.has_reference = has_reference;
        run.places = table.places(&names);
        let mut cols = Vec::with_capacity(N);
        for c in need {
            let v = match c {
                Column::Time => run.t_s.clone(),
                Column::RefRate => run.ref_rate_dps.clone(),
                Column::Rate => run.rate_dps.clone(),
                _ => table.column(c.name())?,
            };
            if let Some(s) = run.slot(c) {
                *s = Some(v.clone());
            }
            cols.push(v);
        }
        let cols: [Vec<f64>; N] = cols
            .try_into()
            .unwrap_or_else(|_| unreachable!("one column per name asked"));
        Ok((RunText { run, table }, cols))
    }

    /// Reads a long run file in one pass: the required columns (each
    /// there; `ref_rate_dps` zeros where absent and not required), those
    /// of `optional` the file has; every cell checked row by row, then the
    /// row count (at least `min_rows` in the stretch asked for), then
    /// `t_s` increasing.
    pub fn read_long(
        source: Source,
        spec: &ReadSpec,
        reference: Reference,
        min_rows: usize,
        optional: &[Column],
    ) -> Result<Self, LabError> {
        check_names(spec)?;
        let mut required = vec![Column::Time.name(), Column::Rate.name()];
        let mut optional_names: Vec<&str> = vec![];
        match reference {
            Reference::Required => required.push(Column::RefRate.name()),
            Reference::ZeroIfAbsent => optional_names.push(Column::RefRate.name()),
        }
        optional_names.extend(optional.iter().map(|c| c.name()));
        let rules = |name: &str| rule(name, spec);
        let plan = Plan {
            spec,
            rules: Some(&rules),
            time: Some(Column::Time.name()),
        };
        let (mut c, present) = ColumnStream::read_source(source, &required, &optional_names, plan)?;
        let places = Places {
            origin: c.origin.clone(),
            header_line: c.header_line,
            fields: (0..c.names.len())
                .map(|k| (c.names[k].clone(), c.fields[k], c.shown[k].clone()))
                .collect(),
        };
        if c.len() < min_rows {
            return Err(too_few(&c.origin, c.len(), min_rows, spec));
        }
        c.check_increasing(0)?;
        let mut take = |i: usize| std::mem::take(&mut c.data[i]);
        let (t, y) = (take(0), take(1));
        let (w, has_reference, present) = match reference {
            Reference::Required => (take(2), true, &present[..]),
            Reference::ZeroIfAbsent => match present[0] {
                Some(i) => (take(i), true, &present[1..]),
                None => (vec![0.0; t.len()], false, &present[1..]),
            },
        };
        let mut run = RunFile::new(t, w, y);
        run.has_reference = has_reference;
        run.places = places;
        for (&col, i) in optional.iter().zip(present) {
            let v = i.map(&mut take);
            if let Some(s) = run.slot(col) {
                *s = v;
            }
        }
        Ok(run)
    }
}

/// Too few rows (in the stretch asked for).
fn too_few(origin: &Origin, n: usize, min_rows: usize, spec: &ReadSpec) -> LabError {
    origin.whole(format!(
        "{n} data rows{}, at least {min_rows} needed",
        spec.stretch()
            .map_or(String::new(), |s| format!(" in the stretch {s}"))
    ))
}

/// A run file read whole: its columns and its text, for errors placed at a
/// column and for writing it back with a column added.
pub struct RunText<'a> {
    pub run: RunFile,
    table: TextTable<'a>,
}

impl RunText<'_> {
    /// Reads those of `cols` the file has into the run.
    pub fn fill_optional(&mut self, cols: &[Column]) -> Result<(), LabError> {
        for &c in cols {
            if let Some(v) = self.table.column_opt(c.name())? {
                if let Some(s) = self.run.slot(c) {
                    *s = Some(v);
                }
                let f = self.table.places(&[c.name()]).fields;
                self.run.places.fields.extend(f);
            }
        }
        Ok(())
    }

    /// An error about column `c` as a whole, placed at its header cell.
    pub fn column_error(&self, c: Column, msg: impl Into<String>) -> LabError {
        self.table.column_error(c.name(), msg)
    }

    /// The run as read (every column, in the stretch asked for) with
    /// `added` columns appended, as text; `comment` as `#` lines first.
    pub fn text_with(&self, comment: &str, added: &[(Column, &[f64])]) -> String {
        let extra: Vec<(&str, &[f64])> = added.iter().map(|(c, v)| (c.name(), *v)).collect();
        self.table.text_with(comment, &extra)
    }
}

/// One column of a run file against time, streamed (the Allan analysis of
/// `rate_dps` or any other column a user names): `t_s` increasing; the
/// reference rate beside it where the file has one.
pub struct Series {
    pub t_s: Vec<f64>,
    pub values: Vec<f64>,
    pub reference: Option<Vec<f64>>,
    /// The temperature columns the file has, by name.
    pub temperatures: Vec<(String, Vec<f64>)>,
    stream: ColumnStream,
}

impl Series {
    /// `t_s` and `column` (ours, or the user's through the spec), with the
    /// reference rate and the temperature columns the file has.
    pub fn read(source: Source, column: &str, spec: &ReadSpec) -> Result<Self, LabError> {
        check_names(&ReadSpec {
            rename: spec
                .rename
                .iter()
                .filter(|(o, _)| o != column)
                .cloned()
                .collect(),
            ..Default::default()
        })?;
        let reference = Column::RefRate.name();
        let mut optional: Vec<&str> = vec![];
        if column != reference {
            optional.push(reference);
        }
        let temps = [Column::Temp, Column::MonoA, Column::MonoB, Column::Case];
        optional.extend(temps.iter().map(|c| c.name()).filter(|n| *n != column));
        let owned = spec.clone();
        let col = column.to_owned();
        let rules = move |name: &str| {
            // A column other than the run file's is a rate in deg/s unless
            // its name says otherwise: the unit given applies to it.
            let ours = if name == col
                && !name.ends_with("_dps")
                && Column::ALL.iter().all(|c| c.name() != name)
            {
                Column::Rate.name()
            } else {
                name
            };
            rule(ours, &owned)
        };
        let plan = Plan {
            spec,
            rules: Some(&rules),
            time: Some(Column::Time.name()),
        };
        let (mut stream, present) =
            ColumnStream::read_source(source, &[Column::Time.name(), column], &optional, plan)?;
        stream.check_increasing(0)?;
        let t_s = std::mem::take(&mut stream.data[0]);
        let values = std::mem::take(&mut stream.data[1]);
        let mut present = present.into_iter();
        let reference = if column != reference {
            present
                .next()
                .flatten()
                .map(|k| std::mem::take(&mut stream.data[k]))
        } else {
            None
        };
        let names: Vec<&str> = temps
            .iter()
            .map(|c| c.name())
            .filter(|n| *n != column)
            .collect();
        let temperatures = names
            .into_iter()
            .zip(present)
            .filter_map(|(n, k)| k.map(|k| (n.to_owned(), std::mem::take(&mut stream.data[k]))))
            .collect();
        Ok(Self {
            t_s,
            values,
            reference,
            temperatures,
            stream,
        })
    }

    /// An error at row `row` of `t_s`.
    pub fn time_error(&self, row: usize, msg: impl Into<String>) -> LabError {
        self.stream.cell_error(row, 0, msg)
    }

    /// Drops the first `k` rows.
    pub fn keep_from(&mut self, k: usize) {
        let k = k.min(self.t_s.len());
        self.t_s.drain(..k);
        self.values.drain(..k);
        if let Some(r) = self.reference.as_mut() {
            r.drain(..k);
        }
        for (_, v) in self.temperatures.iter_mut() {
            v.drain(..k);
        }
        self.stream.lines.drain(..k.min(self.stream.lines.len()));
    }

    /// An error about the analysed column as a whole, at its header cell.
    pub fn column_error(&self, msg: impl Into<String>) -> LabError {
        self.stream.origin.column(
            self.stream.header_line,
            self.stream.fields[1],
            &self.stream.shown[1],
            msg,
        )
    }

    /// The analysed column as the file names it.
    pub fn shown(&self) -> &str {
        &self.stream.shown[1]
    }
}

/// A run file written row by row: the columns and each one's number format
/// are the writer's choice.
pub struct RunWriter(CsvWriter);

impl RunWriter {
    pub fn create(
        path: &Path,
        comment: &str,
        columns: &[(Column, CellFormat)],
    ) -> Result<Self, LabError> {
        let cols: Vec<(&str, CellFormat)> = columns.iter().map(|(c, f)| (c.name(), *f)).collect();
        CsvWriter::create(path, comment, &cols).map(Self)
    }

    /// One row, a value per column in the order given to `create`.
    pub fn row(&mut self, values: &[f64]) -> Result<(), LabError> {
        self.0.row(values)
    }

    pub fn finish(self) -> Result<(), LabError> {
        self.0.finish()
    }
}

#[cfg(test)]
mod header_tests {
    use super::super::header::Header;
    use super::*;

    fn header(names: &[&str], rename: &str) -> Header {
        Header::new(
            names.iter().map(|s| s.to_string()).collect(),
            &ReadSpec {
                rename: ReadSpec::parse_rename(rename).unwrap(),
                ..Default::default()
            },
        )
    }

    #[test]
    fn every_missing_column_is_named_with_a_mapping() {
        let h = header(&["time", "gyro_z", "temp"], "");
        let e = h
            .require(
                &Origin::File("a.csv".into()),
                1,
                &["t_s", "ref_rate_dps", "rate_dps"],
            )
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "a.csv:1: missing columns `t_s`, `ref_rate_dps`, `rate_dps`; the file has `time`, `gyro_z`, `temp`; map yours onto them with --columns t_s=time,rate_dps=gyro_z"
        );
    }

    #[test]
    fn a_mapped_column_is_found_by_its_name() {
        let h = header(&["time", "gyro_z"], "rate_dps=gyro_z,t_s=time");
        assert_eq!(h.find("rate_dps"), Some(1));
        assert_eq!(h.shown("rate_dps"), "gyro_z");
        let e = header(&["time", "gz"], "rate_dps=gyro_z")
            .require(&Origin::File("a.csv".into()), 2, &["rate_dps"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`gyro_z` (given for rate_dps by --columns)"),
            "{e}"
        );
    }
}
