"""`listen --air-roll on` (the air-rate pair in the live learner; thirty-first session, live-pair31; the default since the
sixty-sixth session) in calm air.

The project's sample flight (``data/flights/sim-trainer-sysid.tlog``: the simulation's turbulence moves the air, not
the roll moment, so there is no rolling gust to find) is fed through the learner with the pair on and off. The
pair's roll fit, made once on the first fit's rows, is refused by the instruments' check (the fit's ``Cl_p`` runs
away: the twenty-ninth session's calm-air finding, i8-guard); the learner then learns the measured Cl for the whole
session, so its model is exactly the model with the pair off, and its status and notes say why. The rolling-gust
side (the target moved, the fit recorded, the session = its raw log) is ``tests/jsbsim/test_listen_air_roll.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.cli import build_parser
from gcs_sysid.live.learner import LearnOptions, learn_from_tlog
from gcs_sysid.live.report import render_markdown

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT, listen_options  # noqa: E402


def test_listen_cli_passes_air_roll(monkeypatch, tmp_path):
    cases = (([], True), (["--air-roll", "on"], True), (["--air-roll", "off"], False))
    got = listen_options(monkeypatch, tmp_path, [extra for extra, _ in cases])
    assert [o.learn.air_roll for o in got] == [want for _, want in cases]
    assert LearnOptions().air_roll is True                         # the default since the sixty-sixth session
    with pytest.raises(SystemExit):
        build_parser().parse_args(["listen", "udpin:0.0.0.0:14550", "--airframe", "a.toml", "--out", str(tmp_path),
                                   "--air-roll", "maybe"])


def test_the_report_says_what_the_pair_did():
    snap = {"connection": "c", "raw_records": 1, "bad_data": 0, "seq_lost": 0, "requests": {}, "samples_learned": 9,
            "steps": 2, "air_roll": {"state": "refused", "note": "Cl's air-rate training target not applied: why"}}
    md = render_markdown(snap)
    assert "the air-rate pair" in md and "refused" in md and "not applied: why" in md
    assert "air-rate pair" not in render_markdown({**snap, "air_roll": {"state": "off", "note": ""}})


@pytest.mark.slow   # two learners over the 240 s sample flight (~1-2 min on 2 cores)
def test_in_calm_air_the_pair_is_refused_and_the_model_is_the_one_without_it():
    af = load_airframe(AIRFRAME)
    opts = dict(n_inducing=24)
    off = learn_from_tlog(FLIGHT, af, LearnOptions(air_roll=False, **opts))
    on = learn_from_tlog(FLIGHT, af, LearnOptions(air_roll=True, **opts))
    assert off.air_roll["state"] == "off" and on.air_roll["state"] == "refused", on.air_roll
    note = on.air_roll["note"]
    assert note.startswith("Cl's air-rate training target not applied") and "instrumented" in note, note
    assert "gyro's roll rate for the whole session" in note
    assert any(note in n for n in on.notes)
    assert on._roll_fit is None and "rows_moved" not in on.air_roll
    assert on.n_learned == off.n_learned and on.outputs == off.outputs
    assert np.array_equal(on.X, off.X) and np.array_equal(on.Y, off.Y, equal_nan=True)   # the measured Cl learned
    m_on, v_on = on.model.predict(off.X)
    m_off, v_off = off.model.predict(off.X)
    assert np.array_equal(np.asarray(m_on), np.asarray(m_off))
    assert np.array_equal(np.asarray(v_on), np.asarray(v_off))
