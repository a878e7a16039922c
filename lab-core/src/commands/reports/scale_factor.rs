//! The report of `fit scale-factor`: the verdict; the measured scale factor
//! against coil temperature (binned means with standard errors) with the
//! chosen model, the firmware's table and each knee's 95 % band (a close
//! look at each knee); the criterion of every family and knee count; the
//! residual against temperature and time; the coil sensor's lag; for a
//! multi-point run its plateaus with error bars.

use super::{against_floor, warnings, MAX_POINTS};
use crate::calibration::scale_factor::diagnostics::{SfDiagnostics, TempBin};
use crate::calibration::scale_factor::multipoint::Plateau;
use crate::calibration::scale_factor::result::{FitMethod, SfFit};
use crate::report::document::Report;
use crate::report::plot::{thin, Axes, Series};
use crate::report::text::num;
use crate::report::verdict::Verdict;

const T_AXIS: &str = "coil temperature, degC";
const SF_AXIS: &str = "scale-factor error, ppm";

/// The fit's scale-factor error at `t`, ppm: its model, else its table.
fn model_ppm(f: &SfFit, t: f64) -> f64 {
    f.curve
        .as_ref()
        .map_or_else(|| f.table.eval(t).0, |c| c.sf_ppm(t))
}

fn bins_series(label: &str, bins: &[TempBin], f: impl Fn(f64) -> f64, color: usize) -> Series {
    let pts = bins.iter().map(|b| (b.t_c, b.ppm - f(b.t_c))).collect();
    let errs = bins
        .iter()
        .map(|b| {
            let e = if b.se.is_finite() { b.se } else { 0.0 };
            (b.ppm - f(b.t_c) - e, b.ppm - f(b.t_c) + e)
        })
        .collect();
    Series::points(label, pts, Some(errs), color)
}

fn verdict(f: &SfFit, plateaus: Option<&[Plateau]>) -> Verdict {
    let mut v = Verdict::new();
    let run = match f.method {
        FitMethod::Continuous => "a continuous-rotation run",
        FitMethod::MultiPoint => "a multi-point run",
    };
    v.text(&format!(
        "Fitted the FOG scale factor over coil temperature on {run}: "
    ))
    .count("rows_used", f.rows_used)
    .text(" rows over ")
    .num("duration_s", f.duration_s, 0)
    .text(" s, coil ")
    .range("range_c", f.range_c, 2)
    .text(" degC");
    if let Some(p) = plateaus {
        v.text(&format!(", {} plateaus", p.len()));
    }
    v.text(". The criterion (BIC) chose ")
        .word("model", f.model.name())
        .text(&format!(" ({}), degree ", f.model.describe()))
        .count("degree", f.degree)
        .text(", with ")
        .count("knees_c.length", f.knees.len())
        .text(" knee(s)");
    for (i, k) in f.knees.iter().enumerate() {
        v.text(if i == 0 { ": at " } else { ", at " })
            .num(&format!("knees_c.{i}"), k.value, 2)
            .text(" degC (95 % interval ")
            .range(&format!("knees_ci_c.{i}"), [k.lo, k.hi], 2)
            .text(")");
    }
    let next = f
        .families
        .iter()
        .filter(|b| b.model != f.model)
        .min_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic));
    if let Some(n) = next {
        v.text(", ")
            .num("criterion_margin", f.criterion_margin, 1)
            .text(&format!(
                " below the best of the other families ({})",
                n.model
            ));
    }
    v.text(". ");
    if let Some(p) = &f.polynomial {
        if p.coef_ppm.len() > 2 {
            let top = p.coef_ppm.len() - 1;
            v.text(&format!(
                "Its x^{top} term (x = T - {} degC) is ",
                p.t_ref_c
            ))
            .num(
                &format!("polynomial.coef_ppm.{top}.value"),
                p.coef_ppm[top].value,
                6,
            )
            .text(" +- ")
            .num(
                &format!("polynomial.coef_ppm.{top}.se"),
                p.coef_ppm[top].se,
                6,
            )
            .text(&format!(" ppm/degC^{top}. "));
        }
    }
    let ratio = f.residual_ppm.value / f.noise_floor_ppm.value;
    v.text("Residual ")
        .num("residual_ppm", f.residual_ppm.value, 3)
        .text(" +- ")
        .num("residual_ppm_se", f.residual_ppm.se, 3)
        .text(" ppm RMS of 60 s means against a noise floor of ")
        .num("noise_floor_ppm.value", f.noise_floor_ppm.value, 3)
        .text(&format!(" ppm: {}. ", against_floor(ratio)));
    if let Some(l) = f.sensor_lag_s {
        v.text("Coil sensor lag ")
            .num("sensor_lag_s.value", l.value, 1)
            .text(" s (95 % interval ")
            .num("sensor_lag_s.lo", l.lo, 1)
            .text(" .. ")
            .num("sensor_lag_s.hi", l.hi, 1)
            .text(" s). ");
    }
    v.text("The firmware's table has ")
        .count("tabulation.nodes", f.tabulation.nodes)
        .text(" nodes; its fixed-point lookup stays within ")
        .num("tabulation.max_error_ppm", f.tabulation.max_error_ppm, 3)
        .text(" ppm of the model.");
    warnings(&mut v, &f.warnings);
    v
}

