//! `gyro-lab bench scale-factor`: the three calibrations side by side on the
//! same simulated gyro, over seeds, against the truth.
//!
//! Per seed: a continuous-rotation fit run (cycle -40..+60 degC and back,
//! +-50 deg/s reversed every 5 min), a classic multi-point run (plateaus
//! -40, -15, 10, 35, 60 degC: the knee at 48 degC falls between the last
//! two) and a validation run of another profile, rate and direction (steps,
//! -100 deg/s only). Both tables compensate the validation run through the
//! firmware's fixed-point code; the figure is the RMS of the scale-factor
//! error over 60 s means. A no-knee gyro's fit run checks that no knee is
//! invented.
//!
//! The model families: five coils (a knee on a straight line, a straight
//! line, a quadratic, a cubic, a knee on the quadratic's curved
//! background), each fitted on the run (the same cycle at +-100
//! deg/s, 0.01 deg/sqrt(h)) and validated on the steps profile at -100
//! deg/s: the family and degree chosen against the truth's,
//! the knees, the curvature with its interval, the validation RMS.

use crate::calibration::scale_factor::compensation::compensate_rows;
use crate::calibration::scale_factor::families::Family;
use crate::calibration::scale_factor::fit::fit;
use crate::calibration::scale_factor::input::{prepare, SfInput};
use crate::calibration::scale_factor::residual::{window_rms_ppm, RESIDUAL_WINDOW_S};
use crate::calibration::scale_factor::result::{SfFit, SfFitError};
use crate::sim::scale_factor_rig::{simulate, Direction, RigParams, Run, SweepProfile, Test};
use gyro_sim::ScaleFactorTruth;

/// The bench's runs that are fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchRun {
    Continuous,
    MultiPoint,
    NoKnee,
    /// One of the families' coils (its name).
    Family(&'static str),
}

/// A fit that failed on the bench's own simulated run.
#[derive(Debug)]
pub struct BenchFitError {
    pub run: BenchRun,
    pub error: SfFitError,
}

impl std::fmt::Display for BenchFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let run = match self.run {
            BenchRun::Continuous => "continuous fit",
            BenchRun::MultiPoint => "multi-point fit",
            BenchRun::NoKnee => "no-knee fit",
            BenchRun::Family(name) => name,
        };
        write!(f, "{run}: {}", self.error)
    }
}

fn input(run: &Run) -> SfInput {
    prepare(&run.t_s, &run.ref_rate_dps, &run.rate_dps, &run.temp_c)
}

pub fn continuous_fit_test() -> Test {
    Test::Continuous {
        profile: SweepProfile::Cycle,
        rate_dps: 50.0,
        direction: Direction::Both,
        reverse_every_s: 300.0,
    }
}

/// The families' fit run (issue 25): the cycle at +-100 deg/s reversed
/// every 5 min, with [`FAMILIES_ARW_DPSH`].
pub fn families_fit_test() -> Test {
    Test::Continuous {
        profile: SweepProfile::Cycle,
        rate_dps: 100.0,
        direction: Direction::Both,
        reverse_every_s: 300.0,
    }
}

/// Angle random walk of the families' runs, deg/sqrt(h).
pub const FAMILIES_ARW_DPSH: f64 = 0.01;

pub fn validation_test() -> Test {
    Test::Continuous {
        profile: SweepProfile::Steps,
        rate_dps: 100.0,
        direction: Direction::Negative,
        reverse_every_s: 300.0,
    }
}

pub fn multipoint_test() -> Test {
    Test::MultiPoint {
        plateaus_c: vec![-40.0, -15.0, 10.0, 35.0, 60.0],
        rates_dps: vec![10.0, 20.0, 50.0, 100.0, 200.0],
        soak_s: 3600.0,
        dwell_s: 60.0,
    }
}

/// Count, mean, standard deviation and largest of a figure over seeds.
#[derive(Clone, Default, serde::Serialize)]
pub struct Stats {
    pub n: usize,
    pub mean: f64,
    pub sd: f64,
    pub max: f64,
}

