"""The commands. Each takes what a notebook holds, runs the command line's
code through the native half (gyrolab._native) and answers as it does."""

from . import _native
from ._inputs import mapped, read_options, run_input, text_input, time_name
from ._result import Result


def _run(run, kw, label="run", also=()):
    opts = read_options(kw)
    return run_input(run, label, time_name(opts), mapped(opts) + tuple(also)), opts


def read_run(run, **read):
    """A run's columns by name (``t_s``, ``rate_dps``, ``ref_rate_dps``
    where it has one, the temperatures...), read and checked as every
    command reads them: units converted, the stretch cut, every value a
    finite number in its physical range."""
    src, opts = _run(run, read)
    return dict(_native.read_run(src, "run", opts))


def allan(run, *, column="rate_dps", **read):
    """``gyro-lab allan``: overlapping Allan deviation of a rate column
    (less ``ref_rate_dps`` where the run has one), IEEE 952 terms with 95 %
    intervals, the fit checked, the readings off the curve."""
    src, opts = _run(run, read, also=(column,))
    return Result("allan", _native.allan(src, "run", column, opts))


def discover(run, *, gyro, model=None, grade=None, validate=None, **read):
    """``gyro-lab discover``: what the model (the ideal gyro without one)
    misses on this run, named, added and the gap shown to shrink.
    ``model_toml`` is the model file written; ``residual`` the residual
    before and after (deg/s); ``validate`` another run of the same gyro the
    model written must predict."""
    src, opts = _run(run, read)
    m = text_input(model, "model") if model is not None else None
    v = run_input(validate, "validate", time_name(opts), mapped(opts)) if validate is not None else None
    native, toml, residual = _native.discover(src, "run", gyro, m, grade, v, opts)
    return Result("discover", native, {"model_toml": toml, "residual": dict(residual)})


def fit_thermal(run, **read):
    """``gyro-lab fit thermal``: the RLG thermal bias model on a chamber
    run; ``coeffs_toml`` is the coefficient file the firmware loads."""
    src, opts = _run(run, read)
    native, toml = _native.fit_thermal(src, "run", opts)
    return Result("fit_thermal", native, {"coeffs_toml": toml})


def fit_scale_factor(run, **read):
    """``gyro-lab fit scale-factor``: the FOG scale factor over
    temperature, knees by BIC; ``coeffs_toml`` is the table the firmware
    loads."""
    src, opts = _run(run, read)
    native, toml = _native.fit_scale_factor(src, "run", opts)
    return Result("fit_scale_factor", native, {"coeffs_toml": toml})


def compensate(coeffs, run, *, cubic_from=None, **read):
    """``gyro-lab compensate``: a coefficient set (a fit's, or a model from
    ``discover``) applied to a run as the firmware applies it; ``run`` is
    the run as read with ``rate_comp_dps`` added."""
    src, opts = _run(run, read)
    c = text_input(coeffs, "coeffs")
    cubic = run_input(cubic_from, "cubic_from", time_name(opts), mapped(opts)) if cubic_from is not None else None
    native, cols = _native.compensate(c, src, "run", opts, cubic)
    return Result("compensate", native, {"run": dict(cols)})


def lockin(fringe, *, pulses_per_deg, input_rate_dps=None, **read):
    """``gyro-lab lockin``: the RLG lock-in rate of a fringe record
    (``t_s``, ``signal``, optional ``signal_q``) by the exact harmonic
    relation."""
    src, opts = _run(fringe, read, "fringe")
    return Result(
        "lockin", _native.lockin(src, "fringe", float(pulses_per_deg), input_rate_dps, opts)
    )


def simulate_run(
    model,
    *,
    profile,
    duration_s=None,
    dt_s=None,
    seed=None,
    arw_dpsh=None,
    bias_instability_dph=None,
    rate_random_walk_dphsh=None,
):
    """``gyro-lab simulate run``: a gyro model on a test profile (table,
    constant-rate, chamber, lockin, vibration, constant-vibration,
    fog-chamber) with the project's noise; the run's columns by name."""
    m = text_input(model, "model")
    cols = _native.simulate_run(
        m,
        profile,
        duration_s,
        dt_s,
        1 if seed is None else int(seed),
        arw_dpsh,
        bias_instability_dph,
        rate_random_walk_dphsh,
    )
    return dict(cols)


def decode_frames(data, *, rlg_counts_per_deg=None):
    """The board's frames from a capture's bytes (a ``raw.bin``, or what a
    serial port gave), as ``gyro-lab record --from`` decodes them: a dict
    with ``fog`` and ``rlg`` (each the run file's columns by name) and
    ``summary`` (``record.json``'s keys: frames, CRC errors, lost frames,
    faults...)."""
    import json

    if isinstance(data, (bytearray, memoryview)):
        data = bytes(data)
    if not isinstance(data, bytes):
        raise TypeError("data: the capture's bytes, not %s" % type(data).__name__)
    fog, rlg, summary = _native.decode_frames(data, "data", rlg_counts_per_deg)
    return {"fog": dict(fog), "rlg": dict(rlg), "summary": json.loads(summary)}
