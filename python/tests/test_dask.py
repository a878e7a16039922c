"""The fleet example (examples/dask_screen.py) on a local
dask.distributed cluster of two worker processes: the results equal a
serial loop's, whether the workers read the files or receive the runs."""

import importlib.util
import json
import pathlib
import shutil

import pytest

from conftest import differences

distributed = pytest.importorskip("dask.distributed")

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "dask_screen.py"


def example():
    spec = importlib.util.spec_from_file_location("dask_screen", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def fleet(runs, cli, tmp_path_factory):
    """Six runs of FOGs of one design: two days of the truth, and four more
    seeds of it."""
    d = tmp_path_factory.mktemp("fleet")
    shutil.copy(runs / "table.csv", d / "unit01.csv")
    shutil.copy(runs / "table2.csv", d / "unit02.csv")
    for i, seed in enumerate([11, 12, 13, 14], start=3):
        cli("simulate", "run", "--model", runs / "truth.toml", "--profile", "table",
            "--seed", seed, "--duration-s", 3600, "--out", d / f"unit{i:02}.csv")
    return d


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as c:
        yield c


def comparable(result):
    return json.loads(result.to_json()), result.model_toml


def same_results(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        (jx, mx), (jy, my) = comparable(x), comparable(y)
        d = differences(jx, jy)
        assert not d, "\n".join(d[:20])
        assert mx == my


def test_cluster_equals_serial_loop(fleet, client):
    ex = example()
    paths = [str(p) for p in ex.runs_in(fleet)]
    serial = ex.screen_serial(paths, "fog")
    on_cluster = ex.screen_on(client, paths, "fog")
    same_results(on_cluster, serial)
    # Two workers did the work, not the client.
    assert len(client.scheduler_info()["workers"]) == 2
    for r in serial:
        assert "scale_factor_knee" in [f["effect"] for f in r["found"]]


def test_runs_shipped_to_the_workers(fleet, client):
    """Inputs pickle: the runs read here and sent as columns give what the
    files give."""
    ex = example()
    paths = ex.runs_in(fleet)
    shipped = ex.screen_on(client, ex.load(paths), "fog")
    from_files = ex.screen_serial([str(p) for p in paths], "fog")
    for x, y in zip(shipped, from_files):
        d = differences(json.loads(x.to_json()), json.loads(y.to_json()))
        assert not d, "\n".join(d[:20])


# The module's cluster holds the dashboard's usual port; the example's own
# cluster takes another.
@pytest.mark.filterwarnings("ignore:Port 8787 is already in use")
def test_example_as_a_program(fleet, capsys):
    ex = example()
    assert ex.main([str(fleet), "--gyro", "fog", "--workers", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    paths = ex.runs_in(fleet)
    expected = [ex.row(p.name, r) for p, r in zip(paths, ex.screen_serial([str(p) for p in paths], "fog"))]
    assert lines[-len(expected):] == expected