pub fn stats(v: &[f64]) -> Stats {
    let n = v.len();
    if n == 0 {
        return Stats::default();
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n.max(2) - 1) as f64).sqrt();
    Stats {
        n,
        mean,
        sd,
        max: v.iter().fold(f64::NEG_INFINITY, |a, x| a.max(*x)),
    }
}

/// The bench's figures (its JSON, in this order).
#[derive(serde::Serialize)]
pub struct ScaleFactorBench {
    pub seeds: u64,
    pub knee_true_c: f64,
    /// Continuous fit: seeds with exactly one knee found, |knee error|, and
    /// seeds whose 95 % interval covers the truth.
    pub continuous_one_knee: usize,
    pub continuous_knee_abs_err_c: Stats,
    pub continuous_knee_ci_width_c: Stats,
    pub continuous_ci_covers: usize,
    pub sensor_lag_s: Stats,
    pub sensor_lag_ci_covers: usize,
    /// Validation RMS of 60 s means, ppm.
    pub validation_raw_ppm: Stats,
    pub validation_multipoint_ppm: Stats,
    pub validation_continuous_ppm: Stats,
    pub multipoint_knee_bracketed: usize,
    pub no_knee_fitted_without_knee: usize,
    /// The model families, one row per coil.
    pub families: Vec<FamilyRow>,
}

/// A coil of the families' bench: what the fit should find.
#[derive(Clone, Copy, Debug)]
pub struct Coil {
    pub name: &'static str,
    pub truth: ScaleFactorTruth,
    pub family: Family,
    /// The JSON degree expected (0 for knees).
    pub degree: usize,
}

/// The five coils.
pub fn coils() -> [Coil; 5] {
    let d = ScaleFactorTruth::default();
    [
        Coil {
            name: "knee at 48 degC",
            truth: d,
            family: Family::Knees,
            degree: 0,
        },
        Coil {
            name: "straight line",
            truth: d.without_knees(),
            family: Family::Polynomial,
            degree: 1,
        },
        Coil {
            name: "quadratic 0.02 ppm/degC^2",
            truth: ScaleFactorTruth::quadratic(),
            family: Family::Polynomial,
            degree: 2,
        },
        Coil {
            name: "cubic 2e-4 ppm/degC^3",
            truth: ScaleFactorTruth::cubic(),
            family: Family::Polynomial,
            degree: 3,
        },
        Coil {
            name: "knee on the quadratic",
            truth: ScaleFactorTruth::knee_on_curve(),
            family: Family::PolynomialWithKnees,
            degree: 2,
        },
    ]
}

/// One coil's figures over the seeds.
#[derive(Clone, serde::Serialize)]
pub struct FamilyRow {
    pub coil: &'static str,
    pub expected_model: Family,
    pub expected_degree: usize,
    /// Seeds fitted with the expected family and degree, and with the
    /// truth's knee count.
    pub right_model: usize,
    pub right_knee_count: usize,
    /// Models chosen: knees, polynomial, polynomial with knees.
    pub chosen: [usize; 3],
    /// Knee error where the knee count is right (the first knee), degC,
    /// and seeds whose 95 % interval covers the truth.
    pub knee_abs_err_c: Stats,
    pub knee_ci_covers: usize,
    /// The highest curvature term the truth has (x^2 or x^3 coefficient
    /// about 20 degC, ppm/degC^k): the estimate and its 95 % interval's
    /// coverage, where the right degree was chosen.
    pub curvature_truth: f64,
    pub curvature: Stats,
    pub curvature_ci_covers: usize,
    /// Table nodes and the firmware lookup's largest departure from the
    /// fitted model, ppm.
    pub table_nodes: Stats,
    /// The closest node spacing of each seed's table, degC.
    pub table_spacing_c: Stats,
    pub tabulation_ppm: Stats,
    /// Validation RMS of 60 s means through the firmware, ppm.
    pub validation_ppm: Stats,
}

