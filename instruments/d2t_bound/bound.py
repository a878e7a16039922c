#!/usr/bin/env python3
"""How well can k * d2T/dt2 be explained when T is read by a quantised,
noisy sensor? A bound, and the tool against it (issue 39).

The term is k T''(t), T the coil's true temperature. The tool sees the
sensor s = Q(T + v): v white (sd sigma_v), Q rounding to q. Whatever the
estimator, what it leaves of the term is k (T'' - c * est), and the gap
after is sqrt(noise^2 + k^2 * mse) for the best c.

The bound (linear time-invariant estimators, which every derivative filter
is: nested slopes, local polynomials, Savitzky-Golay, any width): with the
sensor's error e = s - T independent of T and stationary with spectrum
S_e, an LTI estimate of T'' from s has, at each DFT frequency f,

    E|err(f)|^2 = |G - 1|^2 |X(f)|^2 + |G|^2 w(f)^4 N S_e(f),

X the DFT of T'', w = 2 pi f, G the filter relative to the exact second
derivative. It is least at G = |X|^2 / (|X|^2 + w^4 N S_e) (Wiener), and
then

    mse_min = (1/N^2) sum_f |X|^2 w^4 N S_e / (|X|^2 + w^4 N S_e).

No LTI filter, at any width, scaled by any c, leaves less: c times a
filter is a filter. The gap ratio it allows is sqrt(1 + k^2 mse_min /
sigma^2), sigma the output's realised noise. S_e is the realised sensor
error's periodogram smoothed over 65 bins (the quantisation's sawtooth is
not white where the temperature creeps; its spectrum is what it is).

The record: a FOG at rest in a chamber; the chamber's air piecewise linear
(ramps at `rate` degC/min between plateaus, sharp corners), the coil a
first-order lag of it (tau_c): T'' jumps at each corner and relaxes over
tau_c, the hardest shape for a smoothing filter. T, T' and T'' are exact
(the lag solved in closed form per segment).

For each case the script writes a run file, runs `gyro-lab discover` on
it, and prints: the bound; the best nested-slope filter over widths; the
tool's fixed 120 s filter fitted directly; and the tool's discovery (its
term, coefficient and gap). `rel` is the least relative error of the
curvature any LTI filter makes (sqrt(mse_min / mean T''^2)); with a term r
times the noise no estimator of that class leaves a gap under sqrt(1 + r^2
rel^2) times the noise. `oracle` applies the bound's own Wiener filter (it
knows the truth's spectrum): it reaches the bound, so the bound is tight.
Run:

    python3 instruments/d2t_bound/bound.py --lab target/release/gyro-lab --work /tmp/d2t

Independent of the lab's code (numpy only), as the other instruments.
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np


def chamber(plan, dt=1.0):
    """Rows every dt s of (t, air, T, T', T'') for a plan of (duration_s,
    air slope degC/s) segments, the coil a first-order lag tau_c of the air.
    Exact per segment: with the air a + b t, T' relaxes to b."""
    t_all, air_all, T_all, d1_all, d2_all = [], [], [], [], []
    air, T, d1, t0 = plan["start_c"], plan["start_c"], 0.0, 0.0
    tau = plan["tau_c"]
    for dur, b in plan["segments"]:
        n = int(round(dur / dt))
        u = np.arange(n) * dt
        # T' = b + (d1 - b) exp(-u/tau); T = T0 + b u + (d1 - b) tau (1 - exp(-u/tau))
        ex = np.exp(-u / tau)
        d1u = b + (d1 - b) * ex
        Tu = T + b * u + (d1 - b) * tau * (1.0 - ex)
        d2u = -(d1 - b) / tau * ex
        t_all.append(t0 + u)
        air_all.append(air + b * u)
        T_all.append(Tu)
        d1_all.append(d1u)
        d2_all.append(d2u)
        e = np.exp(-dur / tau)
        T = T + b * dur + (d1 - b) * tau * (1.0 - e)
        d1 = b + (d1 - b) * e
        air += b * dur
        t0 += dur
    return [np.concatenate(x) for x in (t_all, air_all, T_all, d1_all, d2_all)]


def plan_of(rate_c_per_min, tau_c, lo=-20.0, hi=60.0, dwell=3600.0, start=20.0):
    r = rate_c_per_min / 60.0
    segs = [(dwell, 0.0)]
    segs.append(((hi - start) / r, r))
    segs.append((dwell, 0.0))
    segs.append(((hi - lo) / r, -r))
    segs.append((dwell, 0.0))
    segs.append(((start - lo) / r, r))
    segs.append((dwell, 0.0))
    return {"start_c": start, "tau_c": tau_c, "segments": segs}


