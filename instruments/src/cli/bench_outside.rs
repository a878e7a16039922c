//! `gyro-instruments bench discover-outside`: discovery on the outside generator's
//! cases (`simulate outside`): for each case, discovery on run A from the
//! ideal gyro, in-process, on all cores; what the model added against the
//! hidden term, the gap after, the model found on A against run B; scored
//! by bench/discover_outside.rs; the table per category, and with `--json`
//! its JSON line.

use crate::bench::discover_outside::{
    means_1s, score, totals, CaseTruth, Evidence, Scored, Totals, GAP_FACTOR, MIN_CORRELATION,
    PREDICT_FACTOR,
};
use crate::cli::outside::HIDDEN_COLUMN;
use clap::Args;
use gyro_lab::cli::args::Json;
use gyro_lab::cli::output::progress_bar;
use gyro_lab_core::data::run_file::Column;
use gyro_lab_core::data::source::Source;
use gyro_lab_core::data::table::ColumnStream;
use gyro_lab_core::error::LabError;
use gyro_lab_core::model::discovery::discover;
use gyro_lab_core::model::gyro_kind::GyroKind;
use gyro_lab_core::model::gyro_model::Model;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Args, Debug, Clone)]
pub struct OutsideBenchArgs {
    /// The directory `simulate outside` wrote (runs, hidden terms, truth.json).
    #[arg(long)]
    pub runs: std::path::PathBuf,
    /// Threads (default: the cores available).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Instead of discovery, each kind's right formula in the term
    /// language with the truth's shape parameters, only its coefficient
    /// and a bias fitted on run A (least squares): whether a case can be
    /// explained from the run file's columns at all. A reference for
    /// discovery, not a score of it.
    #[arg(long)]
    pub oracle: bool,
    #[command(flatten)]
    pub json: Json,
}

/// The hidden term per row, deg/h, from its side file.
fn read_hidden(path: &Path) -> Result<(Vec<f64>, Vec<f64>), LabError> {
    let mut c = ColumnStream::read(path, &[Column::Time.name(), HIDDEN_COLUMN])?;
    let h = c.data.pop().unwrap_or_default();
    let t = c.data.pop().unwrap_or_default();
    Ok((t, h))
}

/// The oracle's formula for a kind (unit coefficient, deg/h) on the run
/// file's columns, and the truth's shape parameters it names; None for a
/// null. Written with placeholders for the columns ({w} rate, {T} coil,
/// {case}, {a}, {b} the RLG's sensors, {acc}, {t} time).
fn oracle_formula(kind: &str) -> Option<(String, Vec<&'static str>)> {
    let (f, p): (&str, Vec<&'static str>) = match kind {
        "w2" => ("{w}^2", vec![]),
        "w3" => ("{w}^3", vec![]),
        "w_abs_w" => ("{w} * abs({w})", vec![]),
        "bias_temp_quadratic" => ("({T} - t0_c)^2", vec!["t0_c"]),
        "sf_temp_quadratic" => ("{w} * ({T} - t0_c)^2", vec!["t0_c"]),
        "coil_curvature" => ("d2dt2({T})", vec![]),
        "sf_temp_rate" => ("{w} * ddt({T})", vec![]),
        "case_minus_mono" => ("{case} - ({a} + {b})/2", vec![]),
        "case_rate" => ("ddt({case})", vec![]),
        "abs_acc" => ("abs({acc})", vec![]),
        // (1 + tanh(x/r))/2 = (step(x) + (1 - step(x)) e)/(1 + e) with
        // e = exp(-2|x|/r): never overflows.
        "step" => (
            "(step({t} - t0_s) + (1 - step({t} - t0_s)) * exp(-2*abs({t} - t0_s)/rise_s)) / (1 + exp(-2*abs({t} - t0_s)/rise_s))",
            vec!["t0_s", "rise_s"],
        ),
        "periodic" => (
            "sin(2*pi*{t}/period_s + phase_rad)",
            vec!["period_s", "phase_rad"],
        ),
        "ageing_ramp" => ("({t} - t1_s) * step({t} - t1_s)", vec!["t1_s"]),
        "settling" => (
            "(1 - exp(-({t} - t1_s)/tau_s)) * step({t} - t1_s)",
            vec!["t1_s", "tau_s"],
        ),
        "lib_scale_factor_error" => ("{w}", vec![]),
        "lib_bias_temperature" => ("{T} - 20", vec![]),
        "lib_case_temperature" => ("{case} - 20", vec![]),
        _ => return None,
    };
    let mut f = f.to_owned();
    for (k, c) in [
        ("{w}", Column::RefRate),
        ("{T}", Column::Temp),
        ("{case}", Column::Case),
        ("{a}", Column::MonoA),
        ("{b}", Column::MonoB),
        ("{acc}", Column::RefAcc),
        ("{t}", Column::Time),
    ] {
        f = f.replace(k, c.name());
    }
    Some((f, p))
}

