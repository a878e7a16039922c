//! Decoding of the firmware's UART frames into a run file, and the summary.

use anyhow::{Context, Result};
use gyro_frames::rows::fog_rates;
use gyro_frames::{Decoded, Decoder, RateLog, Recorder, Reference, Scales, Summary};
use gyro_sim::profile::qemu_demo;
use gyro_sim::rlg_dither_rig::qemu_stimulus;
use gyro_sim::ChamberParams;
use gyro_sp::fog::scale_factor::FogTempFlags;
use gyro_sp::fog::{Faults, FogConfig, FogParams};
use gyro_sp::frame::Frame;
use gyro_sp::rlg::RlgFlags;
use std::io::Write;
use std::path::Path;

const DEG: f64 = std::f64::consts::PI / 180.0;
const DPH: f64 = 3600.0 / DEG;
/// The qemu board's RLG update rate, one per frame (src/app.rs `RLG_HZ`).
const RLG_HZ: u32 = 500;
/// Time left out of the dither statistics while the stripping learns its
/// corrections (the quadrant offset in 64 latches, 80 ms; the alternation
/// averages 256, a time constant of 0.32 s), s.
const DITHER_SETTLE_S: f64 = 0.5;
/// The residual dither the stripping may leave, counts rms at the frame
/// rate (issue 33's acceptance).
pub const RESIDUAL_DITHER_MAX_COUNTS: f64 = 0.5;

pub struct Row {
    pub t_s: f64,
    pub ref_rate: f64,
    /// FOG rate, rad/s: eps^2-corrected (nominal scale factor), uncorrected,
    /// and compensated over temperature (the final output).
    pub rate: f64,
    pub rate_raw: f64,
    pub rate_comp: f64,
    pub frame: Frame,
    pub decoded: Decoded,
    pub segment: usize,
    pub t_in_segment: f64,
}

