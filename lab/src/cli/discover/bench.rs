//! `gyro-lab bench discover`: the lab's generator's randomised trials,
//! the confusion table, and with `--json` its JSON line.

use crate::cli::args::{Json, Seed};
use crate::cli::output::progress_bar;
use clap::Args;
use gyro_lab_core::bench::discover_categories::{trials, TrialCounts};
use gyro_lab_core::bench::discover_summary::{summarize, Summary};
use gyro_lab_core::bench::discover_trials::run_all;
use gyro_lab_core::error::LabError;

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
    let mut rows: Vec<(&String, &gyro_lab_core::bench::discover_summary::Tally)> =
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
