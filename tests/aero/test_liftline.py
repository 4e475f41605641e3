"""The lift line carried across live windows (:class:`gcs_sysid.aero.liftline.LiftLinePool`): on windows whose alpha
carries each its own level error, the slopes come from within the windows, the level is the windows' mean, a line
that moved a window is undone before it joins, and the line's 1-sigma shrinks as windows accumulate."""

import numpy as np
import pytest

from gcs_sysid.aero.liftline import LiftLinePool
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from gcs_sysid.estimation.airangles import AxisFit
from gcs_sysid.estimation.states import FlightStates

LINE = {"CL0": 0.30, "CL_alpha": 5.0, "CL_q": 6.0, "CL_delta_e": 0.4}
MASS, S, QBAR = 1000.0, 16.0, 1500.0


class _Airframe:
    mass, S = MASS, S


def _window(rng, t0, level, shift=0.0, s_w=0.01, moved=False, n=500, dt=0.02):
    """One window: the true alpha and its rows' lift on LINE; alpha in the table is the true one + ``level``
    (the window's own error) + ``shift`` (a line's move); the force coefficients from the true lift and a drag."""
    t = t0 + dt * np.arange(n)
    a_true = 0.05 + 0.6 * level + 0.03 * np.sin(0.7 * t) + 0.01 * rng.standard_normal(n)
    q_hat = 0.004 * np.sin(1.3 * t + 1.0) + 0.001 * rng.standard_normal(n)
    de = -0.05 + 0.02 * np.sin(0.5 * t + 2.0) + 0.003 * rng.standard_normal(n)
    CL = LINE["CL0"] + LINE["CL_alpha"] * a_true + LINE["CL_q"] * q_hat + LINE["CL_delta_e"] * de
    CD = 0.03 + 0.05 * CL**2
    CX = -CD * np.cos(a_true) + CL * np.sin(a_true)          # wind axes to body axes at the true alpha
    CZ = -CD * np.sin(a_true) - CL * np.cos(a_true)
    X = np.zeros((n, len(REGRESSORS)))
    X[:, REGRESSORS.index("alpha")] = a_true + level + shift
    X[:, REGRESSORS.index("q_hat")] = q_hat
    X[:, REGRESSORS.index("delta_e")] = de
    Y = np.full((n, len(COEFFICIENTS)), np.nan)
    Y[:, 0], Y[:, 2] = CX, CZ
    qbar = np.full(n, QBAR)
    tab = CoefficientTable(t, X, Y, np.ones(n, bool), qbar)
    fit = AxisFit(name="alpha", used=True, reason="", mean_shift=shift, bias_sigma=s_w / 2 if moved else s_w,
                  wind_sigma=s_w if moved else float("nan"))
    st = FlightStates(t, 1 / dt, {"ax": CX * QBAR * S / MASS}, angle_fits={"alpha": fit})
    return tab, st


def test_line_from_windows_with_their_own_levels():
    """Levels of -2..+2 deg that no slope explains: the within-window slopes are the line's (the pooled slope
    would read the levels' spread), CL0 is off by CL_alpha times the windows' mean level, and a window moved by a
    carried line (its ``mean_shift``) joins at its own level."""
    rng = np.random.default_rng(3)
    levels = np.radians([-2.0, 1.5, 2.0, -0.5, 0.8])
    pool = LiftLinePool(window_s=30.0)
    for k, lv in enumerate(levels):
        moved = k >= 2
        tab, st = _window(rng, 10.0 * k, lv, shift=np.radians(1.7) if moved else 0.0, moved=moved)
        assert pool.add(tab, np.ones(len(tab.t), bool), st, _Airframe()) == len(tab.t)
    ln = pool.line()
    # the rotation through the window's own (level-shifted) alpha moves the lift by CD * sin(level): small
    assert ln["CL_alpha"] == pytest.approx(LINE["CL_alpha"], rel=0.02)
    assert ln["CL_q"] == pytest.approx(LINE["CL_q"], rel=0.1)
    assert ln["CL_delta_e"] == pytest.approx(LINE["CL_delta_e"], abs=0.1)
    assert ln["CL0"] == pytest.approx(LINE["CL0"] - LINE["CL_alpha"] * levels.mean(), abs=0.01)
    # the pooled least squares (one intercept) reads the levels' spread into the slope: what the within estimator
    # avoids (here 2.6/rad against 5.0)
    rng, A, L = np.random.default_rng(3), [], []
    for k, lv in enumerate(levels):
        tab = _window(rng, 10.0 * k, lv)[0]
        a = tab.x("alpha")
        A.append(np.c_[np.ones(len(a)), a, tab.x("q_hat"), tab.x("delta_e")])
        L.append(-tab.Y[:, 2] * np.cos(a) + tab.Y[:, 0] * np.sin(a))
    pooled = np.linalg.lstsq(np.concatenate(A), np.concatenate(L), rcond=None)[0]
    assert pooled[1] < 0.8 * LINE["CL_alpha"]


def test_sigma_shrinks_as_windows_accumulate_and_none_before():
    """No line before MIN_LINE_S of rows; the line's 1-sigma is CL_alpha * s_w / sqrt(span / window) (at least one
    window's worth), so it halves from 30 s to 120 s of rows."""
    rng = np.random.default_rng(5)
    pool = LiftLinePool(window_s=30.0)
    tab, st = _window(rng, 0.0, 0.0, n=100)                 # 2 s of rows
    pool.add(tab, np.ones(100, bool), st, _Airframe())
    assert pool.line() is None and "none yet" in pool.note()
    sig = []
    for k in range(12):
        tab, st = _window(rng, 2.0 + 10.0 * k, 0.0)
        pool.add(tab, np.ones(len(tab.t), bool), st, _Airframe())
        sig.append(pool.line()["CL0_sigma"])
    assert sig[1] == pytest.approx(sig[0], rel=0.05)        # 12 s, 22 s of rows: one window's worth
    span = pool.span_s
    assert sig[-1] == pytest.approx(LINE["CL_alpha"] * 0.01 / np.sqrt(span / 30.0), rel=0.03)
    assert "lift line from 13 windows" in pool.note()


def test_rows_outside_the_mask_and_non_finite_rows_stay_out():
    rng = np.random.default_rng(7)
    pool = LiftLinePool()
    tab, st = _window(rng, 0.0, 0.0)
    rows = np.zeros(len(tab.t), bool)
    rows[:300] = True
    tab.X[:10, REGRESSORS.index("q_hat")] = np.nan
    assert pool.add(tab, rows, st, _Airframe()) == 290
    assert pool.add(tab, np.zeros(len(tab.t), bool), st, _Airframe()) == 0 and pool.windows == 1
    with pytest.raises(ValueError, match="window_s"):
        LiftLinePool(window_s=0.0)
