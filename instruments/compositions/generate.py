#!/usr/bin/env python3
"""Independent test data for discovery beyond the effect library: compositions.

Writes a folder of simulated gyro records in the format `gyro-lab bench
discover-outside --runs DIR` reads. Each case is one gyro recorded twice (run A and
run B: different days, so a different noise seed, turn-on bias, rate profile and
temperature program; the same hidden coefficient and shape parameters). The gyro is
ideal (output = reference rate) except for a constant turn-on bias, its noise and ONE
hidden term that is a composition of simple physical inputs, the kind a real gyro has
and no effect library lists. Null cases hide nothing: only coloured noise.

    rate_dps = ref_rate_dps + (bias + hidden(t) + noise(t)) / 3600

Inputs of the hidden terms are the TRUE quantities: w the true rate about the axis
(table rate + Earth-rate vertical component 15.041 deg/h * sin(lat)), eps its angular
acceleration, T the gyro's internal temperature (FOG coil / MEMS die), dT/dt its rate of
change; for an RLG Tc the case, Ta and Tb the two monoblock places. The run file only
shows what a test rig records: the reference rate (and, where given, ref_acc_dps2 with
rig noise) and the temperature SENSORS, which read the internal temperatures through a
lag of tens of seconds, with a few mdegC of noise and quantised to 0.01 or 1/16 degC.
Every value in a row (rate, hidden term) is the mean of the true signal over the row.
L(x, tau) below is a first-order lag of x with time constant tau (300..1500 s), a
thermal path inside the gyro, distinct from the sensor lag. t is time since power-on.

Physical compositions (expect ["term"]):
  w_x_temp          mems  k*w*(T-20)       scale factor linear in die temperature (MEMS
                           libraries carry no scale factor over temperature)
  w_x_dtemp         fog   k*w*dT/dt        scale factor of the Shupe gradient: a
                           time-varying radial gradient changes the coil's effective area
  absw_x_temp       fog   k*|w|*(T-20)     temperature-dependent scale-factor asymmetry
  temp_x_dtemp      fog   k*(T-20)*dT/dt   Shupe coefficient that changes with temperature
                           (fibre jacket stiffness): d/dt of a quadratic bias
  w2_x_temp         fog   k*w^2*(T-20)     centrifugal coil stress, temperature dependent
  lag_temp_sq       fog   k*(L(T,tau)-20)^2  bias from the stress of an inner potting
                           layer that follows the coil through its own thermal path
  w_x_lag_temp      mems  k*w*(L(T,tau)-20)  scale factor following the package (not the
                           die) temperature
  w_x_lag_temp      fog   k*w*(L(T,tau)-20)  scale factor following the source's
                           wavelength, whose mount lags the coil sensor
  acc_x_w           fog   k*eps*w          (1/2) d(w^2)/dt: coil strain while the
                           centripetal load changes; ref_acc_dps2 is in the file
  w_x_decay         rlg   k*w*exp(-t/tau)  scale-factor warm-up of the gas discharge
  temp_x_t          fog   k*(T-20)*t/3600  ageing of the thermal bias coefficient
                           during the run (curing of the coil adhesive), per hour
  w_x_step          fog   k*w*step(t-t0)   scale-factor jump (source mode hop) at t0
  case_mono_x_dcase rlg   k*(Tc-(Ta+Tb)/2)*dTc/dt  gradient between case and block
                           times the case's rate of change (mount stress while heating)
  lag_mono_diff     rlg   k*L(Ta-Tb,tau)   the block's internal gradient reaching the
                           mirrors through a lag
  w_x_temp2         mems  k*w*(T-20)^2     curvature of the MEMS scale factor over temp.
Events, two shape parameters each (expect ["term"]):
  jump_relax        fog/mems  k*step(t-t0)*exp(-(t-t0)/tau)  a jump that relaxes
  ramp_saturate     rlg   k*(1-exp(-(t-t0)/tau)) after t0    a drift that saturates
  pulse             fog   k*(step(t-t0)-step(t-t1))          a step up and back down
Nulls (expect [], nothing hidden; ordinary profiles and temperatures):
  null_flicker (mems) white + flicker; null_rrw (fog) white + rate random walk;
  null_markov (rlg) white + first-order Markov (100..1000 s); null_mixed (fog) white +
  flicker + rate random walk + Markov.

Noise (physics.md): FOG ARW 0.002..0.01 deg/sqrt(h) (1 s white RMS = 60*ARW deg/h),
flicker B 0.005..0.02 deg/h (Allan floor 0.664 B), sometimes a rate random walk; RLG
ARW 0.001..0.004, B 0.003..0.01; MEMS (tactical) ARW 0.1..0.3, B 1..5 deg/h. Rows every
0.5 or 1 s. Amplitude: the coefficient is set so that the hidden term's 1 s RMS (about
its mean) is 3.5..7 times the noise floor (geometric mean over the two runs), moved
where needed so that each run lies within 3..8 times its floor.
floor_dph = noise_1s_dph = RMS, about their mean, of the 1 s means (windows from the
first row) of the added noise; white_1s_dph the same for its white part.

`allow` lists "bias" and the library effects the composition genuinely contains as a
component (e.g. w*(T-20) with T averaging 35 degC holds a constant scale-factor error).

Usage: python3 generate.py --seed 1 --out DIR [--hours 3]
"""
import argparse
import json
import math
import os

