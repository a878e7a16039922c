"""Every function runs the command line's code: the same file gives the
same JSON, key by key and bit for bit (the clock and the output paths
aside), and the same files."""

import json
import pathlib

import numpy as np
import pandas as pd
import pytest

import gyrolab
from conftest import HUB, OUTPUT, TIMING, WHITE_RW, differences


def same(py_result, cli_json):
    d = differences(json.loads(py_result.to_json()), cli_json)
    assert not d, "\n".join(d[:20])


def allan_records(runs):
    out = [WHITE_RW, runs / "chamber.csv", runs / "table.csv"]
    return out + ([HUB] if HUB.exists() else [])


def test_allan(cli, runs):
    for path in allan_records(runs):
        same(gyrolab.allan(str(path)), cli("allan", "--data", path))


def test_allan_options(cli, runs):
    """The read options mean what the command line's mean."""
    path = runs / "chamber.csv"
    py = gyrolab.allan(str(path), from_s=3000, to_s=18000, column="rate_dps")
    same(py, cli("allan", "--data", path, "--from-s", 3000, "--to-s", 18000, "--column", "rate_dps"))


@pytest.mark.parametrize(
    "name,gyro", [("table.csv", "fog"), ("chamber.csv", "rlg"), ("hub", "mems")]
)
def test_discover(cli, runs, tmp_path, name, gyro):
    path = HUB if name == "hub" else runs / name
    if not path.exists():
        pytest.skip(f"{path}: the workplace's measured record is not here")
    c = cli("discover", "--gyro", gyro, "--data", path, "--out", tmp_path / "d")
    py = gyrolab.discover(str(path), gyro=gyro)
    same(py, c)
    assert py.model_toml == (tmp_path / "d" / "model.toml").read_text()
    res = pd.read_csv(tmp_path / "d" / "residual.csv", comment="#")
    for col, values in py.residual.items():
        assert col in res.columns, f"residual.csv has no {col}"
        np.testing.assert_allclose(values, res[col].to_numpy(), rtol=1e-9, atol=1e-12)


def test_discover_with_model_and_validation(cli, runs, tmp_path):
    t1, t2 = runs / "table.csv", runs / "table2.csv"
    first = gyrolab.discover(str(t1), gyro="fog")
    model = tmp_path / "model.toml"
    model.write_text(first.model_toml)
    c = cli("discover", "--gyro", "fog", "--data", t1, "--model", model, "--validate", t2,
            "--out", tmp_path / "d")
    # The model as text or as a path: the same.
    same(gyrolab.discover(str(t1), gyro="fog", model=first.model_toml, validate=str(t2)), c)
    same(gyrolab.discover(str(t1), gyro="fog", model=str(model), validate=str(t2)), c)


def test_fit_thermal(cli, runs, tmp_path):
    out = tmp_path / "thermal.toml"
    c = cli("fit", "thermal", "--data", runs / "chamber.csv", "--out", out)
    py = gyrolab.fit_thermal(str(runs / "chamber.csv"))
    same(py, c)
    assert py.coeffs_toml == out.read_text()


def test_fit_scale_factor(cli, runs, tmp_path):
    out = tmp_path / "sf.toml"
    c = cli("fit", "scale-factor", "--data", runs / "sf.csv", "--out", out)
    py = gyrolab.fit_scale_factor(str(runs / "sf.csv"))
    same(py, c)
    assert py.coeffs_toml == out.read_text()


def test_compensate(cli, runs, tmp_path):
    coeffs = tmp_path / "thermal.toml"
    cli("fit", "thermal", "--data", runs / "chamber.csv", "--out", coeffs)
    out = tmp_path / "comp.csv"
    c = cli("compensate", "--coeffs", coeffs, "--data", runs / "chamber.csv", "--out", out)
    py = gyrolab.compensate(str(coeffs), str(runs / "chamber.csv"))
    same(py, c)
    written = pd.read_csv(out, comment="#")
    # The file holds what the run holds, printed to its digits.
    np.testing.assert_allclose(
        py.run["rate_comp_dps"], written["rate_comp_dps"].to_numpy(), rtol=1e-9, atol=1e-12
    )
    # And a model from discover, applied the same way.
    model = tmp_path / "model.toml"
    model.write_text(gyrolab.discover(str(runs / "table.csv"), gyro="fog").model_toml)
    c = cli("compensate", "--coeffs", model, "--data", runs / "table2.csv", "--out",
            tmp_path / "comp2.csv")
    same(gyrolab.compensate(model.read_text(), str(runs / "table2.csv")), c)


def test_lockin(cli, runs):
    path = runs / "fringe.csv"
    c = cli("lockin", "--data", path, "--pulses-per-deg", 2000)
    same(gyrolab.lockin(str(path), pulses_per_deg=2000), c)


def test_simulate_run(cli, runs):
    """The arrays equal the command line's file to the digits it prints."""
    cols = gyrolab.simulate_run(str(runs / "truth.toml"), profile="table", seed=2)
    written = pd.read_csv(runs / "table2.csv", comment="#")
    assert list(written.columns) == list(cols)
    np.testing.assert_array_equal(cols["t_s"], written["t_s"].to_numpy())
    for name in written.columns:
        np.testing.assert_allclose(cols[name], written[name].to_numpy(), rtol=5e-12, atol=1e-4 if name == "temp_c" else 1e-15)


def test_read_run(runs):
    """read_run reads what the file holds (pandas' own reading, exactly)."""
    path = runs / "chamber.csv"
    cols = gyrolab.read_run(str(path))
    df = pd.read_csv(path, comment="#")
    # The run file's own columns (others are kept in the file and ignored).
    assert {"t_s", "rate_dps", "ref_rate_dps", "t_case_c"} <= set(cols)
    for name, values in cols.items():
        np.testing.assert_allclose(values, df[name].to_numpy(dtype=float), rtol=1e-15, err_msg=name)


def qemu_capture():
    return pathlib.Path(__file__).resolve().parents[2] / "runs" / "qemu" / "raw.bin"


def test_decode_frames(cli, tmp_path):
    """The board's bytes as `gyro-lab record --from` decodes them: a QEMU
    run's capture (``cargo xtask qemu`` makes it), whole and damaged."""
    import os

    raw = qemu_capture()
    if not raw.exists():
        if os.environ.get("GYROLAB_REQUIRE_CLI") == "1":
            pytest.fail(f"{raw}: no QEMU capture (cargo xtask test makes one first)")
        pytest.skip(f"{raw}: no QEMU capture (run `cargo xtask qemu`)")
    data = raw.read_bytes()
    rng = np.random.default_rng(7)
    damaged = bytearray(data)
    for i in rng.integers(0, len(damaged), 40):
        damaged[i] ^= 0x5A
    for name, bytes_ in [("whole", data), ("damaged", bytes(damaged))]:
        src = tmp_path / f"{name}.bin"
        src.write_bytes(bytes_)
        c = cli("record", "--from", src, "--out", tmp_path / name)
        py = gyrolab.decode_frames(bytes_)
        summary = json.loads((tmp_path / name / "record.json").read_text())
        # All but where the bytes came from (a file there, memory here).
        d = differences(py["summary"], summary, skip=TIMING | OUTPUT | {"source"})
        assert not d, "\n".join(d[:20])
        for kind in ("fog", "rlg"):
            written = pd.read_csv(tmp_path / name / f"{kind}.csv", comment="#")
            for col in written.columns:
                np.testing.assert_allclose(py[kind][col], written[col].to_numpy(dtype=float),
                                           rtol=1e-9, atol=1e-9, err_msg=f"{name} {kind}.{col}")
        assert c is not None