/// The coefficient of (T - 20)^k of a coil's truth (the curvature terms
/// about their centre, re-expanded about 20 degC).
fn truth_coef(t: &ScaleFactorTruth, k: usize) -> f64 {
    let c = 20.0 - t.curve_centre_c;
    match k {
        2 => t.quad_ppm_per_c2 + 3.0 * t.cubic_ppm_per_c3 * c,
        3 => t.cubic_ppm_per_c3,
        _ => f64::NAN,
    }
}

fn family_index(f: Family) -> usize {
    match f {
        Family::Knees => 0,
        Family::Polynomial => 1,
        Family::PolynomialWithKnees => 2,
    }
}

/// Figures of one coil's fit gathered over seeds.
#[derive(Default)]
struct Gather {
    right_model: usize,
    right_knees: usize,
    chosen: [usize; 3],
    knee_err: Vec<f64>,
    knee_covers: usize,
    curv: Vec<f64>,
    curv_covers: usize,
    nodes: Vec<f64>,
    spacing: Vec<f64>,
    tab: Vec<f64>,
    val: Vec<f64>,
}

impl Gather {
    fn add(&mut self, coil: &Coil, f: &SfFit, val_ppm: f64) {
        let t = &coil.truth;
        self.chosen[family_index(f.model)] += 1;
        if f.model == coil.family && f.degree == coil.degree {
            self.right_model += 1;
        }
        if f.knees.len() == t.n_knees {
            self.right_knees += 1;
            if let (Some(k), Some(tk)) = (f.knees.first(), t.knees.first()) {
                if t.n_knees > 0 {
                    self.knee_err.push((k.value - tk.0).abs());
                    if k.lo <= tk.0 && tk.0 <= k.hi {
                        self.knee_covers += 1;
                    }
                }
            }
        }
        let top = if t.cubic_ppm_per_c3 != 0.0 {
            3
        } else if t.quad_ppm_per_c2 != 0.0 {
            2
        } else {
            0
        };
        if let (true, Some(p)) = (top > 0, &f.polynomial) {
            if p.coef_ppm.len() == top + 1 {
                let c = p.coef_ppm[top];
                let truth = truth_coef(t, top);
                self.curv.push(c.value);
                if (c.value - truth).abs() <= 1.96 * c.se {
                    self.curv_covers += 1;
                }
            }
        }
        self.nodes.push(f.tabulation.nodes as f64);
        let closest = f
            .tabulation
            .spacing_c
            .iter()
            .fold(f64::INFINITY, |a, &h| a.min(h));
        self.spacing.push(closest);
        self.tab.push(f.tabulation.max_error_ppm);
        self.val.push(val_ppm);
    }

    fn row(self, coil: &Coil) -> FamilyRow {
        let t = &coil.truth;
        let top = if t.cubic_ppm_per_c3 != 0.0 { 3 } else { 2 };
        FamilyRow {
            coil: coil.name,
            expected_model: coil.family,
            expected_degree: coil.degree,
            right_model: self.right_model,
            right_knee_count: self.right_knees,
            chosen: self.chosen,
            knee_abs_err_c: stats(&self.knee_err),
            knee_ci_covers: self.knee_covers,
            curvature_truth: truth_coef(t, top),
            curvature: stats(&self.curv),
            curvature_ci_covers: self.curv_covers,
            table_nodes: stats(&self.nodes),
            table_spacing_c: stats(&self.spacing),
            tabulation_ppm: stats(&self.tab),
            validation_ppm: stats(&self.val),
        }
    }
}

