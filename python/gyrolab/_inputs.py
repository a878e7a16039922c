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


def _naive_datetimes(values):
    """A pandas column or index of time-zone-aware datetimes as naive UTC
    (numpy has no time zones); others as they are."""
    if getattr(getattr(values, "dtype", None), "tz", None) is None:
        return values
    if hasattr(values, "dt"):
        return values.dt.tz_convert("UTC").dt.tz_localize(None)
    return values.tz_convert("UTC").tz_localize(None)


def _is_time(a):
    return np.issubdtype(a.dtype, np.datetime64) or np.issubdtype(a.dtype, np.timedelta64)


def _column(values, is_time=False):
    """One column as a numpy array: as it is where numpy allows (no copy),
    pandas' nullable numbers with NaN for missing values, datetimes (time
    zones included) in seconds since the first; the time column's text
    timestamps (`2026-03-01 14:02:07.125`) parsed as the command line
    parses them."""
    values = _naive_datetimes(values)
    dtype = getattr(values, "dtype", None)
    if dtype is not None and not isinstance(dtype, np.dtype):
        # A pandas extension dtype (Float64, Int64): NaN where missing, so
        # the lab names the row.
        try:
            return values.to_numpy(dtype="float64", na_value=np.nan)
        except (TypeError, ValueError):
            values = np.asarray(values, dtype=object)
    a = values.to_numpy() if hasattr(values, "to_numpy") else np.asarray(values)
    if is_time and a.dtype.kind in "OU" and a.size:
        try:
            a = np.asarray(a, dtype="datetime64[ns]")
        except (TypeError, ValueError):
            pass
    if _is_time(a):
        return _seconds(a)
    return a


# The run file's and the fringe file's own columns (docs/interfaces.md).
RUN_COLUMNS = {
    "t_s",
    "ref_rate_dps",
    "rate_dps",
    "temp_c",
    "t_mono_a_c",
    "t_mono_b_c",
    "t_case_c",
    "ref_acc_dps2",
    "angle_deg",
    "signal",
    "signal_q",
}


def _pairs(items, time_name, wanted):
    """(name, array) pairs of the columns a command may read. Other
    columns that do not hold numbers (a unit's serial, a comment) are
    left out, as the command line ignores a file's other columns; a
    column the command may read is kept whatever it holds, so its error
    names it."""
    keep = RUN_COLUMNS | {time_name} | set(wanted)
    out = []
    for name, values in items:
        name = str(name)
        a = _column(values, is_time=name == time_name)
        if name not in keep and a.dtype.kind not in "biuf":
            continue
        out.append((name, a))
    return out


def run_input(run, label="run", time_name="t_s", wanted=()):
    """A path (str or os.PathLike), or a list of (name, array) pairs; a
    DataFrame's datetime or timedelta index is its time where it has no
    time column. `wanted`: the user's names of columns the command reads
    beyond the run file's own (through `columns`, or allan's `column`)."""
    if isinstance(run, (str, os.PathLike)):
        return os.fspath(run)
    if _is_dataframe(run):
        pairs = _pairs(((c, run[c]) for c in run.columns), time_name, wanted)
        names = {p[0] for p in pairs}
        index = _naive_datetimes(run.index)
        if time_name not in names and isinstance(index.dtype, np.dtype) and _is_time(index):
            pairs.insert(0, (time_name, _seconds(index.to_numpy())))
        return pairs
    if isinstance(run, Mapping):
        return _pairs(run.items(), time_name, wanted)
    raise TypeError(
        "%s: a path, a dict of 1-D arrays or a pandas DataFrame, not %s"
        % (label, type(run).__name__)
    )


def time_name(kw):
    """The caller's name of the time column (through `columns`)."""
    return (kw.get("columns") or {}).get("t_s", "t_s")


def mapped(kw):
    """The caller's names that `columns` maps onto the run file's."""
    return tuple(str(v) for v in (kw.get("columns") or {}).values())


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
