"""Issue 8: the band at a flight's own regressors takes the estimator's stated air-angle variance.

The NIGP input noise (``gp/inputnoise.py``) is learned from the GP's residuals. An air angle aided by the
specific force is built partly from the measured force coefficient, so its error moves that coefficient
with it: the residual ``y - m(x_est)`` does not show it, the learned input noise stays small, and the
band with noise under-covers the truth (t6, light turbulence: CY 64-70 %, CZ 59-68 %). The estimator
states the angle's per-row 1-sigma (``FlightStates.sigma``); ``CoefficientTable.x_var`` carries it, less
the flight-common offset, and ``predict(X, x_var=...)`` uses the larger of it and the learned variance.
"""

from dataclasses import replace

import numpy as np
import pytest

from gcs_sysid.aero import compute_coefficients
from gcs_sysid.aero.coefficients import stated_input_variance
from gcs_sysid.errors import InputError
from gcs_sysid.estimation.states import FlightStates

from gp_data import FAST, flight_regressors, linear_truth


def test_stated_input_variance_is_sigma_less_the_common_offset():
    n = 5
    sa = np.radians(np.array([0.05, 0.04, np.nan, 0.03, 0.02]))
    st = FlightStates(np.arange(n) * 0.02, 50.0, {}, sigma={"alpha": sa, "beta": np.full(n, 0.001),
                                                           "p": np.full(n, 0.01)},
                      offsets={"alpha": np.radians(0.03)})
    xv = stated_input_variance(st)
    assert xv.shape == (n, 10)
    np.testing.assert_allclose(xv[:, 0], [sa[0] ** 2 - np.radians(0.03) ** 2, sa[1] ** 2 - np.radians(0.03) ** 2,
                                          np.nan, 0.0, 0.0], rtol=1e-12)      # not aided: NaN; below: 0
    np.testing.assert_allclose(xv[:, 1], 1e-6)                               # no offset for beta
    assert np.isnan(xv[:, 2:]).all()                                         # rates: the learned noise only
    assert stated_input_variance(FlightStates(np.arange(n) * 0.02, 50.0, {})) is None
    # the table carries it (compute_coefficients), and select() keeps it row by row
    from gcs_sysid.airframe import Airframe

    data = {k: np.full(n, v) for k, v in dict(ax=0.1, ay=0.0, az=-9.8, p=0.0, q=0.0, r=0.0, p_dot=0.0, q_dot=0.0,
                                               r_dot=0.0, V=20.0, qbar=240.0, alpha=0.05, beta=0.0, delta_e=0.0,
                                               delta_a=0.0, delta_r=0.0, delta_t=0.5).items()}
    st.data.update(data)
    tab = compute_coefficients(st, Airframe("test", 2.0, 0.1, 0.1, 0.2, 0.0, 0.5, 2.0, 0.25, ()))
    np.testing.assert_allclose(tab.x_var, xv)
    np.testing.assert_allclose(tab.select(np.array([0, 1, 0, 1, 0], bool)).x_var, xv[[1, 3]])


def test_predict_takes_the_larger_of_stated_and_learned_input_variance(fitted, flight):
    """The slope term with ``x_var``: per row and regressor ``max(learned, stated)`` through the mean's slope;
    unchanged where nothing is stated or the statement is smaller; not used at exact conditions."""
    model, _ = fitted
    X = flight[0][400:]                                                      # test_model.py's query shape
    mean0, var0 = model.predict(X)
    stated = np.full(X.shape, np.nan)
    _, v_nan = model.predict(X, x_var=stated)
    np.testing.assert_allclose(v_nan, var0, rtol=1e-12)
    learned = np.asarray(model.input_var) * model.scaler.x_std**2           # data units
    stated[:, 0] = 0.5 * learned[0]                                          # smaller than learned: no change
    np.testing.assert_allclose(model.predict(X, x_var=stated)[1], var0, rtol=1e-12)
    s_alpha = np.radians(0.5)
    stated[:, 0] = s_alpha**2                                                # larger: its slope term is added
    mean1, var1 = model.predict(X, x_var=stated)
    np.testing.assert_allclose(mean1, mean0)
    from gcs_sysid.gp.inputnoise import mean_gradient

    g = mean_gradient(model.params, model.post, model.scaler.x(X))[:, :, 0] * model.scaler.y_std / model.scaler.x_std[0]
    expect = var0 + g**2 * (s_alpha**2 - learned[0])
    np.testing.assert_allclose(var1, expect, rtol=1e-6, atol=1e-14)
    assert np.median(var1[:, 2] / var0[:, 2]) > 2.0                          # CZ (CZ_alpha -4.5) gains most
    # exact conditions: no input noise, so no statement either
    np.testing.assert_allclose(model.predict(X, input_noise=False, x_var=stated)[1],
                               model.predict(X, input_noise=False)[1])
    with pytest.raises(InputError, match="x_var"):
        model.predict(X, x_var=stated[:, :3])


