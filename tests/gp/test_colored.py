"""Coloured residuals (issue 8, calibration): the long-run variance ratio and where it enters the band."""

from dataclasses import replace

import numpy as np
import pytest

from gcs_sysid.gp import load_gp
from gcs_sysid.gp.colored import variance_inflation


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
