//! The third generator's test profiles, each drawn afresh per run: a rate
//! table with log-spaced rates and raised-cosine transitions while the
//! chamber ramps; a FOG soaking at random chamber levels; an RLG heating
//! itself in a chamber (case lag 400..800 s, monoblock lags 1000..3200 s);
//! an RLG stepped through rates below 0.5 deg/s, in its lock-in regime;
//! a FOG vibrated at 45..110 Hz; a MEMS gyro heating itself or in a
//! chamber from 5 to 65 degC.

use super::rng::Rng;
use super::thermal::{air, lag, plus_heating, soaks, Temp};
use super::truth::Physics;

/// Earth rate, deg/s.
const EARTH_DPS: f64 = 7.292_115e-5 * 180.0 / std::f64::consts::PI;

/// The kinds of profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Profile {
    Table,
    FogSoak,
    RlgChamber,
    LockInSteps,
    Vibration,
    MemsHeating,
    MemsChamber,
}

/// Rows `dt` apart over `dur` s, from `dt`.
fn rows(dt: f64, dur: f64) -> Vec<f64> {
    let n = (dur / dt).round() as usize;
    (1..=n).map(|k| k as f64 * dt).collect()
}

/// The Earth rate's component on an axis at `elev` degrees from the
/// horizontal, `az` degrees from north, at latitude `lat`.
fn earth_component(lat: f64, elev: f64, az: f64) -> f64 {
    let (l, e, a) = (lat.to_radians(), elev.to_radians(), az.to_radians());
    EARTH_DPS * (l.sin() * e.sin() + l.cos() * e.cos() * a.cos())
}

fn constant_rate(ph: &mut Physics, w: f64) {
    let n = ph.t.len();
    ph.w = vec![w; n];
    ph.w2 = vec![w * w; n];
    ph.wabs = vec![w.abs(); n];
    ph.wabsw = vec![w * w.abs(); n];
    ph.acc2 = vec![0.0; n];
}

/// A FOG coil behind its housing in chamber air through `corners`.
fn coil(t: &[f64], corners: &[(f64, f64)], rng: &mut Rng) -> Temp {
    let a = air(t, corners);
    let t0 = corners[0].1;
    let housing = lag(t, &a, rng.between(200.0, 600.0), t0);
    lag(t, &housing, rng.between(300.0, 900.0), t0)
}

/// Chamber levels: `n` levels within [lo, hi], each at least `gap` from
/// the last.
fn levels(rng: &mut Rng, n: usize, lo: f64, hi: f64, gap: f64) -> Vec<f64> {
    let mut v = vec![rng.between(lo, lo + 0.3 * (hi - lo))];
    while v.len() < n {
        let x = rng.between(lo, hi);
        if (x - v[v.len() - 1]).abs() >= gap {
            v.push(x);
        }
    }
    v
}

impl Profile {
    /// Builds the physics and the row period.
    pub fn build(self, rng: &mut Rng) -> (Physics, f64) {
        match self {
            Profile::Table => table(rng),
            Profile::FogSoak => fog_soak(rng),
            Profile::RlgChamber => rlg_chamber(rng),
            Profile::LockInSteps => lock_in_steps(rng),
            Profile::Vibration => vibration(rng),
            Profile::MemsHeating => mems(rng, false),
            Profile::MemsChamber => mems(rng, true),
        }
    }
}

