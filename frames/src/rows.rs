//! The run-file rows of decoded frames: `fog.csv` and `rlg.csv` (the run
//! file of docs/interfaces.md, with the board's extra columns), one row per
//! decoded frame, time from the board's closure counter, rates over the
//! span since the previous decoded frame (a gap included), and the
//! cumulative angle since the record's start.

use crate::decode::{Decoded, Increments};
use crate::scales::Scales;
use std::io::{self, Write};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// The FOG file's columns (the run file's first three, then the board's).
pub const FOG_COLUMNS: &str = "t_s,ref_rate_dps,rate_dps,rate_raw_dps,rate_comp_dps,temp_c,t_coil_c,sf_corr_ppm,fog_bias_dph,fog_temp_flags,faults,seq,dc_lsb,codes_per_turn,closures_missed,angle_deg";
/// The RLG file's columns.
pub const RLG_COLUMNS: &str = "t_s,ref_rate_dps,rate_dps,rate_raw_dps,delta_counts,t_mono_a_c,t_mono_b_c,t_case_c,bias_dph,rlg_flags,angle_deg";

/// Writes both files' rows and keeps the angles since the record's start.
pub struct RunWriter<W: Write> {
    fog: W,
    rlg: W,
    scales: Scales,
    /// FOG angle since the record's start, angle LSB (i128: no wrap).
    fog_angle: i128,
    rlg_counts: i64,
}

/// The physical values of one frame's FOG row, deg/s and deg.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FogRates {
    pub rate_dps: f64,
    pub rate_raw_dps: f64,
    pub rate_comp_dps: f64,
}

/// The FOG rates over the frame's span (the angle's own time: closures the
/// board missed carry no angle). `None` when no closure was processed.
pub fn fog_rates(d: &Decoded, inc: &Increments, s: &Scales) -> Option<FogRates> {
    let processed = d.processed_closures();
    if processed == 0 {
        return None;
    }
    let per = s.fog_rad_per_lsb / (processed as f64 * s.closure_s) / DEG;
    Some(FogRates {
        rate_dps: inc.fog as f64 * per,
        rate_raw_dps: inc.fog_raw as f64 * per,
        rate_comp_dps: inc.fog_comp as f64 * per,
    })
}

impl<W: Write> RunWriter<W> {
    /// Starts both files: a `#` comment line each, then the header.
    pub fn new(mut fog: W, mut rlg: W, scales: Scales, comment: &str) -> io::Result<Self> {
        writeln!(fog, "# {comment}; FOG channel, one row per frame")?;
        writeln!(fog, "{FOG_COLUMNS}")?;
        writeln!(rlg, "# {comment}; RLG channel, one row per frame")?;
        writeln!(rlg, "{RLG_COLUMNS}")?;
        Ok(Self {
            fog,
            rlg,
            scales,
            fog_angle: 0,
            rlg_counts: 0,
        })
    }

    /// One decoded frame's rows; `ref_rate_dps`: the reference over its
    /// span. An anchor frame (no increments) writes nothing.
    pub fn row(&mut self, d: &Decoded, ref_rate_dps: f64) -> io::Result<()> {
        let (Some(inc), s) = (d.increments, self.scales) else {
            return Ok(());
        };
        self.fog_angle += inc.fog as i128;
        self.rlg_counts += inc.rlg_counts;
        let f = &d.frame;
        let t_s = d.counter as f64 * s.closure_s;
        if let Some(r) = fog_rates(d, &inc, &s) {
            let th = &f.fog_temp;
            writeln!(
                self.fog,
                "{:.6},{:.9},{:.9},{:.9},{:.9},{:.4},{:.4},{:.4},{:.5},{},{},{},{},{:.4},{},{:.9}",
                t_s,
                ref_rate_dps,
                r.rate_dps,
                r.rate_raw_dps,
                r.rate_comp_dps,
                th.t_sensor_q8 as f64 / 256.0,
                th.t_coil_q8 as f64 / 256.0,
                th.sf_corr_q32 as f64 / 4_294_967_296.0 * 1e6,
                th.bias_q16_dph as f64 / 65_536.0,
                th.flags.bits(),
                f.faults.bits(),
                f.seq,
                f.dc,
                f.codes_per_turn_q8 as f64 / 256.0,
                f.closures_missed,
                self.fog_angle as f64 * s.fog_rad_per_lsb / DEG,
            )?;
        }
        let g = &f.rlg;
        let span_s = d.span_closures as f64 * s.closure_s;
        let raw_dps = inc.rlg_counts as f64 / s.rlg_counts_per_deg / span_s.max(f64::MIN_POSITIVE);
        let bias_dph = g.bias_q16_dph as f64 / 65_536.0;
        // The board's compensated rate is over its last update; after a gap
        // the same compensation over the whole gap.
        let rate_dps = if d.lost_before == 0 {
            g.rate_comp_udps as f64 * 1e-6
        } else {
            raw_dps - bias_dph / 3600.0
        };
        writeln!(
            self.rlg,
            "{:.6},{:.9},{:.6},{:.6},{},{:.4},{:.4},{:.4},{:.5},{},{:.9}",
            t_s,
            ref_rate_dps,
            rate_dps,
            raw_dps,
            inc.rlg_counts,
            g.t_mono_a_q8 as f64 / 256.0,
            g.t_mono_b_q8 as f64 / 256.0,
            g.t_case_q8 as f64 / 256.0,
            bias_dph,
            g.flags.bits(),
            self.rlg_counts as f64 / s.rlg_counts_per_deg,
        )
    }

    /// The FOG angle since the record's start, deg.
    pub fn fog_angle_deg(&self) -> f64 {
        self.fog_angle as f64 * self.scales.fog_rad_per_lsb / DEG
    }

    /// The RLG counts since the record's start.
    pub fn rlg_counts(&self) -> i64 {
        self.rlg_counts
    }

    pub fn flush(&mut self) -> io::Result<()> {
        self.fog.flush()?;
        self.rlg.flush()
    }

    /// The two writers back (flushed).
    pub fn into_inner(mut self) -> io::Result<(W, W)> {
        self.flush()?;
        Ok((self.fog, self.rlg))
    }
}
