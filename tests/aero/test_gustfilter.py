"""The filter-error rolling gust (gcs_sysid.aero.gustfilter) on a synthetic roll-moment record.

The record is built here, not flown: a first-order Gauss-Markov ``p_hat_g`` with a known correlation time and
intensity, regressors driven by random controls (open loop, so the controls are valid instruments), and
``Cl = theta . x - Cl_p p_hat_g + white noise``. The test checks the mechanism (the gust state and its fitted
process model), not a claim about JSBSim's turbulence.
"""

import numpy as np
import pytest
from scipy.signal import lfilter

from gcs_sysid.aero import gustfilter as gf
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS

DT, TAU, SIG, CLP, R_NOISE = 0.02, 0.8, 0.01, -0.5, 2e-4**2
THETA = {"alpha": 0.0, "beta": -0.08, "p_hat": CLP, "r_hat": 0.12, "delta_a": -0.2, "delta_r": 0.01}


def _lowpass(x, tau):
    a = np.exp(-DT / tau)
    return lfilter([1 - a], [1, -a], x)


def _record(n=6000, seed=0):
    rng = np.random.default_rng(seed)
    a = np.exp(-DT / TAU)
    g = lfilter([np.sqrt(1 - a * a) * SIG], [1, -a], rng.normal(size=n))
    # controls: smoothed random steps (exogenous); the rates and sideslip respond to them
    da = np.repeat(rng.normal(0, 0.1, n // 50 + 1), 50)[:n]
    dr = np.repeat(rng.normal(0, 0.05, n // 70 + 1), 70)[:n]
    X = np.zeros((n, len(REGRESSORS)))
    col = REGRESSORS.index
    X[:, col("alpha")] = 0.05 + 0.01 * rng.normal(size=n).cumsum() / np.sqrt(n)
    X[:, col("delta_a")], X[:, col("delta_r")] = da, dr
    X[:, col("p_hat")] = _lowpass(-0.5 * da, 0.3) + 0.002 * _lowpass(rng.normal(size=n), 2.0)
    X[:, col("r_hat")] = _lowpass(0.2 * dr + 0.1 * da, 0.6) + 0.002 * _lowpass(rng.normal(size=n), 2.0)
    X[:, col("beta")] = _lowpass(0.5 * dr, 0.8) + 0.005 * _lowpass(rng.normal(size=n), 2.0)
    X[:, col("V")] = 30.0
    Y = np.zeros((n, len(COEFFICIENTS)))
    Y[:, COEFFICIENTS.index("Cl")] = (sum(v * X[:, col(k)] for k, v in THETA.items()) - CLP * g
                                      + rng.normal(0, np.sqrt(R_NOISE), n))
    return X, Y, g


def test_recovers_known_rolling_gust():
    """Cl_p, tau and sigma are recovered and the smoothed p_hat_g follows the true one (120 s at 50 Hz); with
    the gust state removed (its intensity forced to zero) the smoother returns the prior mean and misses the
    gust by its whole SD."""
    X, Y, g = _record()
    rows = np.ones(len(X), bool)
    rows[1200:1500] = False                       # a held-out block: never used, prior mean there
    G = gf.fit_roll_gust(DT, X, Y, rows, R=R_NOISE)
    u = G.used
    assert G.g.shape == (len(X),) and G.g_var.shape == (len(X),)
    assert not u[1200:1500].any() and np.all(G.g[1200:1500] == 0.0)
    assert np.allclose(G.g_var[1200:1500], G.sigma**2)
    # bounds hold on seeds 0-7 (Cl_p -0.41..-0.54, tau 0.70..0.88 s, sigma 0.0089..0.0117, RMS error 0.11..0.38 SIG)
    assert abs(G.Cl_p - CLP) < 0.1
    assert 0.6 * TAU < G.tau < 1.4 * TAU
    assert 0.75 * SIG < G.sigma < 1.33 * SIG
    err = G.g[u] - g[u]
    assert np.corrcoef(G.g[u], g[u])[0, 1] > 0.93
    assert np.sqrt(np.mean(err**2)) < 0.5 * SIG
    assert np.all(G.g_var[u] < SIG**2)            # the smoother knows more than the prior

    # the same filter without the gust state: the smoothed gust is its prior mean, 0
    gains = gf._gains(np.exp(-DT / TAU), 0.0, -CLP, R_NOISE)
    A = np.c_[np.ones(u.sum()), X[u][:, [REGRESSORS.index(k) for k in gf.LAT_TERMS]]]
    g0 = gf._smooth(Y[u, COEFFICIENTS.index("Cl")] - A @ G.theta, np.exp(-DT / TAU), gains, -CLP)
    assert np.sqrt(np.mean((g0 - g[u]) ** 2)) > 0.9 * SIG


def test_bad_input_raises():
    X, Y, _ = _record(n=400)
    with pytest.raises(ValueError, match="usable rows"):
        gf.fit_roll_gust(DT, X, Y, np.r_[np.ones(150, bool), np.zeros(250, bool)])
    with pytest.raises(ValueError, match="X \\(T, 10\\)"):
        gf.fit_roll_gust(DT, X[:, :5], Y, np.ones(400, bool))
    with pytest.raises(ValueError, match="dt must be positive"):
        gf.fit_roll_gust(0.0, X, Y, np.ones(400, bool))
