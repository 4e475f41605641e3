"""Mean-only inputs (``GPConfig.mean_only_inputs``): the pipeline's ``alpha_dot_hat`` reaches Cm's linear mean
and nothing else (``docs/gp.md``, "Mean-only inputs")."""

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from gcs_sysid.errors import InputError
from gcs_sysid.gp import GPConfig, fit_gp
from gcs_sysid.gp.fit import MEAN_ONLY_LENGTHSCALE, mean_only_masks, rows_without_mean_only
from gcs_sysid.pipeline import ALPHA_DOT_GP, ALPHA_DOT_PARTNER_RULE, gp_inputs

from gp_data import FAST, flight_regressors, linear_truth

CM = COEFFICIENTS.index("Cm")


def _flight(n=1200, seed=5, cm_alpha_dot=-9.0, cm_q=None):
    """Flight-like regressors, an ``alpha_dot_hat`` that is ``q_hat`` plus an independent part (as the
    force equations make it), and the derivative model's coefficients with ``Cm_alpha_dot`` added."""
    X = flight_regressors(n, seed)
    rng = np.random.default_rng(seed + 1)
    adh = X[:, 3] + np.convolve(rng.normal(0, 0.004, n), np.ones(15) / 15, "same")
    Y = linear_truth(X) + rng.normal(0, 1e-3, (n, 6))
    Y[:, CM] += cm_alpha_dot * adh
    if cm_q is not None:                      # replace the derivative model's Cm_q (-12)
        Y[:, CM] += (cm_q + 12.0) * X[:, 3]
    t = np.arange(n) * 0.05
    table = CoefficientTable(t, X, Y, np.ones(n, bool), np.full(n, 5e3), [], alpha_dot_hat=adh)
    return table, adh


def test_alpha_dot_hat_reaches_cm_and_only_cm():
    """The pipeline's inputs carry alpha_dot_hat as the last column; with the pipeline's settings the kernels
    never see it and only Cm's linear mean may carry it, where the data make it significant (the pinned
    length-scale itself is checked by the slow fit below)."""
    table, adh = _flight()
    X, xv = gp_inputs(table, np.ones(len(table.t), bool), True)
    assert X.shape == (len(table.t), len(REGRESSORS) + 1) and np.array_equal(X[:, -1], adh) and xv is None
    cfg = GPConfig(**ALPHA_DOT_GP)
    Xs = (X - X.mean(0)) / X.std(0)
    Ys = (table.Y - table.Y.mean(0)) / table.Y.std(0)
    kernel, allowed, info = mean_only_masks(cfg, REGRESSORS + ("alpha_dot_hat",), COEFFICIENTS, Xs, Ys,
                                            np.ones(11, bool), X.std(0))
    assert kernel.tolist() == [True] * 10 + [False]
    assert allowed[:, -1].tolist() == [c == "Cm" for c in COEFFICIENTS]
    assert allowed[:, :-1].all() and info["outputs"] == {"Cm": ["alpha_dot_hat"]}
    assert "partner" not in info      # Cm_q -12 stays in the fit, |Cm_alpha_dot| 9 < 12
    # without the term in the data the coloured t test leaves it out of Cm too
    table0, _ = _flight(cm_alpha_dot=0.0)
    Y0 = (table0.Y - table0.Y.mean(0)) / table0.Y.std(0)
    _, allowed0, info0 = mean_only_masks(cfg, REGRESSORS + ("alpha_dot_hat",), COEFFICIENTS, Xs, Y0,
                                         np.ones(11, bool))
    assert not allowed0[:, -1].any() and info0["outputs"] == {"Cm": []}
    # a significant slope of the wrong sign (Cm_alpha_dot > 0: what a pitch gust rate gives) is left out too
    table1, _ = _flight(cm_alpha_dot=+9.0)
    Y1 = (table1.Y - table1.Y.mean(0)) / table1.Y.std(0)
    _, allowed1, info1 = mean_only_masks(cfg, REGRESSORS + ("alpha_dot_hat",), COEFFICIENTS, Xs, Y1,
                                         np.ones(11, bool))
    assert not allowed1[:, -1].any() and info1["wrong_sign"] == ["Cm:alpha_dot_hat"]
    # without the switch the inputs are the ten regressors
    assert gp_inputs(table, np.ones(len(table.t), bool), False)[0].shape[1] == len(REGRESSORS)