@pytest.mark.slow
def test_band_covers_the_truth_when_the_angle_is_built_from_the_measured_force():
    """A synthetic flight with an aided alpha: ``alpha_est = alpha + e`` (coloured, 0.25 deg), and the measured
    forces move with it (``CZ_meas = CZ(alpha + e)``: the angle came from them), the moments not. The learned
    input noise misses ``e``; the band with noise at held-out estimated regressors under-covers the truth
    of CZ; with the estimator's stated ``x_var`` it covers 90-99 %."""
    from gcs_sysid.gp import fit_gp

    n, rate = 1500, 20.0
    X = flight_regressors(n, seed=31, rate_hz=rate)
    rng = np.random.default_rng(32)
    s_e, rho = np.radians(0.25), np.exp(-1.0 / (rate * 0.5))               # 0.5-s correlation time
    e = np.zeros(n)
    w = rng.standard_normal(n) * s_e * np.sqrt(1 - rho**2)
    e[0] = s_e * rng.standard_normal()
    for k in range(1, n):
        e[k] = rho * e[k - 1] + w[k]
    X_est = X.copy()
    X_est[:, 0] += e
    truth = linear_truth(X)
    Y = truth + 0.01 * truth.std(0) * rng.standard_normal(truth.shape)
    Y[:, :3] = linear_truth(X_est)[:, :3] + 0.01 * truth[:, :3].std(0) * rng.standard_normal((n, 3))
    tr, te = slice(0, 1200), slice(1200, n)
    model, _ = fit_gp(X_est[tr], Y[tr], replace(FAST, local=False))
    xv = np.full((n - 1200, 10), np.nan)
    xv[:, 0] = s_e**2
    m0, v0 = model.predict(X_est[te])
    m1, v1 = model.predict(X_est[te], x_var=xv)
    cov0 = 100 * np.mean(np.abs(m0[:, 2] - truth[te, 2]) <= 1.96 * np.sqrt(v0[:, 2]))
    cov1 = 100 * np.mean(np.abs(m1[:, 2] - truth[te, 2]) <= 1.96 * np.sqrt(v1[:, 2]))
    assert cov0 < 80.0, cov0
    assert 90.0 <= cov1 <= 99.5, cov1


def test_exact_condition_band_carries_a_common_scale_error(fitted, flight, tmp_path):
    """``scale_var`` (the aided angles' ``AxisFit.scale_sigma^2``): at exact conditions the variance gains
    ``(dm/dx)^2 s^2 (x - mean x)^2``; nothing at the flight's own regressors; saved and loaded."""
    from gcs_sysid.gp import load_gp
    from gcs_sysid.gp.discrepancy import with_offset_covariance
    from gcs_sysid.gp.inputnoise import mean_gradient
    from gcs_sysid.gp.io import save_model

    model, _ = fitted
    X = flight[0][400:]
    _, v0 = model.predict(X, include_noise=False, input_noise=False)
    sv = np.zeros(10)
    sv[0] = 0.1**2                                                           # alpha's scale known to 10 %
    scaled = with_offset_covariance(model, None, scale_var=sv)
    _, v1 = scaled.predict(X, include_noise=False, input_noise=False)
    Xs = model.scaler.x(X)
    g = mean_gradient(model.params, model.post, Xs)[:, :, 0] * model.scaler.y_std
    np.testing.assert_allclose(v1, v0 + g**2 * sv[0] * Xs[:, [0]] ** 2, rtol=1e-6, atol=1e-14)
    np.testing.assert_allclose(scaled.predict(X)[1], model.predict(X)[1])    # the flight's own regressors
    back = load_gp(save_model(scaled, tmp_path / "m"))
    np.testing.assert_allclose(back.predict(X, include_noise=False, input_noise=False)[1], v1, rtol=1e-9)
    from gcs_sysid.gp.discrepancy import model_error_summary

    assert model_error_summary(scaled)["scale_std"] == {"alpha": pytest.approx(0.1)}
    # combined as independent across flights when the model was updated with this one
    again = with_offset_covariance(scaled, None, rows=model.n_used // 2, scale_var=sv)
    np.testing.assert_allclose(again.scale_var[0], 0.01 * 0.5, rtol=0.02)
    with pytest.raises(InputError, match="scale variance"):
        with_offset_covariance(model, None, scale_var=np.zeros(3))
