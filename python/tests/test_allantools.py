"""The overlapping Allan deviation equals allantools' ``oadev`` on the same
array at the same averaging times (relative 1e-6), on a measured record
where the workplace has one, on a committed white + random-walk record,
and on coloured (flicker + random-walk) noise."""

import allantools
import numpy as np
import pytest

import gyrolab
from conftest import HUB, WHITE_RW


def check_against_allantools(run):
    cols = gyrolab.read_run(run) if not isinstance(run, dict) else run
    rate = np.asarray(cols["rate_dps"], float)
    if "ref_rate_dps" in cols:
        rate = rate - np.asarray(cols["ref_rate_dps"], float)
    a = gyrolab.allan(run)
    taus = np.asarray(a["taus_s"])
    assert len(taus) >= 5
    t_out, adev, _, _ = allantools.oadev(
        rate, rate=1.0 / a["tau0_s"], data_type="freq", taus=taus
    )
    np.testing.assert_allclose(t_out, taus, rtol=1e-12)
    np.testing.assert_allclose(np.asarray(a["adev_dph"]) / 3600.0, adev, rtol=1e-6)
    return a


def test_measured_hub():
    if not HUB.exists():
        pytest.skip(f"{HUB}: the workplace's measured record is not here")
    a = check_against_allantools(str(HUB))
    assert a["samples"] == 320 and a["tau0_s"] == 15.0


def test_white_random_walk():
    check_against_allantools(str(WHITE_RW))


def flicker(n, rng):
    """1/f noise by spectral shaping (a generator apart from the lab's)."""
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.arange(len(spec), dtype=float)
    f[0] = 1.0
    return np.fft.irfft(spec / np.sqrt(f), n)


def test_coloured_noise_in_a_dict():
    rng = np.random.default_rng(3)
    n = 200_000
    tau0 = 0.01
    rate = (
        1e-3 * rng.standard_normal(n)
        + 2e-4 * flicker(n, rng)
        + 1e-7 * np.cumsum(rng.standard_normal(n))
    )
    check_against_allantools({"t_s": np.arange(n) * tau0, "rate_dps": rate})