def test_partner_rule_and_rows_without_alpha_dot_hat():
    """The partner rule (``GPConfig.mean_only_partners``): alpha_dot_hat stays out of Cm's mean when it takes
    more than q_hat's slope (|Cm_alpha_dot| > |Cm_q|) or pushes q_hat out of the fit (no pitch damping left:
    what the F-16's nonlinear Cm did); rows that lack only alpha_dot_hat are training rows when the gates leave
    the column out, and left out when it is kept."""
    cfg = GPConfig(**ALPHA_DOT_GP, **ALPHA_DOT_PARTNER_RULE)
    names = REGRESSORS + ("alpha_dot_hat",)
    for cm_q, why in ((-6.0, "|slope| above 1 x q_hat's"), (0.0, "q_hat not in the fit")):
        table, _ = _flight(cm_q=cm_q)
        X, _ = gp_inputs(table, np.ones(len(table.t), bool), True)
        Xs, Ys = (X - X.mean(0)) / X.std(0), (table.Y - table.Y.mean(0)) / table.Y.std(0)
        _, allowed, info = mean_only_masks(cfg, names, COEFFICIENTS, Xs, Ys, np.ones(11, bool), X.std(0))
        assert not allowed[:, -1].any() and info["partner"] == [f"Cm:alpha_dot_hat: {why}"], info
    # rows without alpha_dot_hat: 100 of 1200
    for cm_alpha_dot, kept in ((0.0, False), (-9.0, True)):
        table, _ = _flight(cm_alpha_dot=cm_alpha_dot)
        X, _ = gp_inputs(table, np.ones(len(table.t), bool), True)
        X[::12, -1] = np.nan
        X2, names2, notes = rows_without_mean_only(X, table.Y, cfg, names, COEFFICIENTS)
        if kept:
            assert X2.shape == X.shape and names2 == names and "left out" in notes[0]
        else:
            assert X2.shape == (1200, 10) and np.isfinite(X2).all() and names2 == REGRESSORS
            assert "on all 1200 rows" in notes[0]
    # nothing to do: no NaN, or no mean-only inputs
    assert rows_without_mean_only(X[1::12], table.Y[1::12], cfg, names, COEFFICIENTS)[2] == []
    assert rows_without_mean_only(X[:, :10], table.Y, GPConfig(), REGRESSORS, COEFFICIENTS)[2] == []


def test_mean_only_inputs_must_be_trailing():
    cfg = GPConfig(mean_only_inputs=("a",), mean_only_outputs=("y",))
    Xs = np.random.default_rng(0).normal(size=(50, 2))
    with pytest.raises(InputError, match="last columns"):
        mean_only_masks(cfg, ("a", "b"), ("y",), Xs, Xs[:, :1], np.ones(2, bool))
    with pytest.raises(InputError, match="sequence of names"):
        GPConfig(mean_only_inputs="alpha_dot_hat")
    with pytest.raises(InputError, match="one partner"):
        GPConfig(mean_only_inputs=("a", "b"), mean_only_partners=("q_hat",))
    with pytest.raises(InputError, match="mean_only_ratio"):
        GPConfig(mean_only_ratio=0.0)


@pytest.mark.slow
def test_fit_learns_cm_alpha_dot_and_queries_may_leave_it_out():
    """A fit with the pipeline's settings: Cm's slope on alpha_dot_hat near the truth's -9 (the q_hat slope
    not absorbing it), every other output's slope exactly 0, the length-scale pinned, and a query without the
    column equals one with it at 0."""
    table, adh = _flight()
    X, _ = gp_inputs(table, np.ones(len(table.t), bool), True)
    from dataclasses import replace

    cfg = replace(FAST, **ALPHA_DOT_GP)
    model, history = fit_gp(X, table.Y, cfg, input_names=REGRESSORS + ("alpha_dot_hat",))
    _, W = model.linear_derivatives()
    assert abs(W[CM, -1] - (-9.0)) < 1.0, W[CM, -1]
    assert abs(W[CM, 3] - (-12.0)) < 1.5, W[CM, 3]
    assert np.all(W[np.arange(6) != CM, -1] == 0.0)
    assert float(np.asarray(model.params.lengthscale)[-1]) == MEAN_ONLY_LENGTHSCALE
    assert history.validation["mean_only"]["outputs"] == {"Cm": ["alpha_dot_hat"]}
    X0 = X.copy()
    X0[:, -1] = 0.0
    m_full, v_full = model.predict(X0[:50])
    m_short, v_short = model.predict(X[:50, :10])
    np.testing.assert_allclose(m_short, m_full)
    np.testing.assert_allclose(v_short, v_full)
