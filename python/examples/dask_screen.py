"""Screen a folder of runs for what their gyro model misses, on a Dask
cluster: one ``gyrolab.discover`` per run, each on a worker.

    python dask_screen.py RUNS/ --gyro fog                  # a local cluster
    python dask_screen.py RUNS/ --gyro fog --workers 8
    python dask_screen.py RUNS/ --gyro fog --scheduler tcp://head:8786

The same code scales from a laptop to many machines: start a scheduler
(``dask scheduler``) and a worker on each machine (``dask worker
tcp://head:8786``) with ``pip install ./python`` done there too, and pass
``--scheduler``. The runs' paths must then be readable on every worker (a
shared folder); otherwise ``--ship`` reads each run here and sends its
columns (inputs and results pickle).
"""

import argparse
import pathlib
import sys

import gyrolab


def screen(run, gyro, model=None):
    """What one run's model misses: discover's result (it pickles back to
    the client whole: JSON keys, model file, report)."""
    return gyrolab.discover(run, gyro=gyro, model=model)


def row(name, result):
    """One line of the screen's table."""
    found = ", ".join(f["effect"] for f in result["found"]) or "-"
    missing = "unexplained" if result["unexplained"] else "nothing missing"
    return (
        f"{name:<28} gap {result['gap_before_dph']:10.4f} -> {result['gap_after_dph']:8.4f} deg/h"
        f" (floor {result['noise_floor_dph']:.4f})  {missing:<15} found: {found}"
    )


def runs_in(folder):
    """The run files of a folder, in name order."""
    paths = sorted(pathlib.Path(folder).glob("*.csv"))
    if not paths:
        raise SystemExit(f"{folder}: no run files (*.csv)")
    return paths


def load(paths):
    """The runs read here, as the columns a worker receives (--ship)."""
    return [gyrolab.read_run(str(p)) for p in paths]


def screen_serial(runs, gyro, model=None):
    """The plain loop: the reference the cluster must equal."""
    return [screen(r, gyro, model) for r in runs]


def screen_on(client, runs, gyro, model=None):
    """The same screen, one task per run on the cluster's workers."""
    futures = client.map(screen, runs, gyro=gyro, model=model, pure=False)
    return client.gather(futures)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("folder", help="a folder of run files (*.csv)")
    p.add_argument("--gyro", required=True, choices=["fog", "rlg", "mems"])
    p.add_argument("--model", help="the units' model file (else the ideal gyro)")
    p.add_argument("--scheduler", help="a running cluster's scheduler address")
    p.add_argument("--workers", type=int, default=2, help="local cluster's workers")
    p.add_argument("--ship", action="store_true", help="read runs here, send columns")
    a = p.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    paths = runs_in(a.folder)
    runs = load(paths) if a.ship else [str(x) for x in paths]
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        client = Client(LocalCluster(n_workers=a.workers, threads_per_worker=1))
    with client:
        results = screen_on(client, runs, a.gyro, a.model)
    for path, r in zip(paths, results):
        print(row(path.name, r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
