//! The firmware's FOG core closed around the simulated interferometer and
//! photodetector (gyro_sim's `FogRig`), sample by sample: the mean error of
//! the output against the true rate, with its standard error, over whole
//! oscillation periods, and the rows of a run file (means over 25
//! closures) for those who want them.

use crate::noise::analysis::analyse;
use gyro_sim::{FogRig, OpticsParams, Profile, Segment};
use gyro_sp::fog::agc::DC_FILTER_CLOSURES;
use gyro_sp::fog::{FogConfig, FogParams};

const DEG: f64 = std::f64::consts::PI / 180.0;
const DPH_PER_RAD_S: f64 = 3600.0 / DEG;
/// Closures per run-file row (a frame's worth).
const ROW_CLOSURES: u32 = 25;
/// The start-up left out of the mean by default, in time constants of the
/// AGC's DC filter: its start from the first closure's DC decays as
/// exp(-t/tau), and under 50 000 deg/s^2 at 60 Hz it starts at about 10 %
/// of the eps^2 drift; five time constants leave 0.07 % of that.
pub const SETTLE_TAUS: f64 = 5.0;

/// A sinusoidal angular oscillation about the constant rate.
#[derive(Clone, Debug)]
pub struct Vibration {
    /// Peak angular acceleration, deg/s^2.
    pub dps2: f64,
    pub hz: f64,
}

#[derive(Clone, Debug)]
pub struct FogRunParams {
    pub phi0_rad: f64,
    pub closure_hz: f64,
    /// Constant input rate, deg/s.
    pub rate_dps: f64,
    pub vibration: Option<Vibration>,
    /// Vibration levels, fractions of the peak (empty: the full level).
    pub levels: Vec<f64>,
    pub duration_s: f64,
    pub vibration_correction: bool,
    /// Shot and intensity noise.
    pub noise: bool,
    pub seed: u64,
    pub loop_gain: f64,
    /// 2*pi loop's acquisition and tracking gains (docs/fog.md, "The 2*pi
    /// loop's gear").
    pub gain_loop_gain: f64,
    pub gain_loop_track_gain: f64,
    /// Modulator gain error, relative.
    pub vpi_error: f64,
    pub adc_bits: u32,
    pub dither_codes: f64,
    /// Start-up time left out of the mean error, s (None: [`SETTLE_TAUS`]
    /// time constants of the AGC's DC filter, the slowest loop).
    pub settle_s: Option<f64>,
    /// DAC latency, closures (0 or 1: the hw board's DMA ping-pong).
    pub dac_latency: u32,
}

/// A parameter of the run checked against its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FogRunParam {
    Duration,
    Rate,
    AdcBits,
    VibrationLevels,
    VibrationDps2,
    VibrationHz,
    DacLatency,
}

/// Why a run cannot be made, in the order the parameters are checked.
#[derive(Debug)]
pub enum FogRunError {
    OutOfRange(FogRunParam, f64),
    /// The loop configuration refused (its reason, as the core states it).
    Loop(String),
    /// More than 8 vibration levels.
    TooManyLevels,
    /// The run is shorter than one oscillation period after settling.
    ShorterThanPeriod,
}

/// Result of a FOG simulation.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FogSummary {
    pub mean_error_dph: f64,
    /// Standard error of `mean_error_dph` from the output's own noise: the
    /// Allan deviation, at the averaging time, of the noise model fitted to
    /// the error's batch means (whole oscillation periods each), which holds
    /// for correlated noise (the slow AGC); null under 3 batches.
    pub mean_error_stderr_dph: Option<f64>,
    pub mean_error_raw_dph: f64,
    pub mean_error_raw_stderr_dph: Option<f64>,
    pub predicted_drift_dph: f64,
    pub duration_s: f64,
    pub averaged_s: f64,
    /// Start-up left out of the mean, s.
    pub settle_s: f64,
    /// The whole settling time was left out (false: the run was too short,
    /// half of it was, and the mean still holds some of the start-up).
    pub settled: bool,
    pub steps: u64,
    pub wall_s: f64,
    pub realtime_factor: f64,
    pub final_codes_per_turn: f64,
    pub faults_seen: u16,
}

/// One run-file row, means over 25 closures: time at the row's middle,
/// true rate, output, output without the eps^2 correction (deg/s), the
/// angular acceleration there (deg/s^2), the loop residual (rad), codes per
/// turn and the fault flags of the row's last closure.
pub type FogRow = [f64; 8];

/// Where the rows go: a writer, whose error ends the run.
pub type RowSink<'a, E> = &'a mut dyn FnMut(&FogRow) -> Result<(), E>;

fn check(p: FogRunParam, v: f64, ok: bool) -> Result<(), FogRunError> {
    if v.is_finite() && ok {
        Ok(())
    } else {
        Err(FogRunError::OutOfRange(p, v))
    }
}

/// Means over the closures of a run-file row.
#[derive(Default)]
struct RowMeans {
    sum: [f64; 4],
    n: u32,
}

