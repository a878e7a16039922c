"""What a notebook shows: the report inline, a short text repr, the JSON
keys as items and attributes, and results that pickle whole."""

import json
import pickle
import tomllib

import numpy as np

import gyrolab


def test_repr_html_is_the_report(runs):
    d = gyrolab.discover(str(runs / "table.csv"), gyro="fog")
    html = d._repr_html_()
    assert html.count("<svg") >= 2
    assert "<script" not in html  # self-contained, nothing to run
    # The fragment is the report's body, styled within itself.
    assert "gyro-report" in html
    assert d.html.lstrip().lower().startswith("<!doctype html")


def test_repr_is_a_short_summary(runs):
    a = gyrolab.allan(str(runs / "chamber.csv"))
    text = repr(a)
    assert text.startswith("<gyrolab.allan>")
    assert len(text.splitlines()) <= 8, text
    assert "angle random walk" in text
    assert len(a.text) > len(text)


def test_keys_items_and_attributes(runs):
    a = gyrolab.allan(str(runs / "chamber.csv"))
    assert isinstance(a["adev_dph"], np.ndarray)
    assert a.adev_dph is a["adev_dph"] or np.array_equal(a.adev_dph, a["adev_dph"])
    assert set(json.loads(a.to_json())) == set(a.keys())
    assert a.terms == a["terms"]


def test_model_toml_is_the_model_file(runs):
    d = gyrolab.discover(str(runs / "table.csv"), gyro="fog")
    m = tomllib.loads(d.model_toml)
    assert m["kind"] == "gyro_model" and m["gyro"] == "fog"
    assert {e["name"] for e in m["effect"]} >= {"scale_factor_knee", "warm_up"}
    # And it is a model the next call takes.
    again = gyrolab.discover(str(runs / "table.csv"), gyro="fog", model=d.model_toml)
    assert again["found"] == [] and again["unexplained"] is None


def test_results_pickle_whole(runs):
    d = gyrolab.discover(str(runs / "table.csv"), gyro="fog")
    e = pickle.loads(pickle.dumps(d))
    assert e.to_json() == d.to_json()
    assert e.model_toml == d.model_toml
    assert e._repr_html_() == d._repr_html_()
    assert repr(e) == repr(d)