import numpy as np
from scipy.signal import lfilter

NS = 10                      # fine sub-samples per row (row values are means over them)
EARTH_DPH = 15.041


# ----------------------------------------------------------------------------- helpers
def lag(x, tau, h):
    """First-order lag of x sampled every h, starting settled at x[0]."""
    a = math.exp(-h / tau)
    return lfilter([1.0 - a], [1.0, -a], x, zi=[a * x[0]])[0]


def rows(x):
    return x.reshape(-1, NS).mean(axis=1)


def rms_1s(t, x):
    """RMS about their mean of the 1 s means of x (windows of 1 s from the first row)."""
    idx = np.floor((t - t[0]) / 1.0 + 1e-9).astype(int)
    cnt = np.bincount(idx)
    keep = cnt > 0
    m = np.bincount(idx, weights=x)[keep] / cnt[keep]
    return float(np.std(m))


def loguniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


# ----------------------------------------------------------------------------- rate profiles
def rate_spec(rng, family):
    """The rig's rate program for one gyro (shared by both runs, varied per run)."""
    if family == "table":
        n = 400
        r = np.where(rng.random(n) < 0.15, 0.0,
                     rng.choice([-1.0, 1.0], n) * np.exp(rng.uniform(0, math.log(200), n)))
        return dict(family="table", rates=r, dwells=rng.uniform(60, 240, n),
                    accs=rng.uniform(5, 20, n))
    if family == "turning":
        return dict(family="turning", w=rng.uniform(20, 150), period=rng.uniform(120, 480),
                    acc=rng.uniform(5, 20))
    return dict(family="rest")


def rate_knots(rng, spec, dur):
    """Piecewise-linear knots (t, w) of the table rate for one run."""
    fam = spec["family"]
    if fam == "rest":
        return np.array([-10.0, dur + 10.0]), np.zeros(2), "at rest"
    start = rng.uniform(60, 180)
    if fam == "table":
        n = len(spec["rates"])
        order = np.argsort(np.arange(n) + rng.uniform(0, 4, n))   # the program, locally shuffled
        plateaus = [(spec["rates"][i], spec["dwells"][i] * rng.uniform(0.85, 1.15),
                     spec["accs"][i]) for i in order]
        desc = "rate table: plateaus +-1..200 deg/s, dwells 60..240 s, accelerations 5..20 deg/s^2"
    else:
        w = spec["w"] * rng.uniform(0.95, 1.05)
        per = spec["period"] * rng.uniform(0.9, 1.1)
        plateaus = [((1.0 if i % 2 == 0 else -1.0) * w, per * rng.uniform(0.95, 1.05), spec["acc"])
                    for i in range(400)]
        desc = "turning at +-%.1f deg/s reversed every %.0f s, %.1f deg/s^2" % (w, per, spec["acc"])
    tk, wk, t, w = [-10.0, start], [0.0, 0.0], start, 0.0
    for r, d, a in plateaus:
        if r != w:
            t += abs(r - w) / a
            tk.append(t), wk.append(r)
            w = r
        t += d
        tk.append(t), wk.append(r)
        if t > dur + 10:
            break
    return np.array(tk), np.array(wk), desc