def centered_slope(x, half):
    """Least-squares slope over +-half rows (1 s rows), fewer at the ends."""
    n = len(x)
    u = np.arange(n, dtype=float)
    c = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones(n), u, u * u, x, u * x)]
    k = np.arange(n)
    lo = np.clip(k - half, 0, n)
    hi = np.clip(k + half + 1, 0, n)
    s = [cc[hi] - cc[lo] for cc in c]
    den = s[0] * s[2] - s[1] ** 2
    return np.where(den > 0, (s[0] * s[4] - s[1] * s[3]) / np.where(den > 0, den, 1.0), 0.0)


def curvature(x, half):
    return centered_slope(centered_slope(x, half), half)


def fit_gap(y, est, sigma, inner):
    """Gap ratio after y's best fit by c * est + constant, over `inner`."""
    a = np.column_stack([est[inner], np.ones(inner.sum())])
    coef, *_ = np.linalg.lstsq(a, y[inner], rcond=None)
    r = y[inner] - a @ coef
    return float(np.sqrt(np.mean(r * r)) / sigma), float(coef[0])


def wiener_mse(d2, err):
    """Least mean-square error of any LTI estimate of T'' (samples d2) from
    T + err, err's spectrum its smoothed periodogram."""
    n = len(d2)
    X = np.fft.rfft(d2)
    E = np.fft.rfft(err - err.mean())
    pe = np.abs(E) ** 2  # N * S_e(f), per bin
    k = 65
    pe = np.convolve(pe, np.ones(k) / k, mode="same")
    # A bin's white-noise floor is never below what a white error of the
    # same variance would give at that bin's neighbours: keep the smoothed.
    w4 = (2.0 * np.pi * np.fft.rfftfreq(n, 1.0)) ** 4
    px = np.abs(X) ** 2
    noise = w4 * pe
    per = np.where(px + noise > 0, px * noise / np.where(px + noise > 0, px + noise, 1.0), 0.0)
    # rfft: bins other than DC and Nyquist stand for two.
    wts = np.full(len(per), 2.0)
    wts[0] = 1.0
    if n % 2 == 0:
        wts[-1] = 1.0
    return float(np.sum(wts * per) / n**2)


def wiener_estimate(d2, err, s):
    """The bound's own filter applied to the sensor (it knows the truth's
    spectrum: an oracle, to show the bound is reached, not only a floor)."""
    n = len(s)
    X = np.fft.rfft(d2)
    E = np.fft.rfft(err - err.mean())
    k = 65
    pe = np.convolve(np.abs(E) ** 2, np.ones(k) / k, mode="same")
    w2 = (2.0 * np.pi * np.fft.rfftfreq(n, 1.0)) ** 2
    px = np.abs(X) ** 2
    g = np.where(px + w2 * w2 * pe > 0, px / np.where(px + w2 * w2 * pe > 0, px + w2 * w2 * pe, 1.0), 0.0)
    # Less the line through its ends (no curvature), so the record's wrap
    # (the DFT's period) joins without a step.
    line = s[0] + (s[-1] - s[0]) * np.arange(n) / (n - 1)
    return np.fft.irfft(-w2 * g * np.fft.rfft(s - line), n)