fn table(rng: &mut Rng) -> (Physics, f64) {
    let dt = if rng.unit() < 0.5 { 1.0 } else { 0.5 };
    let dur = rng.between(2.5, 4.0) * 3600.0;
    let t = rows(dt, dur);
    let mags = [1.0, 3.0, 10.0, 30.0, 100.0, 200.0, 300.0];
    let mut plan: Vec<(f64, f64)> = vec![]; // (start, rate)
    let mut s = 0.0;
    let mut i = 0;
    while s < dur + 200.0 {
        let r = if i % 5 == 4 {
            0.0
        } else {
            let m = mags[rng.pick(mags.len())];
            if rng.unit() < 0.5 {
                -m
            } else {
                m
            }
        };
        plan.push((s, r));
        s += rng.between(40.0, 100.0);
        i += 1;
    }
    let earth = earth_component(rng.between(30.0, 60.0), 90.0, 0.0);
    let ramp = 1.5;
    let rate_at = |x: f64| -> f64 {
        let j = plan.partition_point(|p| p.0 <= x).saturating_sub(1);
        let (start, r) = plan[j];
        let prev = if j == 0 { 0.0 } else { plan[j - 1].1 };
        let into = x - start;
        let w = if into < ramp {
            prev + (r - prev) * 0.5 * (1.0 - (std::f64::consts::PI * into / ramp).cos())
        } else {
            r
        };
        w + earth
    };
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    let sub = 16;
    for &x in &t {
        let (mut m1, mut m2, mut ma, mut mw) = (0.0, 0.0, 0.0, 0.0);
        for j in 0..sub {
            let w = rate_at(x - dt + (j as f64 + 0.5) * dt / sub as f64);
            m1 += w;
            m2 += w * w;
            ma += w.abs();
            mw += w * w.abs();
        }
        let f = sub as f64;
        ph.w.push(m1 / f);
        ph.w2.push(m2 / f);
        ph.wabs.push(ma / f);
        ph.wabsw.push(mw / f);
    }
    ph.acc2 = vec![0.0; t.len()];
    let (a, b) = if rng.unit() < 0.5 {
        (-20.0, 60.0)
    } else {
        (60.0, -20.0)
    };
    let corners = [(0.0, a), (1200.0, a), (dur - 1200.0, b), (dur + 10.0, b)];
    ph.main = Some(coil(&t, &corners, rng));
    (ph, dt)
}

fn fog_soak(rng: &mut Rng) -> (Physics, f64) {
    let dt = 1.0;
    let dur = rng.between(3.0, 6.0) * 3600.0;
    let t = rows(dt, dur);
    let count = 4 + rng.pick(3);
    let lv = levels(rng, count, -30.0, 60.0, 15.0);
    let soak: Vec<f64> = (0..6).map(|_| rng.between(1200.0, 3000.0)).collect();
    let corners = soaks(
        &lv,
        rng.between(0.5, 2.0),
        &soak,
        rng.between(300.0, 1200.0),
    );
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    constant_rate(
        &mut ph,
        earth_component(
            rng.between(20.0, 65.0),
            rng.between(-90.0, 90.0),
            rng.between(0.0, 360.0),
        ),
    );
    ph.main = Some(coil(&t, &corners, rng));
    (ph, dt)
}

fn rlg_chamber(rng: &mut Rng) -> (Physics, f64) {
    let dt = if rng.unit() < 0.5 { 1.0 } else { 2.0 };
    let dur = rng.between(4.0, 7.0) * 3600.0;
    let t = rows(dt, dur);
    let lv = vec![
        rng.between(-25.0, 0.0),
        rng.between(40.0, 60.0),
        rng.between(10.0, 25.0),
    ];
    let soak: Vec<f64> = (0..3).map(|_| rng.between(1800.0, 3600.0)).collect();
    let corners = soaks(
        &lv,
        rng.between(0.5, 1.5),
        &soak,
        rng.between(600.0, 1800.0),
    );
    let a = air(&t, &corners);
    let heated = plus_heating(&t, &a, rng.between(2.0, 6.0), rng.between(600.0, 1800.0));
    let t0 = lv[0];
    let case = lag(&t, &heated, rng.between(400.0, 800.0), t0);
    let ua = plus_heating(&t, &case, rng.between(3.0, 7.0), rng.between(800.0, 2500.0));
    let ub = plus_heating(&t, &case, rng.between(1.0, 5.0), rng.between(800.0, 2500.0));
    let ta = rng.between(1000.0, 3200.0);
    let mut tb = rng.between(1000.0, 3200.0);
    if (ta - tb).abs() < 300.0 {
        tb = if ta < 2100.0 { ta + 800.0 } else { ta - 800.0 };
    }
    let ma = lag(&t, &ua, ta, t0);
    let mb = lag(&t, &ub, tb, t0);
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    constant_rate(&mut ph, earth_component(rng.between(20.0, 65.0), 90.0, 0.0));
    ph.main = Some(case.clone());
    ph.case = Some(case);
    ph.mono = Some((ma, mb));
    (ph, dt)
}

