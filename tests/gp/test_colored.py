"""Coloured residuals (issue 8, calibration): the long-run variance ratio and where it enters the band."""

from dataclasses import replace

import numpy as np
import pytest

from gcs_sysid.gp import load_gp
from gcs_sysid.gp import GPConfig
from gcs_sysid.gp.colored import decorrelation_lag, linear_residual, variance_inflation
from gcs_sysid.gp.fit import hyper_stride_of


def _ar1(n, phi, rng):
    e = rng.standard_normal(n)
    x = np.empty(n)
    x[0] = e[0]
    for t in range(1, n):
        x[t] = phi * x[t - 1] + e[t]
    return x


def test_variance_inflation_of_ar1_white_and_shuffled_residuals():
    """AR(1) residuals with rho(k) = 0.9^k: the factor is the Bartlett-weighted sum up to the first
    lag below 0.05 (k = 29), ~14.6; white or shuffled residuals give ~1."""
    rng = np.random.default_rng(4)
    r = _ar1(40000, 0.9, rng)
    K = int(np.ceil(np.log(0.05) / np.log(0.9)))
    k = np.arange(1, K + 1)
    expected = 1 + 2 * np.sum((1 - k / (K + 1)) * 0.9**k)
    white = rng.standard_normal(40000)
    c = variance_inflation(np.column_stack([r, white, rng.permutation(r)]))
    assert c[0] == pytest.approx(expected, rel=0.15)
    assert 1.0 <= c[1] < 1.1 and 1.0 <= c[2] < 1.1
    np.testing.assert_array_equal(variance_inflation(np.ones((5, 2))), 1.0)     # too few rows


def test_decorrelation_lag_of_ar1_white_and_missing_rows():
    """AR(1) ``phi = 0.9``: ``rho(k) = 0.9^k`` first falls below 1/e at ``k = 10`` (``0.9^9 = 0.387``,
    ``0.9^10 = 0.349``); white noise at lag 1; ``phi = 0.5`` at lag 2 (0.25); NaN rows of a column are dropped."""
    rng = np.random.default_rng(3)
    R = np.column_stack([_ar1(20000, 0.9, rng), rng.standard_normal(20000), _ar1(20000, 0.5, rng)])
    R[::7, 1] = np.nan
    lag = decorrelation_lag(R)
    assert 9 <= lag[0] <= 11 and lag[1] == 1 and lag[2] == 2
    with pytest.raises(ValueError, match="level"):
        decorrelation_lag(R, level=1.0)


def test_hyper_stride_from_the_linear_residuals_decorrelation_time():
    """``GPConfig.hyper_stride = 0``: the median over outputs of the 1/e lags of the ridge fit's residual (a linear
    signal leaves only the coloured noise): two AR(1) 0.9 outputs (lag ~10) and one white (1) give ~10; at most
    ``N // 20``; a given stride is kept."""
    rng = np.random.default_rng(4)
    n = 6000
    X = rng.standard_normal((n, 2))
    E = np.column_stack([_ar1(n, 0.9, rng), _ar1(n, 0.9, rng), rng.standard_normal(n)])
    Y = X @ np.array([[1.0, -2.0, 0.5], [0.3, 1.0, 2.0]]) + 0.5 * E
    R = linear_residual(X, Y)
    assert np.std(R, 0) == pytest.approx(0.5 * np.std(E, 0), rel=0.02)
    active = np.ones(2, bool)
    assert 9 <= hyper_stride_of(X, Y, active, GPConfig(hyper_stride=0)) <= 11
    assert hyper_stride_of(X[:100], Y[:100], active, GPConfig(hyper_stride=0)) <= 5
    assert hyper_stride_of(X, Y, active, GPConfig(hyper_stride=3)) == 3


def test_var_scale_multiplies_only_the_explained_variance_and_is_saved(fitted, flight, tmp_path):
    model, _ = fitted
    X, _, _ = flight
    Xq = X[400:450]
    scaled = replace(model, var_scale=np.array([4.0, 1.0, 1.0, 1.0, 1.0, 1.0]))
    m0, v0 = model.predict_global(Xq, include_noise=False)
    m1, v1 = scaled.predict_global(Xq, include_noise=False)
    np.testing.assert_allclose(m1, m0)
    np.testing.assert_allclose(v1[:, 1:], v0[:, 1:], rtol=1e-10)
    assert np.all(v1[:, 0] > v0[:, 0]) and np.all(v1[:, 0] <= 4.0 * v0[:, 0] + 1e-15)
    back = load_gp(scaled.save(tmp_path / "gp"))
    np.testing.assert_allclose(back.var_scale, scaled.var_scale)
    np.testing.assert_allclose(back.predict(Xq)[1], scaled.predict(Xq)[1], rtol=1e-9)