/// The measured scale factor against temperature, the model, the table,
/// the knees' bands (or the plateaus).
fn sf_plot(r: &mut Report, f: &SfFit, d: &SfDiagnostics, plateaus: Option<&[Plateau]>) {
    let (lo, hi) = (f.range_c[0], f.range_c[1]);
    let mut s = vec![];
    match plateaus {
        Some(p) => s.push(Series::points(
            "plateaus (95 % error bars)",
            p.iter().map(|p| (p.temp_c, p.sf_ppm.value)).collect(),
            Some(
                p.iter()
                    .map(|p| {
                        let e = 1.96 * p.sf_ppm.se;
                        (p.sf_ppm.value - e, p.sf_ppm.value + e)
                    })
                    .collect(),
            ),
            0,
        )),
        None => s.push(bins_series(
            "measured, 1 degC bins (+-1 standard error)",
            &d.sf_bins,
            |_| 0.0,
            0,
        )),
    }
    if f.curve.is_some() {
        let grid = (0..=300)
            .map(|i| {
                let t = lo + (hi - lo) * i as f64 / 300.0;
                (t, model_ppm(f, t))
            })
            .collect();
        s.push(Series::line(
            &format!("model: {} degree {}", f.model, f.degree),
            grid,
            1,
        ));
    }
    let n = f.table.n;
    let nodes: Vec<(f64, f64)> = (0..n)
        .map(|k| (f.table.temps_c[k], f.table.sf_ppm[k]))
        .collect();
    // The table lies within hundredths of a ppm of the model: its line is
    // dashed over the model's, and its nodes are marked so it shows.
    s.push(Series::dashed(
        "firmware table, linear between nodes",
        nodes.clone(),
        2,
    ));
    s.push(Series::points(
        &format!("firmware table's {n} nodes"),
        nodes,
        None,
        2,
    ));
    if !f.knees.is_empty() {
        s.push(Series::bands(
            "knee, 95 % interval",
            f.knees.iter().map(|k| (k.lo, k.hi)).collect(),
            3,
        ));
    }
    r.plot(
        &Axes::linear("Scale factor against coil temperature", T_AXIS, SF_AXIS),
        &s,
        "The measured scale-factor error (output over reference rate, minus 1, the bias removed) against the \
         coil temperature the fit estimates from its sensor, the chosen model, the table the firmware \
         interpolates and each knee's 95 % interval. Binned means take each 10 s bin about the model and \
         put the model back at the bin's mean temperature, so the slope within a bin does not inflate its \
         standard error.",
    );
}

/// A close look at each knee: the departure from the model's tangent just
/// below it.
fn knee_plots(r: &mut Report, f: &SfFit, d: &SfDiagnostics) {
    if f.curve.is_none() {
        return;
    }
    for k in &f.knees {
        let t0 = k.value;
        let h = 1e-3;
        let slope = (model_ppm(f, t0) - model_ppm(f, t0 - h)) / h;
        let tangent = |t: f64| model_ppm(f, t0) + slope * (t - t0);
        let (a, b) = ((t0 - 8.0).max(f.range_c[0]), (t0 + 8.0).min(f.range_c[1]));
        let bins: Vec<TempBin> = d
            .sf_bins
            .iter()
            .copied()
            .filter(|x| x.t_c >= a && x.t_c <= b)
            .collect();
        let grid = (0..=160)
            .map(|i| {
                let t = a + (b - a) * i as f64 / 160.0;
                (t, model_ppm(f, t) - tangent(t))
            })
            .collect();
        r.plot(
            &Axes::linear(
                &format!("Around the knee at {:.2} degC", t0),
                T_AXIS,
                "departure from the tangent below the knee, ppm",
            ),
            &[
                bins_series("measured, 1 degC bins (+-1 s.e.)", &bins, tangent, 0),
                Series::line("model", grid, 1),
                Series::bands("knee, 95 % interval", vec![(k.lo, k.hi)], 3),
            ],
            &format!(
                "The scale factor minus the model's tangent just below the knee: flat below it, bending \
                 with the slope change above it. The 95 % interval {:.3} .. {:.3} degC is {:.3} degC wide.",
                k.lo,
                k.hi,
                k.hi - k.lo
            ),
        );
    }
}

