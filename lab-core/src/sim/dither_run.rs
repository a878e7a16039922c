//! A mechanically dithered RLG (`gyro_sim::rlg_dither`) counted and
//! dither-stripped by the firmware's own RLG core (`gyro_sp::rlg`): each
//! pickoff zero crossing goes to the core's latch, each 500 Hz update reads
//! the counter and gives the frame words, as on the board. The output's
//! angle random walk comes from the Allan analysis of the frames' rate; the
//! prediction from the crossing map (dither_theory.rs).

use super::dither_theory::{predict, Prediction};
use crate::noise::analysis::analyse;
use crate::noise::terms::to_units;
use gyro_sim::{DitherParams, DitheredRlg};
use gyro_sp::rlg::thermal::ThermalConfig;
use gyro_sp::rlg::{LatchSample, RlgChannel, RlgConfig, StripConfig, ThermalCoeffs};

/// The board's RLG update (and frame) rate, Hz.
pub const FRAME_HZ: u32 = 500;
/// The latch timer's clock on the hw board (TIM5 at 84 MHz), Hz.
pub const CLOCK_HZ: u32 = 84_000_000;
/// Frames averaged for the Allan analysis (its tau0 = 20 ms): below that
/// the curve holds the stripping's residual and the frames' aliasing of it
/// (hundredths of a count, white in angle), which at the low random walks
/// of the range hide the walk's slope from the fit.
pub const ALLAN_FRAMES: usize = 10;

/// Where a run hands each frame (a run file's writer).
pub type RowSink<'a, E> = &'a mut dyn FnMut(&DitherRow) -> Result<(), E>;

/// One run's settings.
#[derive(Clone, Copy, Debug)]
pub struct DitherRun {
    pub gyro: DitherParams,
    /// Constant input rate, deg/s.
    pub rate_dps: f64,
    pub duration_s: f64,
    /// Time left out of the statistics while the core's estimates settle, s.
    pub settle_s: f64,
    /// The photodiodes place each latch within its count (else the latch
    /// stands for its count's middle).
    pub photodiodes: bool,
}

/// One frame of the run.
#[derive(Clone, Copy, Debug, Default)]
pub struct DitherRow {
    /// The instant the frame's angle stands for (one update before the
    /// frame: the stripping waits for the latch after it), s.
    pub t_s: f64,
    pub ref_rate_dps: f64,
    /// The core's compensated rate over the frame, deg/s.
    pub rate_dps: f64,
    /// The counter read as it is, without stripping, deg/s.
    pub raw_rate_dps: f64,
    /// Cumulative output angle (the frames' whole counts), deg.
    pub angle_deg: f64,
    /// Stripped angle minus the gyro's angle without the dither, counts.
    pub residual_counts: f64,
    /// The raw counter's angle minus the same, counts.
    pub raw_residual_counts: f64,
}

/// What a run measured, and what the physics predicts.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DitherSummary {
    /// The output's angle random walk (Allan analysis), deg/sqrt(h), with
    /// its 95 % interval; null where the fit has no such term.
    pub arw_dpsh: Option<f64>,
    pub arw_lo_dpsh: Option<f64>,
    pub arw_hi_dpsh: Option<f64>,
    /// The crossings' random walk the physics predicts, deg/sqrt(h)
    /// (Killpatrick's with the kicks' random part, `sqrt(1 - e^(-sigma^2))`).
    pub arw_predicted_dpsh: f64,
    /// The long-time walk where a dynamic lock-in zone holds the phase
    /// (the washboard's effective diffusion), deg/sqrt(h), and the zone's
    /// relaxation time, s (null: no pull, or one slower than 1e9 s).
    pub arw_long_time_predicted_dpsh: f64,
    pub zone_relaxation_s: Option<f64>,
    /// Killpatrick's `Omega_L/sqrt(2 pi K Omega_d)`, K in fringes per degree.
    pub arw_killpatrick_dpsh: f64,
    /// The same formula with K in counts per degree (4x the fringes): what
    /// taking K from `--counts-per-deg` would give, half the truth.
    pub arw_killpatrick_counts_k_dpsh: f64,
    /// RMS (about its mean) of the stripped angle minus the gyro's angle
    /// without the dither at the frame rate, counts; its largest excursion;
    /// the same for the raw counter (the dither the stripping removed).
    pub dither_residual_counts_rms: f64,
    pub dither_residual_counts_max: f64,
    pub raw_dither_counts_rms: f64,
    /// Mean of output minus input rate, deg/h, its standard error (the
    /// Allan model at the record's length) and the crossing map's prediction.
    pub mean_rate_error_dph: f64,
    pub mean_rate_error_stderr_dph: f64,
    pub predicted_rate_error_dph: f64,
    /// Fringe phase rms at a turnaround from the amplitude noise, rad.
    pub crossing_phase_rms_rad: f64,
    /// The nearest dynamic lock-in zone (`m f_d / K`), its residual lock-in
    /// rate (deg/h) and barrier over diffusion.
    pub dynamic_zone: i64,
    pub residual_lock_in_dph: f64,
    pub zone_kappa: f64,
    /// The Allan fit's verdict on itself.
    pub allan_fit_consistent: bool,
    pub allan_chi2_per_dof: f64,
    /// The alternation the core learnt (angle lead at a rising latch), counts.
    pub alternation_counts: f64,
    /// RLG flags seen in any frame (bits of `RlgFlags`).
    pub flags_seen: u8,
    pub duration_s: f64,
    pub analysed_s: f64,
    pub frames: usize,
    pub wall_s: f64,
    pub realtime_factor: f64,
}

