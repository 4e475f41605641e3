"""Standard errors of a named term that cover the truth on coloured residuals (issue 9, ninth session).

Fast (< 2 s together). A synthetic regression with AR(1) noise, as a gust-driven residual on a 90-s flight
at 50 Hz: the white least-squares standard error ``s^2 (X'X)^-1`` covers the true slope far less often
than 95 %, the diagnosis's type-A standard error (:func:`gcs_sysid.diagnose.uncertainty.type_a`: the larger
of Morelli and Klein's coloured form and the Kuensch block jackknife) covers it at about 95 %. Fails if the
standard error ignores the colour of the residual.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from gcs_sysid.diagnose.regression import ols
from gcs_sysid.diagnose.uncertainty import (air_data_uncertainty, angle_sensitivity, block_jackknife_cov, combine,
                                            fit_standard_errors, type_a)


def _ar1(rng, n, phi, sd):
    """Stationary AR(1) with standard deviation ``sd``."""
    e = rng.standard_normal(n) * sd * np.sqrt(1 - phi**2)
    e[0] = rng.standard_normal() * sd
    return lfilter([1.0], [1.0, -phi], e)


def test_type_a_standard_error_covers_a_slope_under_ar1_noise_where_the_white_one_does_not():
    rng = np.random.default_rng(7)
    n, dt, reps, theta = 4500, 0.02, 80, 0.8
    t = np.arange(n) * dt
    white = ours = 0
    for _ in range(reps):
        # a manoeuvre-like regressor (two slow sines, random phases) and a gust-like AR(1) residual (tau 1 s)
        x = (np.sin(2 * np.pi * 0.07 * t + rng.uniform(0, 6.3))
             + 0.5 * np.sin(2 * np.pi * 0.23 * t + rng.uniform(0, 6.3)))
        v = _ar1(rng, n, np.exp(-dt / 1.0), 0.5)
        A = np.column_stack([np.ones(n), x])
        y = theta * x + v
        w = ols(A, y, ["1", "x"], colored=False)
        white += abs(w.theta[1] - theta) <= 2 * w.std_error[1]
        res = fit_standard_errors(t, A, y, ["1", "x"])
        ours += abs(res["theta"][1] - theta) <= 2 * type_a(res)[1]
    print(f"2-se coverage: white {white / reps:.2f}, type A {ours / reps:.2f}")
    assert white / reps < 0.6, white / reps          # the white form under-covers badly
    assert ours / reps >= 0.88, ours / reps         # about 95 % (the jackknife has few blocks)


def test_block_jackknife_is_the_white_variance_on_white_noise_and_needs_three_blocks():
    rng = np.random.default_rng(3)
    n = 9000
    t = np.arange(n) * 0.02
    x = rng.standard_normal(n)
    A = np.column_stack([np.ones(n), x])
    y = 0.3 * x + rng.standard_normal(n)
    cov = block_jackknife_cov(t, A, y, 15.0)
    se_white = ols(A, y, ["1", "x"], colored=False).std_error[1]
    assert 0.5 < np.sqrt(cov[1, 1]) / se_white < 2.0
    assert block_jackknife_cov(t[:1400], A[:1400], y[:1400], 15.0) is None    # 28 s: two blocks


def test_air_angle_type_b_propagates_scale_and_offset_through_the_fit():
    rng = np.random.default_rng(1)
    n = 3000
    a = 0.05 * rng.standard_normal(n)
    X = np.zeros((n, 10))
    X[:, 0] = a - a.mean()
    r = -2.0 * X[:, 0]
    rows = np.arange(n)

    def lin(Xp):
        return np.column_stack([np.ones(len(Xp)), Xp[:, 0]])

    def beta_only(Xp):
        return np.column_stack([np.ones(len(Xp)), Xp[:, 1] + 1.0])

    u = angle_sensitivity(lin, X, r, rows, 1, 0, scale=0.05, offset=0.01)
    assert abs(u["scale"] - 0.05 * 2.0) < 0.01 and u["offset"] < 1e-9      # a linear term: u_s theta; no offset effect
    assert angle_sensitivity(beta_only, X, r, rows, 1, 0, 0.05, 0.01) == {"scale": 0.0, "offset": 0.0}
    assert abs(combine({"a": 3.0, "b": 4.0, "c": float("nan"), "d": None}) - 5.0) < 1e-12


def test_scale_type_b_of_a_power_term_is_first_order_at_a_small_step():
    """A term in alpha^2 (the change -8 read on an alpha with a stated scale uncertainty of 0.98): at +- u the minus
    branch shrinks alpha's excursions to 2 % and the coefficient comes out 2500 times its size; at a 0.1 step times
    u / step it is the first-order sensitivity, 2 |theta| u (theta scales as (1 + s)^-2); below the step nothing
    changes."""
    rng = np.random.default_rng(2)
    n = 4000
    X = np.zeros((n, 10))
    X[:, 0] = 0.05 + 0.04 * rng.standard_normal(n)
    r = -8.0 * X[:, 0] ** 2
    rows = np.arange(n)

    def quad(Xp):
        return np.column_stack([np.ones(len(Xp)), Xp[:, 0], Xp[:, 0] ** 2])

    at_u = angle_sensitivity(quad, X, r, rows, 2, 0, scale=0.98, offset=0.0)["scale"]
    first = angle_sensitivity(quad, X, r, rows, 2, 0, scale=0.98, offset=0.0, scale_step=0.1)["scale"]
    assert at_u > 1000 * 8.0
    assert first == pytest.approx(2 * 8.0 * 0.98, rel=0.03)
    small = angle_sensitivity(quad, X, r, rows, 2, 0, scale=0.05, offset=0.01)
    assert angle_sensitivity(quad, X, r, rows, 2, 0, scale=0.05, offset=0.01, scale_step=0.1) == small


def test_air_data_uncertainty_reads_the_estimators_own_fits():
    class Fit:
        used, coef, coef_sigma, bias_sigma, scale_sigma = (True, np.array([0.0, -5.0]), np.array([np.nan, 0.1]),
                                                            0.002, 0.03)

    u = air_data_uncertainty({"alpha": Fit()})
    assert abs(u["alpha"]["scale"] - np.hypot(0.02, 0.03)) < 1e-12 and u["alpha"]["offset_rad"] == 0.002
    assert u["beta"] == {"scale": 0.0, "offset_rad": 0.0}
    both = air_data_uncertainty({"alpha": Fit()}, {"alpha": Fit()})
    assert abs(both["alpha"]["offset_rad"] - np.sqrt(2) * 0.002) < 1e-12
