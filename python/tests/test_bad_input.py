"""Bad input of each kind raises ValueError with the command line's located
message (TypeError where the argument is not a run at all); nothing
panics, nothing answers silently."""

import numpy as np
import pandas as pd
import pytest

import gyrolab

N = 1000


def good():
    rng = np.random.default_rng(1)
    return {"t_s": np.arange(N, dtype=float), "rate_dps": rng.normal(0, 0.01, N)}


def test_nan_names_column_and_row():
    for make in (dict, pd.DataFrame):
        run = good()
        run["rate_dps"][17] = np.nan
        with pytest.raises(ValueError, match=r"row 17 \(column `rate_dps`\): `NaN` is not a finite number"):
            gyrolab.allan(make(run))


def test_nan_in_time_and_infinity():
    run = good()
    run["t_s"][3] = np.nan
    with pytest.raises(ValueError, match=r"row 3 \(column `t_s`\)"):
        gyrolab.allan(run)
    run = good()
    run["rate_dps"][900] = np.inf
    with pytest.raises(ValueError, match=r"row 900 \(column `rate_dps`\)"):
        gyrolab.discover(run, gyro="fog")


def test_wrong_length():
    run = good()
    run["rate_dps"] = run["rate_dps"][:-1]
    with pytest.raises(ValueError, match=r"column `rate_dps`\): 999 rows where `t_s` has 1000"):
        gyrolab.allan(run)


def test_missing_column_lists_what_was_given():
    run = good()
    run["gyro_z"] = run.pop("rate_dps")
    with pytest.raises(ValueError, match=r"missing column `rate_dps`; the columns given are `t_s`, `gyro_z`"):
        gyrolab.allan(run)
    # ... and the mapping it suggests works.
    a = gyrolab.allan(run, columns={"rate_dps": "gyro_z"})
    assert a["samples"] == N


@pytest.mark.parametrize(
    "values,dtype",
    [
        (np.arange(N).astype(str), "<U"),
        (np.array([object()] * N), "object"),
        (np.zeros(N, complex), "complex128"),
        (np.zeros(N, bool), "bool"),
    ],
)
def test_wrong_dtype(values, dtype):
    run = good()
    run["rate_dps"] = values
    with pytest.raises(ValueError, match=rf"column `rate_dps`\): dtype {dtype}"):
        gyrolab.allan(run)


def test_strings_in_a_dataframe():
    df = pd.DataFrame(good())
    df["rate_dps"] = df["rate_dps"].astype(str)
    df.loc[5, "rate_dps"] = "abc"
    with pytest.raises(ValueError, match=r"column `rate_dps`"):
        gyrolab.allan(df)


def test_empty_arrays():
    with pytest.raises(ValueError, match=r"0 samples"):
        gyrolab.allan({"t_s": np.array([]), "rate_dps": np.array([])})
    with pytest.raises(ValueError):
        gyrolab.discover({"t_s": np.array([]), "rate_dps": np.array([])}, gyro="mems")
    with pytest.raises(ValueError):
        gyrolab.allan(pd.DataFrame({"t_s": [], "rate_dps": []}))


def test_two_dimensional():
    run = good()
    run["rate_dps"] = run["rate_dps"].reshape(10, 100)
    with pytest.raises(ValueError, match=r"a 2-D array; a column is 1-D"):
        gyrolab.allan(run)


def test_not_a_run():
    with pytest.raises(TypeError, match=r"a path, a dict of 1-D arrays or a pandas DataFrame"):
        gyrolab.allan(42)
    with pytest.raises(ValueError, match=r"cannot read"):
        gyrolab.allan("/nonexistent/run.csv")


def test_bad_options():
    with pytest.raises(ValueError, match=r"`furlong` is not a rate unit"):
        gyrolab.allan(good(), rate_unit="furlong")
    with pytest.raises(TypeError, match=r"unexpected keyword argument\(s\) bogus"):
        gyrolab.allan(good(), bogus=1)
    with pytest.raises(ValueError, match=r"gyro `hemispherical`: fog, rlg or mems"):
        gyrolab.discover(good(), gyro="hemispherical")


def test_bad_model_is_located():
    model = 'kind = "gyro_model"\nversion = 1\ngyro = "fog"\n[[effect]]\nname = "nope"\n'
    run = dict(good(), ref_rate_dps=np.zeros(N))
    with pytest.raises(ValueError, match=r"^model:5:\d+: unknown effect `nope`"):
        gyrolab.discover(run, gyro="fog", model=model)


def test_unit_mistake_is_caught():
    """Rates in rad/s read as deg/s: warned with the factor, as the CLI does."""
    rng = np.random.default_rng(2)
    t = np.arange(20000.0)
    # A navigation-grade FOG at rest: Earth rate (about 10 deg/h) in rad/s.
    rate = np.deg2rad(10.0 / 3600 + 0.005 / 60 * rng.standard_normal(len(t)))
    a = gyrolab.allan({"t_s": t, "rate_dps": rate, "temp_c": 20 + 0 * t})
    codes = [w["code"] for w in a["warnings"]]
    assert any("unit" in c for c in codes), codes


def test_garbage_frames_do_not_panic():
    rng = np.random.default_rng(5)
    with pytest.raises(ValueError, match=r"^data: no frame found in 50000 bytes"):
        gyrolab.decode_frames(rng.integers(0, 256, 50_000, dtype=np.uint8).tobytes())
    with pytest.raises(TypeError):
        gyrolab.decode_frames("not bytes")
