//! The `allan` report: the curve with its intervals, the fitted terms and
//! the readings; where the model misses; the terms' table.

use super::words::{headline, readings_text, term_rows, verdict};
use crate::commands::adev_plot::{adev_series, misfit_series, missed_series, reading_marks};
use crate::noise::analysis::Allan;
use crate::record::Warning;
use crate::report::document::Report;
use crate::report::plot::Axes;
use crate::report::text::sig;

pub fn report(an: &Allan, name: &str, column: &str, warnings: &[Warning]) -> Report {
    let mut r = Report::new(&format!("Allan deviation of {column} in {name}"));
    for w in warnings {
        r.paragraph(&format!("WARNING ({}): {}.", w.code, w.message));
    }
    r.paragraph(&format!(
        "{} samples every {} s ({:.4} h). Overlapping Allan deviation at {} averaging times from {} s to a third \
         of the record ({} s), with 95 % chi-square intervals from Greenhall's equivalent degrees of freedom of \
         the noise types the fitted model holds at each averaging time.",
        an.n,
        sig(an.tau0),
        an.n as f64 * an.tau0 / 3600.0,
        an.taus.len(),
        sig(an.taus[0]),
        sig(an.taus[an.taus.len() - 1])
    ));
    r.paragraph(&headline(an));
    r.heading("Does the model fit?");
    r.paragraph(&verdict(an));
    r.heading("Allan deviation, the fitted noise terms and the readings");
    let mut series = adev_series(an, "measured (95 % interval)", 0, true);
    if let Some(m) = missed_series(an) {
        series.insert(1, m);
    }
    let (lines, marks) = reading_marks(an);
    series.extend(lines);
    r.plot_annotated(
        &Axes {
            title: "Allan deviation".into(),
            x_label: "averaging time tau, s".into(),
            y_label: "Allan deviation, deg/h".into(),
            log_x: true,
            log_y: true,
        },
        &series,
        &marks,
        "Measured overlapping Allan deviation with its 95 % intervals (points the model misses in orange), the \
         fitted model (solid) and each term it holds (dashed); the conventional readings: the -1/2 line read at \
         tau = 1 s and the floor.",
    );
    r.paragraph(&readings_text(an));
    r.heading("Where the model misses");
    r.plot_annotated(
        &Axes {
            title: "Normalised residual of the Allan variance".into(),
            x_label: "averaging time tau, s".into(),
            y_label: "(measured - model) / sd".into(),
            log_x: true,
            log_y: false,
        },
        &misfit_series(an),
        &[],
        "The measured Allan variance less the model's, in standard deviations of the estimate (from its \
         equivalent degrees of freedom): a right model keeps within the dashed band at 95 % of the averaging times \
         (neighbours correlate, so a run of points on one side is common); where points leave it, the model misses \
         the curve there.",
    );
    r.heading("IEEE 952 noise terms");
    r.table(
        &[
            "term",
            "slope",
            "value",
            "95 % low",
            "95 % high",
            "unit",
            "reliable",
        ],
        &term_rows(an),
    );
    r.note(
        "The terms are fitted to the whole curve by weighted least squares with non-negative coefficients; the \
         sinusoid's frequency, the Markov correlation time and the white noise's filter time constant are searched. \
         A term is reported only if it carries at least half of the model at some measured averaging time and the \
         curve needs it (its interval excludes zero, or leaving it out costs the fit far more than chance); \
         otherwise it is absent, not small. A -1 slope is quantization or white angle noise (one shape). The \
         intervals are widened by the chi-square in excess of a right model's, where the term carries the model \
         and overall, and to the values the missed points ask for; a term is unreliable where it carries \
         averaging times the model misses. Bias instability includes the 0.664 factor (B = floor / 0.664). Units: \
         quantization in arcsec of angle; angle random walk in deg/sqrt(h); bias instability in deg/h; rate random \
         walk in deg/h/sqrt(h); rate ramp in deg/h^2.",
    );
    r.paragraph(&format!(
        "Mean rate {:.6e} deg/s, standard error {:.2e} deg/s (the fitted model's Allan deviation at the record's \
         length).",
        an.mean_dps, an.mean_se_dps
    ));
    r
}
