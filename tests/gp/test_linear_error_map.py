"""The band at exact conditions carries the aided angles' flight-common linear error (eleventh session).

A model learned on an angle whose error is ``e_j(x) = M_j (x - mean x)`` is off by ``-dm/dx_j e_j(x)`` at exact
conditions. ``with_offset_covariance(..., map_cov=C)`` (``C[j]`` the second moment of ``M_j``) adds
``(dm/dx_j)^2 (x - mean x)^T C_j (x - mean x)`` in place of ``scale_var_j``; ``docs/gp.md``.
"""

from dataclasses import replace

import numpy as np
import pytest

from gcs_sysid.errors import InputError
from gcs_sysid.gp import load_gp
from gcs_sysid.gp.discrepancy import with_offset_covariance
from gcs_sysid.gp.inputnoise import mean_gradient


def test_map_term_formula_replaces_the_angles_scale_and_is_saved(fitted, flight, tmp_path):
    model, _ = fitted
    model = replace(model, offset_cov=None, scale_var=None, map_cov=None)
    X = flight[0][400:]                                                      # test_model.py's query shape
    D = model.n_inputs
    rng = np.random.default_rng(0)
    L = rng.normal(size=(D, D)) * 0.1
    C = np.zeros((D, D, D))
    C[0] = L @ L.T                                                          # alpha's error along every regressor
    sv = np.zeros(D)
    sv[0], sv[1] = 0.04, 0.09                                               # scales of alpha and beta
    base = model.predict(X, include_noise=False, input_noise=False)[1]
    with_scale = with_offset_covariance(model, None, scale_var=sv)
    both = with_offset_covariance(with_scale, None, map_cov=C)
    only_beta = with_offset_covariance(model, None, scale_var=np.where(np.arange(D) == 1, sv, 0.0))
    v_both = both.predict(X, include_noise=False, input_noise=False)[1]
    v_beta = only_beta.predict(X, include_noise=False, input_noise=False)[1]
    sc = model.scaler
    Xs = np.where(sc.active, (X - sc.x_mean) / sc.x_std, 0.0)
    g = mean_gradient(model.params, model.post, Xs, model.config.batch_size)          # (N, P, D), standardised
    s = np.where(sc.active, sc.x_std, 0.0)
    Cs = C[0] * np.outer(s, s) / sc.x_std[0] ** 2
    expect = g[:, :, 0] ** 2 * np.einsum("nd,de,ne->n", Xs, Cs, Xs)[:, None] * sc.y_std[None, :] ** 2
    np.testing.assert_allclose(v_both - v_beta, expect, rtol=1e-6, atol=1e-14)     # alpha's scale: replaced
    assert (v_beta >= base - 1e-15).all() and (expect > 0).any()
    both.save(tmp_path / "m")
    back = load_gp(tmp_path / "m")
    np.testing.assert_allclose(back.map_cov, both.map_cov)
    np.testing.assert_allclose(back.predict(X, include_noise=False, input_noise=False)[1], v_both, rtol=1e-9)
    np.testing.assert_allclose(model.predict(X)[1], both.predict(X)[1], rtol=1e-12)   # the flight's own band: no
    with pytest.raises(InputError, match="linear-error map"):
        with_offset_covariance(model, None, map_cov=np.zeros((D, D)))
