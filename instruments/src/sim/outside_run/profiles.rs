//! The outside generator's test profiles: what the table turns and what
//! the chamber does, the true state over the rows (rates as row means of
//! sub-steps, temperatures from thermal.rs's networks) and what the run
//! file's sensors read.
//!
//! - `Table`: a FOG on a rate table visiting +-{1, 2, 5, .., 200} deg/s
//!   in shuffled order, dwelling 90 .. 240 s, back to rest after every
//!   three plateaus, moving at 4 .. 15 deg/s^2; 2 h at 2 Hz in a room.
//! - `ChamberStatic` / `ChamberTurning`: a FOG in a chamber (levels in
//!   -25 .. 55 degC, eased moves of 0.3 .. 1.0 degC/min, soaks of 25 .. 50
//!   min); air -> housing (500 .. 1200 s) -> coil (150 .. 400 s), its
//!   source heating the housing by 1 .. 3 degC; the coil sensor lags 4 .. 12
//!   s, reads with 3 mdegC of noise and is quantised to 0.01 degC. Static
//!   (Earth rate) or turning at +-20 .. 80 deg/s, reversed every 2 .. 5 min;
//!   5 h at 1 Hz.
//! - `RlgChamber`: an RLG in a chamber (-15 .. 45 degC): air -> case (400 ..
//!   900 s, the case heated by 0.5 .. 2 degC) -> two monoblocks (1200 ..
//!   2800 s each, heated by the discharge unequally, 1 .. 4 degC); the case
//!   sensor lags 15 .. 40 s, the monoblock sensors 40 .. 120 s, all
//!   quantised to 1/16 degC or 0.01 degC; static; 5 h at 1 Hz.
//! - `RlgRoom`: the same RLG on a bench in a room (self-heating only); 3 h.
//! - `Swings`: a FOG on a table swinging sinusoidally (0.05 .. 0.4 Hz,
//!   peak acceleration 2 .. 40 deg/s^2, whole cycles) with rests between,
//!   and a `ref_acc_dps2` column that is the true acceleration plus 0.1 ..
//!   0.3 deg/s^2 of white noise; 2 h at 10 Hz in a room.
//! - `Room`: a FOG at rest in a room; 3 h at 1 Hz.
//!
//! Every rate carries the Earth rate's vertical component at a latitude
//! of 35 .. 60 deg.

use super::rng::Rng;
use super::thermal::{integrate, read, Program, Temp};

/// Sub-steps per row for the rate's row means.
const RATE_SUB: usize = 10;
const EARTH_DPH: f64 = 15.041_067;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Profile {
    Table,
    ChamberStatic,
    ChamberTurning,
    RlgChamber,
    RlgRoom,
    Swings,
    Room,
}

impl Profile {
    pub fn is_rlg(self) -> bool {
        matches!(self, Profile::RlgChamber | Profile::RlgRoom)
    }

    /// Record length (s) and row interval (s).
    pub fn size(self) -> (f64, f64) {
        match self {
            Profile::Table => (7200.0, 0.5),
            Profile::ChamberStatic | Profile::ChamberTurning | Profile::RlgChamber => {
                (18_000.0, 1.0)
            }
            Profile::RlgRoom | Profile::Room => (10_800.0, 1.0),
            Profile::Swings => (7200.0, 0.1),
        }
    }
}

/// The true state over a run's rows and what its sensors read.
#[derive(Clone, Debug, Default)]
pub struct State {
    pub dt: f64,
    pub t: Vec<f64>,
    /// Row means of the true rate (deg/s) and of w^2, w^3, w|w|; of the
    /// angular acceleration (deg/s^2) and of its magnitude.
    pub w: Vec<f64>,
    pub w2: Vec<f64>,
    pub w3: Vec<f64>,
    pub wabsw: Vec<f64>,
    pub acc: Vec<f64>,
    pub abs_acc: Vec<f64>,
    /// The reference acceleration column (true plus noise), if the rig has one.
    pub acc_column: Option<Vec<f64>>,
    /// FOG coil: true and sensed.
    pub coil: Option<Temp>,
    pub coil_sensor: Option<Vec<f64>>,
    /// RLG case and monoblocks: true and sensed.
    pub case: Option<Temp>,
    pub mono: Option<(Temp, Temp)>,
    pub case_sensor: Option<Vec<f64>>,
    pub mono_sensors: Option<(Vec<f64>, Vec<f64>)>,
    pub describe: String,
}