impl RowMeans {
    /// Adds a closure's true rate, output and raw output (rad/s) and loop
    /// residual (rad); the row's means when this closure completes it.
    fn add(&mut self, v: [f64; 4]) -> Option<[f64; 4]> {
        for (s, x) in self.sum.iter_mut().zip(v) {
            *s += x;
        }
        self.n += 1;
        if self.n < ROW_CLOSURES {
            return None;
        }
        let n = self.n as f64;
        let means = self.sum.map(|s| s / n);
        *self = Self::default();
        Some(means)
    }
}

/// A run ready to go: its configuration, rig and averaging plan.
pub struct FogRun {
    cfg: FogConfig,
    optics: OpticsParams<f64>,
    profile: Profile<f64>,
    predicted_dph: f64,
    steps: u64,
    avg_steps: u64,
    batch_steps: u64,
    settled: bool,
}

/// The input-rate profile of a run: constant, or the oscillation in equal
/// parts of whole periods (the rate continuous at each change: every
/// segment starts at a zero crossing). Returns the profile and the period.
fn profile(p: &FogRunParams, levels: &[f64]) -> Result<(Profile<f64>, Option<f64>), FogRunError> {
    let rate = p.rate_dps * DEG;
    let Some(v) = &p.vibration else {
        return Ok((Profile::constant(rate), None));
    };
    let (eps, f) = (v.dps2, v.hz);
    check(FogRunParam::VibrationDps2, eps, eps >= 0.0)?;
    check(
        FogRunParam::VibrationHz,
        f,
        f > 0.0 && f < p.closure_hz / 4.0,
    )?;
    let part = if levels.len() > 1 {
        (p.duration_s / levels.len() as f64 * f).floor().max(1.0) / f
    } else {
        f64::INFINITY
    };
    let segs: Vec<Segment<f64>> = levels
        .iter()
        .enumerate()
        .map(|(i, &l)| Segment::Oscillation {
            offset: rate,
            eps_peak: eps * DEG * l,
            freq_hz: f,
            duration: if i + 1 == levels.len() {
                f64::INFINITY
            } else {
                part
            },
        })
        .collect();
    Ok((Profile::new(&segs), Some(1.0 / f)))
}

impl FogRun {
    /// Checks the parameters (in this order: duration, rate, ADC bits, DAC
    /// latency, the loop configuration, the vibration levels, acceleration and
    /// frequency, the length against one period) and plans the run.
    pub fn new(p: &FogRunParams) -> Result<Self, FogRunError> {
        let d = p.duration_s;
        check(FogRunParam::Duration, d, d > 0.0 && d <= 1e5)?;
        check(FogRunParam::Rate, p.rate_dps, p.rate_dps.abs() <= 2000.0)?;
        let bits = p.adc_bits;
        check(FogRunParam::AdcBits, bits as f64, (8..=16).contains(&bits))?;
        let lat = p.dac_latency;
        check(FogRunParam::DacLatency, lat as f64, lat <= 1)?;
        let params = FogParams {
            phi0_rad: p.phi0_rad,
            closure_hz: p.closure_hz,
            loop_gain: p.loop_gain,
            gain_loop_gain: p.gain_loop_gain,
            gain_loop_track_gain: p.gain_loop_track_gain,
            dither_adc_codes: p.dither_codes,
            vibration_correction: p.vibration_correction,
            dac_latency: p.dac_latency,
            ..FogParams::default()
        };
        let mut optics = OpticsParams::<f64>::nominal(
            params.tau_s,
            params.samples_per_half,
            params.dac_codes_per_turn,
        );
        optics.noise = p.noise;
        optics.seed = p.seed;
        optics.adc_bits = p.adc_bits;
        optics.vpi_gain_error = p.vpi_error;
        let params = optics.matched(params);
        let cfg = FogConfig::new(params).map_err(|e| FogRunError::Loop(format!("{e:?}")))?;
        let levels: Vec<f64> = if p.levels.is_empty() {
            vec![1.0]
        } else {
            p.levels.clone()
        };
        if levels.len() > 8 {
            return Err(FogRunError::TooManyLevels);
        }
        for &l in &levels {
            check(FogRunParam::VibrationLevels, l, (0.0..=1.0).contains(&l))?;
        }
        let (profile, period) = profile(p, &levels)?;
        let mean_level_sq = levels.iter().map(|l| l * l).sum::<f64>() / levels.len() as f64;
        let mean_eps_sq = p
            .vibration
            .as_ref()
            .map_or(0.0, |v| (v.dps2 * DEG).powi(2) / 2.0 * mean_level_sq);
        let predicted_dph = cfg.predicted_vibration_drift(mean_eps_sq) * DPH_PER_RAD_S;
        let dt = cfg.closure_period_s();
        let steps = (p.duration_s / dt).round() as u64;
        // Average over whole oscillation periods after the settling time;
        // at most half the run is left out, and a run too short for the
        // whole settling says so (`settled`).
        let settle_s = p
            .settle_s
            .unwrap_or(SETTLE_TAUS * DC_FILTER_CLOSURES as f64 * dt);
        let want_steps = (settle_s / dt).ceil() as u64;
        let settle_steps = want_steps.min(steps / 2);
        let settled = settle_steps == want_steps;
        let avg_steps = match period {
            Some(per) => {
                let per = per / dt;
                let whole = ((steps - settle_steps) as f64 / per).floor();
                if whole < 1.0 {
                    return Err(FogRunError::ShorterThanPeriod);
                }
                (whole * per).round() as u64
            }
            None => steps - settle_steps,
        };
        // Batches for the standard error: whole oscillation periods (else 25
        // steps, a frame), at most about 10^6 of them.
        let batch_steps = {
            let per = period.map_or(25.0, |per| per / dt);
            let whole = (avg_steps as f64 / 1e6 / per).ceil().max(1.0);
            (whole * per).round().max(1.0) as u64
        };
        Ok(Self {
            cfg,
            optics,
            profile,
            predicted_dph,
            steps,
            avg_steps,
            batch_steps,
            settled,
        })
    }

