"""A run as a path, a pandas DataFrame or a dict of arrays (or lists):
the same numbers give the same answer, and what the file's options do
(column names, units, a stretch, clock timestamps) the keywords do."""

import json

import numpy as np
import pandas as pd
import pytest

import gyrolab
from conftest import differences

# The source's name: the path, or "run" for what is in memory.
NAMES = {"data", "source", "file"}


def as_json(result):
    return json.loads(result.to_json())


def equal(a, b):
    d = differences(as_json(a), as_json(b), skip={"read_s", "compute_s", "elapsed_s"} | NAMES)
    assert not d, "\n".join(d[:20])


def test_path_dataframe_dict_lists_agree(runs):
    path = str(runs / "chamber.csv")
    df = pd.read_csv(path, comment="#")
    cols = {k: df[k].to_numpy() for k in df.columns}
    lists = {k: v.tolist() for k, v in cols.items()}
    ref = gyrolab.allan(path)
    for run in (df, cols, lists):
        equal(gyrolab.allan(run), ref)
    equal(gyrolab.fit_thermal(df), gyrolab.fit_thermal(path))


def test_discover_on_a_dataframe_names_what_the_cli_names(cli, runs, tmp_path):
    path = runs / "table.csv"
    c = cli("discover", "--gyro", "fog", "--data", path, "--out", tmp_path / "d")
    py = gyrolab.discover(pd.read_csv(path, comment="#"), gyro="fog")
    assert [f["effect"] for f in py["found"]] == [f["effect"] for f in c["found"]]
    assert [f["effect"] for f in py["found"]] == ["scale_factor_knee", "warm_up"]
    assert py["gap_after_dph"] == c["gap_after_dph"]
    assert py["gap_before_dph"] == c["gap_before_dph"]
    assert "<svg" in py._repr_html_()
    # The same model file, but for the source named in its first comment.
    written = (tmp_path / "d" / "model.toml").read_text()
    assert py.model_toml.splitlines()[1:] == written.splitlines()[1:]


def test_views_and_other_dtypes():
    """Strided views, float32, int64 and big-endian arrays read as their
    values (copied only where numpy cannot lend them as f64)."""
    rng = np.random.default_rng(4)
    t = np.arange(4000.0)
    r = rng.normal(0, 0.01, 4000)
    ref = gyrolab.allan({"t_s": t[::2], "rate_dps": r[::2]})
    equal(gyrolab.allan({"t_s": t[::2].copy(), "rate_dps": r[::2].copy()}), ref)
    equal(gyrolab.allan({"t_s": t[::2].astype(">f8"), "rate_dps": r[::2].astype(">f8")}), ref)
    q = np.round(r * 1e4).astype(np.int64)
    a = gyrolab.allan({"t_s": t.astype(np.int64), "rate_dps": q})
    b = gyrolab.allan({"t_s": t, "rate_dps": q.astype(float)})
    equal(a, b)
    f32 = r.astype(np.float32)
    equal(gyrolab.allan({"t_s": t, "rate_dps": f32}), gyrolab.allan({"t_s": t, "rate_dps": f32.astype(float)}))


def test_column_names_and_units_of_the_users_file():
    rng = np.random.default_rng(6)
    n = 7200
    t = np.arange(n, dtype=float)
    temp = 20 + 10 * np.sin(t / 2000)
    rate = 0.01 + 1e-4 * (temp - 20) + rng.normal(0, 1e-3, n)
    ours = gyrolab.allan({"t_s": t, "rate_dps": rate, "temp_c": temp})
    theirs = pd.DataFrame({"time": t * 1000, "gyro_z": np.deg2rad(rate), "temp": temp + 273.15})
    a = gyrolab.allan(
        theirs,
        columns={"t_s": "time", "rate_dps": "gyro_z", "temp_c": "temp"},
        time_unit="ms",
        rate_unit="rad/s",
        temp_unit="K",
    )
    np.testing.assert_allclose(a["adev_dph"], ours["adev_dph"], rtol=1e-9)
    assert a["units"]["rate"] == "rad/s" and a["units"]["temperature"] == "K"