/// A rate schedule: plateaus reached at a constant acceleration.
struct Moves {
    /// (start time, rate before, rate after, |acceleration|)
    moves: Vec<(f64, f64, f64, f64)>,
}

impl Moves {
    /// Rate (deg/s) and acceleration at t.
    fn at(&self, t: f64) -> (f64, f64) {
        let mut w = 0.0;
        for &(t0, a, b, acc) in &self.moves {
            if t < t0 {
                break;
            }
            let d = (b - a).abs() / acc;
            if t < t0 + d {
                let s = (b - a).signum() * acc;
                return (a + s * (t - t0), s);
            }
            w = b;
        }
        (w, 0.0)
    }
}

/// The rate table's ladder: +-{1, 2, 5, 10, 20, 50, 100, 200} shuffled,
/// with a rest after every three plateaus.
fn ladder(rng: &mut Rng, span: f64) -> Moves {
    let mags = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0];
    let acc = rng.uniform(4.0, 15.0);
    let mut moves = vec![];
    let mut t = rng.uniform(60.0, 120.0);
    let mut w = 0.0;
    let mut count = 0;
    while t < span {
        let mut set: Vec<f64> = mags.iter().flat_map(|m| [*m, -*m]).collect();
        // Fisher-Yates.
        for i in (1..set.len()).rev() {
            let j = rng.index(i + 1);
            set.swap(i, j);
        }
        for next in set {
            moves.push((t, w, next, acc));
            t += (next - w).abs() / acc + rng.uniform(90.0, 240.0);
            w = next;
            count += 1;
            if count % 3 == 0 {
                moves.push((t, w, 0.0, acc));
                t += w.abs() / acc + rng.uniform(60.0, 120.0);
                w = 0.0;
            }
            if t >= span {
                break;
            }
        }
    }
    Moves { moves }
}

/// Continuous rotation reversed every 2 .. 5 min.
fn turning(rng: &mut Rng, span: f64) -> (Moves, f64) {
    let rate = rng.uniform(20.0, 80.0);
    let acc = 10.0;
    let mut moves = vec![(0.0, 0.0, rate, acc)];
    let mut t = rate / acc + rng.uniform(120.0, 300.0);
    let mut w = rate;
    while t < span {
        moves.push((t, w, -w, acc));
        t += 2.0 * rate / acc + rng.uniform(120.0, 300.0);
        w = -w;
    }
    (Moves { moves }, rate)
}

/// Sinusoidal swings of whole cycles with rests: (start, amplitude deg/s,
/// frequency Hz, cycles).
fn swings(rng: &mut Rng, span: f64) -> Vec<(f64, f64, f64, f64)> {
    let mut out = vec![];
    let mut t = rng.uniform(30.0, 90.0);
    while t < span {
        let f = rng.uniform(0.05, 0.4);
        let eps = rng.uniform(2.0, 40.0);
        let amp = eps / (2.0 * std::f64::consts::PI * f);
        let cycles = (3 + rng.index(10)) as f64;
        out.push((t, amp, f, cycles));
        t += cycles / f + rng.uniform(20.0, 90.0);
    }
    out
}

fn swing_at(sw: &[(f64, f64, f64, f64)], t: f64) -> (f64, f64) {
    for &(t0, a, f, c) in sw {
        if t >= t0 && t < t0 + c / f {
            let ph = 2.0 * std::f64::consts::PI * f * (t - t0);
            return (a * ph.sin(), a * 2.0 * std::f64::consts::PI * f * ph.cos());
        }
    }
    (0.0, 0.0)
}

/// Row means over sub-steps of the rate function.
fn rate_rows(st: &mut State, n: usize, earth: f64, rate: &dyn Fn(f64) -> (f64, f64)) {
    let dt = st.dt;
    for k in 0..n {
        let tk = k as f64 * dt;
        let (mut w, mut w2, mut w3, mut wa, mut a, mut aa) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for j in 0..RATE_SUB {
            let s = tk - 0.5 * dt + (j as f64 + 0.5) * dt / RATE_SUB as f64;
            let (x, acc) = rate(s.max(0.0));
            let x = x + earth;
            w += x;
            w2 += x * x;
            w3 += x * x * x;
            wa += x * x.abs();
            a += acc;
            aa += acc.abs();
        }
        let m = RATE_SUB as f64;
        st.t.push(tk);
        st.w.push(w / m);
        st.w2.push(w2 / m);
        st.w3.push(w3 / m);
        st.wabsw.push(wa / m);
        st.acc.push(a / m);
        st.abs_acc.push(aa / m);
    }
}

