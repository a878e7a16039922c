//! A scale-factor table applied to a run as the firmware applies it
//! (compensation.rs), judged: the scale-factor error before and after as
//! 60 s means (over time and coil temperature), their RMS with its
//! standard error, the noise floor under it, the spans where the coil left
//! the calibrated range or its sensor was flagged, and the warnings.

use super::compensation::compensate_rows;
use super::residual::{
    noise_floor_ppm, window_means, window_rms_ppm, WindowMean, RESIDUAL_WINDOW_S,
};
use super::result::Est;
use crate::calibration::warning::Warning;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::fog::scale_factor::FogTempFlags;

/// A stretch of consecutive rows with a flag up.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct FlagSpan {
    pub from_s: f64,
    pub to_s: f64,
    /// Coil sensor's extremes over the span, degC.
    pub min_c: f64,
    pub max_c: f64,
}

/// The compensated run and its figures.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Validation {
    pub rows: usize,
    pub duration_s: f64,
    /// RMS of 60 s means of the scale-factor error, ppm, before and after,
    /// with standard errors; the windows; the noise floor after; the
    /// flags of all rows. (`compensate` states the first four and the
    /// flags as plain numbers in its JSON.)
    #[serde(skip)]
    pub raw_ppm: Est,
    #[serde(skip)]
    pub comp_ppm: Est,
    #[serde(skip)]
    pub windows: usize,
    pub noise_floor_ppm: Est,
    #[serde(skip)]
    pub flags_seen: u8,
    /// The table's nodes, calibrated range (degC) and sensor lag (s).
    pub table_nodes: usize,
    pub calibrated_range_c: [f64; 2],
    pub sensor_lag_s: f64,
    pub out_of_range_spans: Vec<FlagSpan>,
    pub sensor_flagged_spans: Vec<FlagSpan>,
    pub warnings: Vec<Warning>,
    /// The compensated rate, deg/s, and the flags of each row.
    #[serde(skip)]
    pub comp_dps: Vec<f64>,
    #[serde(skip)]
    pub flags: Vec<u8>,
    /// 60 s means before and after (`extra`: the coil sensor).
    #[serde(skip)]
    pub before: Vec<WindowMean>,
    #[serde(skip)]
    pub after: Vec<WindowMean>,
}

/// Spans closer than this are one, s.
pub const SPAN_GAP_S: f64 = 60.0;
/// A coil this far outside the calibrated range is warned about, degC (a
/// coil soaked at the range's end dithers across it by its estimate's
/// noise: the table's end value then holds to that noise).
pub const OUT_OF_RANGE_MARGIN_C: f64 = 0.5;

/// Stretches of rows with `bit` up in `flags`, those less than
/// [`SPAN_GAP_S`] apart merged (the first row, which has no derivative
/// yet, is not counted).
pub fn flag_spans(t: &[f64], flags: &[u8], bit: u8, temp_c: &[f64]) -> Vec<FlagSpan> {
    let mut out: Vec<FlagSpan> = vec![];
    let mut open = false;
    for k in 1..t.len().min(flags.len()) {
        if flags[k] & bit != 0 {
            let tc = temp_c.get(k).copied().unwrap_or(f64::NAN);
            match out.last_mut() {
                Some(s) if open || t[k - 1] - s.to_s < SPAN_GAP_S => {
                    s.to_s = t[k];
                    s.min_c = s.min_c.min(tc);
                    s.max_c = s.max_c.max(tc);
                }
                _ => out.push(FlagSpan {
                    from_s: t[k - 1],
                    to_s: t[k],
                    min_c: tc,
                    max_c: tc,
                }),
            }
            open = true;
        } else {
            open = false;
        }
    }
    out
}

fn est((v, se): (f64, f64)) -> Est {
    Est { value: v, se }
}

