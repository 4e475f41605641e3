"""The live learner's end with the rows moved to the session's final pitch gust share (``LearnOptions.
air_pitch_relearn``, :meth:`Learner.pitch_relearn`, seventieth session).

Each window's ``q_hat`` was moved with the share pooled up to it (``kappa_k g``; 0 while the pool did not pass its
gates). At the end every kept row's ``q_hat`` must be the gyro's less ``kappa g`` with the final share, exactly, and
the GP learned again on them; where the final fit does not pass the gates every row goes back to the gyro's rate.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.aero.table import REGRESSORS, CoefficientTable
from gcs_sysid.airframe import load_airframe
from gcs_sysid.errors import InputError
from gcs_sysid.live.learner import LearnOptions, Learner

ROOT = Path(__file__).resolve().parents[2]
IQ = REGRESSORS.index("q_hat")


def _window(n: int, seed: int, t0: float):
    """A window's table at the gyro's rate and its pitch gust rate ``g`` (NaN on a few rows: unknown there)."""
    rng = np.random.default_rng(seed)
    X = np.column_stack([rng.normal(0.05, 0.03, n), rng.normal(0, 0.02, n), rng.normal(0, 0.02, (n, 3)),
                         rng.normal(0, 0.05, (n, 3)), rng.uniform(0.3, 0.7, n), rng.normal(20, 1, n)])
    Y = (X - X.mean(0)) / X.std(0) @ rng.normal(0, 1, (10, 6)) * 0.05 + 0.01 * rng.standard_normal((n, 6))
    g = 0.004 * rng.standard_normal(n)
    g[:5] = np.nan
    return CoefficientTable(t0 + np.arange(n) * 0.02, X, Y, np.ones(n, bool), np.full(n, 200.0)), g


def _moved(table: CoefficientTable, g: np.ndarray, kappa: float) -> CoefficientTable:
    """What the learner's window step hands on: ``q_hat - kappa g`` where ``g`` is known."""
    X = table.X.copy()
    ok = np.isfinite(g)
    X[ok, IQ] -= kappa * g[ok]
    return CoefficientTable(table.t, X, table.Y, table.valid, table.qbar)


@pytest.fixture(scope="module")
def windows():
    # kappa of each window's time: the gyro's rate (the pool not yet past its gates), then a settling share
    return [(*_window(n, s, t0), k) for n, s, t0, k in ((150, 1, 0.0, 0.0), (150, 2, 10.0, -1.2), (150, 3, 20.0, -0.6))]


def _learned(windows, relearn: bool = True) -> Learner:
    lr = Learner(load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml"),
                 LearnOptions(min_rows=200, n_inducing=12, hyper_every=0, stated_errors=False, air_roll=False,
                              air_pitch_relearn=relearn))
    for table, g, kappa in windows:
        rows = np.ones(len(table.t), bool)
        lr._pitch_window = (np.where(np.isfinite(g), g, 0.0), kappa)      # what _air_pitch leaves for the window
        lr._window_in(table, rows, None)
        lr._learn(_moved(table, g, kappa), rows)
    return lr


def test_every_row_moves_to_the_final_share_and_is_learned_again(windows):
    lr = _learned(windows)
    before = lr.model
    n = lr.pitch_relearn({"applied": True, "kappa": -0.7, "windows": 3})
    gyro = np.concatenate([t.X[:, IQ] for t, _, _ in windows])
    g = np.concatenate([np.where(np.isfinite(g), g, 0.0) for _, g, _ in windows])
    assert np.allclose(lr.X[:, IQ], gyro + 0.7 * g, rtol=0, atol=1e-15)
    assert n == lr.n_learned == 450 and lr.model is not before
    info = lr.air_pitch["relearn"]
    assert info["kappa"] == -0.7 and info["rows_moved"] == 3 * 145 and info["rows"] == 450
    assert "moved to the share of all 3 windows, kappa -0.700" in lr.notes[-1] and "learned again" in lr.notes[-1]
    # the same kept rows learned from the start at the final share give the same model
    same = _learned([(t, g, -0.7) for t, g, _ in windows], relearn=False)
    x = windows[0][0].X[:20]
    assert np.allclose(np.asarray(lr.model.predict(x)[0]), np.asarray(same.model.predict(x)[0]), atol=1e-9)


def test_a_final_fit_without_the_share_puts_every_row_back_at_the_gyros_rate(windows):
    lr = _learned(windows)
    lr.pitch_relearn({"applied": False, "kappa": float("nan"), "windows": 3})
    gyro = np.concatenate([t.X[:, IQ] for t, _, _ in windows])
    assert np.allclose(lr.X[:, IQ], gyro, rtol=0, atol=1e-15) and np.all(lr._pitch_k == 0.0)
    assert lr.air_pitch["relearn"]["rows_moved"] == 2 * 145 and "the gyro's rate" in lr.notes[-1]
    # nothing left to move: no second learning
    model = lr.model
    assert lr.pitch_relearn({"applied": False, "kappa": float("nan")}) == 0 and lr.model is model


def test_the_option_needs_the_air_pitch():
    with pytest.raises(InputError, match="--air-pitch-relearn on needs --air-pitch on"):
        LearnOptions(air_pitch=False, air_pitch_relearn=True)
    assert LearnOptions().air_pitch_relearn is False


@pytest.mark.parametrize("flags, expected", [([], False), (["--air-pitch-relearn", "on"], True)])
def test_listen_passes_the_option_and_refuses_it_without_the_air_pitch(monkeypatch, tmp_path, capsys, flags, expected):
    import gcs_sysid.live.session as session
    from gcs_sysid.cli import main

    seen = {}

    def fake_run_listen(airframe, out, opts):
        seen["learn"] = opts.learn
        return {"raw_log": "raw.tlog", "raw_records": 0}

    monkeypatch.setattr(session, "run_listen", fake_run_listen)
    base = ["listen", "udpin:127.0.0.1:14550", "--airframe", str(ROOT / "data" / "airframes" / "sim-trainer.toml"),
            "--out", str(tmp_path / "o")]
    assert main(base + flags, handle_signals=False) == 0 and seen["learn"].air_pitch_relearn is expected
    seen.clear()
    assert main(base + ["--air-pitch", "off", "--air-pitch-relearn", "on"], handle_signals=False) == 2
    assert "--air-pitch-relearn on needs --air-pitch on" in capsys.readouterr().err and not seen