/// A FOG's coil in `air`: housing and coil lags, the source heating the
/// housing, the sensor's lag; the true coil and the sensor's reading.
fn fog_coil(rng: &mut Rng, air: &Program, n: usize, dt: f64) -> (Temp, Vec<f64>, String) {
    let t1 = rng.uniform(500.0, 1200.0);
    let t2 = rng.uniform(150.0, 400.0);
    let ts = rng.uniform(4.0, 12.0);
    let heat = rng.uniform(1.0, 3.0);
    let a0 = air.at(0.0).0;
    let xs = integrate(
        n,
        dt,
        (4.0 * dt).ceil() as usize,
        &[a0, a0, a0],
        |t, x, d| {
            let u = air.at(t).0 + heat;
            d[0] = (u - x[0]) / t1;
            d[1] = (x[0] - x[1]) / t2;
            d[2] = (x[1] - x[2]) / ts;
        },
    );
    let mut coil = Temp::default();
    let mut lagged = Vec::with_capacity(n);
    for (k, x) in xs.iter().enumerate() {
        let u = air.at(k as f64 * dt).0 + heat;
        let d0 = (u - x[0]) / t1;
        let d1 = (x[0] - x[1]) / t2;
        coil.v.push(x[1]);
        coil.d1.push(d1);
        coil.d2.push((d0 - d1) / t2);
        lagged.push(x[2]);
    }
    let sensor = read(&lagged, 0.003, 0.01, rng);
    let d = format!(
        "coil: housing lag {t1:.0} s, coil lag {t2:.0} s, source heating {heat:.2} degC, sensor lag {ts:.1} s, 0.01 degC steps"
    );
    (coil, sensor, d)
}

/// An RLG's case and monoblocks in `air`, with their sensors.
fn rlg_block(rng: &mut Rng, air: &Program, n: usize, dt: f64, st: &mut State) -> String {
    let tc = rng.uniform(400.0, 900.0);
    let hc = rng.uniform(0.5, 2.0);
    let ta = rng.uniform(1200.0, 2800.0);
    let tb = rng.uniform(1200.0, 2800.0);
    let ha = rng.uniform(1.0, 4.0);
    let hb = ha * rng.uniform(0.5, 0.9);
    let sc = rng.uniform(15.0, 40.0);
    let sa = rng.uniform(40.0, 120.0);
    let sb = rng.uniform(40.0, 120.0);
    let step = if rng.index(2) == 0 { 0.0625 } else { 0.01 };
    let a0 = air.at(0.0).0;
    let xs = integrate(n, dt, (4.0 * dt).ceil() as usize, &[a0; 6], |t, x, d| {
        d[0] = (air.at(t).0 + hc - x[0]) / tc;
        d[1] = (x[0] + ha - x[1]) / ta;
        d[2] = (x[0] + hb - x[2]) / tb;
        d[3] = (x[0] - x[3]) / sc;
        d[4] = (x[1] - x[4]) / sa;
        d[5] = (x[2] - x[5]) / sb;
    });
    let (mut case, mut ma, mut mb) = (Temp::default(), Temp::default(), Temp::default());
    let (mut lc, mut la, mut lb) = (vec![], vec![], vec![]);
    for (k, x) in xs.iter().enumerate() {
        let (u, du, _) = air.at(k as f64 * dt);
        let dc = (u + hc - x[0]) / tc;
        let da = (x[0] + ha - x[1]) / ta;
        let db = (x[0] + hb - x[2]) / tb;
        case.v.push(x[0]);
        case.d1.push(dc);
        case.d2.push((du - dc) / tc);
        ma.v.push(x[1]);
        ma.d1.push(da);
        ma.d2.push((dc - da) / ta);
        mb.v.push(x[2]);
        mb.d1.push(db);
        mb.d2.push((dc - db) / tb);
        lc.push(x[3]);
        la.push(x[4]);
        lb.push(x[5]);
    }
    st.case_sensor = Some(read(&lc, 0.004, step, rng));
    st.mono_sensors = Some((read(&la, 0.004, step, rng), read(&lb, 0.004, step, rng)));
    st.case = Some(case);
    st.mono = Some((ma, mb));
    format!(
        "RLG: case lag {tc:.0} s heated {hc:.2} degC, monoblocks {ta:.0} / {tb:.0} s heated {ha:.2} / {hb:.2} degC, sensor lags {sc:.0} / {sa:.0} / {sb:.0} s, steps {step} degC"
    )
}

