//! `gyro-lab allan`: noise analysis of a rate column of a run file
//! (gyro_lab_core's commands::allan): the text or the JSON, allan.csv and
//! the report in `--out`.

use crate::cli::args::{Json, OutOpt, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use clap::Args;
use gyro_lab_core::commands::allan::allan;
use gyro_lab_core::data::allan_file;
use gyro_lab_core::data::run_file::Column;
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A folder: allan.csv and report.html are written in it")))]
pub struct AllanArgs {
    /// Run file (t_s and the rate column; temperature columns where present).
    #[arg(long)]
    pub data: PathBuf,
    /// The rate column to analyse (our name or the file's); less
    /// `ref_rate_dps` where the file has it.
    #[arg(long, default_value = Column::Rate.name())]
    pub column: String,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: OutOpt,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &AllanArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    if let Some(dir) = &a.out.out {
        out_path::folder(
            "allan",
            dir,
            &[
                ("allan.csv", FileKind::Csv),
                ("report.html", FileKind::Html),
            ],
            &[("--data", &a.data)],
            a.out.force,
        )?;
    }
    let big = std::fs::metadata(&a.data).is_ok_and(|m| m.len() > 20_000_000);
    let spinner = if big && !a.json.json {
        let s = indicatif::ProgressBar::new_spinner();
        s.set_message(format!("analysing {}", a.data.display()));
        s.enable_steady_tick(std::time::Duration::from_millis(200));
        s
    } else {
        indicatif::ProgressBar::hidden()
    };
    let o = allan(Source::File(&a.data), &a.column, &spec)?;
    spinner.finish_and_clear();
    if let Some(dir) = &a.out.out {
        out_path::make(dir)?;
        allan_file::write(&dir.join("allan.csv"), &o.rows())?;
        write_report(&o.report(), &dir.join("report.html"))?;
    }
    if a.json.json {
        println!("{}", o.json());
        return Ok(());
    }
    let written = a.out.out.as_ref().map(|dir| {
        format!(
            "{}, {}",
            dir.join("allan.csv").display(),
            dir.join("report.html").display()
        )
    });
    for l in o.text(written.as_deref()) {
        println!("{l}");
    }
    Ok(())
}