def eval_rate(tk, wk, tf):
    w = np.interp(tf, tk, wk)
    slope = np.diff(wk) / np.diff(tk)
    seg = np.clip(np.searchsorted(tk, tf, side="right") - 1, 0, len(slope) - 1)
    return w, slope[seg]


# ----------------------------------------------------------------------------- temperatures
def ambient_spec(rng, family):
    if family == "chamber":
        hot = rng.random() < 0.5
        segs = []
        for _ in range(12):
            target = rng.uniform(40, 60) if hot else rng.uniform(-20, 5)
            segs.append((rng.uniform(900, 2400), target, rng.uniform(0.5, 1.5) / 60.0))
            hot = not hot
        return dict(family="chamber", start=rng.uniform(18, 25), segs=segs)
    return dict(family="room", t0=rng.uniform(20, 25), amp=rng.uniform(0.3, 1.0),
                period=rng.uniform(3, 8) * 3600)


def ambient(rng, spec, tf):
    """Ambient temperature of one run (a day's variation of the program)."""
    if spec["family"] == "chamber":
        t, temp = 0.0, spec["start"] + rng.uniform(-1, 1)
        tk, vk, parts = [-10.0, 0.0], [temp, temp], ["chamber from %.1f degC" % temp]
        for soak, target, rate in spec["segs"]:
            soak *= rng.uniform(0.9, 1.1)
            target += rng.uniform(-3, 3)
            rate *= rng.uniform(0.9, 1.1)
            t += soak
            tk.append(t), vk.append(temp)
            t += abs(target - temp) / rate
            tk.append(t), vk.append(target)
            if t < tf[-1]:
                parts.append("soak %.0f s, to %.1f degC at %.2f degC/min" % (soak, target, rate * 60))
            temp = target
            if t > tf[-1] + 10:
                break
        tk.append(max(t, tf[-1]) + 10), vk.append(temp)
        return np.interp(tf, tk, vk), "; ".join(parts)
    t0 = spec["t0"] + rng.uniform(-1, 1)
    ph = rng.uniform(0, 2 * math.pi)
    amb = t0 + spec["amp"] * np.sin(2 * math.pi * tf / spec["period"] + ph)
    return amb, "room %.1f degC +-%.2f degC over %.1f h" % (t0, spec["amp"], spec["period"] / 3600)


def thermal_spec(rng, gyro):
    """The gyro's own thermal paths and sensors (the same in both runs)."""
    q = float(rng.choice([0.01, 0.0625]))
    if gyro == "rlg":
        ta = rng.uniform(1000, 3000)
        tb = ta + rng.choice([-1, 1]) * rng.uniform(400, 1200)
        tb = float(np.clip(tb, 600, 3600))
        return dict(tau_case=rng.uniform(400, 900), heat_case=rng.uniform(0.5, 2),
                    tau_a=ta, tau_b=tb, heat_a=rng.uniform(0.5, 3), heat_b=rng.uniform(0.5, 3),
                    warm_a=rng.uniform(600, 2000), warm_b=rng.uniform(600, 2000),
                    warm_case=rng.uniform(600, 2000), lags=rng.uniform(20, 100, 3),
                    noise=rng.uniform(0.002, 0.005), q=q)
    return dict(tau_house=rng.uniform(300, 1200),
                heat=rng.uniform(1, 3) if gyro == "fog" else rng.uniform(0.5, 2),
                warm=rng.uniform(600, 2000), lag=rng.uniform(10, 60),
                noise=rng.uniform(0.002, 0.005), q=q)


