"""The suite's runs, made by the command line (``gyro-lab``), and the
command line itself to compare with.

``GYRO_LAB`` names the command line's binary (``cargo xtask test`` sets
it); else target/release/gyro-lab is used. Where neither exists the
comparisons are skipped, unless ``GYROLAB_REQUIRE_CLI=1`` (as in
``cargo xtask test``), where they fail.
"""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
# The measured records of the workplace (not in the repository: their
# sources carry no licence), used where present.
MEASURED = ROOT.parent / "shared" / "data" / "measured"
HUB = MEASURED / "spike_hub_RB_gyroZ.csv"
# A committed record with a reference made by allantools (lab tests).
WHITE_RW = ROOT / "lab" / "tests" / "data" / "white_rw.csv"

# Keys that differ between two runs of the same code: the clock, and where
# the command line wrote its files.
TIMING = {"read_s", "compute_s", "elapsed_s"}
OUTPUT = {"out", "report"}

TRUTH = """kind = "gyro_model"
version = 1
gyro = "fog"
[[effect]]
name = "scale_factor_knee"
knee_c = 30.0
slope_change_ppm_per_c = 4.0
[[effect]]
name = "warm_up"
amplitude_dph = 0.5
tau_s = 600.0
"""


def lab_binary():
    env = os.environ.get("GYRO_LAB")
    if env:
        return pathlib.Path(env)
    p = ROOT / "target" / "release" / "gyro-lab"
    return p if p.exists() else None


class Cli:
    """``gyro-lab`` with ``--json``: the object on its last line."""

    def __init__(self, binary):
        self.binary = binary

    def __call__(self, *args):
        r = subprocess.run(
            [str(self.binary), *map(str, args), "--json"], capture_output=True, text=True
        )
        assert r.returncode == 0, f"gyro-lab {' '.join(map(str, args))}: {r.stderr}"
        return json.loads(r.stdout.strip().splitlines()[-1])

    def fails(self, *args):
        """The exit code and stderr of a command that must fail."""
        r = subprocess.run([str(self.binary), *map(str, args)], capture_output=True, text=True)
        return r.returncode, r.stderr.strip()


@pytest.fixture(scope="session")
def cli():
    b = lab_binary()
    if b is None or not b.exists():
        msg = f"no gyro-lab binary (GYRO_LAB={os.environ.get('GYRO_LAB')})"
        if os.environ.get("GYROLAB_REQUIRE_CLI") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    return Cli(b)


@pytest.fixture(scope="session")
def runs(tmp_path_factory, cli):
    """The runs every test reads: made once per session by the command
    line's simulators (the same files for both sides of a comparison)."""
    d = tmp_path_factory.mktemp("runs")
    (d / "truth.toml").write_text(TRUTH)
    cli("simulate", "run", "--model", d / "truth.toml", "--profile", "table", "--out", d / "table.csv")
    cli(
        "simulate", "run", "--model", d / "truth.toml", "--profile", "table", "--seed", 2,
        "--out", d / "table2.csv",
    )
    cli("simulate", "chamber", "--out", d / "chamber.csv")
    cli("simulate", "scale-factor", "--out", d / "sf.csv")
    cli("simulate", "lockin", "--out", d / "fringe.csv")
    return d


def differences(a, b, path="", skip=TIMING | OUTPUT):
    """Where two JSON values differ, key by key (exactly: the same code
    gives the same bits), the keys of `skip` left out."""
    out = []
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in skip:
                continue
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only on one side")
            else:
                out += differences(a[k], b[k], f"{path}.{k}", skip)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items against {len(b)}")
        else:
            for i, (x, y) in enumerate(zip(a, b)):
                out += differences(x, y, f"{path}[{i}]", skip)
    elif a != b and not (a != a and b != b):
        out.append(f"{path}: {a!r} against {b!r}")
    return out