/// The criterion of each family and knee count.
fn criterion_tables(r: &mut Report, f: &SfFit) {
    r.heading("Model choice: the criterion of each family and knee count");
    let degrees: std::collections::BTreeSet<usize> =
        f.criteria.iter().map(|c| c.poly_degree).collect();
    let max_k = f.criteria.iter().map(|c| c.knees).max().unwrap_or(0);
    let mut header = vec!["smooth part".to_owned()];
    header.extend((0..=max_k).map(|k| format!("{k} knee(s): BIC - chosen")));
    let rows: Vec<Vec<String>> = degrees
        .iter()
        .map(|&deg| {
            let mut row = vec![match deg {
                // The knees family: lines, no polynomial (degree 0, as the
                // JSON and the verdict state it).
                1 => "straight lines: the knees family (degree 0)".to_owned(),
                d => format!("polynomial, degree {d}"),
            }];
            for k in 0..=max_k {
                row.push(
                    f.criteria
                        .iter()
                        .find(|c| c.poly_degree == deg && c.knees == k)
                        .map_or("-".into(), |c| {
                            if c.delta_bic == 0.0 {
                                "0 (chosen)".to_owned()
                            } else {
                                format!("{:.1}", c.delta_bic)
                            }
                        }),
                );
            }
            row
        })
        .collect();
    let h: Vec<&str> = header.iter().map(String::as_str).collect();
    r.table(&h, &rows);
    let rows: Vec<Vec<String>> = f
        .families
        .iter()
        .map(|b| {
            vec![
                format!("{} ({})", b.model, b.model.describe()),
                b.degree.to_string(),
                b.knees.to_string(),
                format!("{:.1}", b.bic),
                format!("{:.1}", b.delta_bic),
            ]
        })
        .collect();
    r.table(
        &["family's best", "degree", "knees", "BIC", "BIC - chosen"],
        &rows,
    );
    r.note(
        "BIC = n ln(SSE/n)/phi + p ln(n) over the 10 s bins (p: the linear coefficients, the knee \
         temperatures), phi the residual's correlation inflation. A difference above 10 is decisive; \
         the knees family is piecewise linear: no polynomial, degree 0 in the JSON and above.",
    );
}

