"""gyrolab.allan against numpy + allantools' oadev on the same array, at
the same averaging times, side by side in one process (``cargo xtask
bench`` runs it; its last line is JSON).

    python python/benchmarks/allan_speed.py [--samples 2000000] [--repeats 7]

Each repeat times both, in alternating order; the figure is the ratio of
the medians. gyrolab's time is the whole call: the array read and
checked, the deviation, the edf and intervals, the IEEE 952 fit and its
check. allantools' is oadev alone.
"""

import argparse
import json
import statistics
import time

import allantools
import numpy as np

import gyrolab


def record(n, seed=1):
    """White + flicker-like + random-walk rate at 100 Hz, deg/s."""
    rng = np.random.default_rng(seed)
    white = 1e-3 * rng.standard_normal(n)
    walk = 1e-7 * np.cumsum(rng.standard_normal(n))
    return {"t_s": np.arange(n) * 0.01, "rate_dps": white + walk}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--samples", type=int, default=2_000_000)
    p.add_argument("--repeats", type=int, default=7)
    a = p.parse_args()
    run = record(a.samples)
    first = gyrolab.allan(run)
    taus = np.asarray(first["taus_s"])
    rate = 1.0 / first["tau0_s"]

    def ours():
        return gyrolab.allan(run)

    def theirs():
        return allantools.oadev(run["rate_dps"], rate=rate, data_type="freq", taus=taus)

    t_ours, t_theirs = [], []
    for i in range(a.repeats):
        pair = [(ours, t_ours), (theirs, t_theirs)]
        for f, times in pair if i % 2 == 0 else pair[::-1]:
            t0 = time.perf_counter()
            out = f()
            times.append(time.perf_counter() - t0)
    adev_theirs = out[1] if isinstance(out, tuple) else theirs()[1]
    err = float(np.max(np.abs(np.asarray(first["adev_dph"]) / 3600 / adev_theirs - 1)))
    m_ours, m_theirs = statistics.median(t_ours), statistics.median(t_theirs)
    print(
        f"allan on {a.samples} samples, {len(taus)} averaging times, {a.repeats} repeats: "
        f"gyrolab {m_ours * 1e3:.1f} ms, allantools.oadev {m_theirs * 1e3:.1f} ms, "
        f"ratio {m_ours / m_theirs:.3f}; largest relative difference {err:.2e}"
    )
    print(
        json.dumps(
            {
                "allan_samples": a.samples,
                "allan_gyrolab_s": m_ours,
                "allan_allantools_s": m_theirs,
                "allan_vs_allantools": m_ours / m_theirs,
                "allan_max_rel_diff": err,
            }
        )
    )


if __name__ == "__main__":
    main()