/// Why a run cannot go.
#[derive(Clone, Debug, PartialEq)]
pub enum DitherRunError {
    /// Parameter, value.
    OutOfRange(&'static str, f64),
    /// The analysis failed (message).
    Analysis(String),
}

impl DitherRun {
    pub fn check(&self) -> Result<(), DitherRunError> {
        let g = &self.gyro;
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let checks: [(&'static str, f64, bool); 9] = [
            (
                "counts-per-deg",
                g.counts_per_deg,
                pos(g.counts_per_deg) && g.counts_per_deg <= 1e6,
            ),
            (
                "lock-in-dps",
                g.lock_in_dps,
                g.lock_in_dps.is_finite() && (0.0..=10.0).contains(&g.lock_in_dps),
            ),
            (
                "dither-dps",
                g.dither_dps,
                pos(g.dither_dps) && g.dither_dps <= 2000.0,
            ),
            (
                "dither-hz",
                g.dither_hz,
                (100.0..=2000.0).contains(&g.dither_hz),
            ),
            (
                "dither-noise-frac",
                g.noise_frac,
                (0.0..=0.2).contains(&g.noise_frac),
            ),
            (
                "rate-dps",
                self.rate_dps,
                self.rate_dps.is_finite() && self.rate_dps.abs() < 0.9 * g.dither_dps,
            ),
            (
                "duration-s",
                self.duration_s,
                self.duration_s.is_finite()
                    && self.duration_s >= self.settle_s + 2.0
                    && self.duration_s <= 1e6,
            ),
            (
                "fd-drift-frac",
                g.fd_drift_frac,
                (0.0..=0.1).contains(&g.fd_drift_frac),
            ),
            (
                "pickoff-delay-ns",
                g.pickoff_delay_s * 1e9,
                (0.0..=5e-6).contains(&g.pickoff_delay_s),
            ),
        ];
        for (name, v, ok) in checks {
            if !ok {
                return Err(DitherRunError::OutOfRange(name, v));
            }
        }
        Ok(())
    }

    /// The core's configuration for this gyro.
    pub fn config(&self) -> RlgConfig {
        let thermal = ThermalConfig::new(&ThermalCoeffs::SAFE, 0.1);
        let f = self.gyro.dither_hz;
        let drift = 1.0 + self.gyro.fd_drift_frac;
        let mut strip = StripConfig::new(
            CLOCK_HZ,
            f / drift,
            f * drift,
            [
                (self.gyro.photodiodes.offset[0]).round() as i32,
                (self.gyro.photodiodes.offset[1]).round() as i32,
            ],
        );
        strip.interpolate = self.photodiodes;
        RlgConfig::new(thermal, self.gyro.counts_per_deg, FRAME_HZ).with_dither(strip)
    }

    pub fn frames(&self) -> u64 {
        (self.duration_s * FRAME_HZ as f64).round() as u64
    }

    pub fn prediction(&self) -> Prediction {
        predict(&self.gyro, self.rate_dps)
    }

    /// Runs, handing each frame to `on_row` and the frame count to
    /// `progress`; then the analysis.
    pub fn run<E: From<DitherRunError>>(
        &self,
        mut on_row: Option<RowSink<'_, E>>,
        mut progress: impl FnMut(u64),
    ) -> Result<DitherSummary, E> {
        self.check()?;
        let wall = std::time::Instant::now();
        let cfg = self.config();
        let k = self.gyro.counts_per_deg;
        let mut sim = DitheredRlg::<f64>::new(self.gyro);
        let mut ch = RlgChannel::default();
        let dt = 1.0 / FRAME_HZ as f64;
        let ticks = |t: f64| ((t * CLOCK_HZ as f64).round() as u64) as u32;
        let n = self.frames();
        let settle = (self.settle_s * FRAME_HZ as f64).ceil() as u64;
        let (mut rates, mut resid, mut raw_resid) = (vec![], vec![], vec![]);
        let mut flags = 0u8;
        let (mut counts0, mut raw_prev, mut truth_prev) = (None::<i64>, 0i64, 0.0f64);
        let mut angle_counts = 0i64;
        for i in 1..=n {
            let t = i as f64 * dt;
            let r = sim.advance(t, self.rate_dps, |l| {
                ch.latch(
                    &cfg,
                    &LatchSample {
                        time: ticks(l.t_s),
                        counter: l.counter,
                        rising: l.rising,
                        photodiodes: Some(l.photodiodes),
                    },
                );
            });
            ch.update(&cfg, ticks(t), r.counter, None);
            let span = ch.take_frame();
            let w = ch.words(&cfg, &span);
            flags |= w.flags.bits();
            angle_counts += span.counts();
            let c0 = *counts0.get_or_insert(r.counts);
            // The stripped angle stands for the previous update's instant.
            let truth = truth_prev - c0 as f64;
            let row = DitherRow {
                t_s: t - dt,
                ref_rate_dps: self.rate_dps,
                rate_dps: w.rate_comp_udps as f64 * 1e-6,
                raw_rate_dps: (r.counts - raw_prev) as f64 / k / dt,
                angle_deg: angle_counts as f64 / k,
                residual_counts: ch.angle_q16() as f64 / 65_536.0 - truth,
                raw_residual_counts: (raw_prev - c0) as f64 - truth,
            };
            raw_prev = r.counts;
            truth_prev = r.truth_counts;
            if i > settle {
                rates.push(row.rate_dps);
                resid.push(row.residual_counts);
                raw_resid.push(row.raw_residual_counts);
            }
            if i > 2 {
                if let Some(f) = on_row.as_mut() {
                    f(&row)?;
                }
            }
            if i % 5000 == 0 {
                progress(i);
            }
        }
        progress(n);
        let wall_s = wall.elapsed().as_secs_f64();
        let averaged: Vec<f64> = rates
            .chunks_exact(ALLAN_FRAMES)
            .map(|c| c.iter().sum::<f64>() / ALLAN_FRAMES as f64)
            .collect();
        let a = analyse(&averaged, dt * ALLAN_FRAMES as f64)
            .map_err(|e| DitherRunError::Analysis(e.to_string()))?;
        const ARW: usize = 1;
        let t = &a.terms;
        let term = |v: f64| t.present[ARW].then(|| to_units(ARW, v));
        let rms_about_mean = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
            let rms =
                (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len().max(1) as f64).sqrt();
            let max = v.iter().map(|x| (x - m).abs()).fold(0.0, f64::max);
            (rms, max)
        };
        let (res_rms, res_max) = rms_about_mean(&resid);
        let (raw_rms, _) = rms_about_mean(&raw_resid);
        let pred = self.prediction();
        let dpsh = |v: f64| v * 60.0;
        let killpatrick_counts = self.gyro.lock_in_dps
            / (2.0 * std::f64::consts::PI * self.gyro.counts_per_deg * self.gyro.dither_dps).sqrt();
        Ok(DitherSummary {
            arw_dpsh: term(t.c[ARW]),
            arw_lo_dpsh: term(t.lo[ARW]),
            arw_hi_dpsh: term(t.hi[ARW]),
            arw_predicted_dpsh: dpsh(pred.arw_dps_rts),
            arw_long_time_predicted_dpsh: dpsh(pred.arw_long_dps_rts),
            // A relaxation beyond any record (1e9 s, 30 years) is no pull:
            // null, not 1e305.
            zone_relaxation_s: (pred.relaxation_s.is_finite() && pred.relaxation_s < 1e9)
                .then_some(pred.relaxation_s),
            arw_killpatrick_dpsh: dpsh(pred.killpatrick_dps_rts),
            arw_killpatrick_counts_k_dpsh: dpsh(killpatrick_counts),
            dither_residual_counts_rms: res_rms,
            dither_residual_counts_max: res_max,
            raw_dither_counts_rms: raw_rms,
            mean_rate_error_dph: (a.mean_dps - self.rate_dps) * 3600.0,
            mean_rate_error_stderr_dph: a.mean_se_dps * 3600.0,
            predicted_rate_error_dph: pred.rate_error_dps * 3600.0,
            crossing_phase_rms_rad: pred.sigma_rad,
            dynamic_zone: pred.zone,
            residual_lock_in_dph: pred.residual_lock_in_dps * 3600.0,
            zone_kappa: pred.kappa,
            allan_fit_consistent: t.goodness.consistent,
            allan_chi2_per_dof: t.goodness.chi2_per_dof,
            alternation_counts: ch.strip.alternation_q16() as f64 / 65_536.0,
            flags_seen: flags,
            duration_s: self.duration_s,
            analysed_s: rates.len() as f64 * dt,
            frames: n as usize,
            wall_s,
            realtime_factor: self.duration_s / wall_s.max(1e-9),
        })
    }
}

/// A parameter out of range, named as the command line names it.
impl From<DitherRunError> for crate::error::LabError {
    fn from(e: DitherRunError) -> Self {
        match e {
            DitherRunError::OutOfRange(name, v) => {
                crate::error::LabError::Usage(format!("--{name} {v}: out of range"))
            }
            DitherRunError::Analysis(m) => {
                crate::error::LabError::Bench(format!("Allan analysis of the run: {m}"))
            }
        }
    }
}
