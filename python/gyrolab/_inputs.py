"""What users hold, as the native half reads it: a path, or named 1-D
columns. Pandas is used when given, never needed."""

import os
from collections.abc import Mapping

import numpy as np

# The keyword arguments that say how to read a run: the command line's
# --columns, --rate-unit, --ref-rate-unit, --temp-unit, --time-unit,
# --from-s and --to-s.
READ_OPTIONS = (
    "columns",
    "rate_unit",
    "ref_rate_unit",
    "temp_unit",
    "time_unit",
    "from_s",
    "to_s",
)


def read_options(kw):
    """The read options among keyword arguments; anything else is refused."""
    unknown = sorted(set(kw) - set(READ_OPTIONS))
    if unknown:
        raise TypeError(
            "unexpected keyword argument(s) %s; the read options are %s"
            % (", ".join(unknown), ", ".join(READ_OPTIONS))
        )
    return {k: v for k, v in kw.items() if v is not None}


def _is_dataframe(x):
    return hasattr(x, "columns") and hasattr(x, "iloc") and hasattr(x, "index")


def _seconds(values):
    """Datetimes or durations as seconds since the first (a clock's
    timestamps, as the command line reads them)."""
    v = np.asarray(values)
    if v.size == 0:
        return v.astype("float64")
    if np.issubdtype(v.dtype, np.datetime64):
        d = v - v[0]
    else:
        d = v
    return d.astype("timedelta64[ns]").astype("int64") / 1e9


def _column(values):
    """One column as a numpy array: as it is where numpy allows (no copy),
    pandas' nullable numbers with NaN for missing values, times in
    seconds."""
    dtype = getattr(values, "dtype", None)
    if dtype is not None and not isinstance(dtype, np.dtype):
        # A pandas extension dtype (Float64, Int64): NaN where missing, so
        # the lab names the row.
        try:
            return values.to_numpy(dtype="float64", na_value=np.nan)
        except (TypeError, ValueError):
            return np.asarray(values, dtype=object)
    a = values.to_numpy() if hasattr(values, "to_numpy") else np.asarray(values)
    if np.issubdtype(a.dtype, np.datetime64) or np.issubdtype(a.dtype, np.timedelta64):
        return _seconds(a)
    return a


def run_input(run, label="run", time_name="t_s"):
    """A path (str or os.PathLike), or a list of (name, array) pairs; a
    DataFrame's datetime or timedelta index is its time where it has no
    time column."""
    if isinstance(run, (str, os.PathLike)):
        return os.fspath(run)
    if _is_dataframe(run):
        pairs = [(str(c), _column(run[c])) for c in run.columns]
        names = {p[0] for p in pairs}
        index = run.index
        if time_name not in names and (
            np.issubdtype(index.dtype, np.datetime64)
            or np.issubdtype(index.dtype, np.timedelta64)
        ):
            pairs.insert(0, (time_name, _seconds(index.to_numpy())))
        return pairs
    if isinstance(run, Mapping):
        return [(str(k), _column(v)) for k, v in run.items()]
    raise TypeError(
        "%s: a path, a dict of 1-D arrays or a pandas DataFrame, not %s"
        % (label, type(run).__name__)
    )


def time_name(kw):
    """The caller's name of the time column (through `columns`)."""
    return (kw.get("columns") or {}).get("t_s", "t_s")


def text_input(x, what):
    """A model or a coefficient set: (its text, what errors call it). A
    path is read; text (anything with a line break or a `=`) is taken as
    it is."""
    if isinstance(x, os.PathLike) or (
        isinstance(x, str) and "\n" not in x and "=" not in x
    ):
        path = os.fspath(x)
        try:
            with open(path, encoding="utf-8") as f:
                return f.read(), path
        except OSError as e:
            raise ValueError("%s: cannot read: %s" % (path, e.strerror or e)) from None
    if isinstance(x, str):
        return x, what
    raise TypeError("%s: a path or the file's text, not %s" % (what, type(x).__name__))
