#!/usr/bin/env python3
"""A new user's mistakes with their own data files, run through `gyro-lab` (issue 38).

Builds simulated runs with the binary (plus the measured MEMS hub record), derives from
them the files and command lines a person gets wrong (units, column names, dialects,
timestamps, bad cells, `--out` over inputs and other kinds, stretches, a reversed axis),
runs each case, and judges it against an expectation written from a gyro engineer's view:
a refusal in one line `file:line:column: message` (exit 2), or a result with the right
numbers and the warning a person needs. Every case also checks: no panic, a one-line
error, no input or other existing file changed, no stray `.*.tmp` left behind.
Cases whose right outcome is debatable are marked "judge" (the preferred outcome is
stated). Writes a markdown table to --out, prints a one-line summary, exits 0.

    python3 scripts/user-mistakes.py --lab target/release/gyro-lab --work /tmp/mistakes --out /tmp/mistakes.md
"""
import argparse
import hashlib
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
import types

import numpy as np
import pandas as pd

HUB = "/work/shared/data/measured/spike_hub_RB_gyroZ.csv"
RAD = 180.0 / np.pi  # deg per rad
# how a unit factor may be printed: 57.2958 / 57.3 / 0.01745, 3600 / 2.78e-4, 273.15
F_RAD, F_DPH, F_K = r"57\.[23]|0\.017[45]", r"3600|2\.77|2\.78|0\.000277|0\.000278", r"273"

# ----------------------------------------------------------------------------- expectations


class Expect:
    """An expectation: a description for the report and a test of the run's result."""

    def __init__(self, desc, test):
        self.desc, self.test = desc, test

    def __call__(self, r):
        try:
            return bool(self.test(r))
        except (KeyError, IndexError, TypeError, ValueError):
            return False


def get(d, path):
    """`a.b.0.c` into nested dicts and lists."""
    for k in path.split("."):
        d = d[int(k)] if isinstance(d, list) else d[k]
    return d


def fails(*patterns, line=None, file=None):
    """Exit 2; each regex in `patterns` found in the message (the paths given on the command line
    taken out, so a file name cannot match); at `file:line:col` if given; naming `file` if given."""
    desc = "exit 2" + (f" at `file:{line}:col`" if line else "") + (f", names the file {file}" if file else "")
    desc += ", says " + " and ".join(f"`{p}`" for p in patterns) if patterns else ""

    def test(r):
        msg = r.err
        for path in r.paths:
            msg = msg.replace(path, "")
        ok = r.rc == 2 and all(re.search(p, msg, re.I) for p in patterns)
        ok = ok and (file is None or file in r.err)
        return ok and (line is None or re.search(rf"\S+:{line}:\d+\b", r.err) is not None)
    return Expect(desc, test)


def succeeds(*checks):
    """Exit 0 with JSON, and each (desc, test(json)) check holds."""
    desc = "exit 0" + "".join(", " + c[0] for c in checks)
    return Expect(desc, lambda r: r.rc == 0 and r.json is not None
                  and all(c[1](r.json) for c in checks))


def either(a, b):
    return Expect(f"({a.desc}) or ({b.desc})", lambda r: a(r) or b(r))


def codes(j):
    return [w.get("code") or w.get("kind") for w in j.get("warnings") or []]


def warn(code, pattern=None):
    desc = f"warning `{code}`" + (f" mentioning `{pattern}`" if pattern else "")

    def test(j):
        return any((w.get("code") or w.get("kind")) == code
                   and (pattern is None or re.search(pattern, w.get("message", ""), re.I))
                   for w in j.get("warnings") or [])
    return desc, test


def any_warn(pattern):
    """Some warning (any code) whose code or message matches `pattern`."""
    return (f"a warning mentioning `{pattern}`",
            lambda j: any(re.search(pattern, (w.get("code") or "") + " " + w.get("message", ""), re.I)
                          for w in j.get("warnings") or []))


def no_warn(code):
    return f"no `{code}` warning", lambda j: code not in codes(j)


BASE = {}  # control case key -> its JSON


def near(path, ref, rel=0.02, absolute=None):
    """Value at `path` close to a number or to the same path in control case `ref`'s JSON."""
    what = f"{ref}" if not isinstance(ref, str) else f"the correct file's ({ref})"
    tol = f"+-{absolute}" if absolute is not None else f"within {rel * 100:g} %"
    desc = f"`{path}` {tol} of {what}"

    def test(j):
        want = get(BASE[ref], path) if isinstance(ref, str) else ref
        got = get(j, path)
        return abs(got - want) <= (absolute if absolute is not None else rel * abs(want))
    return desc, test


# ----------------------------------------------------------------------------- inputs


