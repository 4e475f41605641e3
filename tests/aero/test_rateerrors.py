"""The gyro rates' stated errors for the band at exact conditions (gcs_sysid.aero.rateerrors)."""

from types import SimpleNamespace

import numpy as np
import pytest

from gcs_sysid.aero.rateerrors import roll_rate_scale, stated_rate_errors, yaw_rate_map
from gcs_sysid.aero.table import REGRESSORS

IP, IR, IB = REGRESSORS.index("p_hat"), REGRESSORS.index("r_hat"), REGRESSORS.index("beta")
DT = 0.02


def _ar1(rng, n, tau, sd):
    a = np.exp(-DT / tau)
    e = rng.normal(0.0, sd * np.sqrt(1 - a * a), n)
    x = np.empty(n)
    x[0] = rng.normal(0.0, sd)
    for k in range(1, n):
        x[k] = a * x[k - 1] + e[k]
    return x


def _table(X, scale_var=None, map_cov=None):
    n = len(X)
    return SimpleNamespace(t=np.arange(n) * DT, X=X, valid=np.ones(n, bool), x_scale_var=scale_var,
                           x_map_cov=map_cov)


def _flight(seed=0, n=6000, gust_sd=0.006):
    """Regressors with the gyro's p_hat = the air-relative rate + an independent rolling gust."""
    rng = np.random.default_rng(seed)
    X = np.column_stack([_ar1(rng, n, 2.0, s) for s in (0.02, 0.03, 0.01, 0.01, 0.1, 0.1, 0.05, 0.05, 0.01, 3.0)])
    X[:, 9] += 20.0
    p_air = X[:, IP].copy()
    g = _ar1(rng, n, 1.5, gust_sd)
    X[:, IP] = p_air + g
    return X, p_air, g


def test_roll_scale_is_the_gusts_share_and_bounds_the_attenuated_slope():
    """rho = var(g)/var(p_hat); a least-squares Cl_p on the gyro's rate is attenuated by about rho, and the stated
    scale error (the model's slope times rho, 1 sigma) holds the slope's actual error within 2 sigma at rho ~ 0.3."""
    X, p_air, g = _flight()
    fit = SimpleNamespace(g=g, used=np.ones(len(g), bool))
    train = np.ones(len(g), bool)
    rho = roll_rate_scale(fit, _table(X), train)
    assert rho == pytest.approx(np.var(g) / np.var(X[:, IP]), rel=1e-9)
    assert 0.2 < rho < 0.45
    Cl_p = -0.45
    Cl = Cl_p * p_air + 0.0005 * np.random.default_rng(1).normal(size=len(g))
    A = np.column_stack([np.ones(len(g)), X[:, IP]])
    b = np.linalg.lstsq(A, Cl, rcond=None)[0][1]
    assert b / Cl_p == pytest.approx(1 - rho, abs=0.05)          # attenuated by the reliability ratio
    assert abs(b - Cl_p) > abs(b) * rho                            # the first-order statement is not generous ...
    assert abs(b - Cl_p) < 2 * abs(b) * rho                        # ... but holds the error within 2 sigma


def test_roll_scale_needs_rows_and_shapes():
    X, _, g = _flight(n=400)
    fit = SimpleNamespace(g=g, used=np.zeros(len(g), bool))
    fit.used[:100] = True
    assert roll_rate_scale(fit, _table(X), np.ones(len(g), bool)) is None       # 100 rows < 150
    with pytest.raises(ValueError, match="roll_rate_scale"):
        roll_rate_scale(SimpleNamespace(g=g[:-1], used=fit.used), _table(X), np.ones(len(g), bool))


def test_yaw_map_recovers_the_gust_rates_slope_on_the_sideslip():
    """r_hat_g = -0.2 beta + white: the map's beta entry is ~0.04 (M M^T), a constant regressor has none."""
    rng = np.random.default_rng(2)
    X, _, _ = _flight(seed=3)
    X[:, REGRESSORS.index("delta_r")] = 0.01                  # constant: no column
    r_g = -0.2 * X[:, IB] + 0.002 * rng.normal(size=len(X))
    C = yaw_rate_map(_table(X), r_g, np.ones(len(X), bool))
    assert C.shape == (10, 10)
    assert np.sqrt(C[IB, IB]) == pytest.approx(0.2, rel=0.05)
    assert np.all(C[REGRESSORS.index("delta_r")] == 0)
    others = [j for j in range(10) if j != IB]
    assert np.sqrt(np.max(np.diag(C)[others])) < 0.02
    train = np.zeros(len(X), bool)
    train[:100] = True
    assert yaw_rate_map(_table(X), r_g, train) is None
    with pytest.raises(ValueError, match="yaw_rate_map"):
        yaw_rate_map(_table(X), r_g[:-1], np.ones(len(X), bool))


def test_stated_errors_add_to_copies_and_say_what_is_missing():
    X, _, g = _flight(seed=4)
    n = len(X)
    sv0, mc0 = np.full(10, 0.01), np.zeros((10, 10, 10))
    mc0[IB, IB, IB] = 0.02
    tab = _table(X, sv0.copy(), mc0.copy())
    fit = SimpleNamespace(g=g, used=np.ones(n, bool))
    r_g = 0.1 * X[:, IB]
    sv, mc, note = stated_rate_errors(tab, np.ones(n, bool), fit, r_g)
    assert np.array_equal(tab.x_scale_var, sv0) and np.array_equal(tab.x_map_cov, mc0)      # the table untouched
    assert sv[IP] == pytest.approx(roll_rate_scale(fit, tab, np.ones(n, bool)) ** 2)
    assert np.delete(sv, IP) == pytest.approx(np.delete(sv0, IP))
    assert mc[IB, IB, IB] == 0.02 and mc[IR, IB, IB] == pytest.approx(0.01, rel=0.01)
    assert "p_hat scale error" in note and "r_hat linear error" in note
    sv, mc, note = stated_rate_errors(_table(X), np.ones(n, bool), "gust filter not run: no p on the table's grid",
                                      None)
    assert sv is None and mc is None
    assert "p_hat: none (no roll fit: no p on the table's grid)" in note and "r_hat: none (no yaw gust rate" in note
