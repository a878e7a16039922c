//! Dithered RLG: the simulator against the brute-force lock-in equation and
//! the physics (Fresnel kick, Killpatrick's random walk), and the
//! firmware's stripping on it (residual dither, no lost count with f_d
//! drifting, faults).

use gyro_sim::rlg_dither::{Accuracy, BruteForce, DitherParams, DitheredRlg, Latch};
use gyro_sp::rlg::dither::atan2_turns;
use gyro_sp::rlg::thermal::ThermalConfig;
use gyro_sp::rlg::{LatchSample, RlgChannel, RlgConfig, RlgFlags, StripConfig, ThermalCoeffs};

const CLOCK_HZ: u32 = 84_000_000;
const FRAME_HZ: u32 = 500;

fn params(k: f64, ol: f64, od: f64, fd: f64, noise: f64) -> DitherParams {
    DitherParams {
        counts_per_deg: k,
        lock_in_dps: ol,
        dither_dps: od,
        dither_hz: fd,
        noise_frac: noise,
        ..Default::default()
    }
}

/// Latches of a fast simulation (f64 or f32 inside the windows) and of the
/// brute force over the same record.
fn both(p: DitherParams, rate: f64, dur: f64, f32_inner: bool) -> (Vec<Latch>, Vec<Latch>) {
    let n = (dur * 500.0) as usize;
    let mut a = vec![];
    if f32_inner {
        let mut s = DitheredRlg::<f32>::new(p);
        for k in 1..=n {
            s.advance(k as f64 / 500.0, rate, |l| a.push(*l));
        }
    } else {
        let mut s = DitheredRlg::<f64>::new(p);
        for k in 1..=n {
            s.advance(k as f64 / 500.0, rate, |l| a.push(*l));
        }
    }
    let mut b = vec![];
    let mut bf = BruteForce::new(p, p.dither_dps * 1.5 + rate.abs(), 12.0);
    for k in 1..=n {
        bf.advance(k as f64 / 500.0, rate, |l| b.push(*l));
    }
    (a, b)
}

