//! The run file (docs/interfaces.md "Run file"): a test-rig or simulation
//! record. Its columns are a type, [`Column`]; it is read and written here
//! and nowhere else, so no other module spells a column's name.

use super::csv_writer::{CellFormat, CsvWriter};
use super::table::{ColumnStream, TextTable};
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

/// The physical range of a run file's column, by the unit its name ends
/// in: a value outside it is no gyro's, rate table's or sensor's (1e300
/// deg/s would turn every sum into infinity and every answer into
/// nothing). Time is judged by its increase instead.
pub fn bounds(name: &str) -> Option<(f64, f64, &'static str)> {
    if name.ends_with("_dps2") {
        Some((
            -1e8,
            1e8,
            "the angular accelerations a rig gives (|x| <= 1e8 deg/s^2)",
        ))
    } else if name.ends_with("_dps") {
        Some((
            -1e5,
            1e5,
            "the rates a gyro or a rate table gives (|x| <= 1e5 deg/s)",
        ))
    } else if name.ends_with("_c") {
        Some((
            -273.15,
            1000.0,
            "the temperatures a sensor reads (-273.15 .. 1000 degC)",
        ))
    } else {
        None
    }
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
    /// [`RunText::write_back`]), checking in this order: the row count (at
    /// least `min_rows`), `t_s` (increasing), `ref_rate_dps`, `rate_dps`,
    /// then each column of `need`, which must be there: they come back in
    /// the order asked (and in the run's fields).
    pub fn read<const N: usize>(
        path: &Path,
        min_rows: usize,
        need: [Column; N],
    ) -> Result<(RunText, [Vec<f64>; N]), LabError> {
        let table = TextTable::read_bounded(path, Some(bounds))?;
        let t = table.time(Column::Time.name(), min_rows)?;
        let w = table.column(Column::RefRate.name())?;
        let y = table.column(Column::Rate.name())?;
        let mut run = RunFile::new(t, w, y);
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
    /// there), those of `optional` the file has; every cell checked row by
    /// row, then the row count (at least `min_rows`), then `t_s`
    /// increasing.
    pub fn read_long(path: &Path, min_rows: usize, optional: &[Column]) -> Result<Self, LabError> {
        let required = [Column::Time, Column::RefRate, Column::Rate].map(Column::name);
        let optional_names: Vec<&str> = optional.iter().map(|c| c.name()).collect();
        let (mut c, present) =
            ColumnStream::read_bounded(path, &required, &optional_names, Some(bounds))?;
        if c.len() < min_rows {
            return Err(LabError::input(
                path,
                format!("{} data rows, at least {min_rows} needed", c.len()),
            ));
        }
        c.check_increasing(0)?;
        let mut take = |i: usize| std::mem::take(&mut c.data[i]);
        let mut run = RunFile::new(take(0), take(1), take(2));
        for (&col, i) in optional.iter().zip(present) {
            let v = i.map(&mut take);
            if let Some(s) = run.slot(col) {
                *s = v;
            }
        }
        Ok(run)
    }
}

/// A run file read whole: its columns and its text, for errors placed at a
/// column and for writing it back with a column added.
pub struct RunText {
    pub run: RunFile,
    table: TextTable,
}

impl RunText {
    /// An error about column `c` as a whole, placed at its header cell.
    pub fn column_error(&self, c: Column, msg: impl Into<String>) -> LabError {
        self.table.column_error(c.name(), msg)
    }

    /// Writes the run back as read (every column, comments dropped) with
    /// `added` columns appended.
    pub fn write_back(&self, out: &Path, added: &[(Column, &[f64])]) -> Result<(), LabError> {
        let extra: Vec<(&str, &[f64])> = added.iter().map(|(c, v)| (c.name(), *v)).collect();
        self.table.write_with(out, &extra)
    }
}

/// One column of a run file against time, streamed (the Allan analysis of
/// `rate_dps` or any other column a user names): `t_s` increasing; the
/// reference rate beside it where the file has one.
pub struct Series {
    pub t_s: Vec<f64>,
    pub values: Vec<f64>,
    pub reference: Option<Vec<f64>>,
    stream: ColumnStream,
}

impl Series {
    pub fn read(path: &Path, column: &str) -> Result<Self, LabError> {
        let reference = Column::RefRate.name();
        let optional: &[&str] = if column == reference {
            &[]
        } else {
            &[reference]
        };
        let (mut stream, present) = ColumnStream::read_bounded(
            path,
            &[Column::Time.name(), column],
            optional,
            Some(bounds),
        )?;
        stream.check_increasing(0)?;
        let t_s = std::mem::take(&mut stream.data[0]);
        let values = std::mem::take(&mut stream.data[1]);
        let reference = present
            .first()
            .copied()
            .flatten()
            .map(|k| std::mem::take(&mut stream.data[k]));
        Ok(Self {
            t_s,
            values,
            reference,
            stream,
        })
    }

    /// An error at row `row` of `t_s`.
    pub fn time_error(&self, row: usize, msg: impl Into<String>) -> LabError {
        self.stream.cell_error(row, 0, msg)
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
