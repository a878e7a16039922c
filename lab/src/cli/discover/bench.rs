//! `gyro-lab bench discover` (the project's generator's randomised trials:
//! the confusion table) and `gyro-lab bench discover-heldout` (an
//! independent generator's held-out set, `simulate heldout`): their
//! tables, and with `--json` their JSON line.

use crate::bench::discover_categories::{trials, TrialCounts};
use crate::bench::discover_summary::{summarize, Summary};
use crate::bench::discover_trials::run_all;
use crate::cli::args::{Json, Seed};
use crate::cli::output::progress_bar;
use crate::error::LabError;
use clap::Args;

#[derive(Args, Debug, Clone)]
pub struct DiscoverBenchArgs {
    /// Trials per effect of the library (14 effects), alone.
    #[arg(long, default_value_t = 8)]
    pub per_effect: u64,
    /// Trials per effect of the library at 1.5 times the noise floor (weak effects).
    #[arg(long, default_value_t = 1)]
    pub weak: u64,
    /// Trials with nothing missing (white noise only).
    #[arg(long, default_value_t = 14)]
    pub nothing: u64,
    /// Trials with two effects hidden at once.
    #[arg(long, default_value_t = 8)]
    pub pairs: u64,
    /// Trials with two effects whose regressors correlate (the run cannot tell them apart).
    #[arg(long, default_value_t = 8)]
    pub collinear: u64,
    /// Null trials with coloured noise (random walk, flicker, Markov).
    #[arg(long, default_value_t = 12)]
    pub coloured: u64,
    /// Trials with a decaying warm-up.
    #[arg(long, default_value_t = 10)]
    pub decaying: u64,
    /// Trials per thermal term with a bias (5 terms).
    #[arg(long, default_value_t = 3)]
    pub bias_thermal: u64,
    /// Trials per disturbance outside the library (13 kinds).
    #[arg(long, default_value_t = 3)]
    pub outside: u64,
    #[command(flatten)]
    pub seed: Seed,
    #[command(flatten)]
    pub json: Json,
}

fn print_discover(s: &Summary, n: usize) {
    println!("discovery on {n} randomized trials (hidden effects, drawn parameters and seeds; the project's generators)");
    println!("confusion: what was hidden (rows) against what was said");
    for (row, cols) in &s.confusion {
        let cells: Vec<String> = cols
            .iter()
            .filter(|(k, _)| *k != "trials" && *k != "right")
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        println!(
            "  {:<50} {:>3} trials, {:>3} right: {}",
            row,
            cols.get("trials").copied().unwrap_or(0),
            cols.get("right").copied().unwrap_or(0),
            cells.join(", ")
        );
    }
    println!(
        "{:<36} {:>6} {:>6} {:>6} {:>9} {:>11} {:>12}",
        "category", "trials", "right", "false", "gap grew", "unexplained", "coverage"
    );
    let mut rows: Vec<(&String, &crate::bench::discover_summary::Tally)> =
        s.categories.iter().collect();
    let all = "all".to_string();
    rows.push((&all, &s.total));
    for (name, t) in rows {
        println!(
            "{:<36} {:>6} {:>6} {:>6} {:>9} {:>11} {:>5}/{:<3} {:>5.1} %",
            name,
            t.trials,
            t.right,
            t.false_names,
            t.gap_grew,
            t.unexplained,
            t.covered,
            t.intervals,
            t.coverage_pct()
        );
    }
    let b = &s.beyond;
    println!(
        "outside the library: physical terms explained {}/{} (what the model added correlating >= 0.95 with the hidden term, the gap after <= 1.25 x the floor), events {}/{} ({} of those explained with library effects named beside or instead of a term); \
         the model written predicted a second run (gap, bias removed, <= 1.5 x the floor) in {}/{}; a term named on {}/{} nulls and {}/{} runs hiding library effects",
        b.physical_explained,
        b.physical,
        b.events_explained,
        b.events,
        b.explained_with_library_names,
        b.second_runs_predicted,
        b.second_runs,
        b.nulls_with_term,
        b.nulls,
        b.library_with_term,
        b.library
    );
    let t = &s.total;
    println!(
        "right {}/{} ({:.1} %); false names {}; the gap grew in {}; 95 % intervals hold the truth for {}/{} parameters ({:.1} %) of the named hidden effects; \
         of those named right, every parameter within 10 %: {}/{}, the gap to reality shrunk 80 %: {}/{}",
        t.right,
        t.trials,
        100.0 * t.right as f64 / t.trials.max(1) as f64,
        t.false_names,
        t.gap_grew,
        t.covered,
        t.intervals,
        t.coverage_pct(),
        t.params_ok,
        t.named_right_with_truth,
        t.gap_ok,
        t.named_right_with_truth
    );
}

pub fn discover(a: &DiscoverBenchArgs) -> Result<(), LabError> {
    let list = trials(&TrialCounts {
        per_effect: a.per_effect,
        nothing: a.nothing,
        pairs: a.pairs,
        collinear: a.collinear,
        coloured: a.coloured,
        bias_thermal: a.bias_thermal,
        decaying: a.decaying,
        outside: a.outside,
        weak: a.weak,
        seed: a.seed.seed,
    });
    let bar = progress_bar(
        list.len() as u64,
        "{bar:40} {pos}/{len} trials {eta}",
        a.json.json,
    );
    let outcomes = run_all(&list, || bar.inc(1));
    bar.finish_and_clear();
    let s = summarize(&outcomes);
    if !a.json.json {
        // The table only: the outcomes' JSON is for --json.
        print_discover(&s, outcomes.len());
        return Ok(());
    }
    println!(
        "{}",
        serde_json::json!({
            "trials": outcomes.len(),
            "right": s.total.right,
            "false_names": s.total.false_names,
            "gap_grew": s.total.gap_grew,
            "intervals": s.total.intervals,
            "covered": s.total.covered,
            "coverage_pct": s.total.coverage_pct(),
            "categories": s.categories,
            "beyond_library": s.beyond,
            "confusion": s.confusion,
            "outcomes": outcomes,
        })
    );
    Ok(())
}

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
    use crate::model::discovery::{discover as run_discover, Options};
    use crate::model::gyro_kind::GyroKind;
    use crate::model::gyro_model::Model;
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
                let run = crate::cli::discover::read_run(&csv, &Default::default())?.0;
                let g = GyroKind::from_name(&t.gyro).unwrap_or(GyroKind::Fog);
                let d = run_discover(&Model::ideal(g), &run, &Default::default());
                // A second day of the same gyro: the model written must
                // predict it up to a bias.
                let v = match &t.validate {
                    Some(f) => {
                        let r2 =
                            crate::cli::discover::read_run(&a.runs.join(f), &Default::default())?.0;
                        let opts = Options {
                            grade: Some(d.grade.value),
                        };
                        Some(crate::cli::discover::predicts(&run_discover(
                            &d.model_after,
                            &r2,
                            &opts,
                        )))
                    }
                    None => None,
                };
                (crate::cli::discover::json(&d), v)
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
