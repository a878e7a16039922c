//! FOG scale factor over temperature (`gyro-lab fit scale-factor`): a
//! piecewise-linear table of the scale-factor error and the bias at up to
//! [`MAX_NODES`] coil temperatures, and the lag of the coil sensor behind
//! the coil.
//!
//! Every model family the fit chooses from is a table: knees are nodes; a
//! polynomial (or the polynomial pieces between knees) is tabulated at
//! nodes close enough that linear interpolation stays within 0.1 ppm of it
//! (the fit states the spacing and the error).
//!
//! Meaning: at coil temperature T the gyro's output with the nominal scale
//! factor is `(1 + sf(T)) * Omega + bias(T)`, with sf (ppm) and bias (deg/h)
//! interpolated linearly between the nodes and held at the end values
//! outside them (the calibrated range is `temps_c[0] ..= temps_c[n-1]`).
//! The coil temperature is estimated from its sensor as
//! `T_sensor + sensor_lag_s * dT_sensor/dt` (the lead that undoes a
//! first-order lag).

use crate::record::{self, CoeffError};

/// Most nodes of a table: a polynomial tabulated over -40..+60 degC at
/// 1.6 degC holds linear interpolation within 0.1 ppm of a curvature up to
/// 0.3 ppm/degC^2, fifteen times the quadratic coils the fit is tested on;
/// knees are nodes of their own; a multi-point calibration has a node per
/// plateau.
pub const MAX_NODES: usize = 64;
/// Record version 2: 64 nodes (version 1 held 8).
pub const VERSION: u16 = 2;
const MAGIC: &[u8; 4] = b"FOGS";
const N_VALUES: usize = 1 + 3 * MAX_NODES;
/// Record: magic "FOGS", version, node count, sensor lag, then the node
/// temperatures, scale-factor errors and biases (each `MAX_NODES` f64,
/// unused ones 0), CRC-32.
pub const RECORD_LEN: usize = record::len(N_VALUES);

/// Range the fixed-point table holds (gyro-sp's fog/scale_factor.rs).
pub const SF_LIMIT_PPM: f64 = 20_000.0;
pub const BIAS_LIMIT_DPH: f64 = 1_000.0;
pub const LAG_LIMIT_S: f64 = 1_000.0;
/// Node temperatures: the TMP117's range, and at least this far apart.
pub const T_MIN_C: f64 = -55.0;
pub const T_MAX_C: f64 = 150.0;
pub const MIN_NODE_GAP_C: f64 = 0.5;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleFactorTable {
    /// Nodes in use, 1 ..= MAX_NODES.
    pub n: usize,
    pub temps_c: [f64; MAX_NODES],
    pub sf_ppm: [f64; MAX_NODES],
    pub bias_dph: [f64; MAX_NODES],
    pub sensor_lag_s: f64,
}

impl ScaleFactorTable {
    /// No compensation: the defined fallback (one node, zero error).
    pub const SAFE: Self = Self {
        n: 1,
        temps_c: [20.0; MAX_NODES],
        sf_ppm: [0.0; MAX_NODES],
        bias_dph: [0.0; MAX_NODES],
        sensor_lag_s: 0.0,
    };

    /// From node lists (at most MAX_NODES; longer lists are refused by
    /// [`Self::check`] through `n`). Not checked.
    pub fn from_nodes(
        temps_c: &[f64],
        sf_ppm: &[f64],
        bias_dph: &[f64],
        sensor_lag_s: f64,
    ) -> Self {
        let mut t = Self {
            n: temps_c.len(),
            temps_c: [0.0; MAX_NODES],
            sf_ppm: [0.0; MAX_NODES],
            bias_dph: [0.0; MAX_NODES],
            sensor_lag_s,
        };
        if temps_c.len() != sf_ppm.len() || temps_c.len() != bias_dph.len() {
            t.n = 0;
        }
        for (d, s) in [
            (&mut t.temps_c, temps_c),
            (&mut t.sf_ppm, sf_ppm),
            (&mut t.bias_dph, bias_dph),
        ] {
            for (x, y) in d.iter_mut().zip(s) {
                *x = *y;
            }
        }
        t
    }