pub struct Report {
    pub rows: Vec<Row>,
    pub bad_frames: usize,
    pub seq_gaps: usize,
    pub step_gaps: usize,
    pub segment_names: [&'static str; 8],
    pub cfg: FogConfig,
    pub summary: Summary,
    /// The simulated RLG's angle without the dither (counts, continuous;
    /// lock-in error, bias and rate noise in it) at the end of each RLG
    /// update (`k` at `(k + 1) / RLG_HZ`), replayed on the host.
    pub rlg_truth: Vec<f64>,
}

/// Decodes frames through the one decoder (`gyro-frames`, as `gyro-lab
/// record` does) and rebuilds the truth from the firmware's built-in profile.
pub fn analyse(path: &Path) -> Result<Report> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let cfg = FogConfig::new(FogParams::default()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let (profile, names) = qemu_demo::<f64>();
    let seg_starts: Vec<f64> = profile
        .segments
        .iter()
        .scan(0.0, |t, s| {
            let start = *t;
            *t += s.duration();
            Some(start)
        })
        .collect();
    let n_half = cfg.n_half as u64;
    let tau = cfg.params.tau_s;
    let scales = Scales::new(&cfg, ChamberParams::default().counts_per_deg);
    let mut dec = Decoder::new();
    let mut decoded = Vec::new();
    dec.push(&bytes, &mut decoded)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut summary = Summary::default();
    let mut rows = Vec::new();
    let mut step_gaps = 0;
    for d in decoded {
        summary.add(&d, &scales);
        let f = d.frame;
        if d.span_closures != f.closures as u64 + f.closures_missed as u64 {
            step_gaps += 1;
        }
        let Some(inc) = d.increments else { continue };
        let Some(r) = fog_rates(&d, &inc, &scales) else {
            continue;
        };
        let end = d.counter;
        let start = end - d.span_closures;
        let mut truth = 0.0;
        for k in start..end {
            for j in 0..n_half {
                truth += profile.rate_at(((k * n_half + j) as f64 + 0.5) * tau);
            }
        }
        let halves = ((end - start) * n_half) as f64;
        let t_mid = (start + end) as f64 / 2.0 * n_half as f64 * tau;
        let segment = seg_starts.iter().rposition(|&s| t_mid >= s).unwrap_or(0);
        rows.push(Row {
            t_s: end as f64 * n_half as f64 * tau,
            ref_rate: truth / halves,
            rate: r.rate_dps * DEG,
            rate_raw: r.rate_raw_dps * DEG,
            rate_comp: r.rate_comp_dps * DEG,
            frame: f,
            decoded: d,
            segment,
            t_in_segment: t_mid - seg_starts[segment],
        });
    }
    summary.finish(&dec);
    let rlg_truth = replay_rlg(rows.len() + 1);
    Ok(Report {
        rlg_truth,
        rows,
        bad_frames: dec.crc_errors as usize,
        seq_gaps: dec.lost_frames as usize,
        step_gaps,
        segment_names: names,
        cfg,
        summary,
    })
}

/// The qemu board's dithered RLG replayed for `updates` updates: its angle
/// without the dither at each update's end. The firmware plays back the
/// record its build script made by the same call
/// (`sim::rlg_dither_rig::qemu_stimulus`), so this is its truth, as the
/// profile is the FOG's.
fn replay_rlg(updates: usize) -> Vec<f64> {
    let mut truth = Vec::with_capacity(updates);
    qemu_stimulus(
        RLG_HZ,
        updates as u32,
        |s| truth.push(s.gyro.truth_counts),
        |_| {},
    );
    truth
}

/// The reference of the QEMU run as a rate log: the built-in profile
/// sampled every 10 us (two half periods), written to `path` as
/// `t_s,ref_rate_dps` (the `--reference` file `gyro-lab record` takes),
/// and returned.
pub fn write_reference(path: &Path) -> Result<RateLog> {
    let (profile, _) = qemu_demo::<f64>();
    let dt = 10e-6;
    let n = (profile.total_duration() / dt).ceil() as usize + 2;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let r: Vec<f64> = t.iter().map(|&t| profile.rate_at(t) / DEG).collect();
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "# the qemu firmware's built-in rate profile, every 10 us"
    )?;
    writeln!(w, "t_s,ref_rate_dps")?;
    for (t, r) in t.iter().zip(&r) {
        writeln!(w, "{t:.6},{r:.12}")?;
    }
    w.flush()?;
    drop(w);
    // Read back as `gyro-lab record --reference` reads it, so both paths
    // hold the very same numbers.
    let text = std::fs::read_to_string(path)?;
    let (mut t, mut r) = (vec![], vec![]);
    for line in text.lines().skip(2) {
        let (a, b) = line.split_once(',').context("reference row")?;
        t.push(a.parse()?);
        r.push(b.parse()?);
    }
    RateLog::new(t, r, 0.0).map_err(|e| anyhow::anyhow!("reference log: {e:?}"))
}

