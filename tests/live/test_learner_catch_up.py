"""A learner that falls behind coalesces its steps (one smoothing pass over a longer window) and defers the
map: no learned row is left out, and a replay of the raw log given the merged steps' stamps learns the same."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.learner import LearnOptions, Learner, iter_tlog_records, learn_from_tlog

ROOT = Path(__file__).resolve().parents[2]
FLIGHT = ROOT / "data" / "flights" / "sim-trainer-sysid.tlog"
OPTS = LearnOptions(window_s=6.0, step_s=2.0, lag_s=1.0, min_rows=10 ** 9)   # no GP: decode + smooth + rows


def test_coalesced_steps_leave_no_row_out(tmp_path):
    records = []
    for stamp, packet in iter_tlog_records(FLIGHT):      # the first 18 s of the sample flight as a raw log
        if records and stamp - records[0][0] > 18e6:
            break
        records.append((stamp, packet))
    raw = tmp_path / "raw.tlog"
    raw.write_bytes(b"".join(s.to_bytes(8, "big") + p for s, p in records))
    airframe = load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml")

    caught = Learner(airframe, OPTS)
    calls = []
    caught.behind = lambda: bool(calls.append(1) or len(calls) % 4)      # behind at three due steps of four
    for stamp, packet in records:
        caught.feed(stamp, packet)
    caught.finish()
    steady = learn_from_tlog(raw, airframe, OPTS)
    assert caught.coalesced >= 4 and steady.coalesced == 0
    assert caught.steps <= steady.steps - 3
    for lr in (steady, caught):
        gaps = np.diff(lr.t)
        assert np.all(gaps > 0) and gaps.max() < 0.05, gaps.max()      # 50 Hz rows, none skipped or repeated
    assert caught.t[0] == steady.t[0] and abs(caught.t[-1] - steady.t[-1]) < 0.05
    # a replay given the merged steps' stamps (session.json's coalesced_at_us) follows the same schedule
    replay = learn_from_tlog(raw, airframe, OPTS, coalesced_at=caught.coalesced_at)
    assert replay.steps == caught.steps and replay.coalesced == caught.coalesced
    np.testing.assert_array_equal(replay.t, caught.t)
    np.testing.assert_array_equal(replay.X, caught.X)
    # the same rows, smoothed with more context: the regressors agree closely with the steady schedule's
    common, i, j = np.intersect1d(np.round(steady.t, 3), np.round(caught.t, 3), return_indices=True)
    assert len(common) > 0.98 * len(steady.t)
    d = np.abs(steady.X[i] - caught.X[j])
    assert np.median(d[:, :5]) < 1e-3
