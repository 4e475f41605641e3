"""The pitch gust rate's moment removed from Cm's residual (gcs_sysid.diagnose.gust_nuisance, opt-in)."""

from types import SimpleNamespace

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.gust_nuisance import pitch_gust_column, pitch_gust_nuisance
from gcs_sysid.estimation.gustrates import lag_filter

B, C, V0, DT = 12.0, 1.6, 60.0, 0.02


def _ctx(T=3000, seed=3, states=True):
    """Level flight due north (body axes = NED) at V0 through a smoothed random vertical gust ``wd``."""
    rng = np.random.default_rng(seed)
    t = np.arange(T) * DT
    wd = lag_filter(DT, rng.normal(size=T), 0.2) * 6.0
    X = np.zeros((T, len(REGRESSORS)))
    X[:, REGRESSORS.index("V")] = V0
    X[:, REGRESSORS.index("alpha")] = 0.05 + 0.004 * np.sin(0.3 * t)
    st = {"phi": np.zeros(T), "theta": np.zeros(T), "psi": np.zeros(T), "wn": np.full(T, 3.0),
          "we": np.zeros(T), "wd": wd} if states else {}
    valid = np.ones(T, bool)
    ctx = DiagContext(t, X, np.zeros((T, 6)), np.full(T, 2000.0), valid, st, SimpleNamespace(b=B, c=C), {},
                      valid.copy(), np.zeros(T, bool))
    return ctx, wd, rng


def test_the_column_is_the_dryden_gradient_of_the_vertical_gust_normalised_like_q_hat():
    ctx, wd, _ = _ctx()
    # body axes = NED: q_g = -(s/V)/(1 + 4b s/(pi V)) w_g (Etkin's sign), then q_g c / (2V)
    want = -lag_filter(DT, np.gradient(wd, DT) / V0, 4 * B / (np.pi * V0)) * C / (2 * V0)
    assert pitch_gust_column(ctx) == pytest.approx(want, rel=1e-9, abs=1e-12)


def test_the_nuisance_takes_the_gust_moment_out_of_cm_alone_with_a_free_sign():
    ctx, _, rng = _ctx()
    g = pitch_gust_column(ctx)
    jm = COEFFICIENTS.index("Cm")
    a = ctx.X[:, REGRESSORS.index("alpha")]
    effect = -8.0 * a**2
    for slope in (+2.0, -2.4):                    # either sign (JSBSim and Etkin disagree)
        R = 1e-4 * rng.normal(size=(len(ctx.t), 6))
        R[:, jm] += slope * g + effect + 0.003
        tr = np.arange(2400)
        N, info = pitch_gust_nuisance(ctx, R, tr)
        assert info["slope"] == pytest.approx(slope, rel=0.02)
        assert abs(info["t"]) > 20
        assert np.all(N[:, [j for j in range(6) if j != jm]] == 0.0)
        left = (R - N)[:, jm]
        # what is left is the effect (and the constant), on the untouched rows too
        te = np.arange(2400, 3000)
        e = left[te] - effect[te]
        assert np.std(e) < 0.1 * np.std(slope * g[te])           # the white noise (1e-4) is left


def test_without_the_states_or_with_cm_inactive_nothing_is_removed():
    ctx, _, _ = _ctx(states=False)
    R = np.ones((len(ctx.t), 6))
    N, info = pitch_gust_nuisance(ctx, R, np.arange(100))
    assert not N.any() and "skipped" in info
    ctx, _, _ = _ctx()
    ctx.active[COEFFICIENTS.index("Cm")] = False
    N, info = pitch_gust_nuisance(ctx, R, np.arange(100))
    assert not N.any() and info["skipped"] == "Cm not active"


def test_a_given_slope_is_used_as_given_and_the_flight_s_own_is_reported():
    ctx, _, rng = _ctx()
    g = pitch_gust_column(ctx)
    jm = COEFFICIENTS.index("Cm")
    R = 1e-4 * rng.normal(size=(len(ctx.t), 6))
    R[:, jm] += 2.0 * g
    tr = np.arange(2400)
    N, info = pitch_gust_nuisance(ctx, R, tr, slope=1.5)
    assert info["slope"] == 1.5 and info["own_slope"] == pytest.approx(2.0, rel=0.02)
    assert N[:, jm] == pytest.approx(1.5 * (g - g[tr].mean()))
