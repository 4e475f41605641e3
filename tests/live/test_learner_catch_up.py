"""A learner that falls behind coalesces its steps (one smoothing pass over a longer window) and defers the
map: no learned row is left out, and with nobody behind the schedule is the stamp-driven one."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.learner import LearnOptions, Learner, iter_tlog_records

ROOT = Path(__file__).resolve().parents[2]
FLIGHT = ROOT / "data" / "flights" / "sim-trainer-sysid.tlog"


def _feed(behind=None, seconds=18.0):
    learner = Learner(load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml"),
                      LearnOptions(window_s=6.0, step_s=2.0, lag_s=1.0, min_rows=10 ** 9))
    learner.behind = behind
    first = None
    for stamp, packet in iter_tlog_records(FLIGHT):
        first = stamp if first is None else first
        if stamp - first > seconds * 1e6:
            break
        learner.feed(stamp, packet)
    learner.finish()
    return learner


def test_coalesced_steps_leave_no_row_out():
    calls = []

    def behind():                      # behind for three due steps out of four
        calls.append(1)
        return len(calls) % 4 != 0

    steady = _feed()
    caught = _feed(behind)
    assert caught.coalesced >= 4 and steady.coalesced == 0
    assert caught.steps <= steady.steps - 3
    for lr in (steady, caught):
        gaps = np.diff(lr.t)
        assert np.all(gaps > 0) and gaps.max() < 0.05, gaps.max()      # 50 Hz rows, none skipped or repeated
    assert caught.t[0] == steady.t[0] and abs(caught.t[-1] - steady.t[-1]) < 0.05
    # the same rows, smoothed with more context: the regressors agree closely
    common, i, j = np.intersect1d(np.round(steady.t, 3), np.round(caught.t, 3), return_indices=True)
    assert len(common) > 0.98 * len(steady.t)
    d = np.abs(steady.X[i] - caught.X[j])
    assert np.median(d[:, :5]) < 1e-3