/// The run files of a capture, through the recorder `gyro-lab record`
/// uses (same decoder, same rows): `dir/fog.csv`, `dir/rlg.csv` and
/// `dir/raw.bin`.
/// Also returns the FOG angle (deg) and RLG counts over the record.
pub fn record_capture(
    capture: &Path,
    dir: &Path,
    reference: RateLog,
) -> Result<(Summary, (f64, i64))> {
    let bytes = std::fs::read(capture).with_context(|| format!("reading {}", capture.display()))?;
    let cfg = FogConfig::new(FogParams::default()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let scales = Scales::new(&cfg, ChamberParams::default().counts_per_deg);
    let mut rec = Recorder::create(
        dir,
        scales,
        Reference::Log(reference),
        "gyro-fw under qemu-system-arm (netduinoplus2), built-in profile; RLG in a simulated chamber at 20 degC",
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    rec.push(&bytes).map_err(|e| anyhow::anyhow!("{e}"))?;
    let angles = rec.angles();
    let summary = rec.finish().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok((summary, angles))
}

/// Per segment, after 20 ms settling: mean and RMS of the final output
/// (compensated over temperature) minus truth, deg/h; the mean of the
/// eps^2-corrected output before the temperature compensation and of the
/// uncorrected one; the scale-factor error before and after the
/// compensation, ppm (segments at a constant nonzero rate).
pub struct SegmentStats {
    pub name: &'static str,
    pub frames: usize,
    pub mean_dph: f64,
    pub rms_dph: f64,
    pub mean_nocomp_dph: f64,
    pub mean_raw_dph: f64,
    pub sf_ppm: Option<(f64, f64)>,
    pub faults: u16,
}

pub fn segment_stats(r: &Report) -> Vec<SegmentStats> {
    (0..r.segment_names.len())
        .map(|s| {
            let rows: Vec<&Row> = r
                .rows
                .iter()
                .filter(|x| x.segment == s && x.t_in_segment > 0.02)
                .collect();
            let n = rows.len().max(1) as f64;
            let mean_of = |f: &dyn Fn(&Row) -> f64| rows.iter().map(|x| f(x)).sum::<f64>() / n;
            let mean = mean_of(&|x| x.rate_comp - x.ref_rate);
            let rms = mean_of(&|x| (x.rate_comp - x.ref_rate).powi(2)).sqrt();
            let constant = rows.len() > 1
                && rows
                    .iter()
                    .all(|x| (x.ref_rate - rows[0].ref_rate).abs() < 1e-9)
                && rows[0].ref_rate.abs() > 1.0 * DEG;
            SegmentStats {
                name: r.segment_names[s],
                frames: rows.len(),
                mean_dph: mean * DPH,
                rms_dph: rms * DPH,
                mean_nocomp_dph: mean_of(&|x| x.rate - x.ref_rate) * DPH,
                mean_raw_dph: mean_of(&|x| x.rate_raw - x.ref_rate) * DPH,
                sf_ppm: constant.then(|| {
                    (
                        mean_of(&|x| x.rate / x.ref_rate - 1.0) * 1e6,
                        mean_of(&|x| x.rate_comp / x.ref_rate - 1.0) * 1e6,
                    )
                }),
                faults: r
                    .rows
                    .iter()
                    .filter(|x| x.segment == s)
                    .fold(0, |a, x| a | x.frame.faults.bits()),
            }
        })
        .collect()
}

pub fn print_summary(r: &Report) {
    println!(
        "frames: {} decoded, {} bad, {} sequence gaps, {} step gaps",
        r.rows.len(),
        r.bad_frames,
        r.seq_gaps,
        r.step_gaps
    );
    println!(
        "{:<28} {:>6} {:>14} {:>14} {:>16} {:>17} {:>22}  faults",
        "segment",
        "frames",
        "mean err deg/h",
        "rms err deg/h",
        "no temp comp",
        "no eps^2 corr",
        "scale factor ppm"
    );
    for s in segment_stats(r) {
        let sf = s
            .sf_ppm
            .map_or(String::from("-"), |(b, a)| format!("{b:+.2} -> {a:+.3}"));
        println!(
            "{:<28} {:>6} {:>14.4} {:>14.3} {:>16.4} {:>17.4} {:>22}  {:#06x}",
            s.name,
            s.frames,
            s.mean_dph,
            s.rms_dph,
            s.mean_nocomp_dph,
            s.mean_raw_dph,
            sf,
            s.faults
        );
    }
    let th = fog_temp_stats(r);
    println!(
        "FOG temperature: coil {:.2} -> {:.2} degC (table input; the simulated coil's knee at 48 degC, \
         calibrated to 60 degC); scale-factor error before -> after compensation in ppm above; flags seen {:#04x}",
        th.first_coil_c, th.last_coil_c, th.flags_seen
    );
    let eps = 50_000.0 * DEG;
    let pred = r.cfg.predicted_vibration_drift(eps * eps / 2.0) * DPH;
    println!("vibration drift formula (-(1/4) cot(phi0) K_s <eps^2> dt_m dt_p): {pred:.4} deg/h");
    let g = rlg_stats(r);
    println!(
        "RLG: angle {:.4} deg from {} counts, truth {:.4} deg (error {:+.1} counts); B_TC {:.4} deg/h; \
         temperatures {:.3}/{:.3}/{:.3} degC (mono A/B, case); flags seen {:#04x}",
        g.angle_deg, g.counts, g.truth_deg, g.error_counts, g.bias_dph, g.temps[0], g.temps[1], g.temps[2], g.flags_seen
    );
    let d = dither_stats(r);
    println!(
        "RLG dither (400 Hz, 150 deg/s, stripped at the pickoff's zero crossings): residual {:.3} counts rms \
         (max {:.3}) at the frame rate over the constant-rate segments ({} frames from {} s); frames' counts {} \
         against the simulated gyro's {:.2} ({:+.2} counts)",
        d.residual_rms, d.residual_max, d.frames, DITHER_SETTLE_S, d.counts, d.truth_counts, d.error_counts
    );
    println!(
        "{:<28} {:>6} {:>16} {:>14} {:>24} {:>16}",
        "RLG segment",
        "frames",
        "stripped deg/s",
        "input deg/s",
        "stripped - truth deg/h",
        "residual counts"
    );
    for s in &d.segments {
        println!(
            "{:<28} {:>6} {:>16.6} {:>14.6} {:>24.3} {:>16.3}{}",
            s.name,
            s.frames,
            s.rate_dps,
            s.input_dps,
            s.error_dph,
            s.residual_rms,
            if s.constant_rate {
                ""
            } else {
                "  (rate not constant: the latches' interpolation)"
            }
        );
    }
}

/// The dithered RLG's frames against the simulated gyro: the frame for
/// RLG update k carries the stripped angle at update k - 1's instant
/// (`k / RLG_HZ`; the stripping waits for the latch after it), so frame
/// row i (update i) stands for the truth at the end of update i - 1.
pub struct DitherStats {
    /// Stripped angle (the frames' rate words, B_TC added back: the angle
    /// before the thermal compensation) minus the gyro's angle without the
    /// dither, counts rms about each segment's mean over the constant-rate
    /// segments (after `DITHER_SETTLE_S`, 20 ms into each), the largest
    /// excursion; frames in it.
    pub residual_rms: f64,
    pub residual_max: f64,
    pub frames: usize,
    /// The frames' whole counts minus the truth's count integral from the
    /// first frame to the last (the floors make it at most one count).
    pub error_counts: f64,
    pub counts: i64,
    pub truth_counts: f64,
    pub segments: Vec<DitherSegment>,
}

/// One segment of the profile (after 20 ms and `DITHER_SETTLE_S`).
pub struct DitherSegment {
    pub name: &'static str,
    pub frames: usize,
    /// The stripped rate's mean and the input rate's, deg/s; the stripped
    /// rate's mean error against the gyro's rate without the dither (bias,
    /// rate noise and lock-in walk in it), deg/h.
    pub rate_dps: f64,
    pub input_dps: f64,
    pub error_dph: f64,
    /// The residual's rms about the segment's mean, counts.
    pub residual_rms: f64,
    pub constant_rate: bool,
}

/// (segment, residual counts, stripped rate, true rate, input rate; deg/s).
type DitherFrame = (usize, f64, f64, f64, f64);

pub fn dither_stats(r: &Report) -> DitherStats {
    let k = ChamberParams::default().counts_per_deg;
    let dt = 1.0 / RLG_HZ as f64;
    let (profile, _) = qemu_demo::<f64>();
    let constant: Vec<bool> = profile
        .segments
        .iter()
        .map(|s| matches!(s, gyro_sim::Segment::Constant { .. }))
        .collect();
    // Row i's truth: the end of update i - 1 (row 0's instant is 0).
    let truth_at = |i: usize| i.checked_sub(1).and_then(|j| r.rlg_truth.get(j).copied());
    // The stripped angle over each frame, counts (the compensated rate
    // with B_TC added back, over one update).
    let stripped = |x: &Row| {
        let w = x.frame.rlg;
        (w.rate_comp_udps as f64 * 1e-6 + w.bias_q16_dph as f64 / 65_536.0 / 3600.0) * dt * k
    };
    let (mut angle, mut counts) = (0.0, 0i64);
    let (mut first, mut last) = (None::<(f64, i64)>, None::<(f64, i64)>);
    let mut used: Vec<DitherFrame> = vec![];
    for (i, x) in r.rows.iter().enumerate() {
        angle += stripped(x);
        counts += x.decoded.increments.map_or(0, |inc| inc.rlg_counts);
        let Some(t) = truth_at(i) else {
            continue;
        };
        first.get_or_insert((t, counts));
        last = Some((t, counts));
        let rate_true = i
            .checked_sub(1)
            .and_then(truth_at)
            .map(|p| (t - p) / k / dt);
        if i as f64 * dt >= DITHER_SETTLE_S && x.t_in_segment > 0.02 {
            if let Some(rt) = rate_true {
                used.push((
                    x.segment,
                    angle - t,
                    stripped(x) / k / dt,
                    rt,
                    x.ref_rate / DEG,
                ));
            }
        }
    }
    // About each segment's own mean: a frame whose words came late (two
    // updates' counts, one update's rate word) shifts the rate words'
    // angle after it; the whole counts are checked over the run apart.
    let seg_mean = |s: usize| {
        let v: Vec<f64> = used.iter().filter(|u| u.0 == s).map(|u| u.1).collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    let means: Vec<f64> = (0..r.segment_names.len()).map(seg_mean).collect();
    let dev = |u: &DitherFrame| u.1 - means[u.0];
    let on_constant: Vec<f64> = used
        .iter()
        .filter(|u| constant.get(u.0) == Some(&true))
        .map(dev)
        .collect();
    let offset = 0.0;
    let rms = |v: &mut dyn Iterator<Item = f64>| {
        let (mut sum, mut m) = (0.0, 0usize);
        for x in v {
            sum += (x - offset).powi(2);
            m += 1;
        }
        (sum / m.max(1) as f64).sqrt()
    };
    let residual_rms = rms(&mut on_constant.iter().copied());
    let residual_max = on_constant
        .iter()
        .map(|v| (v - offset).abs())
        .fold(0.0, f64::max);
    let ((t0, c0), (t1, c1)) = (first.unwrap_or_default(), last.unwrap_or_default());
    let segments = (0..r.segment_names.len())
        .map(|s| {
            let v: Vec<&DitherFrame> = used.iter().filter(|u| u.0 == s).collect();
            let m = v.len().max(1) as f64;
            let mean = |f: &dyn Fn(&DitherFrame) -> f64| v.iter().map(|u| f(u)).sum::<f64>() / m;
            DitherSegment {
                name: r.segment_names[s],
                frames: v.len(),
                rate_dps: mean(&|u| u.2),
                input_dps: mean(&|u| u.4),
                error_dph: mean(&|u| u.2 - u.3) * 3600.0,
                residual_rms: rms(&mut v.iter().map(|u| dev(u))),
                constant_rate: constant.get(s) == Some(&true),
            }
        })
        .collect();
    DitherStats {
        residual_rms,
        residual_max,
        frames: on_constant.len(),
        error_counts: (c1 - c0) as f64 - (t1 - t0),
        counts: c1 - c0,
        truth_counts: t1 - t0,
        segments,
    }
}

pub struct FogTempStats {
    pub first_coil_c: f64,
    pub last_coil_c: f64,
    pub flags_seen: u8,
}

pub fn fog_temp_stats(r: &Report) -> FogTempStats {
    let coil = |x: Option<&Row>| x.map_or(f64::NAN, |x| x.frame.fog_temp.t_coil_q8 as f64 / 256.0);
    FogTempStats {
        first_coil_c: coil(r.rows.first()),
        last_coil_c: coil(r.rows.last()),
        flags_seen: r
            .rows
            .iter()
            .fold(0, |a, x| a | x.frame.fog_temp.flags.bits()),
    }
}

pub struct RlgStats {
    pub counts: i64,
    pub angle_deg: f64,
    pub truth_deg: f64,
    pub error_counts: f64,
    pub bias_dph: f64,
    pub temps: [f64; 3],
    pub flags_seen: u8,
    /// Frames with the case-sensor flag, and whether the last frame is clear.
    pub case_flagged: usize,
    pub case_cleared: bool,
}

pub fn rlg_stats(r: &Report) -> RlgStats {
    let k = ChamberParams::default().counts_per_deg;
    let counts: i64 = r
        .rows
        .iter()
        .filter_map(|x| x.decoded.increments)
        .map(|i| i.rlg_counts)
        .sum();
    let mut truth = 0.0;
    let mut t_prev = 0.0;
    for x in &r.rows {
        truth += x.ref_rate / DEG * (x.t_s - t_prev);
        t_prev = x.t_s;
    }
    let last = r.rows.last().map(|x| x.frame.rlg).unwrap_or_default();
    RlgStats {
        counts,
        angle_deg: counts as f64 / k,
        truth_deg: truth,
        error_counts: counts as f64 - truth * k,
        bias_dph: last.bias_q16_dph as f64 / 65_536.0,
        temps: [
            last.t_mono_a_q8 as f64 / 256.0,
            last.t_mono_b_q8 as f64 / 256.0,
            last.t_case_q8 as f64 / 256.0,
        ],
        flags_seen: r.rows.iter().fold(0, |a, x| a | x.frame.rlg.flags.bits()),
        case_flagged: r
            .rows
            .iter()
            .filter(|x| x.frame.rlg.flags.contains(RlgFlags::SENSOR_CASE))
            .count(),
        case_cleared: !last.flags.contains(RlgFlags::SENSOR_CASE),
    }
}

/// The firmware tests under QEMU: (name, passed, detail).
pub fn qemu_checks(r: &Report, log: &str) -> Vec<(&'static str, bool, String)> {
    let stats = segment_stats(r);
    let expected_frames = 30_000 / 25;
    let mut v = vec![
        (
            "frames_decode",
            r.bad_frames == 0 && r.rows.len() == expected_frames,
            format!(
                "{} of {expected_frames}, {} bad",
                r.rows.len(),
                r.bad_frames
            ),
        ),
        (
            "no_sequence_gaps",
            r.seq_gaps == 0 && r.step_gaps == 0,
            format!("{} seq gaps, {} step gaps", r.seq_gaps, r.step_gaps),
        ),
        ("no_panic", !log.contains("panic"), "firmware log".into()),
    ];
    // The injected overrun (the idle loop holds the closure off for 1.5
    // periods once): exactly one frame flags it and counts one missed
    // closure, the time base spans it, the firmware saw the same.
    let overrun: Vec<&Row> = r
        .rows
        .iter()
        .filter(|x| x.frame.faults.contains(Faults::CLOSURE_OVERRUN))
        .collect();
    let logged = log.contains("closures_missed=1 ");
    v.push((
        "missed_closure_flagged_and_counted",
        overrun.len() == 1
            && overrun[0].frame.closures_missed == 1
            && overrun[0].decoded.span_closures == 26
            && r.summary.closures_missed == 1
            && logged,
        format!(
            "{} frames flagged, {} closures missed, firmware log {}",
            overrun.len(),
            r.summary.closures_missed,
            if logged { "agrees" } else { "disagrees" }
        ),
    ));
    v.push((
        "first_frame_says_power_on",
        r.summary.starts.len() == 1
            && r.summary.starts[0].1 == gyro_sp::frame::ResetCause::PowerOn
            && r.rows.first().is_some_and(|x| x.decoded.counter == 25),
        format!("starts {:?}", r.summary.starts),
    ));
    // Locked: every constant-rate segment tracked (mean error under 1 deg/h, no lock
    // fault); the power-loss segment holds the output on purpose and has its own check.
    for s in stats.iter().filter(|s| {
        !s.name.starts_with("vibration")
            && !s.name.starts_with("ramp")
            && !s.name.contains("power loss")
    }) {
        let ok = s.mean_dph.abs() < 1.0 && s.faults & Faults::OUT_OF_LOCK.bits() == 0;
        v.push(("locked", ok, format!("{}: {:.4} deg/h", s.name, s.mean_dph)));
    }
    // The scale factor over temperature: each constant-rate segment's error
    // shrinks from the coil's hundreds of ppm to under 2 ppm; the coil
    // sensor answers (its flag is up only for the first frame, before a
    // read), the table loads, and the sweep beyond 60 degC is flagged as
    // outside the calibrated range.
    for s in stats.iter().filter(|s| s.sf_ppm.is_some()) {
        let (before, after) = s.sf_ppm.unwrap_or_default();
        v.push((
            "scale_factor_compensated",
            after.abs() < 2.0 && before.abs() > 50.0,
            format!("{}: {before:+.2} ppm -> {after:+.3} ppm", s.name),
        ));
    }
    let th = fog_temp_stats(r);
    let sensor_flagged = r
        .rows
        .iter()
        .skip(1)
        .filter(|x| {
            x.frame
                .fog_temp
                .flags
                .intersects(FogTempFlags::COIL_SENSOR | FogTempFlags::COEFFS_REFUSED)
        })
        .count();
    v.push((
        "fog_coil_sensor_and_table",
        sensor_flagged == 0 && th.last_coil_c > 60.0 && th.flags_seen & FogTempFlags::OUT_OF_RANGE.bits() != 0,
        format!(
            "{sensor_flagged} frames flagged after the first; coil {:.2} -> {:.2} degC; flags seen {:#04x}",
            th.first_coil_c, th.last_coil_c, th.flags_seen
        ),
    ));
    let vib = stats.iter().find(|s| s.name.starts_with("vibration"));
    if let Some(s) = vib {
        let ok = s.mean_dph.abs() < 0.1 * s.mean_raw_dph.abs();
        v.push((
            "vibration_correction",
            ok,
            format!(
                "{:.3} deg/h corrected vs {:.3} raw",
                s.mean_dph, s.mean_raw_dph
            ),
        ));
    }
    let fault_rows: Vec<&Row> = r
        .rows
        .iter()
        .filter(|x| x.frame.faults.contains(Faults::OPTICAL_POWER_LOW))
        .collect();
    let cleared = r
        .rows
        .last()
        .is_some_and(|x| !x.frame.faults.contains(Faults::OPTICAL_POWER_LOW));
    v.push((
        "power_loss_flag_rises_and_clears",
        !fault_rows.is_empty() && cleared,
        format!("{} flagged frames", fault_rows.len()),
    ));
    // RLG: no count lost (the angle from the frames' counts matches the
    // profile's angle within the counter's quantization and the bias), the
    // case sensor's NACK window flags and clears, the coefficients loaded.
    let g = rlg_stats(r);
    v.push((
        "rlg_no_lost_counts",
        g.error_counts.abs() <= 3.0 && g.counts != 0,
        format!(
            "{} counts, {:+.2} counts from the truth",
            g.counts, g.error_counts
        ),
    ));
    // The dithered gyro: the stripping leaves at most 0.5 count rms of
    // dither at the frame rate, and the frames' counts are the simulated
    // gyro's (no dither, lock-in walk in it) to the floors' one count.
    let d = dither_stats(r);
    // Every frame carries exactly one RLG update's words (the firmware
    // counts the frames that did not: the update task was late), and every
    // update had the recorded gyro behind it (none past the record's end).
    let word = |key: &str| {
        log.split_whitespace()
            .find_map(|w| w.strip_prefix(key))
            .and_then(|v| v.parse::<u64>().ok())
    };
    let (late, held) = (word("rlg_frames_late="), word("rlg_stimulus_held="));
    v.push((
        "rlg_updates_on_time",
        late == Some(0) && held == Some(0),
        format!(
            "{late:?} frames without their RLG update's words, {held:?} updates past the recorded gyro"
        ),
    ));
    v.push((
        "rlg_dither_stripped",
        d.residual_rms <= RESIDUAL_DITHER_MAX_COUNTS
            && d.frames > 0
            && d.error_counts.abs() < 1.0 + 2.0 * d.residual_max
            && g.flags_seen & (RlgFlags::NO_PICKOFF | RlgFlags::LATCH_REFUSED).bits() == 0,
        format!(
            "residual {:.3} counts rms (max {:.3}); {:+.2} counts from the simulated gyro; flags seen {:#04x}",
            d.residual_rms, d.residual_max, d.error_counts, g.flags_seen
        ),
    ));
    v.push((
        "rlg_sensor_fault_flag_rises_and_clears",
        g.case_flagged > 0 && g.case_cleared,
        format!("{} frames with the case sensor flagged", g.case_flagged),
    ));
    v.push((
        "rlg_coefficients_loaded",
        g.flags_seen & RlgFlags::COEFFS_DEFAULT.bits() == 0 && g.bias_dph != 0.0,
        format!(
            "B_TC {:.4} deg/h, flags seen {:#04x}",
            g.bias_dph, g.flags_seen
        ),
    ));
    v
}

/// Flash (vector table, code, read-only data, initialised data) and static RAM.
pub fn elf_sizes(elf: &Path) -> Result<(u64, u64)> {
    use object::{Object, ObjectSection};
    let data = std::fs::read(elf)?;
    let file = object::File::parse(&*data)?;
    let (mut flash, mut ram) = (0, 0);
    for s in file.sections() {
        let name = s.name().unwrap_or("");
        match name {
            ".vector_table" | ".text" | ".rodata" => flash += s.size(),
            ".data" => {
                flash += s.size();
                ram += s.size();
            }
            ".bss" | ".uninit" => ram += s.size(),
            _ => {}
        }
    }
    Ok((flash, ram))
}