def lab(labbin, cwd, *args):
    p = subprocess.run([labbin, *args], cwd=cwd, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit(f"setup failed: gyro-lab {' '.join(args)}: {p.stderr.strip()}")


def write(df, path, **kw):
    df.to_csv(path, index=False, **kw)


def edit_line(src, dst, lineno, fn):
    """Copy src to dst with physical line `lineno` (1-based) replaced by fn(cells)."""
    lines = open(src, newline="").read().split("\n")
    cells = lines[lineno - 1].split(",")
    lines[lineno - 1] = ",".join(fn(cells))
    open(dst, "w", newline="").write("\n".join(lines))


def build_inputs(labbin, w):
    """Every input file, in w/in/. Returns nothing; the cases name them."""
    d = os.path.join(w, "in")
    os.makedirs(d)
    sims = [("chamber", "--profile", "soak", "--soak-c", "20", "--duration-s", "20000", "--out", "rest.csv"),
            ("chamber", "--profile", "cycle", "--out", "cycle.csv"),
            ("scale-factor", "--out", "sf.csv"),
            ("lockin", "--rate-dps", "1", "--lock-in-dps", "0.05", "--noise", "0.01", "--out", "fringe.csv")]
    for s in sims:
        lab(labbin, d, "simulate", *s)
    shutil.copy(HUB, os.path.join(d, "hub.csv"))
    p = lambda n: os.path.join(d, n)  # noqa: E731
    rest, cycle, sf, fringe, hub = (pd.read_csv(p(n), comment="#") for n in ("rest.csv", "cycle.csv", "sf.csv", "fringe.csv", "hub.csv"))
    temps = lambda df: [c for c in df.columns if c.endswith("_c")]  # noqa: E731

    def variant(df, name, **cols):
        v = df.copy()
        for c, f in cols.items():
            v[c] = f(v[c])
        write(v, p(name))

    to_rad, to_dph = (lambda x: x / RAD), (lambda x: x * 3600.0)
    # rates in rad/s and deg/h: rate only, both, reference only
    variant(rest, "rest_rate_rads.csv", rate_dps=to_rad)
    variant(rest, "rest_rate_dph.csv", rate_dps=to_dph)
    variant(rest, "rest_both_dph.csv", rate_dps=to_dph, ref_rate_dps=to_dph)
    variant(sf, "sf_rate_rads.csv", rate_dps=to_rad)
    variant(sf, "sf_both_rads.csv", rate_dps=to_rad, ref_rate_dps=to_rad)
    variant(sf, "sf_ref_rads.csv", ref_rate_dps=to_rad)
    variant(sf, "sf_rate_dph.csv", rate_dps=to_dph)
    variant(sf, "sf_ref_dph.csv", ref_rate_dps=to_dph)
    variant(cycle, "cycle_rate_dph.csv", rate_dps=to_dph)
    variant(hub, "hub_rads.csv", rate_dps=to_rad)
    variant(sf, "sf_reversed.csv", rate_dps=lambda x: -x)
    # temperatures in kelvin and in Fahrenheit
    variant(cycle, "cycle_K.csv", **{c: (lambda x: x + 273.15) for c in temps(cycle)})
    variant(sf, "sf_K.csv", **{c: (lambda x: x + 273.15) for c in temps(sf)})
    variant(hub, "hub_K.csv", temp_c=lambda x: x + 273.15)
    variant(sf, "sf_F.csv", **{c: (lambda x: x * 1.8 + 32) for c in temps(sf)})
    variant(hub, "hub_F.csv", temp_c=lambda x: x * 1.8 + 32)
    # time in ms (column still called t_s)
    variant(rest, "rest_ms.csv", t_s=lambda x: x * 1000.0)
    variant(cycle, "cycle_ms.csv", t_s=lambda x: x * 1000.0)
    variant(fringe, "fringe_ms.csv", t_s=lambda x: x * 1000.0)
    # other column names, clock timestamps
    write(hub.rename(columns={"t_s": "time", "rate_dps": "gyro_z", "temp_c": "temp"}), p("hub_names.csv"))
    stamps = (pd.Timestamp("2026-03-01 14:00:00") + pd.to_timedelta(hub.t_s, unit="s")).dt.strftime(
        "%Y-%m-%d %H:%M:%S.%f").str[:-3]
    write(hub.assign(t_s=stamps).rename(columns={"t_s": "Timestamp", "rate_dps": "gyro_z", "temp_c": "temp"}),
          p("hub_stamp.csv"))
    write(hub.assign(t_s=stamps), p("hub_iso.csv"))
    write(fringe.rename(columns={"t_s": "time", "signal": "photodiode"}), p("fringe_names.csv"))
    # dialects
    write(hub, p("hub_semicolon.csv"), sep=";", decimal=",")
    write(hub, p("hub_tab.csv"), sep="\t", decimal=",")
    write(cycle, p("cycle_semicolon.csv"), sep=";", decimal=",")
    text = open(p("hub.csv")).read()
    open(p("hub_bom.csv"), "w", encoding="utf-8").write("\ufeff# exported from the hub logger\n" + text)
    open(p("hub_crlf.csv"), "w", newline="").write(text.replace("\n", "\r\n"))
    lines = text.rstrip("\n").split("\n")
    lines[0] = ",".join(f'"{c}"' for c in lines[0].split(","))
    open(p("hub_quoted.csv"), "w").write("\n".join(lines) + "\n")
    lines = text.rstrip("\n").split("\n")
    open(p("hub_blank.csv"), "w").write("\n".join(lines[:1] + [""] + lines[1:100] + ["", ""] + lines[100:]) + "\n\n\n")
    # missing columns, no reference
    write(sf.drop(columns=["rate_dps", "temp_c"]), p("sf_missing2.csv"))
    write(cycle.drop(columns=["t_mono_b_c", "t_case_c"]), p("cycle_missing2.csv"))
    write(hub.drop(columns=["ref_rate_dps"]), p("hub_noref.csv"))
    write(rest.drop(columns=["ref_rate_dps"]), p("rest_noref.csv"))
    write(sf.drop(columns=["ref_rate_dps"]), p("sf_noref.csv"))
    # PC-stamped timestamps: +-1 % of the period
    rng = np.random.default_rng(38)
    write(rest.assign(t_s=rest.t_s + rng.uniform(-0.01, 0.01, len(rest)) * 1.0), p("rest_jitter.csv"))
    dt = float(np.median(np.diff(fringe.t_s)))
    write(fringe.assign(t_s=fringe.t_s + rng.uniform(-0.01, 0.01, len(fringe)) * dt), p("fringe_jitter.csv"))
    # bad cells (hub: header on line 1, data from line 2; columns t_s,rate_dps,temp_c,ref_rate_dps)
    edit_line(p("hub.csv"), p("hub_nan.csv"), 101, lambda c: [c[0], "NaN", *c[2:]])
    edit_line(p("hub.csv"), p("hub_empty_cell.csv"), 151, lambda c: [c[0], "", *c[2:]])
    edit_line(p("hub.csv"), p("hub_text.csv"), 201, lambda c: [c[0], c[1], "ERR", c[3]])
    edit_line(p("hub.csv"), p("hub_short_row.csv"), 251, lambda c: c[:3])
    edit_line(p("hub.csv"), p("hub_backwards.csv"), 121, lambda c: [str(float(c[0]) - 30), *c[1:]])
    open(p("empty.csv"), "w").close()
    open(p("header_only.csv"), "w").write(lines[0] + "\n")
    open(p("fringe_header_only.csv"), "w").write("t_s,signal\n")


# ----------------------------------------------------------------------------- cases

C = []  # (key, mistake, argv, expectation, sure, setup, allowed_changes)


def case(key, mistake, argv, expect, sure=True, setup=None, allow=()):
    """One case; `{o}` in argv is its own output folder out/<key>; every command gets --json."""
    C.append(dict(key=key, mistake=mistake, argv=(argv.replace("{o}", f"out/{key}") + " --json").split(),
                  expect=expect, sure=sure, setup=setup, allow=allow))


def copy_to(src, dst):
    return lambda P: shutil.copy(P(src), P(dst))


def planted_th(P):
    """An older coefficient file (bias0 1.0) where --force must put the new one."""
    text = re.sub(r"(?m)^bias0_dph = .*$", "bias0_dph = 1.0", open(P("out/ctl-thermal/th.toml")).read())
    open(P("{o}/th.toml"), "w").write(text)


def make_dir_with(path, name):
    def f(P):
        os.makedirs(P(path), exist_ok=True)
        open(os.path.join(P(path), name), "w").write("a colleague's notes\n")
    return f


def define_cases():
    ok_units = [no_warn("unit")]
    mems = "discover --gyro mems --data in/"
    # --- controls: the correct files (also the baselines of the comparisons below)
    case("ctl-allan", "control: static RLG soak", "allan --data in/rest.csv --out {o}", succeeds(*ok_units, warn("warm_up")))
    case("ctl-thermal", "control: RLG chamber cycle", "fit thermal --data in/cycle.csv --out {o}/th.toml", succeeds(*ok_units))
    case("ctl-sf", "control: FOG continuous-rotation run", "fit scale-factor --data in/sf.csv --out {o}/sf.toml",
         succeeds(*ok_units, near("knees_c.0", 48.0, absolute=0.5)))
    case("ctl-disc-hub", "control: measured MEMS hub", mems + "hub.csv --out {o}", succeeds(*ok_units))
    case("ctl-disc-rlg", "control: RLG chamber cycle", "discover --gyro rlg --data in/cycle.csv --out {o}", succeeds(*ok_units))
    case("ctl-disc-fog", "control: FOG rotation run", "discover --gyro fog --data in/sf.csv --out {o}",
         succeeds(*ok_units, ("knee found", lambda j: "scale_factor_knee" in [f["effect"] for f in j["found"]])))
    case("ctl-lockin", "control: RLG fringe record", "lockin --data in/fringe.csv --pulses-per-deg 2000",
         succeeds(near("lock_in_dps", 0.05, 0.05), no_warn("jitter")))
    for key, coeffs, data in [("ctl-comp", "ctl-thermal/th.toml", "cycle"), ("ctl-comp-sf", "ctl-sf/sf.toml", "sf"),
                              ("ctl-comp-model", "ctl-disc-hub/model.toml", "hub")]:
        case(key, f"control: {coeffs} on its own run",
             f"compensate --coeffs out/{coeffs} --data in/{data}.csv --out {{o}}/comp.csv", succeeds(*ok_units))
    case("nonstat-allan-hub", "noise analysis of a heating record (26 -> 65 degC)", "allan --data in/hub.csv",
         succeeds(("warning `non_stationary` or `warm_up`", lambda j: {"non_stationary", "warm_up"} & set(codes(j)))))
    case("nonstat-allan-sf", "noise analysis of a rate-table run", "allan --data in/sf.csv",
         succeeds(any_warn("not_static|non_stationary")))

    # --- rate units
    unit_rad = either(succeeds(warn("unit", F_RAD)), fails("rad/s|--rate-unit|--ref-rate-unit"))
    unit_dph = either(succeeds(warn("unit", F_DPH)), fails("deg/h|--rate-unit|--ref-rate-unit"))
    fitsf = "fit scale-factor --data in/"
    case("rate-rads-allan", "rate in rad/s, reference in deg/s (static)", "allan --data in/rest_rate_rads.csv", unit_rad)
    case("rate-rads-sf", "rate in rad/s, reference in deg/s (rate table)", fitsf + "sf_rate_rads.csv --out {o}/sf.toml", unit_rad)
    case("rate-rads-disc", "rate in rad/s, reference in deg/s", "discover --gyro fog --data in/sf_rate_rads.csv --out {o}", unit_rad)
    case("rate-rads-comp", "compensating a rad/s run with a deg/s table",
         "compensate --coeffs out/ctl-sf/sf.toml --data in/sf_rate_rads.csv --out {o}/comp.csv", unit_rad)
    case("both-rads-sf", "rate and reference both in rad/s (slope 1; table at 0.87 'deg/s')",
         fitsf + "sf_both_rads.csv --out {o}/sf.toml", unit_rad, sure=False)
    case("both-rads-disc", "rate and reference both in rad/s", "discover --gyro fog --data in/sf_both_rads.csv --out {o}",
         unit_rad, sure=False)
    case("ref-rads-sf", "reference in rad/s, rate in deg/s", fitsf + "sf_ref_rads.csv --out {o}/sf.toml", unit_rad)
    case("rate-rads-ok", "rad/s rate declared, reference in deg/s declared",
         fitsf + "sf_rate_rads.csv --rate-unit rad/s --ref-rate-unit deg/s --out {o}/sf.toml",
         succeeds(near("knees_c.0", "ctl-sf", absolute=0.3), near("residual_ppm", "ctl-sf", 0.05)))
    case("hub-rads", "MEMS rate in rad/s, reference 0 (static)", mems + "hub_rads.csv --out {o}", unit_rad, sure=False)
    case("hub-rads-ok", "MEMS rate in rad/s, declared", mems + "hub_rads.csv --rate-unit rad/s --out {o}",
         succeeds(near("gap_before_dph", "ctl-disc-hub", 0.01), near("gap_after_dph", "ctl-disc-hub", 0.02)))
    case("rate-dph-allan", "rate in deg/h, reference in deg/s (static)", "allan --data in/rest_rate_dph.csv", unit_dph)
    case("both-dph-allan", "rate and reference both in deg/h (static: the Earth rate reads 11 'deg/s')",
         "allan --data in/rest_both_dph.csv", unit_dph, sure=False)
    case("rate-dph-sf", "rate in deg/h, reference in deg/s", fitsf + "sf_rate_dph.csv --out {o}/sf.toml", unit_dph)
    case("ref-dph-sf", "reference in deg/h, rate in deg/s", fitsf + "sf_ref_dph.csv --out {o}/sf.toml", unit_dph)
    case("rate-dph-thermal", "RLG rate in deg/h, reference in deg/s",
         "fit thermal --data in/cycle_rate_dph.csv --out {o}/th.toml", unit_dph)
    case("rate-dph-thermal-ok", "RLG rate in deg/h, declared",
         "fit thermal --data in/cycle_rate_dph.csv --rate-unit deg/h --ref-rate-unit deg/s --out {o}/th.toml",
         succeeds(near("coefficients.k1_dph_per_c", "ctl-thermal", 0.02)))
    case("wrong-ref-unit", "--ref-rate-unit rad/s on a deg/s file", fitsf + "sf.csv --ref-rate-unit rad/s --out {o}/sf.toml",
         unit_rad)
    case("wrong-rate-unit", "--rate-unit rad/s --ref-rate-unit deg/s on a deg/s file",
         fitsf + "sf.csv --rate-unit rad/s --ref-rate-unit deg/s --out {o}/sf.toml", unit_rad)
    sign = either(succeeds(any_warn("sign|revers|invert|-1\\.0")), fails("sign|revers|invert"))
    case("reversed-sf", "axis sign reversed on the rate table (slope -1)", fitsf + "sf_reversed.csv --out {o}/sf.toml", sign)
    case("reversed-disc", "axis sign reversed on the rate table", "discover --gyro fog --data in/sf_reversed.csv --out {o}", sign)
    case("reversed-comp", "compensating a sign-reversed run",
         "compensate --coeffs out/ctl-sf/sf.toml --data in/sf_reversed.csv --out {o}/comp.csv", sign)

    # --- temperature units
    kel = either(succeeds(warn("unit", F_K + "|kelvin")), fails("kelvin|--temp-unit"))
    case("K-thermal", "temperatures in kelvin", "fit thermal --data in/cycle_K.csv --out {o}/th.toml", kel)
    case("K-thermal-ok", "temperatures in kelvin, declared", "fit thermal --data in/cycle_K.csv --temp-unit K --out {o}/th.toml",
         succeeds(near("coefficients.k1_dph_per_c", "ctl-thermal", 0.02)))
    case("K-sf", "coil temperature in kelvin", fitsf + "sf_K.csv --out {o}/sf.toml", kel)
    case("K-disc", "MEMS temperature in kelvin", mems + "hub_K.csv --out {o}", kel)
    case("K-comp", "compensating a kelvin run with degC coefficients",
         "compensate --coeffs out/ctl-thermal/th.toml --data in/cycle_K.csv --out {o}/comp.csv", kel)
    fahr = either(succeeds(any_warn("fahrenheit|unit|range")), fails("fahrenheit|temp"))
    case("F-sf", "coil temperature in Fahrenheit (-40..140)", fitsf + "sf_F.csv --out {o}/sf.toml", fahr, sure=False)
    case("F-disc", "MEMS temperature in Fahrenheit (79..149)", mems + "hub_F.csv --out {o}", fahr, sure=False)
    case("K-given-on-C-thermal", "--temp-unit K on a degC file (-40 K is impossible)",
         "fit thermal --data in/cycle.csv --temp-unit K --out {o}/th.toml", fails("kelvin|absolute|below 0|negative|--temp-unit"))
    case("K-given-on-C-disc", "--temp-unit K on a degC file (26..65 K: cryogenic)", mems + "hub.csv --temp-unit K --out {o}",
         either(succeeds(warn("unit", "kelvin|273")), fails("kelvin|--temp-unit")))

    # --- time units
    ms = either(succeeds(any_warn("\\bms\\b|millisec|1000")), fails("\\bms\\b|millisec|--time-unit"))
    case("ms-allan", "time in ms in a t_s column (1000 's' period)", "allan --data in/rest_ms.csv", ms, sure=False)
    case("ms-allan-ok", "time in ms, declared", "allan --data in/rest_ms.csv --time-unit ms",
         succeeds(near("sampling.period_s", 1.0, 0.001), near("terms.angle_random_walk_dpsh.value", "ctl-allan", 0.02)))
    case("ms-thermal", "time in ms in a t_s column", "fit thermal --data in/cycle_ms.csv --out {o}/th.toml", ms, sure=False)
    case("ms-lockin", "fringe time in ms (the beat reads 2 Hz)", "lockin --data in/fringe_ms.csv --pulses-per-deg 2000",
         ms, sure=False)
    case("ms-lockin-ok", "fringe time in ms, declared", "lockin --data in/fringe_ms.csv --time-unit ms --pulses-per-deg 2000",
         succeeds(near("lock_in_dps", "ctl-lockin", 0.01)))

    # --- column names, timestamps
    same_gap = [near("gap_before_dph", "ctl-disc-hub", 0.01), near("gap_after_dph", "ctl-disc-hub", 0.02)]
    case("names-bare", "columns time,gyro_z,temp without --columns", mems + "hub_names.csv --out {o}",
         fails("t_s|rate_dps", "--columns"))
    case("names-mapped", "columns time,gyro_z,temp with --columns",
         mems + "hub_names.csv --columns t_s=time,rate_dps=gyro_z,temp_c=temp --out {o}", succeeds(*ok_units, *same_gap))
    case("names-allan", "allan --column gyro_z, time column not mapped", "allan --data in/hub_names.csv --column gyro_z",
         fails("t_s|time", "--columns"))
    case("stamp-mapped", "Timestamp column of clock times, with --columns",
         mems + "hub_stamp.csv --columns t_s=Timestamp,rate_dps=gyro_z,temp_c=temp --out {o}",
         succeeds(near("sampling.period_s", 15.0, 0.001), *same_gap))
    case("stamp-bare", "Timestamp column without --columns", mems + "hub_stamp.csv --out {o}", fails("t_s|Timestamp", "--columns"))
    case("iso-t_s", "ISO clock timestamps instead of seconds", mems + "hub_iso.csv --out {o}",
         succeeds(near("sampling.period_s", 15.0, 0.001), *same_gap))
    case("fringe-names", "fringe columns time,photodiode without --columns",
         "lockin --data in/fringe_names.csv --pulses-per-deg 2000", fails("t_s|signal", "--columns"))
    case("fringe-mapped", "fringe columns mapped",
         "lockin --data in/fringe_names.csv --columns t_s=time,signal=photodiode --pulses-per-deg 2000",
         succeeds(near("lock_in_dps", "ctl-lockin", 0.001)))

    # --- dialects
    same_hub = succeeds(*ok_units, near("gap_before_dph", "ctl-disc-hub", 0.001),
                        near("gap_after_dph", "ctl-disc-hub", 0.001), near("stretch.rows", 320, 0))
    for key, what in [("semicolon", "semicolons and decimal commas"), ("tab", "tabs and decimal commas"),
                      ("bom", "UTF-8 BOM before a # comment line"), ("crlf", "Windows CRLF line ends"),
                      ("quoted", "quoted header names"), ("blank", "blank lines in and after the data")]:
        case(f"dialect-{key}", what, mems + f"hub_{key}.csv --out {{o}}", same_hub)
    case("dialect-semicolon-thermal", "chamber run with semicolons and decimal commas",
         "fit thermal --data in/cycle_semicolon.csv --out {o}/th.toml",
         succeeds(near("coefficients.k1_dph_per_c", "ctl-thermal", 0.001)))

    # --- missing columns, no reference
    case("missing-2-sf", "rate_dps and temp_c both missing", fitsf + "sf_missing2.csv --out {o}/sf.toml",
         fails("rate_dps", "temp_c"))
    case("missing-2-thermal", "t_mono_b_c and t_case_c both missing",
         "fit thermal --data in/cycle_missing2.csv --out {o}/th.toml", fails("t_mono_b_c", "t_case_c"))
    case("noref-disc", "static MEMS record without ref_rate_dps", mems + "hub_noref.csv --out {o}",
         succeeds(warn("no_reference"), *same_gap))
    case("noref-allan", "static RLG record without ref_rate_dps", "allan --data in/rest_noref.csv",
         succeeds(near("terms.angle_random_walk_dpsh.value", "ctl-allan", 0.02)))
    case("noref-sf", "rate-table run without ref_rate_dps (a scale factor needs it)",
         fitsf + "sf_noref.csv --out {o}/sf.toml", fails("ref_rate_dps"))

    # --- sampling: jitter
    case("jitter-allan", "PC-stamped times, +-1 % jitter", "allan --data in/rest_jitter.csv",
         succeeds(warn("jitter"), near("terms.angle_random_walk_dpsh.value", "ctl-allan", 0.05)))
    case("jitter-lockin", "PC-stamped fringe times, +-1 % jitter", "lockin --data in/fringe_jitter.csv --pulses-per-deg 2000",
         succeeds(warn("jitter")))

    # --- bad cells and files
    case("cell-nan", "a NaN rate cell (line 101)", mems + "hub_nan.csv --out {o}", fails(file="hub_nan.csv", line=101))
    case("cell-empty", "an empty rate cell (line 151)", mems + "hub_empty_cell.csv --out {o}", fails(file="hub_empty_cell.csv", line=151))
    case("cell-text", "'ERR' in a temperature cell (line 201)", mems + "hub_text.csv --out {o}",
         fails("ERR|temp_c|number|numeric", line=201))
    case("cell-text-allan", "'ERR' in a temperature cell, allan (it reads temperatures)", "allan --data in/hub_text.csv",
         fails("ERR|temp_c|number|numeric", line=201))
    case("row-short", "a row with a missing cell (line 251)", mems + "hub_short_row.csv --out {o}", fails("cell|column", line=251))
    case("time-back", "time goes backwards (line 121)", mems + "hub_backwards.csv --out {o}",
         fails("increas|monoton|back|order", line=121))
    case("time-back-allan", "time goes backwards, allan", "allan --data in/hub_backwards.csv",
         fails("increas|monoton|back|order", line=121))
    case("empty-file", "an empty file", "allan --data in/empty.csv", fails(file="empty.csv"))
    case("empty-file-thermal", "an empty file, fit thermal", "fit thermal --data in/empty.csv --out {o}/th.toml", fails(file="empty.csv"))
    case("header-only", "a header and no rows", mems + "header_only.csv --out {o}", fails("row|sample|data", file="header_only.csv"))
    case("header-only-lockin", "a fringe header and no rows", "lockin --data in/fringe_header_only.csv --pulses-per-deg 2000",
         fails("row|sample|data", file="fringe_header_only.csv"))

    # --- --out over an input
    inp, inp_dir = fails("input|--data|--coeffs|--out"), fails("input|--data|folder|directory")
    th = "out/ctl-thermal/th.toml"
    case("out-input-thermal", "fit thermal --out names the run", "fit thermal --data in/cycle.csv --out in/cycle.csv", inp)
    case("out-input-thermal-force", "... and with --force", "fit thermal --data in/cycle.csv --out in/cycle.csv --force", inp)
    case("out-input-sf", "fit scale-factor --out names the run", fitsf + "sf.csv --out in/sf.csv --force", inp)
    case("out-input-comp", "compensate --out names the run",
         f"compensate --coeffs {th} --data in/cycle.csv --out in/cycle.csv --force", inp)
    case("out-coeffs-comp", "compensate --out names the coefficient file",
         f"compensate --coeffs {th} --data in/cycle.csv --out {th} --force", inp)
    case("out-input-disc", "discover --out names the run file", mems + "hub.csv --out in/hub.csv --force", inp_dir)
    case("out-input-disc-dir", "discover --out the folder holding the run, which is named residual.csv",
         "discover --gyro mems --data {o}/residual.csv --out {o} --force", inp, setup=copy_to("in/hub.csv", "{o}/residual.csv"))
    case("out-model-disc", "discover --model M --out the folder holding M (model.toml)",
         mems + "hub.csv --model {o}/model.toml --out {o} --force", fails("input|--model"),
         setup=copy_to("out/ctl-disc-hub/model.toml", "{o}/model.toml"))
    case("out-input-allan", "allan --out names the run", "allan --data in/rest.csv --out in/rest.csv --force", inp_dir)
    case("out-input-allan-dir", "allan --out the folder holding the run, which is named allan.csv",
         "allan --data {o}/allan.csv --out {o} --force", inp, setup=copy_to("in/rest.csv", "{o}/allan.csv"))
    case("out-input-lockin", "lockin --out names the fringe file",
         "lockin --data in/fringe.csv --pulses-per-deg 2000 --out in/fringe.csv --force", inp_dir)

    # --- --out existing, folders and files, other kinds
    case("out-exists", "--out an existing coefficient file, no --force", "fit thermal --data in/cycle.csv --out {o}/th.toml",
         fails("--force"), setup=copy_to(th, "{o}/th.toml"))
    case("out-exists-force", "--out an existing coefficient file, --force",
         "fit thermal --data in/cycle.csv --out {o}/th.toml --force",
         succeeds(("th.toml rewritten", lambda j: "bias0_dph = 1.0\n" not in open(
             os.path.join(WORK, "out/out-exists-force/th.toml")).read())), setup=planted_th,
         allow=("out/out-exists-force/th.toml",))
    case("out-exists-disc", "discover --out a folder holding an earlier result, no --force", mems + "hub.csv --out {o}",
         fails("--force"), setup=copy_to("out/ctl-disc-hub/model.toml", "{o}/model.toml"))
    case("out-dir-for-file", "fit thermal --out an existing folder (a file expected)",
         "fit thermal --data in/cycle.csv --out {o}/calib", either(fails("folder|directory"), succeeds(
             ("written inside the folder, its files kept", lambda j: True))), setup=make_dir_with("{o}/calib", "keep.txt"))
    case("out-dir-for-file-force", "compensate --out an existing folder, --force",
         f"compensate --coeffs {th} --data in/cycle.csv --out {{o}}/comp --force", fails("folder|directory"),
         setup=make_dir_with("{o}/comp", "keep.txt"))
    case("out-file-for-dir", "allan --out an existing file (a folder expected)", "allan --data in/rest.csv --out {o}/notes.txt",
         fails("folder|directory|file|--force"), setup=make_dir_with("{o}", "notes.txt"))
    case("out-file-for-dir-force", "allan --out an existing file, --force",
         "allan --data in/rest.csv --out {o}/notes.txt --force", fails("folder|directory|kind|file"),
         setup=make_dir_with("{o}", "notes.txt"))
    case("out-file-for-dir-disc", "discover --out an existing run file, --force", mems + "hub.csv --out {o}/other_run.csv --force",
         fails("folder|directory|kind|file"), setup=copy_to("in/rest.csv", "{o}/other_run.csv"))
    case("out-mymodel", "discover --out mymodel.toml (a folder expected)", mems + "hub.csv --out {o}/mymodel.toml",
         either(fails("folder|directory"), succeeds(("mymodel.toml is a gyro_model file", lambda j: os.path.isfile(os.path.join(WORK, "out/out-mymodel/mymodel.toml"))
             and 'kind = "gyro_model"' in open(os.path.join(WORK, "out/out-mymodel/mymodel.toml")).read()))))
    case("out-kind-csv", "fit thermal --out a run file (not an input), --force",
         "fit thermal --data in/cycle.csv --out {o}/run.csv --force", fails("kind|run|csv|toml"),
         setup=copy_to("in/rest.csv", "{o}/run.csv"))
    case("out-kind-toml", "compensate --out a coefficient file (not an input), --force",
         f"compensate --coeffs {th} --data in/cycle.csv --out {{o}}/old.toml --force", fails("kind|coeff|toml|csv"),
         setup=copy_to("out/ctl-sf/sf.toml", "{o}/old.toml"))
    case("out-kind-model", "fit scale-factor --out a gyro_model TOML, --force (a TOML of another kind)",
         fitsf + "sf.csv --out {o}/model.toml --force", fails("kind|gyro_model"),
         setup=copy_to("out/ctl-disc-hub/model.toml", "{o}/model.toml"))

    # --- stretches
    case("stretch-allan", "--from-s 1000 --to-s 5000", "allan --data in/rest.csv --from-s 1000 --to-s 5000",
         succeeds(near("stretch.rows", 4001, 0.001)))
    case("stretch-after-warmup", "--from-s 6000 (after the warm-up)", "allan --data in/rest.csv --from-s 6000",
         succeeds(no_warn("warm_up"), ("analysed from >= 6000 s", lambda j: (j.get("analysed_from_s") or 6000) >= 6000)))
    case("stretch-empty", "an empty stretch past the record's end", mems + "hub.csv --from-s 30000 --to-s 40000 --out {o}",
         fails("30000|stretch|--from-s|no rows|empty"))
    case("stretch-reversed", "--from-s after --to-s", "fit thermal --data in/cycle.csv --from-s 5000 --to-s 4000 --out {o}/th.toml",
         fails("--from-s|--to-s|stretch"))
    case("stretch-short-thermal", "a 300 s stretch for fit thermal (it needs 600 s)",
         "fit thermal --data in/cycle.csv --to-s 300 --out {o}/th.toml", fails("600"))
    case("stretch-lockin", "a 1 s stretch of the fringe", "lockin --data in/fringe.csv --pulses-per-deg 2000 --from-s 1 --to-s 2",
         succeeds(near("lock_in_dps", "ctl-lockin", 0.05)))
    case("stretch-iso", "--from-s on clock timestamps (since the first row)", mems + "hub_iso.csv --from-s 1500 --out {o}",
         succeeds(("rows 220 +- 2 (1500 s after the first row on)", lambda j: abs(j["stretch"]["rows"] - 220) <= 2)))


# ----------------------------------------------------------------------------- running

WORK = None


def sha(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for b in iter(lambda: f.read(1 << 20), b""):
            h.update(b)
    return h.hexdigest()


_cache = {}


def snapshot(w):
    """path -> hash of every file under w (hashes cached by inode, size and mtime)."""
    out = {}
    for root, _, files in (x for sub in ("in", "out") for x in os.walk(os.path.join(w, sub))):
        for n in files:
            p = os.path.join(root, n)
            st = os.stat(p)
            key = (p, st.st_ino, st.st_size, st.st_mtime_ns)
            if key not in _cache:
                _cache[key] = sha(p)
            out[os.path.relpath(p, w)] = _cache[key]
    return out


def strays(w):
    return {os.path.relpath(os.path.join(r, n), w) for r, ds, fs in os.walk(w) for n in fs + ds
            if n.startswith(".") and n.endswith(".tmp")}


def input_paths(argv):
    return [argv[i + 1] for i, a in enumerate(argv[:-1])
            if a in ("--data", "--coeffs", "--model", "--validate", "--cubic-from")]


def run_case(labbin, w, c):
    if c["setup"] or f"out/{c['key']}/" in " ".join(c["argv"]):  # --out a folder: left to the tool
        os.makedirs(os.path.join(w, "out", c["key"]), exist_ok=True)
    if c["setup"]:
        c["setup"](lambda s: os.path.join(w, s.replace("{o}", f"out/{c['key']}")))
    ins = input_paths(c["argv"])
    r = types.SimpleNamespace(paths=[c["argv"][i + 1] for i, a in enumerate(c["argv"][:-1]) if a == "--out"] + ins)
    before_in = {p: sha(os.path.join(w, p)) for p in ins if os.path.isfile(os.path.join(w, p))}
    before, tmp0 = snapshot(w), strays(w)
    try:
        p = subprocess.run([labbin, *c["argv"]], cwd=w, capture_output=True, text=True, timeout=900)
        r.rc, r.out, r.err = p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired:
        r.rc, r.out, r.err = "timeout", "", "timeout after 900 s"
    after = snapshot(w)
    r.inputs_changed = [p for p, h in before_in.items()
                        if not os.path.isfile(os.path.join(w, p)) or sha(os.path.join(w, p)) != h]
    r.others_changed = [p for p, h in before.items() if after.get(p) != h and p not in ins
                        and p not in c["allow"]]
    r.strays = sorted(strays(w) - tmp0)
    r.one_line = len(r.err.strip().splitlines()) <= 1
    r.panicked = "panicked" in r.err
    r.json = None
    try:
        r.json = json.loads(r.out.strip().splitlines()[-1]) if r.rc == 0 else None
    except (ValueError, IndexError):
        pass
    return r


def key_numbers(j):
    """A few numbers that say whether the answer is right, by command."""
    picks = ["units.rate", "units.temperature", "sampling.period_s", "sampling.kind", "stretch.rows",
             "terms.angle_random_walk_dpsh.value", "analysed_from_s", "knees_c", "residual_ppm",
             "coefficients.k1_dph_per_c", "gap_before_dph", "gap_after_dph", "lock_in_dps",
             "input_rate_dps", "comp_std_100s_dph"]
    out = []
    for p in picks:
        try:
            v = get(j, p)
        except (KeyError, IndexError, TypeError):
            continue
        if isinstance(v, float):
            v = f"{v:.4g}"
        elif isinstance(v, list):
            v = "[" + ", ".join(f"{x:.4g}" if isinstance(x, float) else str(x) for x in v[:4]) + "]"
        out.append(f"{p.split('.')[-2] if p.endswith('.value') else p}={v}")
    if "found" in j:
        out.append("found=" + "+".join(f["effect"] for f in j["found"]))
    return ", ".join(out)


def outcome(r):
    if r.rc != 0 or r.json is None:
        return (r.err.strip().splitlines() or ["(no stderr)"])[0][:400]
    ws = r.json.get("warnings") or []
    parts = ["warnings: " + (", ".join(w.get("code") or w.get("kind") or "?" for w in ws) or "none")]
    for w in ws:
        if (w.get("code") or w.get("kind")) in ("unit", "jitter", "no_reference", "sign"):
            parts.append(f"[{w.get('code')}] {w['message'][:220]}")
    parts.append(key_numbers(r.json))
    return "; ".join(parts)


def verdict(c, r):
    bad = []
    if r.rc not in (0, 2):
        bad.append(f"exit {r.rc}")
    if r.panicked:
        bad.append("panicked")
    if r.rc == 2 and not r.one_line:
        bad.append("error not one line")
    if r.rc == 2 and not re.search(r"\S", r.err):
        bad.append("no error message")
    if r.rc == 0 and r.json is None:
        bad.append("no JSON on the last stdout line")
    if r.inputs_changed:
        bad.append("input modified: " + ", ".join(r.inputs_changed))
    if r.others_changed:
        bad.append("existing file changed: " + ", ".join(r.others_changed))
    if r.strays:
        bad.append("stray temporary: " + ", ".join(r.strays))
    met = c["expect"](r)
    if bad:
        return "FAIL", "; ".join(bad)
    if not c["sure"]:
        return "judge", "preferred outcome " + ("met" if met else "not met")
    return ("PASS", "") if met else ("FAIL", "expectation not met")


def cell(s):
    return str(s).replace("|", "\\|").replace("\n", " ")


def main():
    global WORK
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lab", required=True, help="the gyro-lab binary")
    ap.add_argument("--work", required=True, help="scratch folder (created, emptied)")
    ap.add_argument("--out", required=True, help="markdown report")
    a = ap.parse_args()
    WORK = os.path.abspath(a.work)
    if os.path.exists(WORK):
        shutil.rmtree(WORK)
    os.makedirs(os.path.join(WORK, "bin"))
    # a private copy: a rebuild of --lab during the run must not mix two binaries
    labbin = shutil.copy2(os.path.abspath(a.lab), os.path.join(WORK, "bin", "gyro-lab"))
    lab_id = f"{os.path.abspath(a.lab)} (sha256 {sha(labbin)[:16]}, built {time.ctime(os.path.getmtime(labbin))})"
    build_inputs(labbin, WORK)
    define_cases()
    rows, tally = [], {"PASS": 0, "FAIL": 0, "judge": 0}
    n_mod = n_panic = 0
    for i, c in enumerate(C, 1):
        r = run_case(labbin, WORK, c)
        if r.rc == 0 and r.json is not None and c["key"].startswith("ctl-"):
            BASE[c["key"]] = r.json
        v, why = verdict(c, r)
        tally[v] += 1
        n_mod += bool(r.inputs_changed)
        n_panic += r.panicked
        rows.append((i, c, r, v, why))
        print(f"{i:3d} {v:5s} {c['key']}: exit {r.rc}", file=sys.stderr)
    left = sorted(strays(WORK))
    located = [r.err.strip() for _, _, r, _, _ in rows if r.rc == 2 and re.search(r":\d+:\d+", r.err)]
    strict = [e for e in located if re.match(r"[^\s:]+:\d+:\d+: ", e)]
    form = (f"{len(strict)} of the {len(located)} located errors have the contract's form "
            f"`file:line:column: message`" + (f"; e.g. `{located[0]}`" if len(strict) < len(located) else ""))
    summary = (f"user-mistakes: {len(C)} cases: {tally['PASS']} PASS, {tally['FAIL']} FAIL, "
               f"{tally['judge']} judge; inputs modified in {n_mod}; panics {n_panic}; "
               f"stray .tmp files {len(left)}; report {a.out}")
    with open(a.out, "w") as f:
        f.write("# gyro-lab: a new user's mistakes with their own files (issue 38)\n\n")
        f.write(f"Binary `{lab_id}`; every command runs in `{WORK}` (`cd {WORK} && gyro-lab ...`).\n"
                "Every case must also: exit 0 or 2, never panic, fail in one stderr line, change no input "
                "or other existing file, leave no `.*.tmp`. \"judge\": the right outcome is debatable; "
                "the expectation column states the preferred one.\n\n")
        f.write(f"**{summary}**\n\n")
        f.write("| # | verdict | mistake | command | exit | 1 line | panic | input changed | "
                "stderr / warnings and key numbers | expectation | note |\n")
        f.write("|" + "---|" * 11 + "\n")
        for i, c, r, v, why in rows:
            cmd = "gyro-lab " + shlex.join(c["argv"])
            f.write("| " + " | ".join(cell(x) for x in (
                i, f"**{v}**", c["mistake"], f"`{cmd}`", r.rc, "yes" if r.one_line else "no",
                "yes" if r.panicked else "no", ", ".join(r.inputs_changed) or "no",
                outcome(r), c["expect"].desc, why)) + " |\n")
        f.write(f"\nError form: {cell(form)}.\n")
        f.write(f"\nStray temporary files left in the work folder at the end: {', '.join(left) or 'none'}.\n")
    print(summary)
    print(form, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