def test_stretch_keywords():
    rng = np.random.default_rng(8)
    t = np.arange(10000.0)
    run = {"t_s": t, "rate_dps": rng.normal(0, 0.01, len(t))}
    a = gyrolab.allan(run, from_s=2000, to_s=8000)
    cut = {k: v[(t >= 2000) & (t <= 8000)] for k, v in run.items()}
    np.testing.assert_allclose(a["adev_dph"], gyrolab.allan(cut)["adev_dph"], rtol=1e-12)


def test_datetime_index_and_timestamps():
    """A DataFrame indexed by clock time (a PC log) reads its times as
    seconds since the first row."""
    rng = np.random.default_rng(9)
    n = 3600
    r = rng.normal(0, 0.01, n)
    idx = pd.date_range("2026-03-01 14:00:00", periods=n, freq="1s")
    a = gyrolab.allan(pd.DataFrame({"rate_dps": r}, index=idx))
    b = gyrolab.allan({"t_s": np.arange(n, dtype=float), "rate_dps": r})
    np.testing.assert_allclose(a["adev_dph"], b["adev_dph"], rtol=1e-12)
    c = gyrolab.allan(pd.DataFrame({"t_s": idx, "rate_dps": r}))
    np.testing.assert_allclose(c["adev_dph"], b["adev_dph"], rtol=1e-12)


def test_simulate_then_analyse_in_memory(runs):
    cols = gyrolab.simulate_run(str(runs / "truth.toml"), profile="table", seed=3, duration_s=3600)
    assert set(cols) >= {"t_s", "rate_dps", "ref_rate_dps", "temp_c"}
    assert len(cols["t_s"]) == 3600
    d = gyrolab.discover(cols, gyro="fog")
    assert "scale_factor_knee" in [f["effect"] for f in d["found"]]


def test_release_the_gil_for_threads(runs):
    """Threads each run a call; all finish and agree (the calls release
    the GIL while they compute, so a thread pool uses the cores)."""
    from concurrent.futures import ThreadPoolExecutor

    path = str(runs / "table.csv")
    with ThreadPoolExecutor(4) as ex:
        results = list(ex.map(lambda _: gyrolab.discover(path, gyro="fog"), range(4)))
    for r in results[1:]:
        equal(r, results[0])


@pytest.mark.parametrize("bad", [{"t_s": [1, 2, 3]}, {}])
def test_dicts_without_a_rate(bad):
    with pytest.raises(ValueError, match="missing column"):
        gyrolab.allan(bad)


def test_what_a_users_dataframe_also_holds():
    """A logger's frame: text timestamps under its own names, a serial
    number and a comment column the command does not read (ignored, as a
    file's other columns are), a time zone on the index."""
    rng = np.random.default_rng(10)
    n = 3600
    r = rng.normal(0, 0.01, n)
    ref = gyrolab.allan({"t_s": np.arange(n, dtype=float), "rate_dps": r})
    stamps = pd.date_range("2026-03-01 14:00:00", periods=n, freq="1s")
    text = stamps.strftime("%Y-%m-%d %H:%M:%S.%f").str[:-3]
    log = pd.DataFrame({"time": text, "gyro_z": r, "serial": "FOG-0042", "note": ""})
    a = gyrolab.allan(log, columns={"t_s": "time", "rate_dps": "gyro_z"})
    np.testing.assert_allclose(a["adev_dph"], ref["adev_dph"], rtol=1e-12)
    zoned = pd.DataFrame({"rate_dps": r}, index=stamps.tz_localize("Europe/Berlin"))
    np.testing.assert_allclose(gyrolab.allan(zoned)["adev_dph"], ref["adev_dph"], rtol=1e-12)
    # A column the command reads is kept whatever it holds: its error names it.
    with pytest.raises(ValueError, match=r"column `time`\): dtype object"):
        gyrolab.allan(log.assign(time="x"), columns={"t_s": "time", "rate_dps": "gyro_z"})
    # allan's `column` may name any column: kept, and checked.
    with pytest.raises(ValueError, match=r"column `serial`"):
        gyrolab.allan(log, columns={"t_s": "time", "rate_dps": "gyro_z"}, column="serial")
