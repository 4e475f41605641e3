"""The live learner's pooled regressor errors (`gcs_sysid.aero.errorpool`): the row-weighted second moments of the
windows' statements, and the rolling gust's share as a ratio of pooled variances."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import gcs_sysid.aero.airyaw as airyaw
import gcs_sysid.aero.gustfilter as gustfilter
from gcs_sysid.aero.errorpool import POOL_STATE_KEYS, WindowErrorPool
from gcs_sysid.aero.rateerrors import roll_rate_scale, roll_rate_variances
from gcs_sysid.aero.table import REGRESSORS, CoefficientTable

D = len(REGRESSORS)
IP, IR = REGRESSORS.index("p_hat"), REGRESSORS.index("r_hat")


def _table(T=600, seed=0, off=None, sv=None, mc=None):
    rng = np.random.default_rng(seed)
    return CoefficientTable(np.arange(T) * 0.02, rng.normal(size=(T, D)), rng.normal(size=(T, 6)), np.ones(T, bool),
                            np.full(T, 500.0), [], off, None, sv, mc)


def _states(T):
    return SimpleNamespace(data={k: np.zeros(T) for k in POOL_STATE_KEYS["data"]}, sigma={})


def test_statements_are_the_row_weighted_means_of_the_windows_that_state_them():
    pool = WindowErrorPool(rate_errors=False)
    c1, c2 = np.eye(D) * 1e-4, np.eye(D) * 4e-4
    s1, s2 = np.full(D, 0.01), np.full(D, 0.04)
    m1 = np.zeros((D, D, D))
    m1[0] = np.eye(D) * 0.02
    rows = np.zeros(600, bool)
    pool.add(_table(off=c1, sv=s1, mc=m1), np.r_[rows[:100] | True, rows[100:]])          # 100 rows
    pool.add(_table(off=c2, sv=s2), np.r_[rows[:300] | True, rows[300:]])                 # 300 rows, no map
    pool.add(_table(), np.r_[rows[:200] | True, rows[200:]])                              # states nothing
    pool.add(_table(off=c2), rows)                                                        # no rows: not counted
    off, sv, mc, note = pool.statement()
    assert pool.windows == 3 and pool.rows == 600
    assert np.allclose(off, (100 * c1 + 300 * c2) / 400) and np.allclose(sv, (100 * s1 + 300 * s2) / 400)
    assert np.allclose(mc, m1)                  # only the first window stated a map
    assert "pooled over 3 windows, 600 rows" in note and "alpha offset 0.0180 rad rms (400 rows)" in note
    assert "p_hat" not in note                  # rate_errors off: nothing said of the rates
    assert WindowErrorPool(rate_errors=False).statement()[:3] == (None, None, None)
    with pytest.raises(ValueError, match=r"rows must be \(600,\)"):
        pool.add(_table(), np.ones(5, bool))


def test_the_rolling_gusts_share_is_a_ratio_of_pooled_variances(monkeypatch):
    """rho = sum n var(g) / sum n var(p_hat) over the windows whose fit was accepted, each on its valid rows up to the
    last row it hands over; a refused window adds nothing to it and says why."""
    T = 600
    tabs = [_table(T, seed=s) for s in range(3)]
    for k, tab in enumerate(tabs):          # p_hat's variance differs by window: the two means would differ
        tab.X[:, IP] *= (1.0, 0.2, 3.0)[k]
    gs = [0.5 * tab.X[:, IP] + 0.1 * np.random.default_rng(9).normal(size=T) for tab in tabs]
    seen = []

    def fake_fit(table, states, airframe, train):
        seen.append(np.asarray(train).copy())
        k = next(i for i, tab in enumerate(tabs) if tab is table)
        return "gust filter not run: refused here" if k == 2 else SimpleNamespace(g=gs[k], used=np.ones(T, bool))

    monkeypatch.setattr(gustfilter, "air_roll_fit", fake_fit)
    monkeypatch.setattr(airyaw, "yaw_gust_hat", lambda states, b: (None, "no yaw gust rate: test"))
    pool = WindowErrorPool(rate_errors=True)
    n = (250, 400, 300)
    for tab, k in zip(tabs, n):
        rows = np.zeros(T, bool)
        rows[100:100 + k] = True
        pool.add(tab, rows, _states(T), SimpleNamespace(b=2.0))
    assert [int(s.sum()) for s in seen] == [350, 500, 400]        # rows up to the last handed over
    v = [roll_rate_variances(SimpleNamespace(g=gs[k], used=np.ones(T, bool)), tabs[k], seen[k]) for k in (0, 1)]
    rho = (n[0] * v[0][0] + n[1] * v[1][0]) / (n[0] * v[0][1] + n[1] * v[1][1])
    off, sv, mc, note = pool.statement()
    assert off is None and mc is None
    assert sv[IP] == pytest.approx(rho**2, rel=1e-12) and np.count_nonzero(sv) == 1
    assert f"p_hat scale error {rho:.2f} (650 rows)" in note and "r_hat: none (no yaw gust rate: test)" in note
    pool.add(tabs[2], np.ones(T, bool), _states(T), SimpleNamespace(b=2.0))     # refused again: said as the replay says
    assert "p_hat" in pool.statement()[3] and pool._why_roll == "no roll fit: refused here"
    assert roll_rate_scale(SimpleNamespace(g=gs[0], used=np.ones(T, bool)), tabs[0], seen[0]) == \
        pytest.approx(v[0][0] / v[0][1])


def test_a_window_without_the_states_adds_no_rates_and_says_which():
    pool = WindowErrorPool(rate_errors=True)
    pool.add(_table(off=np.eye(D) * 1e-4), np.ones(600, bool), SimpleNamespace(data={"p": np.zeros(600)}, sigma={}),
             SimpleNamespace(b=2.0))
    off, sv, mc, note = pool.statement()
    assert off is not None and sv is None and mc is None
    assert "p_hat: none (no wn we wd phi theta psi V in the window's states)" in note