def case(args, name, rate, tau_c, q, sd_v, ratio, seed):
    rng = np.random.default_rng(seed)
    t, air, T, d1, d2 = chamber(plan_of(rate, tau_c))
    n = len(t)
    s = T + sd_v * rng.standard_normal(n)
    if q > 0:
        s = np.round(s / q) * q
    sigma_w = 0.3  # deg/h per 1 s row: a tactical FOG's 0.005 deg/sqrt(h)
    k = ratio * sigma_w / np.sqrt(np.mean(d2 * d2))  # term RMS = ratio x noise
    noise = sigma_w * rng.standard_normal(n)
    y = noise + k * d2
    sig = float(np.std(noise))
    inner = np.zeros(n, bool)
    inner[600:-600] = True  # the filters' widths never reach the ends
    mse = wiener_mse(d2, s - T)
    bound = float(np.sqrt(1.0 + k * k * mse / sig**2))
    oracle = fit_gap(y, wiener_estimate(d2, s - T, s), sig, inner)
    best = min(
        (fit_gap(y, curvature(s, h), sig, inner) + (h,) for h in (10, 20, 30, 45, 60, 90, 120, 180, 240)),
        key=lambda v: v[0],
    )
    tool_fixed = fit_gap(y, curvature(s, 120), sig, inner)
    row = {
        "case": name,
        "rate_c_per_min": rate,
        "tau_c_s": tau_c,
        "q_c": q,
        "sensor_sd_c": sd_v,
        "term_over_noise": ratio,
        "k_dph_per_c_per_s2": k,
        "bound_gap_ratio": bound,
        # The least relative error of any LTI curvature: with a term r
        # times the noise the gap after is at least sqrt(1 + r^2 rel^2).
        "bound_relative_error": float(np.sqrt(mse / np.mean(d2 * d2))),
        "wiener_oracle_gap_ratio": oracle[0],
        "best_width_gap_ratio": best[0],
        "best_width_half_s": best[2],
        "best_width_k_ratio": best[1] / k,
        "tool_filter_120s_gap_ratio": tool_fixed[0],
        "tool_filter_120s_k_ratio": tool_fixed[1] / k,
    }
    if args.lab:
        os.makedirs(args.work, exist_ok=True)
        path = os.path.join(args.work, f"{name}.csv")
        with open(path, "w") as f:
            f.write("t_s,ref_rate_dps,rate_dps,temp_c\n")
            for i in range(n):
                f.write(f"{t[i]:.0f},0,{y[i] / 3600.0:.12e},{s[i]:.4f}\n")
        out = os.path.join(args.work, name)
        p = subprocess.run(
            [args.lab, "discover", "--gyro", "fog", "--data", path, "--out", out, "--force", "--json"],
            capture_output=True,
            text=True,
        )
        if p.returncode != 0:
            sys.exit(f"{name}: gyro-lab discover failed: {p.stderr.strip()}")
        j = json.loads(p.stdout.strip().splitlines()[-1])
        found = j.get("found", [])
        row["tool_named"] = [e["formula"] if e.get("effect") == "term" else e.get("effect") for e in found]
        # The tool's residual over the same inner rows, less its mean (a
        # bias is the model's own).
        res = np.loadtxt(os.path.join(out, "residual.csv"), delimiter=",", skiprows=1)[:, 2] * 3600.0
        r = res[inner] - res[inner].mean()
        row["tool_gap_ratio"] = float(np.sqrt(np.mean(r * r)) / sig)
        kk = [e for e in found if e.get("effect") == "term" and "d2dt2" in e.get("formula", "")]
        if kk and "k_dph" in kk[0].get("parameters", {}):
            row["tool_k_ratio"] = kk[0]["parameters"]["k_dph"] / k
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lab", help="gyro-lab binary (omit: the bound and the filters only)")
    ap.add_argument("--work", default="/tmp/d2t")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    cases = [
        ("slow-q0.01", 0.5, 900.0, 0.01, 0.003, 4.0),
        ("slow-q16th", 0.5, 900.0, 0.0625, 0.0, 4.0),
        ("fast-q0.01", 2.0, 300.0, 0.01, 0.003, 4.0),
        ("fast-q16th", 2.0, 300.0, 0.0625, 0.0, 4.0),
        ("fast-q16th-noisy", 2.0, 300.0, 0.0625, 0.02, 4.0),
        ("sharp-q16th", 3.0, 120.0, 0.0625, 0.0, 4.0),
    ]
    rows = [case(a, *c, seed=a.seed + i) for i, c in enumerate(cases)]
    if a.json:
        # One line: each case's bound and, where run, the tool's gap (as
        # `cargo xtask bench` reads them), then the rows in full.
        keys = {}
        for r in rows:
            c = r["case"].replace("-", "_")
            keys[f"d2t_{c}_bound_gap_ratio"] = round(r["bound_gap_ratio"], 3)
            if "tool_gap_ratio" in r:
                keys[f"d2t_{c}_discover_gap_ratio"] = round(r["tool_gap_ratio"], 3)
        keys["d2t_rows"] = rows
        print(json.dumps(keys))
        return
    hdr = f"{'case':18} {'rel':>6} {'bound':>6} {'oracle':>6} {'best h':>12} {'k/k':>6} {'tool 120s':>9} {'k/k':>6}"
    if a.lab:
        hdr += f" {'discover':>9} {'k/k':>6}  named"
    print(hdr)
    for r in rows:
        line = (
            f"{r['case']:18} {r['bound_relative_error']:6.3f} {r['bound_gap_ratio']:6.3f} {r['wiener_oracle_gap_ratio']:6.3f} {r['best_width_gap_ratio']:6.3f} ({r['best_width_half_s']:3d} s)"
            f" {r['best_width_k_ratio']:6.3f} {r['tool_filter_120s_gap_ratio']:9.3f} {r['tool_filter_120s_k_ratio']:6.3f}"
        )
        if a.lab:
            line += f" {r['tool_gap_ratio']:9.3f} {r.get('tool_k_ratio', float('nan')):6.3f}  {r['tool_named']}"
        print(line)


if __name__ == "__main__":
    main()
