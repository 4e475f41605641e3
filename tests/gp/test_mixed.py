"""Mixed estimation of single slopes on the GP's training target (gcs_sysid.gp.mixed; numpy only, < 0.5 s)."""

import numpy as np
import pytest

from gcs_sysid.errors import InputError
from gcs_sysid.gp.mixed import apply_slope_prior, mixed_estimate

NAMES = ("beta", "r_hat", "delta_r")


def _ou(rng, n, hz, tau, sd):
    a = np.exp(-1.0 / (hz * tau))
    e = rng.standard_normal(n) * sd * np.sqrt(1 - a * a)
    x = np.zeros(n)
    for i in range(1, n):
        x[i] = a * x[i - 1] + e[i]
    return x


def gust_confounded(n=1500, seed=3, hz=20.0):
    """A side-force flight where the estimator's sideslip misses the gust's part ``b_g`` and the yaw rate follows it:
    ``CY = -1.0 (beta + b_g) + 0 r_hat + 0.1 delta_r + noise``; least squares puts the gust on ``r_hat``."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / hz
    dr = 0.1 * np.sign(np.sin(2 * np.pi * t / 6.0)) * (np.sin(2 * np.pi * t / 23) > 0)
    beta = _ou(rng, n, hz, 2.0, 0.03) + 0.2 * np.convolve(dr, np.ones(20) / 20, "same")
    b_g = _ou(rng, n, hz, 1.0, 0.02)
    r_hat = 0.5 * np.convolve(b_g, np.ones(10) / 10, "same") + 0.3 * _ou(rng, n, hz, 0.5, 0.01) \
        + 0.02 * np.convolve(dr, np.ones(10) / 10, "same")
    cy = -1.0 * (beta + b_g) + 0.1 * dr + 0.002 * rng.standard_normal(n)
    return np.c_[beta, r_hat, dr], cy


def _slopes(X, z):
    return np.linalg.lstsq(np.c_[np.ones(len(X)), X], z, rcond=None)[0][1:]


def test_tight_prior_keeps_the_yaw_rate_slope_at_its_true_value_where_least_squares_does_not():
    X, cy = gust_confounded()
    assert _slopes(X, cy)[1] < -1.0                     # least squares: the gust's side force on r_hat
    Y2, info = apply_slope_prior(X, cy[:, None], NAMES, ("CY",), (("CY", "r_hat", 1e-3),))
    s = _slopes(X, Y2[:, 0])                             # what the GP's mean and kernel see in the target
    assert abs(s[1]) < 0.02 and abs(s[0] + 1.0) < 0.05 and abs(s[2] - 0.1) < 0.03
    assert info["CY"]["ls"]["r_hat"] < -1.0 and abs(info["CY"]["mixed"]["r_hat"]) < 0.02
    # the residual is least squares' own: only the linear part changed
    r_ls = cy - np.c_[np.ones(len(X)), X] @ np.linalg.lstsq(np.c_[np.ones(len(X)), X], cy, rcond=None)[0]
    r_me = Y2[:, 0] - np.c_[np.ones(len(X)), X] @ np.linalg.lstsq(np.c_[np.ones(len(X)), X], Y2[:, 0], rcond=None)[0]
    assert np.allclose(r_ls, r_me, atol=1e-10)
    # sd 0: the slope fixed at 0, the restricted least-squares fit
    th_ls, th_0 = mixed_estimate(X, cy, np.array([np.inf, 0.0, np.inf]))
    restricted = np.linalg.lstsq(np.c_[np.ones(len(X)), X[:, [0, 2]]], cy, rcond=None)[0]
    assert th_0[2] == 0.0 and np.allclose(th_0[[0, 1, 3]], restricted, rtol=1e-8, atol=1e-12)


def test_weak_prior_leaves_a_slope_the_data_determine_and_no_prior_changes_nothing():
    X, cy = gust_confounded()
    th_ls, th_me = mixed_estimate(X, cy, np.array([np.inf, 0.5, np.inf]))
    assert abs(th_me[2] - th_ls[2]) < 0.05 * abs(th_ls[2])      # the data's information dwarfs a 0.5 prior
    Y2, info = apply_slope_prior(X, cy[:, None], NAMES, ("CY",), (("Cn", "r_hat", 1e-3), ("CY", "q_hat", 1e-3)))
    assert info == {} and np.array_equal(Y2[:, 0], cy)
    ls, me = mixed_estimate(X, cy, np.full(3, np.inf))
    assert np.allclose(ls, me, rtol=1e-8, atol=1e-10)


def test_missing_rows_and_bad_input():
    X, cy = gust_confounded(n=400)
    Y = np.c_[cy, cy]
    Y[::7, 0] = np.nan
    Y2, info = apply_slope_prior(X, Y, NAMES, ("CY", "Cn"), (("CY", "r_hat", 1e-3),))
    assert np.isnan(Y2[::7, 0]).all() and np.array_equal(Y2[:, 1], Y[:, 1]) and "CY" in info
    with pytest.raises(InputError):
        mixed_estimate(X, cy, np.array([1.0, -1.0, 1.0]))
    with pytest.raises(InputError):
        mixed_estimate(X, cy[:-1], np.ones(3))


def test_fixed_slopes_are_returned_by_least_squares_of_the_target_and_the_rest_refitted():
    """``apply_fixed_slopes``: least squares of ``y'`` returns the fixed slope exactly, the others are least
    squares of ``y - x_F theta_F`` on the rest, the residual is least squares' own; unknown names are ignored and a
    non-finite slope is refused."""
    from gcs_sysid.gp.mixed import apply_fixed_slopes

    rng = np.random.default_rng(3)
    n = 400
    X = rng.normal(size=(n, 3))
    X[:, 1] += 0.6 * X[:, 0]
    Y = np.c_[0.2 + X @ [1.0, -2.0, 0.5] + 0.1 * rng.normal(size=n), rng.normal(size=n)]
    Y[5, 0] = np.nan
    Y2, info = apply_fixed_slopes(X, Y, ["a", "b", "c"], ["o", "k"], {"o": {"b": -1.5, "zz": 3.0}, "nope": {"a": 1}})
    r = np.isfinite(Y[:, 0])
    A = np.c_[np.ones(r.sum()), X[r]]
    th = np.linalg.lstsq(A, Y2[r, 0], rcond=None)[0]
    assert th[2] == pytest.approx(-1.5)
    rest = np.linalg.lstsq(np.c_[np.ones(r.sum()), X[r][:, [0, 2]]], Y[r, 0] + 1.5 * X[r, 1], rcond=None)[0]
    assert np.allclose(th[[0, 1, 3]], rest)
    th_ls = np.linalg.lstsq(A, Y[r, 0], rcond=None)[0]
    assert np.allclose(Y2[r, 0] - A @ th, Y[r, 0] - A @ th_ls)
    assert np.isnan(Y2[5, 0]) and np.array_equal(Y2[:, 1], Y[:, 1])
    assert info == {"o": {"inputs": ["b"], "ls": {"b": pytest.approx(th_ls[2])}, "fixed": {"b": -1.5}}}
    with pytest.raises(InputError, match="finite"):
        apply_fixed_slopes(X, Y, ["a", "b", "c"], ["o", "k"], {"o": {"a": np.nan}})
