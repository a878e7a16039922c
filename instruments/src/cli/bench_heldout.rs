//! `gyro-instruments bench discover-heldout`: discovery on an
//! independent generator's held-out set (`simulate heldout`), scored
//! against its truth.

use clap::Args;
use gyro_lab::cli::args::Json;
use gyro_lab::cli::output::progress_bar;
use gyro_lab_core::error::LabError;

#[derive(Args, Debug, Clone)]
pub struct HeldOutBenchArgs {
    /// The directory `simulate heldout` wrote (runs and truth.json).
    #[arg(long)]
    pub runs: std::path::PathBuf,
    /// Score the JSON another `discover` printed, one `<run>.json` per run
    /// here (its last line), instead of running this one.
    #[arg(long)]
    pub results: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub json: Json,
}

/// A run's index in the set, its score and whether its second day was
/// predicted (None: it has none).
type Indexed = (
    usize,
    Result<(crate::bench::discover_heldout::Scored, Option<bool>), LabError>,
);

pub fn discover_heldout(a: &HeldOutBenchArgs) -> Result<(), LabError> {
    use crate::bench::discover_heldout::{score, totals, Scored, Truth};
    use gyro_lab_core::model::discovery::{discover as run_discover, Options};
    use gyro_lab_core::model::gyro_kind::GyroKind;
    use gyro_lab_core::model::gyro_model::Model;
    let tp = a.runs.join("truth.json");
    let text = std::fs::read_to_string(&tp)
        .map_err(|e| LabError::input(&tp, format!("cannot read: {e}")))?;
    let truth: Vec<Truth> =
        serde_json::from_str(&text).map_err(|e| LabError::input(&tp, e.to_string()))?;
    let bar = progress_bar(
        truth.len() as u64,
        "{bar:40} {pos}/{len} runs {eta}",
        a.json.json,
    );
    // Each run on its own (two threads: the machine's cores), scored in
    // the truth's order.
    let one = |t: &Truth| -> Result<(Scored, Option<bool>), LabError> {
        let csv = a.runs.join(&t.file);
        let (r, validated) = match &a.results {
            Some(dir) => {
                let p = dir.join(t.file.replace(".csv", ".json"));
                let s = std::fs::read_to_string(&p)
                    .map_err(|e| LabError::input(&p, format!("cannot read: {e}")))?;
                let j: serde_json::Value = serde_json::from_str(s.lines().last().unwrap_or("{}"))
                    .map_err(|e| LabError::input(&p, e.to_string()))?;
                let v = j["validation"]["predicts"].as_bool();
                (j, v)
            }
            None => {
                let run = gyro_lab_core::commands::discover::read_run(
                    gyro_lab_core::data::source::Source::File(&csv),
                    &Default::default(),
                )?
                .0;
                let g = GyroKind::from_name(&t.gyro).unwrap_or(GyroKind::Fog);
                let d = run_discover(&Model::ideal(g), &run, &Default::default());
                // A second day of the same gyro: the model written must
                // predict it up to a bias.
                let v = match &t.validate {
                    Some(f) => {
                        let r2 = gyro_lab_core::commands::discover::read_run(
                            gyro_lab_core::data::source::Source::File(&a.runs.join(f)),
                            &Default::default(),
                        )?
                        .0;
                        let opts = Options::with_grade(Some(d.grade.value));
                        Some(gyro_lab_core::commands::discover::predicts(&run_discover(
                            &d.model_after,
                            &r2,
                            &opts,
                        )))
                    }
                    None => None,
                };
                (gyro_lab_core::commands::discover::json(&d), v)
            }
        };
        Ok((score(t, &r), validated))
    };
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Vec<Indexed>> = std::thread::scope(|sc| {
        let workers: Vec<_> = (0..2)
            .map(|_| {
                sc.spawn(|| {
                    let mut out = vec![];
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(t) = truth.get(i) else {
                            break;
                        };
                        out.push((i, one(t)));
                        bar.inc(1);
                    }
                    out
                })
            })
            .collect();
        workers
            .into_iter()
            .map(|w| w.join().unwrap_or_default())
            .collect()
    });
    let mut all: Vec<Indexed> = results.into_iter().flatten().collect();
    all.sort_by_key(|x| x.0);
    let mut scored = vec![];
    let mut second_days: Vec<(String, bool)> = vec![];
    for (i, r) in all {
        let (s, v) = r?;
        if let Some(v) = v {
            second_days.push((truth[i].name.clone(), v));
        }
        scored.push(s);
    }
    bar.finish_and_clear();
    let tot = totals(&scored);
    if !a.json.json {
        println!(
            "discovery on the held-out set of {} ({} runs)",
            a.runs.display(),
            scored.len()
        );
        for s in &scored {
            let mark = if s.right { "right" } else { "WRONG" };
            let miss: Vec<String> = s
                .missed
                .iter()
                .map(|(e, p, v, lo, hi)| format!("{e}.{p} {v:.4e} outside [{lo:.4e}, {hi:.4e}]"))
                .collect();
            println!(
                "  {:<5} {:<34} expect [{}] named [{}]{}{}{}",
                mark,
                s.name,
                s.expect.join(", "),
                s.named.join(", "),
                if s.ambiguous.is_empty() {
                    String::new()
                } else {
                    format!(" ambiguous {:?}", s.ambiguous)
                },
                if s.unexplained { " unexplained" } else { "" },
                if miss.is_empty() {
                    String::new()
                } else {
                    format!("; missed: {}", miss.join("; "))
                }
            );
        }
        println!(
            "{:<36} {:>5} {:>6} {:>6} {:>9} {:>11} {:>12}",
            "category", "runs", "right", "false", "gap grew", "unexplained", "coverage"
        );
        for (k, t) in &tot {
            println!(
                "{:<36} {:>5} {:>6} {:>6} {:>9} {:>11} {:>5}/{:<3} {:>5.1} %",
                k,
                t.runs,
                t.right,
                t.false_names,
                t.gap_grew,
                t.unexplained,
                t.covered,
                t.intervals,
                100.0 * t.covered as f64 / t.intervals.max(1) as f64
            );
        }
    }
    let predicted = second_days.iter().filter(|x| x.1).count();
    if !a.json.json {
        if !second_days.is_empty() {
            let miss: Vec<&str> = second_days
                .iter()
                .filter(|x| !x.1)
                .map(|x| x.0.as_str())
                .collect();
            println!(
                "second day of the same gyro predicted up to a bias by the model written on the first: {predicted}/{}{}",
                second_days.len(),
                if miss.is_empty() {
                    String::new()
                } else {
                    format!(" (not: {})", miss.join(", "))
                }
            );
        }
        return Ok(());
    }
    println!(
        "{}",
        serde_json::json!({
            "totals": tot,
            "runs": scored,
            "second_days": second_days.len(),
            "second_days_predicted": predicted,
        })
    );
    Ok(())
}
