//! `gyro-lab discover`: the arguments, the files it reads and writes
//! (model.toml, residual.csv, report.html); the discovery and its words
//! are gyro_lab_core's commands::discover.

pub mod bench;

use crate::cli::args::{Json, Out, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use clap::{Args, ValueEnum};
use gyro_lab_core::commands::discover::{discover_run, Request};
use gyro_lab_core::commands::model_file::read_model_file;
use gyro_lab_core::data::residual_file;
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use gyro_lab_core::model::grade::Grade;
use gyro_lab_core::model::gyro_kind::GyroKind;
use std::path::{Path, PathBuf};

/// The gyro kinds, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GyroArg {
    Fog,
    Rlg,
    /// A MEMS rate gyro with one temperature sensor (temp_c).
    Mems,
}

impl From<GyroArg> for GyroKind {
    fn from(g: GyroArg) -> Self {
        match g {
            GyroArg::Fog => GyroKind::Fog,
            GyroArg::Rlg => GyroKind::Rlg,
            GyroArg::Mems => GyroKind::Mems,
        }
    }
}

/// The grades, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GradeArg {
    Navigation,
    Tactical,
    Industrial,
    Consumer,
}

impl From<GradeArg> for Grade {
    fn from(g: GradeArg) -> Self {
        match g {
            GradeArg::Navigation => Grade::Navigation,
            GradeArg::Tactical => Grade::Tactical,
            GradeArg::Industrial => Grade::Industrial,
            GradeArg::Consumer => Grade::Consumer,
        }
    }
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A folder: model.toml, residual.csv and report.html are written in it")))]
pub struct DiscoverArgs {
    /// The gyro the run is from: its kind sets the ideal model and the library of effects.
    #[arg(long, value_enum)]
    pub gyro: GyroArg,
    /// The gyro's grade: sets the physical ranges of the effects'
    /// parameters (judged from the run's white noise without it).
    #[arg(long, value_enum)]
    pub grade: Option<GradeArg>,
    /// Another run of the same gyro: the model written must predict it
    /// too (up to a bias).
    #[arg(long)]
    pub validate: Option<PathBuf>,
    /// The model (model.toml); the ideal gyro without it.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Run file (t_s, rate_dps, ref_rate_dps unless static; temp_c,
    /// t_mono_a_c, t_mono_b_c, t_case_c, ref_acc_dps2 where the effects
    /// need them).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &DiscoverArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    let mut inputs: Vec<(&str, &Path)> = vec![("--data", &a.data)];
    if let Some(p) = &a.model {
        inputs.push(("--model", p));
    }
    if let Some(p) = &a.validate {
        inputs.push(("--validate", p));
    }
    out_path::folder(
        "discover",
        &a.out.out,
        &[
            ("model.toml", FileKind::Toml("gyro_model")),
            ("residual.csv", FileKind::Csv),
            ("report.html", FileKind::Html),
        ],
        &inputs,
        a.out.force,
    )?;
    let gyro = GyroKind::from(a.gyro);
    let model = match &a.model {
        Some(p) => Some((read_model_file(p, gyro)?, p.display().to_string())),
        None => None,
    };
    let o = discover_run(Request {
        source: Source::File(&a.data),
        spec: &spec,
        gyro,
        model,
        grade: a.grade.map(Grade::from),
        validate: a.validate.as_deref().map(Source::File),
    })?;
    let out = &a.out.out;
    out_path::make(out)?;
    gyro_lab_core::data::atomic::write(&out.join("model.toml"), o.model_toml())?;
    residual_file::write(
        &out.join("residual.csv"),
        &o.data.inputs.t,
        &o.d.residual_before,
        &o.d.residual_after,
    )?;
    write_report(&o.report(), &out.join("report.html"))?;
    if a.json.json {
        println!("{}", o.json());
        return Ok(());
    }
    let written = format!(
        "{}, residual.csv, report.html",
        out.join("model.toml").display()
    );
    for l in o.text(Some(&written)) {
        println!("{l}");
    }
    Ok(())
}