fn residual_plots(r: &mut Report, d: &SfDiagnostics) {
    r.heading("Residual");
    let pts: Vec<(f64, f64)> = d.residual.iter().map(|w| (w.extra, w.ppm)).collect();
    let (lo, hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    r.plot(
        &Axes::linear("Residual against coil temperature", T_AXIS, "residual, ppm"),
        &[
            Series::points("60 s means", thin(pts, MAX_POINTS), None, 7),
            bins_series(
                "1 degC bins of 10 s means (+-1 s.e.)",
                &d.resid_bins,
                |_| 0.0,
                1,
            ),
            Series::dashed("zero", vec![(lo, 0.0), (hi, 0.0)], 0),
        ],
        "What the model leaves of the scale factor, against the coil temperature: structure here (a bend, \
         a step) is a knee or curvature the model lacks.",
    );
    let pts: Vec<(f64, f64)> = d.residual.iter().map(|w| (w.t_s / 3600.0, w.ppm)).collect();
    r.plot(
        &Axes::linear("Residual against time", "time, h", "residual, ppm"),
        &[Series::points("60 s means", thin(pts, MAX_POINTS), None, 7)],
        "The same over the run: a drift, or a difference between the ramps up and down (a lag the model \
         has wrong), shows here.",
    );
}

fn lag_plots(r: &mut Report, f: &SfFit, d: &SfDiagnostics) {
    let Some(l) = f.sensor_lag_s else {
        r.note("Coil sensor lag: not measurable on soaked plateaus (the table uses 0 s).");
        return;
    };
    r.heading("The coil sensor's lag");
    let (a, b) = d
        .lag_profile
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    r.plot(
        &Axes::linear(
            "Profile of the criterion over the sensor lag",
            "coil sensor lag, s",
            "chi-square above the minimum, dimensionless",
        ),
        &[
            Series::line("model's shape held", d.lag_profile.clone(), 0),
            Series::dashed(
                "95 % threshold (3.84)",
                vec![(a, 3.841), (b, 3.841)],
                1,
            ),
            Series::bands("95 % interval", vec![(l.lo, l.hi)], 3),
        ],
        &format!(
            "The fit's criterion against the lag of the coil sensor behind the coil ({:.1} s, 95 % interval \
             {:.1} .. {:.1} s; the interval's own profile re-fits the knees at each lag, this one holds them).",
            l.value, l.lo, l.hi
        ),
    );
    let lead = d.temps.iter().map(|p| (p.0 / 3600.0, p.2 - p.1)).collect();
    let sensor = d.temps.iter().map(|p| (p.0 / 3600.0, p.1)).collect();
    r.plot(
        &Axes::linear(
            "The lead the lag adds to the coil sensor",
            "time, h",
            "coil estimate - sensor, degC",
        ),
        &[Series::line("lag x d(sensor)/dt", lead, 1)],
        "How far the coil runs ahead of its sensor by the fitted lag: the lag times the sensor's \
         filtered rate of change, as the firmware forms it (zero on soaks, lag x ramp rate on ramps).",
    );
    r.plot(
        &Axes::linear("Coil sensor", "time, h", "temperature, degC"),
        &[Series::line("coil sensor", sensor, 0)],
        "The coil sensor over the run: the chamber's sweep as the gyro saw it.",
    );
}

fn tables(r: &mut Report, f: &SfFit, plateaus: Option<&[Plateau]>) {
    r.heading("Coefficients and the firmware's table");
    if let Some(p) = &f.polynomial {
        let rows: Vec<Vec<String>> = p
            .coef_ppm
            .iter()
            .enumerate()
            .map(|(k, c)| {
                vec![
                    format!("x^{k}"),
                    format!("{:.6}", c.value),
                    format!("{:.6}", c.se),
                    format!("ppm/degC^{k}"),
                ]
            })
            .collect();
        r.table(
            &["term (x = T - 20 degC)", "value", "standard error", "unit"],
            &rows,
        );
    }
    if f.segments.len() <= 12 {
        let rows: Vec<Vec<String>> = f
            .segments
            .iter()
            .map(|s| {
                vec![
                    format!("{:.2} .. {:.2}", s.from_c, s.to_c),
                    format!("{:.3} ({:.3})", s.k0_ppm, s.k0_se * 1e6),
                    format!("{:.4} ({:.4})", s.k_t_ppm_per_c, s.k_t_se * 1e6),
                ]
            })
            .collect();
        r.table(
            &[
                "segment, degC",
                "K0 - 1, ppm (s.e.)",
                "K_T, ppm/degC (s.e.)",
            ],
            &rows,
        );
    }
    let t = &f.tabulation;
    let spacing: Vec<String> = t.spacing_c.iter().map(|h| format!("{h:.3}")).collect();
    r.table(
        &["firmware table", "value"],
        &[
            vec!["nodes".into(), t.nodes.to_string()],
            vec!["spacing per piece, degC".into(), spacing.join(", ")],
            vec!["largest |lookup - model|, ppm".into(), num(t.max_error_ppm)],
            vec!["record".into(), "gyro-coeffs FOGS version 2".into()],
        ],
    );
    if let Some(p) = plateaus {
        let e = |x: Option<crate::calibration::scale_factor::result::Est>| {
            x.map_or("-".into(), |x| format!("{:.3} ({:.3})", x.value, x.se))
        };
        let rows: Vec<Vec<String>> = p
            .iter()
            .map(|p| {
                vec![
                    format!("{:.2}", p.temp_c),
                    format!("{:.3} ({:.3})", p.sf_ppm.value, p.sf_ppm.se),
                    format!("{:.4} ({:.4})", p.bias_dph.value, p.bias_dph.se),
                    e(p.asymmetry_ppm),
                    e(p.nonlinearity_ppm),
                ]
            })
            .collect();
        r.table(
            &[
                "plateau, degC",
                "scale-factor error, ppm (s.e.)",
                "bias, deg/h (s.e.)",
                "asymmetry, ppm",
                "nonlinearity, ppm",
            ],
            &rows,
        );
    }
    for n in &f.notes {
        r.note(n);
    }
}

/// The report of a scale-factor fit on the run `name`.
pub fn report(name: &str, f: &SfFit, d: &SfDiagnostics, plateaus: Option<&[Plateau]>) -> Report {
    let mut r = Report::new(&format!("FOG scale factor over temperature: {name}"));
    r.verdict(&verdict(f, plateaus));
    r.heading("Scale factor against coil temperature");
    sf_plot(&mut r, f, d, plateaus);
    knee_plots(&mut r, f, d);
    criterion_tables(&mut r, f);
    residual_plots(&mut r, d);
    lag_plots(&mut r, f, d);
    tables(&mut r, f, plateaus);
    r
}