    /// Closures the run takes.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Runs it: `rows` takes each run-file row when given, `progress` the
    /// closure count now and then.
    pub fn run<E>(
        self,
        mut rows: Option<RowSink<E>>,
        mut progress: impl FnMut(u64),
    ) -> Result<FogSummary, E> {
        let dt = self.cfg.closure_period_s();
        let (steps, avg_steps) = (self.steps, self.avg_steps);
        let start_avg = steps - avg_steps;
        let mut batches: Vec<(f64, f64)> = Vec::new();
        let (mut b_err, mut b_raw, mut b_n) = (0.0f64, 0.0f64, 0u64);
        let mut rig = FogRig::new(self.cfg, self.optics, self.profile);
        let lsb_rate = self.cfg.rad_s_per_phase_lsb();
        let (mut err_sum, mut raw_sum) = (0.0f64, 0.0f64);
        let mut faults_seen = 0u16;
        let mut last_cpt = 0u32;
        let mut row = RowMeans::default();
        let t0 = std::time::Instant::now();
        for k in 0..steps {
            let r = rig.run_closure();
            let out = r.out.sagnac_phase_corrected as f64 * lsb_rate;
            let raw = r.out.sagnac_phase as f64 * lsb_rate;
            if k >= start_avg {
                err_sum += out - r.true_rate;
                raw_sum += raw - r.true_rate;
                b_err += out - r.true_rate;
                b_raw += raw - r.true_rate;
                b_n += 1;
                if b_n == self.batch_steps {
                    batches.push((b_err / b_n as f64, b_raw / b_n as f64));
                    (b_err, b_raw, b_n) = (0.0, 0.0, 0);
                }
            }
            faults_seen |= r.out.faults.bits();
            last_cpt = r.out.codes_per_turn_q8;
            if let Some(sink) = rows.as_mut() {
                let residual = r.out.residual as f64 * gyro_sp::RAD_PER_PHASE_LSB;
                if let Some(m) = row.add([r.true_rate, out, raw, residual]) {
                    // Acceleration at the row's middle: its square samples the
                    // oscillation's phases evenly (the rectification's mean).
                    let t_mid = r.t_end - 12.5 * dt;
                    sink(&[
                        t_mid,
                        m[0] / DEG,
                        m[1] / DEG,
                        m[2] / DEG,
                        rig.profile.accel_at(t_mid) / DEG,
                        m[3],
                        r.out.codes_per_turn_q8 as f64 / 256.0,
                        r.out.faults.bits() as f64,
                    ])?;
                }
            }
            if k % 65_536 == 0 {
                progress(k);
            }
        }
        let wall = t0.elapsed().as_secs_f64();
        let n = avg_steps.max(1) as f64;
        let batch_s = self.batch_steps as f64 * dt;
        let se = |f: fn(&(f64, f64)) -> f64| {
            let v: Vec<f64> = batches.iter().map(f).collect();
            analyse(&v, batch_s)
                .ok()
                .map(|a| a.mean_se_dps * DPH_PER_RAD_S)
        };
        Ok(FogSummary {
            mean_error_dph: err_sum / n * DPH_PER_RAD_S,
            mean_error_stderr_dph: se(|b| b.0),
            mean_error_raw_dph: raw_sum / n * DPH_PER_RAD_S,
            mean_error_raw_stderr_dph: se(|b| b.1),
            predicted_drift_dph: self.predicted_dph,
            duration_s: steps as f64 * dt,
            averaged_s: avg_steps as f64 * dt,
            settle_s: (steps - avg_steps) as f64 * dt,
            settled: self.settled,
            steps,
            wall_s: wall,
            realtime_factor: steps as f64 * dt / wall.max(1e-9),
            final_codes_per_turn: last_cpt as f64 / 256.0,
            faults_seen,
        })
    }
}