/// The state of a run of `profile`, drawn from `rng`.
pub fn build(profile: Profile, rng: &mut Rng) -> State {
    let (span, dt) = profile.size();
    let n = (span / dt).round() as usize;
    let earth = EARTH_DPH * rng.uniform(35.0, 60.0).to_radians().sin() / 3600.0;
    let mut st = State {
        dt,
        ..Default::default()
    };
    let room = |rng: &mut Rng| {
        let base = rng.uniform(20.0, 25.0);
        Program::room(rng, span, base, 0.6)
    };
    let mut parts = vec![];
    match profile {
        Profile::Table => {
            let m = ladder(rng, span);
            rate_rows(&mut st, n, earth, &|t| m.at(t));
            parts.push("rate ladder +-1 .. 200 deg/s".to_owned());
        }
        Profile::ChamberTurning => {
            let (m, r) = turning(rng, span);
            rate_rows(&mut st, n, earth, &|t| m.at(t));
            parts.push(format!("turning at +-{r:.1} deg/s"));
        }
        Profile::Swings => {
            let sw = swings(rng, span);
            rate_rows(&mut st, n, earth, &|t| swing_at(&sw, t));
            let sd = rng.uniform(0.1, 0.3);
            st.acc_column = Some(st.acc.iter().map(|a| a + sd * rng.gauss()).collect());
            parts.push(format!(
                "{} swings, acceleration column noise {sd:.2} deg/s^2",
                sw.len()
            ));
        }
        _ => {
            rate_rows(&mut st, n, earth, &|_| (0.0, 0.0));
            parts.push("at rest".to_owned());
        }
    }
    let air = match profile {
        Profile::ChamberStatic | Profile::ChamberTurning => {
            let start = rng.uniform(18.0, 26.0);
            Program::chamber(
                rng,
                span,
                start,
                (-25.0, 55.0),
                (0.005, 0.017),
                (1500.0, 3000.0),
            )
        }
        Profile::RlgChamber => {
            let start = rng.uniform(18.0, 26.0);
            Program::chamber(
                rng,
                span,
                start,
                (-15.0, 45.0),
                (0.005, 0.017),
                (1500.0, 3000.0),
            )
        }
        _ => room(rng),
    };
    if profile.is_rlg() {
        parts.push(rlg_block(rng, &air, n, dt, &mut st));
    } else {
        let (coil, sensor, d) = fog_coil(rng, &air, n, dt);
        st.coil = Some(coil);
        st.coil_sensor = Some(sensor);
        parts.push(d);
    }
    st.describe = format!("{profile:?}: {}", parts.join("; "));
    st
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_means_and_derivatives_are_consistent() {
        let mut rng = Rng::new(8, 8);
        let st = build(Profile::ChamberTurning, &mut rng);
        let c = st.coil.as_ref().unwrap();
        // The stated derivatives against central differences of the values.
        for k in (100..st.t.len() - 100).step_by(97) {
            let d1 = (c.v[k + 1] - c.v[k - 1]) / 2.0;
            let d2 = (c.d1[k + 1] - c.d1[k - 1]) / 2.0;
            assert!((c.d1[k] - d1).abs() < 1e-5 * (1.0 + d1.abs() * 1e3), "{k}");
            assert!((c.d2[k] - d2).abs() < 2e-7, "{k}: {} {d2}", c.d2[k]);
        }
        // Mean square >= square of the mean, row by row.
        assert!(st.w.iter().zip(&st.w2).all(|(w, w2)| *w2 >= w * w - 1e-9));
        // The sensor follows the coil within its lag and steps.
        let s = st.coil_sensor.as_ref().unwrap();
        let worst = s
            .iter()
            .zip(&c.v)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.5, "{worst}");
    }
}