/// Runs the bench over seeds 1..=`seeds`; `progress` after each seed.
pub fn run(seeds: u64, mut progress: impl FnMut()) -> Result<ScaleFactorBench, BenchFitError> {
    let base = RigParams::default();
    let knee_true = base.truth.knees[0].0;
    let fail = |run: BenchRun, error: SfFitError| BenchFitError { run, error };
    let (mut knee_err, mut knee_w, mut lag) = (vec![], vec![], vec![]);
    let (mut one_knee, mut covers, mut lag_covers, mut bracketed, mut no_knee_ok) = (0, 0, 0, 0, 0);
    let (mut raw, mut mp, mut cont) = (vec![], vec![], vec![]);
    let coils = coils();
    let mut gathered: Vec<Gather> = coils.iter().map(|_| Gather::default()).collect();
    for seed in 1..=seeds {
        let rig = |s: u64| RigParams { seed: s, ..base };
        let fit_run = simulate(&continuous_fit_test(), &rig(seed));
        let (cf, _) = fit(&input(&fit_run)).map_err(|e| fail(BenchRun::Continuous, e))?;
        if cf.knees.len() == 1 {
            one_knee += 1;
            let k = cf.knees[0];
            knee_err.push((k.value - knee_true).abs());
            knee_w.push(k.hi - k.lo);
            if k.lo <= knee_true && knee_true <= k.hi {
                covers += 1;
            }
        }
        if let Some(l) = cf.sensor_lag_s {
            lag.push(l.value);
            if l.lo <= base.tau_sensor_s && base.tau_sensor_s <= l.hi {
                lag_covers += 1;
            }
        }
        let mp_run = simulate(&multipoint_test(), &rig(seed + 10_000));
        let (mf, _) = fit(&input(&mp_run)).map_err(|e| fail(BenchRun::MultiPoint, e))?;
        if mf
            .knees
            .iter()
            .any(|k| k.lo <= knee_true && knee_true <= k.hi)
        {
            bracketed += 1;
        }
        let val = simulate(&validation_test(), &rig(seed + 20_000));
        let ppm = |rate: &[f64]| validation_ppm(&val, rate);
        raw.push(ppm(&val.rate_dps));
        for (table, out) in [(&mf.table, &mut mp), (&cf.table, &mut cont)] {
            let (c, _) = compensate_rows(table, &val.t_s, &val.rate_dps, &val.temp_c);
            out.push(ppm(&c));
        }
        let nk = RigParams {
            truth: base.truth.without_knees(),
            ..rig(seed + 30_000)
        };
        let nk_run = simulate(&continuous_fit_test(), &nk);
        let (nf, _) = fit(&input(&nk_run)).map_err(|e| fail(BenchRun::NoKnee, e))?;
        if nf.knees.is_empty() {
            no_knee_ok += 1;
        }
        for (j, (coil, g)) in coils.iter().zip(&mut gathered).enumerate() {
            let p = RigParams {
                truth: coil.truth,
                arw_dpsh: FAMILIES_ARW_DPSH,
                ..rig(seed + 40_000 + 1_000 * j as u64)
            };
            let (f, _) = fit(&input(&simulate(&families_fit_test(), &p)))
                .map_err(|e| fail(BenchRun::Family(coil.name), e))?;
            let v = simulate(
                &validation_test(),
                &RigParams {
                    seed: p.seed + 500,
                    ..p
                },
            );
            let (c, _) = compensate_rows(&f.table, &v.t_s, &v.rate_dps, &v.temp_c);
            g.add(coil, &f, validation_ppm(&v, &c));
        }
        progress();
    }
    Ok(ScaleFactorBench {
        seeds,
        knee_true_c: knee_true,
        continuous_one_knee: one_knee,
        continuous_knee_abs_err_c: stats(&knee_err),
        continuous_knee_ci_width_c: stats(&knee_w),
        continuous_ci_covers: covers,
        sensor_lag_s: stats(&lag),
        sensor_lag_ci_covers: lag_covers,
        validation_raw_ppm: stats(&raw),
        validation_multipoint_ppm: stats(&mp),
        validation_continuous_ppm: stats(&cont),
        multipoint_knee_bracketed: bracketed,
        no_knee_fitted_without_knee: no_knee_ok,
        families: coils.iter().zip(gathered).map(|(c, g)| g.row(c)).collect(),
    })
}

/// RMS of 60 s means of a validation run's scale-factor error, ppm.
fn validation_ppm(val: &Run, rate: &[f64]) -> f64 {
    let err: Vec<f64> = rate
        .iter()
        .zip(&val.ref_rate_dps)
        .map(|(y, w)| y - w)
        .collect();
    window_rms_ppm(&val.t_s, &val.ref_rate_dps, &err, RESIDUAL_WINDOW_S).0
}