fn warnings(v: &Validation) -> Vec<Warning> {
    let mut w = vec![];
    if v.flags_seen & FogTempFlags::COEFFS_REFUSED.bits() != 0 {
        w.push(Warning::new(
            "table_refused",
            "the firmware's check refused the table: the run was not compensated".into(),
        ));
    }
    let (lo, hi) = v
        .out_of_range_spans
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
            (a.min(s.min_c), b.max(s.max_c))
        });
    let [r0, r1] = v.calibrated_range_c;
    if lo < r0 - OUT_OF_RANGE_MARGIN_C || hi > r1 + OUT_OF_RANGE_MARGIN_C {
        let secs: f64 = v.out_of_range_spans.iter().map(|s| s.to_s - s.from_s).sum();
        w.push(Warning::new(
            "outside_calibrated_range",
            format!(
                "{secs:.0} s of the run in {} span(s) had the coil outside the calibrated range \
                 {:.1} .. {:.1} degC (sensor {lo:.1} .. {hi:.1} degC): the table held its end values there",
                v.out_of_range_spans.len(),
                v.calibrated_range_c[0],
                v.calibrated_range_c[1]
            ),
        ));
    }
    if !v.sensor_flagged_spans.is_empty() {
        w.push(Warning::new(
            "coil_sensor_flagged",
            format!(
                "the coil sensor was flagged in {} span(s): its last good value was held",
                v.sensor_flagged_spans.len()
            ),
        ));
    }
    if v.windows == 0 {
        w.push(Warning::new(
            "no_windows",
            "no 60 s stretch at a constant nonzero rate: the run gives no scale-factor figure"
                .into(),
        ));
    } else if v.comp_ppm.value > 2.0 * v.noise_floor_ppm.value + 2.0 * v.comp_ppm.se {
        w.push(Warning::new(
            "residual_above_noise",
            format!(
                "after compensation the error ({:.3} ppm) is {:.1} times the run's noise floor ({:.3} ppm): \
                 the table does not describe this gyro over this run (a scale-factor asymmetry between the \
                 rate signs, which one table cannot hold, shows so on a one-sign run; or a knee, curvature \
                 or lag the table lacks)",
                v.comp_ppm.value,
                v.comp_ppm.value / v.noise_floor_ppm.value,
                v.noise_floor_ppm.value
            ),
        ));
    }
    w
}

/// Applies `table` to a run (time s, reference and output rates deg/s,
/// coil sensor degC) as the firmware does, and judges the result.
pub fn validate(
    table: &ScaleFactorTable,
    t: &[f64],
    w: &[f64],
    y: &[f64],
    temp_c: &[f64],
) -> Validation {
    let (comp, flags) = compensate_rows(table, t, y, temp_c);
    let err = |v: &[f64]| -> Vec<f64> { v.iter().zip(w).map(|(a, b)| a - b).collect() };
    let (e_raw, e_comp) = (err(y), err(&comp));
    let (c, c_se, m) = window_rms_ppm(t, w, &e_comp, RESIDUAL_WINDOW_S);
    let (r, r_se, _) = window_rms_ppm(t, w, &e_raw, RESIDUAL_WINDOW_S);
    let n = table.n.clamp(1, table.temps_c.len());
    let mut v = Validation {
        rows: t.len(),
        duration_s: t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0),
        raw_ppm: est((r, r_se)),
        comp_ppm: est((c, c_se)),
        windows: m,
        noise_floor_ppm: noise_floor_ppm(t, w, &e_comp),
        flags_seen: flags.iter().fold(0, |x, f| x | f),
        table_nodes: table.n,
        calibrated_range_c: [table.temps_c[0], table.temps_c[n - 1]],
        sensor_lag_s: table.sensor_lag_s,
        out_of_range_spans: flag_spans(t, &flags, FogTempFlags::OUT_OF_RANGE.bits(), temp_c),
        sensor_flagged_spans: flag_spans(t, &flags, FogTempFlags::COIL_SENSOR.bits(), temp_c),
        warnings: vec![],
        before: window_means(t, w, &e_raw, temp_c, RESIDUAL_WINDOW_S),
        after: window_means(t, w, &e_comp, temp_c, RESIDUAL_WINDOW_S),
        comp_dps: comp,
        flags,
    };
    v.warnings = warnings(&v);
    v
}
