"""gyrolab: the gyro lab in Python, over the same code as the ``gyro-lab``
command line.

Each function runs what its command runs and answers with the same JSON
keys, the same text and the same report::

    import gyrolab, pandas as pd
    df = pd.read_csv("chamber.csv", comment="#")
    a = gyrolab.allan(df)                 # the rate's Allan deviation
    a["adev_dph"], a.terms["bias_instability_dph"]
    a                                     # in a notebook: the report
    d = gyrolab.discover(df, gyro="fog")  # what the model misses
    d.found, d.gap_after_dph, d.model_toml

A run is a path to a run file, a dict of 1-D arrays or a pandas DataFrame
with the run file's column names (``t_s``, ``rate_dps``, optional
``ref_rate_dps``, temperatures...); ``columns={"rate_dps": "gyro_z"}`` maps
yours onto them, and ``rate_unit``, ``ref_rate_unit``, ``temp_unit``,
``time_unit``, ``from_s`` and ``to_s`` say what the command line's options
say. A model or a coefficient set is a path or the file's text. Bad input
raises ``ValueError`` with the command line's message, naming the column
and the row. Calls release the GIL; inputs and results pickle, so Dask or
Ray workers can run them (examples/dask_screen.py).
"""

from ._api import (
    allan,
    compensate,
    decode_frames,
    discover,
    fit_scale_factor,
    fit_thermal,
    lockin,
    read_run,
    simulate_run,
)
from ._result import Result

__version__ = "0.1.0"

__all__ = [
    "Result",
    "allan",
    "compensate",
    "decode_frames",
    "discover",
    "fit_scale_factor",
    "fit_thermal",
    "lockin",
    "read_run",
    "simulate_run",
]