    /// Node count in range, every value finite and within the fixed-point
    /// range, node temperatures increasing by at least MIN_NODE_GAP_C.
    pub fn check(&self) -> Result<(), CoeffError> {
        let n = self.n;
        if !(1..=MAX_NODES).contains(&n) {
            return Err(CoeffError::Range);
        }
        let t = &self.temps_c[..n];
        let ok = t
            .iter()
            .all(|x| x.is_finite() && (T_MIN_C..=T_MAX_C).contains(x))
            && t.windows(2).all(|w| w[1] - w[0] >= MIN_NODE_GAP_C)
            && self.sf_ppm[..n]
                .iter()
                .all(|x| x.is_finite() && x.abs() <= SF_LIMIT_PPM)
            && self.bias_dph[..n]
                .iter()
                .all(|x| x.is_finite() && x.abs() <= BIAS_LIMIT_DPH)
            && self.sensor_lag_s.is_finite()
            && (0.0..=LAG_LIMIT_S).contains(&self.sensor_lag_s);
        if ok {
            Ok(())
        } else {
            Err(CoeffError::Range)
        }
    }

    /// The table's model in floating point: (sf ppm, bias deg/h) at coil
    /// temperature `t_c`, and whether `t_c` is outside the calibrated range.
    pub fn eval(&self, t_c: f64) -> (f64, f64, bool) {
        let n = self.n.clamp(1, MAX_NODES);
        let t = &self.temps_c[..n];
        // One node: a constant correction, valid at every temperature.
        if n == 1 {
            return (self.sf_ppm[0], self.bias_dph[0], false);
        }
        if t_c <= t[0] {
            return (self.sf_ppm[0], self.bias_dph[0], t_c < t[0]);
        }
        if t_c >= t[n - 1] {
            return (self.sf_ppm[n - 1], self.bias_dph[n - 1], t_c > t[n - 1]);
        }
        let i = t.windows(2).position(|w| t_c < w[1]).unwrap_or(n - 2);
        let f = (t_c - t[i]) / (t[i + 1] - t[i]);
        let lerp = |v: &[f64; MAX_NODES]| v[i] + f * (v[i + 1] - v[i]);
        (lerp(&self.sf_ppm), lerp(&self.bias_dph), false)
    }

    fn values(&self) -> [f64; N_VALUES] {
        let mut v = [0.0; N_VALUES];
        v[0] = self.sensor_lag_s;
        let n = self.n.min(MAX_NODES);
        for k in 0..n {
            v[1 + k] = self.temps_c[k];
            v[1 + MAX_NODES + k] = self.sf_ppm[k];
            v[1 + 2 * MAX_NODES + k] = self.bias_dph[k];
        }
        v
    }

    pub fn to_record(self) -> [u8; RECORD_LEN] {
        let mut r = [0u8; RECORD_LEN];
        let n = self.n.min(u16::MAX as usize) as u16;
        record::encode(MAGIC, VERSION, n, &self.values(), &mut r);
        r
    }

    /// Parses and checks a stored record.
    pub fn from_record(r: &[u8]) -> Result<Self, CoeffError> {
        let mut v = [0f64; N_VALUES];
        let n = record::decode(MAGIC, VERSION, r, &mut v)? as usize;
        if n > MAX_NODES {
            return Err(CoeffError::Range);
        }
        let t = Self::from_nodes(
            &v[1..1 + n],
            &v[1 + MAX_NODES..1 + MAX_NODES + n],
            &v[1 + 2 * MAX_NODES..1 + 2 * MAX_NODES + n],
            v[0],
        );
        t.check()?;
        Ok(t)
    }
}