/// Kicks: the change of the angle without the dither between latches,
/// less the input's.
fn kicks(v: &[Latch], rate: f64, k: f64) -> Vec<f64> {
    v.windows(2)
        .map(|w| w[1].truth_counts - w[0].truth_counts - rate * k * (w[1].t_s - w[0].t_s))
        .collect()
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// The fast simulator (windows integrated, averaged equation between)
/// against RK4 of the plain lock-in equation at 12 steps per radian of
/// fringe phase: each crossing's kick to 1e-3 of its size, the angle to
/// 1e-3 count, at rest, near the dither's peak rate and with f_d drifting;
/// f32 inside the windows (the QEMU board's) to 2e-3.
#[test]
fn simulator_matches_brute_force() {
    let drifting = DitherParams {
        fd_drift_frac: 0.02,
        fd_drift_period_s: 0.1,
        ..params(3000.0, 0.1, 200.0, 400.0, 0.05)
    };
    let qemu = DitherParams {
        accuracy: Accuracy::QEMU,
        ..params(8000.0, 0.05, 150.0, 400.0, 0.05)
    };
    for (p, rate, f32_inner, tol) in [
        (params(2000.0, 0.2, 100.0, 500.0, 0.05), 0.0, false, 1e-3),
        (params(5000.0, 0.02, 300.0, 300.0, 0.02), 0.01, false, 1e-3),
        (params(3000.0, 0.1, 200.0, 400.0, 0.05), 150.0, false, 1e-3),
        (drifting, -7.0, false, 1e-3),
        (qemu, 60.0, true, 2e-3),
    ] {
        let (a, b) = both(p, rate, 0.2, f32_inner);
        assert_eq!(a.len(), b.len());
        assert!(a.len() > 100);
        for (x, y) in a.iter().zip(&b) {
            assert!((x.t_s - y.t_s).abs() < 1e-12);
            assert!(
                (x.truth_counts - y.truth_counts).abs() < 1e-3,
                "{p:?} at {}: {} vs {}",
                x.t_s,
                x.truth_counts,
                y.truth_counts
            );
        }
        let (ka, kb) = (
            kicks(&a, rate, p.counts_per_deg),
            kicks(&b, rate, p.counts_per_deg),
        );
        let diff: Vec<f64> = ka.iter().zip(&kb).map(|(x, y)| x - y).collect();
        let ratio = rms(&diff) / rms(&kb);
        assert!(
            ratio < tol,
            "{p:?}: per-crossing error {ratio:.2e} of the kick"
        );
    }
}

/// Each crossing kicks the angle by `Omega_L sqrt(1/(K Omega_dot))
/// sin(psi_0 + pi/4)` (Fresnel, K in fringes per degree): with the phase
/// randomised the kicks' rms is that over sqrt(2), and they add up as
/// Killpatrick's random walk `Omega_L/sqrt(2 pi K Omega_d)`.
#[test]
fn fresnel_kick_and_killpatrick_walk() {
    for p in [
        params(2000.0, 0.2, 100.0, 500.0, 0.08),
        params(5000.0, 0.05, 300.0, 300.0, 0.05),
    ] {
        let mut s = DitheredRlg::<f64>::new(p);
        let mut lat = vec![];
        let mut e = vec![];
        for k in 1..=300 {
            let r = s.advance(k as f64 * 0.1, 0.0, |l| lat.push(*l));
            e.push(r.lockin_counts / p.counts_per_deg);
        }
        let kr = rms(&kicks(&lat, 0.0, p.counts_per_deg)) / p.counts_per_deg;
        let kfr = p.fringes_per_deg();
        let fresnel = p.lock_in_dps * (1.0 / (kfr * p.omega_dot())).sqrt() / 2f64.sqrt();
        // 30 s of kicks at 2 f_d: the rms to about 0.5 %.
        assert!(
            (kr / fresnel - 1.0).abs() < 0.02,
            "{p:?}: kick {kr:.4e} vs {fresnel:.4e}"
        );
        // The walk over 0.1 s steps: 300 increments, N to about 4 %.
        let d: Vec<f64> = e.windows(2).map(|w| w[1] - w[0]).collect();
        let n = rms(&d) / 0.1f64.sqrt();
        let kp = p.killpatrick_arw_dps_rts();
        assert!((n / kp - 1.0).abs() < 0.15, "{p:?}: N {n:.4e} vs {kp:.4e}");
    }
}

/// The firmware's core on the simulator, frame by frame: what a board does.
struct Rig {
    sim: DitheredRlg<f64>,
    ch: RlgChannel,
    cfg: RlgConfig,
    i: u64,
    counts0: Option<i64>,
    truth_prev: f64,
    /// Sum of the frames' whole counts.
    frame_counts: i64,
}

struct FrameOut {
    /// Output angle minus the gyro's angle without the dither at the
    /// instant it stands for, and that angle, counts.
    residual: f64,
    truth: f64,
    rate_dps: f64,
    flags: RlgFlags,
}

impl Rig {
    fn new(p: DitherParams, photodiodes: bool) -> Self {
        let drift = 1.0 + p.fd_drift_frac;
        let mut strip = StripConfig::new(
            CLOCK_HZ,
            p.dither_hz / drift,
            p.dither_hz * drift,
            [
                p.photodiodes.offset[0] as i32,
                p.photodiodes.offset[1] as i32,
            ],
        );
        strip.interpolate = photodiodes;
        let thermal = ThermalConfig::new(&ThermalCoeffs::SAFE, 0.1);
        Self {
            sim: DitheredRlg::new(p),
            ch: RlgChannel::default(),
            cfg: RlgConfig::new(thermal, p.counts_per_deg, FRAME_HZ).with_dither(strip),
            i: 0,
            counts0: None,
            truth_prev: 0.0,
            frame_counts: 0,
        }
    }

    /// One frame; `board(latch, out)` puts what the latch interrupt sees
    /// of each zero crossing in `out` (nothing, it, or it and a glitch).
    fn frame(
        &mut self,
        rate: f64,
        mut board: impl FnMut(&Latch, &mut Vec<LatchSample>),
    ) -> FrameOut {
        self.i += 1;
        let t = self.i as f64 / FRAME_HZ as f64;
        let ticks = |t: f64| ((t * CLOCK_HZ as f64).round() as u64) as u32;
        let (ch, cfg) = (&mut self.ch, &self.cfg);
        let mut seen = Vec::new();
        let r = self.sim.advance(t, rate, |l| {
            seen.clear();
            board(l, &mut seen);
            for s in &seen {
                ch.latch(cfg, s);
            }
        });
        self.ch.update(&self.cfg, ticks(t), r.counter, None);
        let span = self.ch.take_frame();
        let w = self.ch.words(&self.cfg, &span);
        self.frame_counts += span.counts();
        let c0 = *self.counts0.get_or_insert(r.counts);
        let truth = self.truth_prev - c0 as f64;
        let residual = self.ch.angle_q16() as f64 / 65_536.0 - truth;
        self.truth_prev = r.truth_counts;
        FrameOut {
            residual,
            truth,
            rate_dps: w.rate_comp_udps as f64 * 1e-6,
            flags: w.flags,
        }
    }
}

fn latch_sample(l: &Latch) -> LatchSample {
    LatchSample {
        time: ((l.t_s * CLOCK_HZ as f64).round() as u64) as u32,
        counter: l.counter,
        rising: l.rising,
        photodiodes: Some(l.photodiodes),
    }
}

fn rms_about_mean(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    rms(&v.iter().map(|x| x - m).collect::<Vec<_>>())
}

/// 60 s with f_d drifting +-2 % (a 20 s cycle), through a wrap of the
/// 32-bit latch timer (51 s at 84 MHz) and hundreds of the 16-bit counter:
/// the stripped angle's residual dither is hundredths of a count with the
/// photodiodes and a quarter count from the latched counts alone, and the
/// frames' whole counts add up to the gyro's angle (no count lost).
#[test]
fn stripping_residual_and_no_lost_count() {
    for (photodiodes, bound) in [(true, 0.05), (false, 0.35)] {
        let p = DitherParams {
            fd_drift_frac: 0.02,
            fd_drift_period_s: 20.0,
            seed: 5,
            ..params(8000.0, 0.05, 150.0, 400.0, 0.05)
        };
        let mut rig = Rig::new(p, photodiodes);
        let rate = 37.3;
        let mut res = vec![];
        let (mut first, mut last) = (None, 0.0);
        for i in 0..30_000 {
            let f = rig.frame(rate, |l, out| out.push(latch_sample(l)));
            if i > 1000 {
                res.push(f.residual);
                assert!(!f.flags.contains(RlgFlags::NO_PICKOFF), "frame {i}");
            }
            if first.is_none() && rig.ch.angle_q16() != 0 {
                // The first output: the frames count from it.
                assert_eq!(rig.frame_counts, 0);
                first = Some(f.truth);
            }
            last = f.truth;
        }
        let r = rms_about_mean(&res);
        assert!(
            r < bound,
            "photodiodes {photodiodes}: residual {r:.4} counts rms"
        );
        // The frames' whole counts against the gyro's angle over the same
        // span: the ends' residuals and the floors' fractions apart.
        let total = rig.frame_counts;
        let want = last - first.unwrap_or(0.0);
        assert!(
            (total as f64 - want).abs() < 2.0,
            "frames {total} counts, gyro {want:.3}"
        );
        assert!(
            total.abs() > 1_000_000,
            "{total} counts: the counter wrapped"
        );
    }
}

/// The pickoff lost for half a second: those frames are flagged and carry
/// the raw count (the dither in it), the angle is never lost, and the
/// stripping is back when the latches are; glitches (an edge of the same
/// polarity, or one too soon) are refused and flagged without a trace in
/// the angle.
#[test]
fn pickoff_faults_lose_no_angle() {
    let p = DitherParams {
        seed: 11,
        ..params(5000.0, 0.1, 200.0, 450.0, 0.05)
    };
    let mut rig = Rig::new(p, true);
    let rate = -3.3;
    let (mut flagged, mut refused) = (0, 0);
    let mut res_after = vec![];
    let (mut first, mut last) = (None, 0.0);
    for i in 0..6000 {
        let lost = (2000..2250).contains(&i);
        let glitch = (4000..4100).contains(&i);
        let f = rig.frame(rate, |l, out| {
            if lost {
                return;
            }
            out.push(latch_sample(l));
            if glitch && l.rising {
                // A spurious edge 50 us later with the same polarity.
                let mut g = latch_sample(l);
                g.time = g.time.wrapping_add(4200);
                g.counter = g.counter.wrapping_add(37);
                out.push(g);
            }
        });
        if f.flags.contains(RlgFlags::NO_PICKOFF) {
            flagged += 1;
            assert!((2000..2260).contains(&i), "frame {i} flagged");
            // The safe path: the raw count, the dither in it (a few hundred counts).
            assert!(f.residual.abs() < 2.0 * 5000.0 * p.amplitude_deg());
        } else if i > 1000 {
            // Settled (the quadrant offset, the alternation): hundredths of
            // a count, after the faults too.
            assert!(f.residual.abs() < 0.2, "frame {i}: {}", f.residual);
        }
        if f.flags.contains(RlgFlags::LATCH_REFUSED) {
            refused += 1;
            assert!((4000..4101).contains(&i), "frame {i} refused a latch");
        }
        if i > 4500 {
            res_after.push(f.residual);
        }
        if first.is_none() && rig.ch.angle_q16() != 0 {
            first = Some(f.truth);
        }
        last = f.truth;
        assert!(f.rate_dps.is_finite());
    }
    assert!(flagged >= 245, "{flagged} frames flagged");
    assert!(refused >= 50, "{refused} frames refused glitches");
    let r = rms_about_mean(&res_after);
    assert!(r < 0.05, "residual after the faults {r:.4}");
    // Whatever happened, the frames' counts add up to the gyro's angle.
    let want = last - first.unwrap_or(0.0);
    assert!(
        (rig.frame_counts as f64 - want).abs() < 2.0,
        "frames {} counts, gyro {want:.3}",
        rig.frame_counts
    );
}

/// Inside the static lock-in band the dithered gyro reads the input: the
/// mean rate error over 60 s is within 3 standard errors (of batch means)
/// of zero, where the undithered gyro would read 0 (an error of the whole
/// input).
#[test]
fn dead_band_gone() {
    let p = DitherParams {
        seed: 3,
        ..params(3000.0, 0.15, 180.0, 420.0, 0.04)
    };
    let mut rig = Rig::new(p, true);
    let rate = 0.6 * p.lock_in_dps;
    let mut rates = vec![];
    for i in 0..30_000 {
        let f = rig.frame(rate, |l, out| out.push(latch_sample(l)));
        if i > 1000 {
            rates.push(f.rate_dps);
        }
    }
    // Batch means of 1 s (500 frames): the white-noise standard error.
    let b: Vec<f64> = rates
        .chunks(500)
        .filter(|c| c.len() == 500)
        .map(|c| c.iter().sum::<f64>() / 500.0 - rate)
        .collect();
    let m = b.iter().sum::<f64>() / b.len() as f64;
    let se = rms_about_mean(&b) / (b.len() as f64 - 1.0).sqrt();
    assert!(
        m.abs() < 3.0 * se,
        "mean error {m:.3e} deg/s, stderr {se:.3e}"
    );
    assert!(
        se < 0.01 * rate,
        "{se:.3e}: the test resolves the dead band"
    );
}

/// The CORDIC's phase against atan2 over the photodiodes' range.
#[test]
fn cordic_phase() {
    let mut worst = 0.0f64;
    for i in 0..720 {
        let a = i as f64 * std::f64::consts::TAU / 720.0 + 0.001;
        for r in [100.0, 1600.0, 4000.0] {
            let (x, y) = ((r * a.cos()).round(), (r * a.sin()).round());
            let want = y.atan2(x) / std::f64::consts::TAU;
            let got = atan2_turns(y as i32, x as i32) as f64 / 4_294_967_296.0;
            let mut d = got - want;
            d -= d.round();
            worst = worst.max(d.abs());
        }
    }
    assert!(worst < 4e-5, "worst {worst:.2e} turn");
}