def sensor(rng, x, tau, th, h):
    s = rows(lag(x, tau, h)) + rng.normal(0, th["noise"], len(x) // NS)
    return np.round(s / th["q"]) * th["q"]


def temperatures(rng, gyro, th, amb, tf, h):
    """True internal temperatures (fine grid) and the sensor columns (rows)."""
    warm = lambda heat, tau: heat * (1 - np.exp(-np.maximum(tf, 0) / tau))
    if gyro == "rlg":
        tc = lag(amb, th["tau_case"], h) + warm(th["heat_case"], th["warm_case"])
        ta = lag(tc, th["tau_a"], h) + warm(th["heat_a"], th["warm_a"])
        tb = lag(tc, th["tau_b"], h) + warm(th["heat_b"], th["warm_b"])
        cols = {"t_mono_a_c": sensor(rng, ta, th["lags"][0], th, h),
                "t_mono_b_c": sensor(rng, tb, th["lags"][1], th, h),
                "t_case_c": sensor(rng, tc, th["lags"][2], th, h)}
        true = dict(Tc=tc, Ta=ta, Tb=tb, dTc=np.gradient(tc, h))
        desc = ("RLG: case lag %.0f s heated %.2f degC, monoblocks %.0f / %.0f s heated "
                "%.2f / %.2f degC, sensor lags %.0f / %.0f / %.0f s, %g degC steps" %
                (th["tau_case"], th["heat_case"], th["tau_a"], th["tau_b"], th["heat_a"],
                 th["heat_b"], *th["lags"], th["q"]))
    else:
        T = lag(amb, th["tau_house"], h) + warm(th["heat"], th["warm"])
        cols = {"temp_c": sensor(rng, T, th["lag"], th, h)}
        true = dict(T=T, dT=np.gradient(T, h))
        desc = ("%s: housing lag %.0f s, self-heating %.2f degC over %.0f s, sensor lag "
                "%.1f s, %g degC steps, %.1f mdegC noise" %
                ("coil" if gyro == "fog" else "die", th["tau_house"], th["heat"], th["warm"],
                 th["lag"], th["q"], th["noise"] * 1e3))
    return true, cols, desc


# ----------------------------------------------------------------------------- noise
def noise_spec(rng, gyro, kind):
    if gyro == "fog":
        s = dict(arw=rng.uniform(0.002, 0.01), flicker=rng.uniform(0.005, 0.02),
                 rrw=rng.uniform(0.002, 0.01) if rng.random() < 0.3 else 0.0)
    elif gyro == "rlg":
        s = dict(arw=rng.uniform(0.001, 0.004), flicker=rng.uniform(0.003, 0.01), rrw=0.0)
    else:
        s = dict(arw=rng.uniform(0.1, 0.3), flicker=rng.uniform(1, 5), rrw=0.0)
    s.update(markov=0.0, markov_s=0.0)
    white1 = 60 * s["arw"]
    if kind == "null_flicker":
        s["flicker"] = rng.uniform(3, 8) if gyro == "mems" else rng.uniform(0.015, 0.02)
    elif kind == "null_rrw":
        s["rrw"] = rng.uniform(0.02, 0.06)
    elif kind == "null_markov":
        s.update(markov=rng.uniform(0.3, 0.6) * white1, markov_s=rng.uniform(100, 1000))
    elif kind == "null_mixed":
        s.update(flicker=rng.uniform(0.01, 0.02), rrw=rng.uniform(0.01, 0.03),
                 markov=rng.uniform(0.2, 0.4) * white1, markov_s=rng.uniform(100, 1000))
    return s


def flicker(rng, n, dt, b):
    """1/f rate noise, two-sided PSD B^2/(2 pi f) as in IEEE 952 (one-sided B^2/(pi f)):
    Allan floor 0.664 B."""
    m = 4 * n
    f = np.fft.rfftfreq(m, dt)
    sd = np.zeros_like(f)
    sd[1:] = np.sqrt(b * b / (math.pi * f[1:]) * m / (4 * dt))
    spec = sd * (rng.normal(size=len(f)) + 1j * rng.normal(size=len(f)))
    return np.fft.irfft(spec, n=m)[:n]


def make_noise(rng, s, n, dt):
    white = rng.normal(0, 60 * s["arw"] / math.sqrt(dt), n)
    total = white + flicker(rng, n, dt, s["flicker"])
    if s["rrw"] > 0:
        total += np.cumsum(rng.normal(0, s["rrw"] * math.sqrt(dt / 3600), n))
    if s["markov"] > 0:
        phi = math.exp(-dt / s["markov_s"])
        x0 = rng.normal(0, s["markov"])
        e = rng.normal(0, s["markov"] * math.sqrt(1 - phi * phi), n)
        total += lfilter([1.0], [1.0, -phi], e, zi=[phi * x0])[0]
    return white, total


# ----------------------------------------------------------------------------- cases
def step(x):
    return (x >= 0).astype(float)


def after(t, t0, tau):
    return np.exp(-np.maximum(t - t0, 0) / tau)


PHYS = "physical"
CASES = [
    dict(kind="w_x_temp", gyro="mems", rate="table", temp="chamber",
         coef="k_dph_per_dps_per_c", allow=["scale_factor_error", "scale_factor_temperature"],
         shape=lambda c, p: c["w"] * (c["T"] - 20),
         text="k * w * (T_die - 20), k = {k:.4g} deg/h per (deg/s degC); true rate, true die temperature"),
    dict(kind="w_x_dtemp", gyro="fog", rate="turning", temp="chamber",
         coef="k_dph_per_dps_per_c_per_s", allow=["scale_factor_error"],
         shape=lambda c, p: c["w"] * c["dT"],
         text="k * w * dT_coil/dt, k = {k:.4g} deg/h per (deg/s degC/s); true rate, true coil"),
    dict(kind="absw_x_temp", gyro="fog", rate="table", temp="chamber",
         coef="k_dph_per_dps_per_c", allow=["bias_temperature", "scale_factor_asymmetry"],
         shape=lambda c, p: np.abs(c["w"]) * (c["T"] - 20),
         text="k * |w| * (T_coil - 20), k = {k:.4g} deg/h per (deg/s degC); true rate, true coil"),
    dict(kind="temp_x_dtemp", gyro="fog", rate="rest", temp="chamber",
         coef="k_dph_per_c2_per_s", allow=["shupe"],
         shape=lambda c, p: (c["T"] - 20) * c["dT"],
         text="k * (T_coil - 20) * dT_coil/dt, k = {k:.4g} deg/h per (degC degC/s); true coil"),
    dict(kind="w2_x_temp", gyro="fog", rate="table", temp="chamber",
         coef="k_dph_per_dps2_per_c", allow=["bias_temperature"],
         shape=lambda c, p: c["w"] ** 2 * (c["T"] - 20),
         text="k * w^2 * (T_coil - 20), k = {k:.4g} deg/h per ((deg/s)^2 degC); true rate, true coil"),
    dict(kind="lag_temp_sq", gyro="fog", rate="rest", temp="chamber",
         coef="k_dph_per_c2", allow=["bias_temperature", "shupe"],
         draw=lambda r, d: {"tau_s": r.uniform(300, 1500)},
         shape=lambda c, p: (lag(c["T"], p["tau_s"], c["h"]) - 20) ** 2,
         text="k * (L(T_coil, {tau_s:.0f} s) - 20)^2, k = {k:.4g} deg/h per degC^2; L a first-order lag of the true coil temperature"),
    dict(kind="w_x_lag_temp", gyro="mems", rate="turning", temp="chamber",
         coef="k_dph_per_dps_per_c", allow=["scale_factor_error"],
         draw=lambda r, d: {"tau_s": r.uniform(300, 1500)},
         shape=lambda c, p: c["w"] * (lag(c["T"], p["tau_s"], c["h"]) - 20),
         text="k * w * (L(T_die, {tau_s:.0f} s) - 20), k = {k:.4g} deg/h per (deg/s degC); L a first-order lag of the true die temperature"),
    dict(kind="w_x_lag_temp", gyro="fog", rate="table", temp="chamber",
         coef="k_dph_per_dps_per_c", allow=["scale_factor_error", "scale_factor_temperature"],
         draw=lambda r, d: {"tau_s": r.uniform(600, 1500)},
         shape=lambda c, p: c["w"] * (lag(c["T"], p["tau_s"], c["h"]) - 20),
         text="k * w * (L(T_coil, {tau_s:.0f} s) - 20), k = {k:.4g} deg/h per (deg/s degC); L a first-order lag of the true coil temperature"),
    dict(kind="acc_x_w", gyro="fog", rate="table", temp="room", acc=True,
         coef="k_dph_per_dps_dps2", allow=[],
         shape=lambda c, p: c["acc"] * c["w"],
         text="k * eps * w, k = {k:.4g} deg/h per (deg/s^2 deg/s); true acceleration and rate (ref_acc_dps2 given, with rig noise)"),
    dict(kind="w_x_decay", gyro="rlg", rate="table", temp="room",
         coef="k_dph_per_dps", allow=["scale_factor_error"],
         draw=lambda r, d: {"tau_s": r.uniform(1200, 3600)},
         shape=lambda c, p: c["w"] * np.exp(-c["t"] / p["tau_s"]),
         text="k * w * exp(-t/{tau_s:.0f}), k = {k:.4g} deg/h per deg/s; true rate, t since power-on"),
    dict(kind="temp_x_t", gyro="fog", rate="rest", temp="chamber",
         coef="k_dph_per_c_per_h", allow=["bias_temperature"],
         shape=lambda c, p: (c["T"] - 20) * c["t"] / 3600,
         text="k * (T_coil - 20) * t/3600, k = {k:.4g} deg/h per (degC h); true coil, t since power-on"),
    dict(kind="w_x_step", gyro="fog", rate="table", temp="room",
         coef="k_dph_per_dps", allow=["scale_factor_error"],
         draw=lambda r, d: {"t0_s": r.uniform(0.3, 0.7) * d},
         shape=lambda c, p: c["w"] * step(c["t"] - p["t0_s"]),
         text="k * w * step(t - {t0_s:.0f}), k = {k:.4g} deg/h per deg/s; true rate"),
    dict(kind="case_mono_x_dcase", gyro="rlg", rate="rest", temp="chamber",
         coef="k_dph_per_c2_per_s",
         allow=["thermal_difference", "thermal_difference_squared"],
         shape=lambda c, p: (c["Tc"] - (c["Ta"] + c["Tb"]) / 2) * c["dTc"],
         text="k * (T_case - (T_mono_a + T_mono_b)/2) * dT_case/dt, k = {k:.4g} deg/h per (degC degC/s); true temperatures"),
    dict(kind="lag_mono_diff", gyro="rlg", rate="rest", temp="chamber",
         coef="k_dph_per_c", allow=["thermal_difference", "thermal_gradient"],
         draw=lambda r, d: {"tau_s": r.uniform(300, 1500)},
         shape=lambda c, p: lag(c["Ta"] - c["Tb"], p["tau_s"], c["h"]),
         text="k * L(T_mono_a - T_mono_b, {tau_s:.0f} s), k = {k:.4g} deg/h per degC; L a first-order lag of the true difference"),
    dict(kind="w_x_temp2", gyro="mems", rate="table", temp="chamber",
         coef="k_dph_per_dps_per_c2", allow=["scale_factor_error", "scale_factor_temperature"],
         shape=lambda c, p: c["w"] * (c["T"] - 20) ** 2,
         text="k * w * (T_die - 20)^2, k = {k:.4g} deg/h per (deg/s degC^2); true rate, true die temperature"),
    # events
    dict(kind="jump_relax", cat="event", gyro="fog", rate="rest", temp="room",
         coef="amplitude_dph", allow=[],
         draw=lambda r, d: {"t0_s": r.uniform(0.2, 0.6) * d, "tau_s": r.uniform(300, 1500)},
         shape=lambda c, p: step(c["t"] - p["t0_s"]) * after(c["t"], p["t0_s"], p["tau_s"]),
         text="k * step(t - {t0_s:.0f}) * exp(-(t - {t0_s:.0f})/{tau_s:.0f}), k = {k:.4g} deg/h"),
    dict(kind="ramp_saturate", cat="event", gyro="rlg", rate="rest", temp="room",
         coef="amplitude_dph", allow=[],
         draw=lambda r, d: {"t0_s": r.uniform(0.2, 0.5) * d, "tau_s": r.uniform(600, 2400)},
         shape=lambda c, p: step(c["t"] - p["t0_s"]) * (1 - after(c["t"], p["t0_s"], p["tau_s"])),
         text="k * (1 - exp(-(t - {t0_s:.0f})/{tau_s:.0f})) from t = {t0_s:.0f} s, k = {k:.4g} deg/h"),
    dict(kind="pulse", cat="event", gyro="fog", rate="table", temp="room",
         coef="amplitude_dph", allow=[],
         draw=lambda r, d: (lambda t0: {"t0_s": t0, "t1_s": min(t0 + r.uniform(600, 2400), 0.9 * d)})(
             r.uniform(0.2, 0.6) * d),
         shape=lambda c, p: step(c["t"] - p["t0_s"]) - step(c["t"] - p["t1_s"]),
         text="k * (step(t - {t0_s:.0f}) - step(t - {t1_s:.0f})), k = {k:.4g} deg/h"),
    dict(kind="jump_relax", cat="event", gyro="mems", rate="turning", temp="chamber",
         coef="amplitude_dph", allow=[],
         draw=lambda r, d: {"t0_s": r.uniform(0.2, 0.6) * d, "tau_s": r.uniform(300, 1500)},
         shape=lambda c, p: step(c["t"] - p["t0_s"]) * after(c["t"], p["t0_s"], p["tau_s"]),
         text="k * step(t - {t0_s:.0f}) * exp(-(t - {t0_s:.0f})/{tau_s:.0f}), k = {k:.4g} deg/h"),
    # nulls
    dict(kind="null_flicker", cat="null", gyro="mems", rate="table", temp="chamber"),
    dict(kind="null_rrw", cat="null", gyro="fog", rate="rest", temp="room"),
    dict(kind="null_markov", cat="null", gyro="rlg", rate="rest", temp="chamber"),
    dict(kind="null_mixed", cat="null", gyro="fog", rate="turning", temp="chamber"),
]


# ----------------------------------------------------------------------------- runs
def simulate_run(rng, case, sh, dur, dt, lat):
    """One record of the case's gyro: inputs, noise and the hidden term's unit shape."""
    n = int(round(dur / dt))
    h = dt / NS
    tf = (np.arange(n * NS) + 0.5) * h - dt / 2          # row i covers t_i +- dt/2
    t = np.arange(n) * dt
    tk, wk, rdesc = rate_knots(rng, sh["rate"], dur)
    table, acc = eval_rate(tk, wk, tf)
    earth = EARTH_DPH * math.sin(math.radians(lat)) / 3600
    amb, adesc = ambient(rng, sh["amb"], tf)
    true, cols, tdesc = temperatures(rng, case["gyro"], sh["thermal"], amb, tf, h)
    ctx = dict(t=tf, h=h, w=table + earth, acc=acc, **true)
    shape = rows(case["shape"](ctx, sh["params"])) if "shape" in case else np.zeros(n)
    white, noise = make_noise(rng, sh["noise"], n, dt)
    out = {"t_s": t, "ref_rate_dps": rows(table) + earth}
    if case.get("acc"):
        out["ref_acc_dps2"] = rows(acc) + rng.normal(0, sh["acc_noise"], n)
    prof = "%s; %s; %s; latitude %.1f deg" % (rdesc, adesc, tdesc, lat)
    if case.get("acc"):
        prof += "; acceleration column noise %.2f deg/s^2" % sh["acc_noise"]
    bias = {"fog": 1.0, "rlg": 0.3, "mems": 150.0}[case["gyro"]] * rng.uniform(-1, 1)
    return dict(t=t, out=out, cols=cols, shape=shape, white=white, noise=noise,
                floor=rms_1s(t, noise), white1=rms_1s(t, white), profile=prof, bias=bias)


def write_csv(path, comment, header, cols, fmts):
    data = np.column_stack(cols)
    with open(path, "w") as f:
        f.write("# " + comment + "\n")
        np.savetxt(f, data, fmt=fmts, delimiter=",", header=",".join(header), comments="")


def write_run(outdir, stem, case, name, which, run, k, seed, nspec):
    hidden = k * run["shape"]
    rate = run["out"]["ref_rate_dps"] + (run["bias"] + hidden + run["noise"]) / 3600
    names = ["t_s", "ref_rate_dps", "rate_dps"] + list(run["cols"])
    vals = [run["t"], run["out"]["ref_rate_dps"], rate] + list(run["cols"].values())
    fmts = ["%.10g", "%.12e", "%.12e"] + ["%.4f"] * len(run["cols"])
    if "ref_acc_dps2" in run["out"]:
        names.append("ref_acc_dps2"), vals.append(run["out"]["ref_acc_dps2"]), fmts.append("%.5f")
    ns = nspec
    comment = ("compositions generator (seed %d): %s run %s (%s); %s; noise: white %.4f deg/sqrt(h), "
               "flicker %.4f deg/h, rate random walk %.4f deg/h/sqrt(h), Markov %.4f deg/h over %.0f s"
               % (seed, name, which, case.get("cat", PHYS), run["profile"], ns["arw"], ns["flicker"],
                  ns["rrw"], ns["markov"], ns["markov_s"]))
    fname, hname = stem + "-%s.csv" % which, stem + "-%s.hidden.csv" % which
    write_csv(os.path.join(outdir, fname), comment, names, vals, fmts)
    write_csv(os.path.join(outdir, hname),
              "compositions generator (seed %d): %s run %s: the hidden term's contribution per row (deg/h)"
              % (seed, name, which), ["t_s", "hidden_dph"], [run["t"], hidden], ["%.10g", "%.10e"])
    h1 = rms_1s(run["t"], hidden)
    return {"file": fname, "hidden": hname, "floor_dph": run["floor"], "noise_1s_dph": run["floor"],
            "white_1s_dph": run["white1"], "rows": len(run["t"]), "dt_s": float(run["t"][1] - run["t"][0]),
            "profile": run["profile"], "bias_dph": run["bias"], "hidden_1s_dph": h1,
            "multiple_of_floor": h1 / run["floor"]}


def make_case(idx, case, seed, hours, outdir):
    rng = np.random.default_rng([seed, idx, 0])
    dur = hours * 3600.0
    dt = float(rng.choice([0.5, 1.0]))
    lat = rng.uniform(35, 60)
    sh = dict(rate=rate_spec(rng, case["rate"]), amb=ambient_spec(rng, case["temp"]),
              thermal=thermal_spec(rng, case["gyro"]), noise=noise_spec(rng, case["gyro"], case["kind"]),
              params=case["draw"](rng, dur) if "draw" in case else {},
              acc_noise=rng.uniform(0.05, 0.3))
    target = rng.uniform(3.5, 7.0)
    sign = rng.choice([-1.0, 1.0])
    runs = [simulate_run(np.random.default_rng([seed, idx, j]), case, sh, dur, dt, lat) for j in (1, 2)]
    cat = case.get("cat", PHYS)
    k = 0.0
    if cat != "null":
        m = [rms_1s(r["t"], r["shape"]) / r["floor"] for r in runs]   # multiples at k = 1
        lo, hi = 3.0 / min(m), 8.0 / max(m)          # both runs within 3..8 x floor if possible
        k = target / math.sqrt(m[0] * m[1])
        k = sign * (min(max(k, lo), hi) if lo <= hi else math.sqrt(lo * hi))
    name = "%s-%s" % (case["kind"], case["gyro"])
    stem = "%02d-%s" % (idx + 1, case["kind"])
    ra, rb = (write_run(outdir, stem, case, name, w, r, k, seed, sh["noise"]) for w, r in zip("AB", runs))
    params = {} if cat == "null" else {case["coef"]: float(k), **{a: float(b) for a, b in sh["params"].items()}}
    hidden = "nothing" if cat == "null" else case["text"].format(k=k, **sh["params"])
    ns = sh["noise"]
    return {"name": name, "kind": case["kind"], "category": cat, "gyro": case["gyro"],
            "expect": [] if cat == "null" else ["term"],
            "allow": ["bias"] + case.get("allow", []),
            "parameters": params, "hidden": hidden, "a": ra, "b": rb,
            "multiple_of_floor": ra["multiple_of_floor"],
            "noise": {"arw_dpsh": ns["arw"], "flicker_dph": ns["flicker"], "rrw_dphsh": ns["rrw"],
                      "markov_dph": ns["markov"], "markov_s": ns["markov_s"], "count_arcsec": 0.0}}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", required=True, help="folder to write (created; files replaced)")
    ap.add_argument("--hours", type=float, default=3.0, help="record length (2..6 h)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    truth = []
    for i, case in enumerate(CASES):
        c = make_case(i, case, a.seed, a.hours, a.out)
        truth.append(c)
        print("%-26s %-8s %-4s x%.2f / x%.2f of floor %.3g deg/h" %
              (c["name"], c["category"], c["gyro"], c["a"]["multiple_of_floor"],
               c["b"]["multiple_of_floor"], c["a"]["floor_dph"]))
    with open(os.path.join(a.out, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1)
    print("%d cases (%d runs) and truth.json -> %s" % (len(truth), 2 * len(truth), a.out))


if __name__ == "__main__":
    main()