fn lock_in_steps(rng: &mut Rng) -> (Physics, f64) {
    let dt = 0.1;
    let dur = rng.between(20.0, 40.0) * 60.0;
    let t = rows(dt, dur);
    let mut plan: Vec<(f64, f64)> = vec![];
    let mut s = 0.0;
    while s < dur + 60.0 {
        let m = rng.log_between(0.02, 0.45);
        plan.push((s, if rng.unit() < 0.5 { -m } else { m }));
        s += rng.between(30.0, 60.0);
    }
    let rate_at = |x: f64| {
        let j = plan.partition_point(|p| p.0 <= x).saturating_sub(1);
        plan[j].1
    };
    let sub = 8;
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    let mut subs = vec![];
    for &x in &t {
        let v: Vec<f64> = (0..sub)
            .map(|j| rate_at(x - dt + (j as f64 + 0.5) * dt / sub as f64))
            .collect();
        let m = v.iter().sum::<f64>() / sub as f64;
        ph.w.push(m);
        ph.w2
            .push(v.iter().map(|w| w * w).sum::<f64>() / sub as f64);
        ph.wabs
            .push(v.iter().map(|w| w.abs()).sum::<f64>() / sub as f64);
        ph.wabsw
            .push(v.iter().map(|w| w * w.abs()).sum::<f64>() / sub as f64);
        subs.push(v);
    }
    ph.acc2 = vec![0.0; t.len()];
    ph.w_sub = Some(subs);
    (ph, dt)
}

fn vibration(rng: &mut Rng) -> (Physics, f64) {
    let f = rng.between(45.0, 110.0);
    let dt = 1.0 / (f * 6.37);
    let dur = rng.between(8.0, 12.0) * 60.0;
    let t = rows(dt, dur);
    let om = std::f64::consts::TAU * f;
    let lv = [0.0, 2000.0, 5000.0, 8000.0, 12000.0];
    let mut plan: Vec<(f64, f64)> = vec![];
    let mut s = 0.0;
    while s < dur + 60.0 {
        plan.push((s, lv[rng.pick(lv.len())] * rng.between(0.8, 1.2)));
        s += rng.between(30.0, 60.0);
    }
    let phase = rng.between(0.0, std::f64::consts::TAU);
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    let mut acc = vec![];
    for &x in &t {
        let (a, b) = (x - dt, x);
        let j = plan.partition_point(|p| p.0 <= a).saturating_sub(1);
        let eps = plan[j].1;
        // Rate eps/om sin(om s + phase); acceleration eps cos(om s + phase).
        let wm = eps / (om * om * dt) * ((om * a + phase).cos() - (om * b + phase).cos());
        let a2 = eps
            * eps
            * (0.5
                + ((2.0 * (om * b + phase)).sin() - (2.0 * (om * a + phase)).sin())
                    / (4.0 * om * dt));
        ph.w.push(wm);
        ph.w2.push(wm * wm);
        ph.wabs.push(wm.abs());
        ph.wabsw.push(wm * wm.abs());
        ph.acc2.push(a2);
        acc.push(eps * (om * (x - 0.5 * dt) + phase).cos());
    }
    ph.acc = Some(acc);
    (ph, dt)
}

fn mems(rng: &mut Rng, chamber: bool) -> (Physics, f64) {
    let dt = [0.1, 0.5, 1.0][rng.pick(3)];
    let dur = rng.between(1.5, 4.0) * 3600.0;
    let t = rows(dt, dur);
    let die = if chamber {
        // 5 .. 65 degC through the chamber, the board a short lag behind.
        let lv = vec![
            rng.between(3.0, 10.0),
            rng.between(60.0, 67.0),
            rng.between(20.0, 35.0),
        ];
        let soak: Vec<f64> = (0..3).map(|_| rng.between(900.0, 1800.0)).collect();
        let corners = soaks(&lv, rng.between(0.8, 2.0), &soak, rng.between(300.0, 900.0));
        let a = air(&t, &corners);
        lag(&t, &a, rng.between(60.0, 300.0), lv[0])
    } else {
        // A board heating itself (a processor, motors) from room
        // temperature, with the room drifting a little.
        let room = rng.between(18.0, 28.0);
        let corners = [(0.0, room), (dur + 10.0, room + rng.signed(0.5, 3.0))];
        let a = air(&t, &corners);
        let heated = plus_heating(&t, &a, rng.between(15.0, 40.0), rng.between(600.0, 2400.0));
        lag(&t, &heated, rng.between(30.0, 200.0), room)
    };
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    constant_rate(
        &mut ph,
        earth_component(rng.between(20.0, 65.0), rng.between(-90.0, 90.0), 0.0),
    );
    ph.main = Some(die);
    (ph, dt)
}
