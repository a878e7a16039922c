"""Issue 22, part 2: a measured static record with documented disturbances
added, to check that `gyro-lab discover` reports them as unexplained with
spans that locate them.

Input: a measured ADIS16405 MEMS record at rest (t_s, ref_rate_dps,
rate_dps; 100 Hz, 10 000 s), e.g. /work/measured/adis1_x.csv. Its 1 s means
scatter by about 145 deg/h (the "floor").

Added (all in deg/s on rate_dps; the reference stays 0):
- door slams: at t0 = 1500, 1530, 4200 and 7300 s, a rock-and-settle pulse
  A (t - t0)/tau exp(1 - (t - t0)/tau) for t >= t0, tau = 2 s,
  A = 600 deg/h (about 4 times the floor at its peak; its 1 s means peak
  near 590 deg/h), gone after about 20 s;
- a vehicle-rocking burst from 5400 to 5700 s: a 0.3 Hz sway of amplitude
  540 deg/h under a Hann envelope (1 s means keep sinc(0.3) = 0.86 of it:
  about 3.2 times the floor at the burst's middle).

Usage: python3 issue-22-inject.py IN.csv OUT.csv
"""

import sys

import numpy as np

DPH = 1.0 / 3600.0


def disturbance(t):
    d = np.zeros_like(t)
    tau = 2.0
    for t0 in (1500.0, 1530.0, 4200.0, 7300.0):
        u = np.clip(t - t0, 0.0, None)
        d += np.where(t >= t0, 600.0 * DPH * (u / tau) * np.exp(1.0 - u / tau), 0.0)
    a, b = 5400.0, 5700.0
    inside = (t >= a) & (t <= b)
    env = np.where(inside, 0.5 - 0.5 * np.cos(2 * np.pi * (t - a) / (b - a)), 0.0)
    d += env * 540.0 * DPH * np.sin(2 * np.pi * 0.3 * t)
    return d


def main():
    src, dst = sys.argv[1], sys.argv[2]
    x = np.loadtxt(src, delimiter=",", skiprows=1)
    t, w, r = x[:, 0], x[:, 1], x[:, 2]
    r = r + disturbance(t)
    with open(dst, "w") as fh:
        fh.write(f"# {src} plus the disturbances of docs/notes/issue-22-inject.py\n")
        fh.write("t_s,ref_rate_dps,rate_dps\n")
        for a, b, c in zip(t, w, r):
            fh.write(f"{a:.2f},{b:g},{c:.9g}\n")


if __name__ == "__main__":
    main()