/// The oracle's model on run A: a bias and the kind's formula, their
/// coefficients by least squares; with the names a tool would print.
fn oracle_model(
    g: GyroKind,
    t: &CaseTruth,
    run: &gyro_lab_core::model::discovery::Run,
) -> Result<(Model, Vec<String>, f64), LabError> {
    use gyro_lab_core::model::term::Term;
    let inp = &run.inputs;
    let y: Vec<f64> = run
        .rate
        .iter()
        .zip(&inp.w)
        .map(|(r, w)| (r - w) * 3600.0)
        .collect();
    let n = y.len() as f64;
    let mut m = Model::ideal(g);
    let (shape, params) = match oracle_formula(&t.kind) {
        Some((f, names)) => {
            let p: BTreeMap<String, f64> = names
                .iter()
                .map(|k| {
                    (
                        k.to_string(),
                        t.parameters.get(*k).copied().unwrap_or(f64::NAN),
                    )
                })
                .collect();
            let term = Term::new(&f, p.clone())
                .map_err(|e| LabError::Bench(format!("oracle formula {f}: {}", e.msg)))?;
            let s = term
                .evaluate(inp)
                .map_err(|e| LabError::Bench(format!("oracle formula {f}: {e:?}")))?;
            (Some((f, s)), p)
        }
        None => (None, BTreeMap::new()),
    };
    let my = y.iter().sum::<f64>() / n;
    let (b, named) = match &shape {
        Some((f, s)) => {
            // y = b + k s: the 2 x 2 normal equations about the means.
            let ms = s.iter().sum::<f64>() / n;
            let (mut sxy, mut sxx) = (0.0, 0.0);
            for (yi, si) in y.iter().zip(s) {
                sxy += (si - ms) * (yi - my);
                sxx += (si - ms) * (si - ms);
            }
            let k = sxy / sxx;
            let mut p = params.clone();
            p.insert("k_oracle".into(), k);
            let term = Term::new(&format!("k_oracle * ({f})"), p)
                .map_err(|e| LabError::Bench(format!("oracle formula {f}: {}", e.msg)))?;
            m.terms.push(term);
            let names = if t.category == "library" {
                t.expect.clone()
            } else {
                vec!["term".to_owned()]
            };
            (my - k * ms, names)
        }
        None => (my, vec![]),
    };
    let bias = Term::new("b_oracle", [("b_oracle".to_owned(), b)].into())
        .map_err(|e| LabError::Bench(format!("oracle bias: {}", e.msg)))?;
    m.terms.push(bias);
    let r: Vec<f64> = run
        .rate
        .iter()
        .zip(m.evaluate(inp))
        .map(|(a, b)| (a - b) * 3600.0)
        .collect();
    let r1 = means_1s(&inp.t, &r);
    let gap = (r1.iter().map(|x| x * x).sum::<f64>() / r1.len().max(1) as f64).sqrt();
    let mut named = named;
    if t.category != "null" {
        // The fitted constant is a bias the truth allows; on a null the
        // oracle names nothing (its constant stands for the carried one).
        named.insert(0, "bias".to_owned());
    }
    Ok((m, named, gap))
}

