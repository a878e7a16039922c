//! The report of `lockin`: the verdict; the fringe record with the fitted
//! closed-form fringe; its harmonics against the geometric series the fit
//! implies; the estimate's uncertainty against the Cramer-Rao bound for
//! this record over the rate ratio.

use super::warnings;
use crate::calibration::lockin::{
    cramer_rao_rel, fringe_model, harmonic_amplitudes, rho_of_ratio, LockIn,
};
use crate::report::document::Report;
use crate::report::plot::{Axes, Series};
use crate::report::verdict::Verdict;

/// Harmonics shown.
const HARMONICS: usize = 8;

fn verdict(r: &LockIn) -> Verdict {
    let mut v = Verdict::new();
    v.text("Measured the RLG lock-in rate by the exact harmonic relation from ")
        .count("samples", r.samples)
        .text(" samples over ")
        .num("duration_s", r.duration_s, 3)
        .text(" s, ")
        .count("channels", r.channels)
        .text(" photodiode channel(s): lock-in ")
        .num("lock_in_dps", r.lock_in_dps, 6)
        .text(" deg/s, 95 % interval ")
        .range("lock_in_ci_dps", r.lock_in_ci_dps, 6)
        .text(" deg/s, at an input rate of ")
        .num("input_rate_dps", r.input_rate_dps, 6)
        .text(&format!(
            " deg/s ({}; Omega_I/Omega_L = ",
            if r.input_rate_given {
                "given"
            } else {
                "estimated from the beat and rho"
            }
        ))
        .num("rate_ratio", r.rate_ratio, 1)
        .text(", beat ")
        .num("beat_hz", r.beat_hz, 3)
        .text(" Hz, harmonic ratio ")
        .num("harmonic_ratio", r.harmonic_ratio, 6)
        .text("). Its relative one-sigma uncertainty, ")
        .num("lock_in_rel_std", r.lock_in_rel_std, 5)
        .text(", stands against a Cramer-Rao bound of ")
        .num("cramer_rao_rel", r.cramer_rao_rel, 5)
        .text(" for this record. The fit's residual, ")
        .num("residual_rms", r.residual_rms, 5)
        .text(" RMS, against the noise under it, ")
        .num("noise_rms", r.noise_rms, 5)
        .text(&format!(
            ": {}. The published approximate formula gives ",
            if r.residual_rms <= 1.05 * r.noise_rms {
                "the fringe model leaves only noise"
            } else {
                "the fringe model leaves more than noise"
            }
        ))
        .num("lock_in_approx_dps", r.lock_in_approx_dps, 6)
        .text(" deg/s on the same record.");
    warnings(&mut v, &r.warnings);
    v
}

/// The first beats of the record with the fitted fringe.
fn record_plot(rep: &mut Report, t: &[f64], s: &[f64], r: &LockIn) {
    let Some(f) = r.channel_fits.first() else {
        return;
    };
    // About four beat periods, at most 1 500 samples.
    let span = 4.0 / r.beat_hz.max(1e-9);
    let n = t
        .iter()
        .take_while(|&&x| x - t[0] <= span)
        .count()
        .clamp(2, 1500)
        .min(t.len());
    let data = t[..n]
        .iter()
        .zip(&s[..n])
        .map(|(a, b)| (a * 1e3, *b))
        .collect();
    let (a, b) = (t[0], t[n - 1]);
    let model = (0..=1200)
        .map(|i| {
            let x = a + (b - a) * i as f64 / 1200.0;
            (x * 1e3, fringe_model(&f.params, f.t_mid, x))
        })
        .collect();
    rep.plot(
        &Axes::linear(
            "Fringe record and the fitted fringe",
            "time, ms",
            "fringe signal, record units",
        ),
        &[
            Series::points("record (first channel)", data, None, 7),
            Series::line("fitted closed-form fringe", model, 1),
        ],
        "The start of the record with the periodic solution of the lock-in equation fitted to the whole \
         record (amplitude, offset, phases, rho, beat frequency): near lock-in the fringe is distorted, \
         its harmonics falling off geometrically with ratio rho.",
    );
}

