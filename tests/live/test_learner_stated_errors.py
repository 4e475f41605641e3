"""The live learner gives its model the windows' stated regressor errors (sixty-fifth session): the band at exact
conditions (what `gcs-sysid predict` states from a saved live model) carries them, as the replay's model carries the
flight's; the mean and the bands at the flight's own regressors do not move.

The first 100 s of the project's sample flight go through two learners, the pooled errors on and off.
"""

from __future__ import annotations

import struct
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.cli import build_parser
from gcs_sysid.live.learner import LearnOptions, iter_tlog_records, learn_from_tlog
from gcs_sysid.live.report import render_markdown

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT, listen_options  # noqa: E402


@pytest.fixture(scope="module")
def learners(tmp_path_factory):
    path = tmp_path_factory.mktemp("stated") / "first100.tlog"
    recs = list(iter_tlog_records(FLIGHT))
    t0 = recs[0][0]
    path.write_bytes(b"".join(struct.pack(">Q", s) + p for s, p in recs if s - t0 <= 100_000_000))
    af = load_airframe(AIRFRAME)
    return {on: learn_from_tlog(path, af, LearnOptions(n_inducing=24, stated_errors=on)) for on in (False, True)}


def test_the_pooled_errors_widen_only_the_band_at_exact_conditions(learners):
    off, on = learners[False], learners[True]
    assert off.errors["state"] == "off" and off.model.offset_cov is None and off.model.scale_var is None
    assert on.errors["state"] == "pooling" and on.errors["windows"] >= 5
    assert on.errors["rows"] == on.n_learned == off.n_learned
    note = on.errors["note"]
    assert note.startswith("stated regressor errors in the band at exact conditions: pooled over")
    assert "alpha offset" in note and "p_hat" in note and "r_hat" in note       # the rates' errors: on by default
    assert on.notes[-1] == f"end: {note}" and not any("stated regressor errors" in n for n in off.notes)
    m = on.model
    assert m.offset_cov is not None and np.isfinite(m.offset_cov).all() and m.offset_cov[0, 0] > 0
    assert m.scale_var is not None and m.map_cov is not None
    X = on.X[::25]
    for kw in ({}, {"include_noise": False}):          # at the flight's own regressors: the same
        a, b = on.model.predict(X, **kw), off.model.predict(X, **kw)
        assert np.array_equal(np.asarray(a[0]), np.asarray(b[0]))
        assert np.array_equal(np.asarray(a[1]), np.asarray(b[1]))
    mu_on, v_on = on.model.predict(X, include_noise=False, input_noise=False)      # exact conditions
    mu_off, v_off = off.model.predict(X, include_noise=False, input_noise=False)
    assert np.array_equal(np.asarray(mu_on), np.asarray(mu_off))
    v_on, v_off = np.asarray(v_on), np.asarray(v_off)
    assert np.all(v_on >= v_off) and np.all(np.median(v_on / v_off, axis=0) > 1.0)
    bare = replace(on.model, offset_cov=None, scale_var=None, map_cov=None)
    assert np.array_equal(np.asarray(bare.predict(X, include_noise=False, input_noise=False)[1]), v_off)


def test_the_report_says_what_the_models_band_carries():
    snap = {"connection": "c", "raw_records": 1, "bad_data": 0, "seq_lost": 0, "requests": {}, "samples_learned": 9,
            "steps": 2, "stated_errors": {"state": "pooling", "note": "stated regressor errors ...: pooled over 3"}}
    md = render_markdown(snap)
    assert "band at exact conditions (`gcs-sysid predict`): stated regressor errors ...: pooled over 3" in md
    assert "band at exact conditions" not in render_markdown({**snap, "stated_errors": {"state": "off", "note": ""}})


def test_listen_cli_passes_rate_errors(monkeypatch, tmp_path):
    cases = (([], None), (["--rate-errors", "on"], True), (["--rate-errors", "off"], False))
    got = listen_options(monkeypatch, tmp_path, [extra for extra, _ in cases])
    assert [o.learn.rate_errors for o in got] == [want for _, want in cases]
    assert all(o.learn.stated_errors is True for o in got)         # on by default
    with pytest.raises(SystemExit):
        build_parser().parse_args(["listen", "udpin:0.0.0.0:14550", "--airframe", "a.toml", "--out", str(tmp_path),
                                   "--rate-errors", "maybe"])