/// Discovery (or the oracle) on a case's run A, and the model it writes
/// on run B.
fn one(dir: &Path, t: &CaseTruth, oracle: bool) -> Result<Scored, LabError> {
    let run = gyro_lab_core::commands::discover::read_run(
        Source::File(&dir.join(&t.a.file)),
        &Default::default(),
    )?
    .0;
    let g = GyroKind::from_name(&t.gyro).ok_or_else(|| {
        LabError::input(dir.join("truth.json"), format!("gyro {:?} unknown", t.gyro))
    })?;
    let given = Model::ideal(g);
    let (model_after, named, gap_after, tool_floor) = if oracle {
        let (m, named, gap) = oracle_model(g, t, &run)?;
        (m, named, gap, f64::NAN)
    } else {
        let d = discover(&given, &run, &Default::default());
        let j = gyro_lab_core::commands::discover::json(&d);
        let named: Vec<String> = j["found"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|f| f["effect"].as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default();
        (d.model_after, named, d.gap_after_dph, d.noise_floor_dph)
    };
    let inp = &run.inputs;
    let added: Vec<f64> = model_after
        .evaluate(inp)
        .iter()
        .zip(given.evaluate(inp))
        .map(|(a, b)| (a - b) * 3600.0)
        .collect();
    let hp = dir.join(&t.a.hidden);
    let (ht, hidden) = read_hidden(&hp)?;
    if ht.len() != inp.t.len() {
        return Err(LabError::input(
            &hp,
            format!("{} rows, the run has {}", ht.len(), inp.t.len()),
        ));
    }
    let rb = gyro_lab_core::commands::discover::read_run(
        Source::File(&dir.join(&t.b.file)),
        &Default::default(),
    )?
    .0;
    let yb = model_after.evaluate(&rb.inputs);
    let res_b: Vec<f64> = rb
        .rate
        .iter()
        .zip(&yb)
        .map(|(r, y)| (r - y) * 3600.0)
        .collect();
    let e = Evidence {
        named,
        added_1s: means_1s(&inp.t, &added),
        hidden_1s: means_1s(&inp.t, &hidden),
        gap_after_dph: gap_after,
        tool_floor_dph: tool_floor,
        residual_b_1s: means_1s(&rb.inputs.t, &res_b),
    };
    Ok(score(t, &e))
}

fn print_table(dir: &Path, scored: &[Scored], tot: &BTreeMap<String, Totals>) {
    println!(
        "discovery beyond the library on {} ({} cases, each run A discovered from the ideal gyro, run B predicted)",
        dir.display(),
        scored.len()
    );
    for s in scored {
        let mark = if s.right { "right" } else { "WRONG" };
        println!(
            "  {:<5} {:<26} named [{}] corr {:>6.3} gap {:.3}/{:.3} deg/h (tool floor {:.3}) B {:.3}/{:.3}{}",
            mark,
            s.name,
            s.named.join(", "),
            s.correlation,
            s.gap_after_dph,
            s.floor_a_dph,
            s.tool_floor_dph,
            s.b_rms_dph,
            s.floor_b_dph,
            if s.false_names.is_empty() {
                String::new()
            } else {
                format!(" false names [{}]", s.false_names.join(", "))
            }
        );
    }
    println!(
        "{:<10} {:>4} {:>10} {:>10} {:>6} {:>10} {:>12} {:>12} {:>6}",
        "category",
        "n",
        "explained",
        "predicts B",
        "both",
        "with term",
        "false terms",
        "false names",
        "right"
    );
    for (k, t) in tot {
        println!(
            "{:<10} {:>4} {:>10} {:>10} {:>6} {:>10} {:>12} {:>12} {:>6}",
            k,
            t.n,
            t.explained,
            t.predicts_b,
            t.explained_and_predicts_b,
            t.with_term,
            t.false_terms,
            t.false_names,
            t.right
        );
    }
    let get = |k: &str| tot.get(k).cloned().unwrap_or_default();
    let pct = |a: usize, n: usize| 100.0 * a as f64 / n.max(1) as f64;
    let (p, e, nu, l) = (get("physical"), get("event"), get("null"), get("library"));
    println!(
        "physical terms explained {}/{} ({:.0} %, bar 80 %), and B predicted too {}/{}",
        p.explained,
        p.n,
        pct(p.explained, p.n),
        p.explained_and_predicts_b,
        p.n
    );
    println!(
        "events explained {}/{} ({:.0} %, bar 80 %), and B predicted too {}/{}",
        e.explained,
        e.n,
        pct(e.explained, e.n),
        e.explained_and_predicts_b,
        e.n
    );
    println!(
        "nulls with any term {}/{} (bar 0), with anything named {}/{} (bar 0)",
        nu.with_term, nu.n, nu.anything_named, nu.n
    );
    println!(
        "library runs named right {}/{} (bar all), with a term {}",
        l.right, l.n, l.with_term
    );
    println!(
        "rules: explained = correlation of the model's addition with the hidden term >= {MIN_CORRELATION}, gap after <= {GAP_FACTOR} x run A's realised noise (truth noise_1s_dph), no library name beyond the truth's; \
         predicts B = B's residual less its mean <= {PREDICT_FACTOR} x B's realised noise (1 s means)"
    );
}

pub fn run_bench(a: &OutsideBenchArgs) -> Result<(), LabError> {
    let tp = a.runs.join("truth.json");
    let text = std::fs::read_to_string(&tp)
        .map_err(|e| LabError::input(&tp, format!("cannot read: {e}")))?;
    let truth: Vec<CaseTruth> =
        serde_json::from_str(&text).map_err(|e| LabError::input(&tp, e.to_string()))?;
    let threads = a
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |p| p.get()))
        .max(1);
    let bar = progress_bar(
        truth.len() as u64,
        "{bar:40} {pos}/{len} cases {eta}",
        a.json.json,
    );
    let mut results: Vec<Option<Result<Scored, LabError>>> =
        (0..truth.len()).map(|_| None).collect();
    std::thread::scope(|sc| {
        let hs: Vec<_> = (0..threads)
            .map(|k| {
                let (truth, bar, dir) = (&truth, &bar, &a.runs);
                sc.spawn(move || {
                    (k..truth.len())
                        .step_by(threads)
                        .map(|i| {
                            let r = one(dir, &truth[i], a.oracle);
                            bar.inc(1);
                            (i, r)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in hs {
            for (i, r) in h.join().unwrap_or_default() {
                results[i] = Some(r);
            }
        }
    });
    bar.finish_and_clear();
    let mut scored = vec![];
    for r in results {
        match r {
            Some(r) => scored.push(r?),
            None => return Err(LabError::Bench("a bench thread stopped".into())),
        }
    }
    let tot = totals(&scored);
    if !a.json.json {
        if a.oracle {
            println!("ORACLE: each kind's right formula with the truth's shape parameters, coefficient and bias fitted on run A (not discovery)");
        }
        print_table(&a.runs, &scored, &tot);
        return Ok(());
    }
    println!(
        "{}",
        serde_json::json!({
            "cases": scored.len(),
            "oracle": a.oracle,
            "totals": tot,
            "rules": {
                "min_correlation": MIN_CORRELATION,
                "gap_factor": GAP_FACTOR,
                "predict_factor": PREDICT_FACTOR,
                "floor": "truth noise_1s_dph: RMS of the 1 s means of measured minus the true output, about their mean",
            },
            "scored": scored,
        })
    );
    Ok(())
}