/// The record's harmonics against the fit's geometric series.
fn harmonics_plot(rep: &mut Report, t: &[f64], s: &[f64], r: &LockIn) {
    let Some(f) = r.channel_fits.first() else {
        return;
    };
    let meas = harmonic_amplitudes(t, s, r.beat_hz, HARMONICS);
    let rho = f.rho;
    // A harmonic's amplitude estimate in white noise (Hann window): sigma
    // sqrt(6/N).
    let noise = f.residual_rms * (6.0 / f.samples.max(1) as f64).sqrt();
    // The series down to a hundredth of the noise.
    let model: Vec<(f64, f64)> = (1..=HARMONICS)
        .map(|n| {
            (
                n as f64,
                f.amplitude * (1.0 - rho * rho) * rho.powi(n as i32 - 1),
            )
        })
        .take_while(|p| p.1 >= 0.01 * noise)
        .collect();
    let pts: Vec<(f64, f64)> = meas
        .iter()
        .enumerate()
        .map(|(k, a)| ((k + 1) as f64, *a))
        .collect();
    rep.plot(
        &Axes {
            title: "Harmonics of the fringe".into(),
            x_label: "harmonic of the beat frequency n, dimensionless".into(),
            y_label: "amplitude, record units".into(),
            log_x: false,
            log_y: true,
        },
        &[
            Series::points("record (Hann-windowed)", pts, None, 0),
            Series::line("fit: A (1 - rho^2) rho^(n-1)", model, 1),
            Series::dashed(
                "noise level of an amplitude",
                vec![(1.0, noise), (HARMONICS as f64, noise)],
                7,
            ),
        ],
        &format!(
            "The record's first {HARMONICS} harmonics against the geometric series of the fit (rho = {rho:.6}); \
             harmonics below the dashed line are lost in the noise, which is where the plain ratio A2/A1 of \
             the published formula loses its accuracy.",
        ),
    );
}

/// The estimate's uncertainty against the bound over the rate ratio.
fn bound_plot(rep: &mut Report, r: &LockIn) {
    let Some(f) = r.channel_fits.first() else {
        return;
    };
    let rel = f.residual_rms / f.amplitude.max(1e-300);
    let curve: Vec<(f64, f64)> = (0..=80)
        .map(|i| {
            let ratio = 10f64.powf(0.3 + 2.0 * i as f64 / 80.0);
            (
                ratio,
                100.0 * cramer_rao_rel(rel, r.samples, rho_of_ratio(ratio), r.channels),
            )
        })
        .collect();
    let est = vec![(r.rate_ratio, 100.0 * r.lock_in_rel_std)];
    rep.plot(
        &Axes {
            title: "Uncertainty of the lock-in rate against the Cramer-Rao bound".into(),
            x_label: "rate ratio Omega_I/Omega_L, dimensionless".into(),
            y_label: "relative one-sigma of Omega_L, %".into(),
            log_x: true,
            log_y: true,
        },
        &[
            Series::line(
                "Cramer-Rao bound for this record's N, noise and amplitude",
                curve,
                1,
            ),
            Series::points("this estimate (fit covariance)", est, None, 0),
        ],
        "The information limit sigma/(sqrt(N) A rho) (docs/lockin.md, the information limit; the small-lock-in form, exact for \
         Omega_I/Omega_L >= 10; sqrt(2) more from one photodiode) for a record like this one at other rate \
         ratios, and where this estimate stands: an estimate on the line extracts all the record holds.",
    );
}

/// The report of a lock-in measurement on the record `name` (first
/// channel `s` at times `t`).
pub fn report(name: &str, t: &[f64], s: &[f64], r: &LockIn) -> Report {
    let mut rep = Report::new(&format!("RLG lock-in rate: {name}"));
    rep.verdict(&verdict(r));
    rep.heading("Fringe record and the harmonic fit");
    record_plot(&mut rep, t, s, r);
    harmonics_plot(&mut rep, t, s, r);
    rep.heading("Estimate against the Cramer-Rao bound");
    rep.table(
        &["quantity", "value"],
        &[
            vec![
                "lock-in rate, deg/s".into(),
                format!("{:.6}", r.lock_in_dps),
            ],
            vec![
                "95 % interval, deg/s".into(),
                format!("{:.6} .. {:.6}", r.lock_in_ci_dps[0], r.lock_in_ci_dps[1]),
            ],
            vec![
                "relative one-sigma (fit), %".into(),
                format!("{:.4}", 100.0 * r.lock_in_rel_std),
            ],
            vec![
                "Cramer-Rao bound, %".into(),
                format!("{:.4}", 100.0 * r.cramer_rao_rel),
            ],
            vec![
                "published formula, deg/s".into(),
                format!("{:.6}", r.lock_in_approx_dps),
            ],
        ],
    );
    bound_plot(&mut rep, r);
    rep
}
