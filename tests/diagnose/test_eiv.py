"""Errors-in-variables correction of a named term in the air angles (gcs_sysid.diagnose.eiv)."""

import numpy as np
import pytest

from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.diagnose.eiv import corrected_fit, hermite_unbiased, monomial_exponents
from gcs_sysid.diagnose.sparse import _with_errors_in_variables


def test_hermite_is_unbiased_for_powers():
    rng = np.random.default_rng(0)
    x, v = 0.03, 0.01**2
    w = x + rng.normal(0.0, 0.01, 400_000)
    for n in (1, 2, 3):
        assert np.mean(hermite_unbiased(w, v, n)) == pytest.approx(x**n, rel=0.02)
        # the plain power is biased by the error (x^2 + v: +11 % at this size)
    assert np.mean(w**2) > 1.08 * x**2
    with pytest.raises(ValueError):
        hermite_unbiased(w, v, -1)


def test_monomial_exponents():
    assert monomial_exponents("alpha^2*beta") == {"alpha": 2, "beta": 1}
    assert monomial_exponents("1") == {}
    for t in ("max(0,alpha-2.0deg)", "alpha_dot_hat", "delta_e(t-0.1)-delta_e", "scale:CY"):
        assert monomial_exponents(t) is None


def _flight(seed=1, n=4500, s_alpha=0.006):
    """Alpha with 0.7-deg excursions about 3 deg, beta 0.7 deg, a per-sample alpha error of ``s_alpha`` rad."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    a = np.radians(3.0) + np.radians(0.7) * np.sin(0.9 * t + rng.normal(0, 0.3)) * (1 + 0.3 * np.sin(0.13 * t))
    b = np.radians(0.7) * np.sin(0.55 * t) + np.radians(0.2) * rng.normal(size=n)
    X = np.zeros((n, len(REGRESSORS)))
    X[:, 0] = a + rng.normal(0.0, s_alpha, n)
    X[:, 1] = b
    return a, b, X


def test_corrected_fit_removes_the_attenuation_of_a_product_and_a_power():
    a, b, X = _flight()
    s = 0.006
    rng = np.random.default_rng(5)
    y = 3.0 * a * b - 8.0 * a**2 + 1e-5 * rng.normal(size=a.size)
    y -= y.mean()
    W, B = X[:, 0], X[:, 1]
    A = np.column_stack([W * B, W**2, B])
    res = corrected_fit(["alpha*beta", "alpha^2", "beta"], A, y, X, {"alpha": np.full(a.size, s**2)})
    assert res["applied"]
    # least squares on the noisy alpha: the power loses about a third (reliability of its excursions ~0.6)
    assert abs(res["theta_ls"][2] / -8.0) < 0.8
    assert res["theta"][2] == pytest.approx(-8.0, rel=0.1)
    assert res["theta"][1] == pytest.approx(3.0, rel=0.1)
    # G maps least squares onto the corrected estimate
    np.testing.assert_allclose(res["G"] @ res["theta_ls"], res["theta"], rtol=0.05, atol=1e-3)


def test_no_correction_without_angles_or_when_not_identified():
    a, b, X = _flight()
    y = 3.0 * a * b
    y -= y.mean()
    d = X[:, 5] = np.sin(np.arange(a.size) * 0.01)
    res = corrected_fit(["delta_e"], d[:, None], y, X, {"alpha": np.full(a.size, 1e-4)})
    assert not res["applied"] and "no selected term" in res["why"]
    res = corrected_fit(["alpha"], X[:, :1], y, X, {})
    assert not res["applied"]
    # a stated error larger than the measured spread: not identified, left as least squares
    res = corrected_fit(["alpha"], X[:, :1], y, X, {"alpha": np.full(a.size, np.var(X[:, 0]) * 1.5)})
    assert not res["applied"] and "not identified" in res["why"]
    np.testing.assert_allclose(res["theta"], res["theta_ls"])


def test_finding_keeps_the_decision_quantities():
    a, b, X = _flight()
    s = 0.006
    r = 3.0 * a * b
    names = ["alpha", "beta", "alpha*beta"]
    Phi = np.column_stack([X[:, 0], X[:, 1], X[:, 0] * X[:, 1]])
    tr = np.arange(a.size)
    A = np.column_stack([np.ones(a.size), Phi[:, 2], Phi[:, 1]])
    ls = np.linalg.lstsq(A, r - r.mean(), rcond=None)[0]
    f = {"cause": "Cl:alpha*beta", "coefficient": "Cl", "estimate": 0.1 + ls[1], "std_error": 0.05,
         "model_value": 0.1, "evidence": {"terms": [{"term": "alpha*beta"}, {"term": "beta"}]}}
    _with_errors_in_variables(f, names, Phi, X, r, tr, {"alpha": np.full(a.size, s)})
    info = f["evidence"]["errors_in_variables"]
    assert info["applied"]
    assert f["evidence"]["correction"] == pytest.approx(ls[1])          # what the differential step reads
    assert f["evidence"]["std_error_decision"] == 0.05
    assert abs(f["estimate"] - 0.1) > abs(ls[1])                         # the attenuation taken out
    assert f["std_error"] == pytest.approx(0.05 * info["factor"])
    # a scale or a delay is not a library term in the angles: untouched
    g = {"cause": "scale:CY", "coefficient": "CY", "estimate": 1.3, "std_error": 0.01, "evidence": {"terms": []}}
    _with_errors_in_variables(g, names, Phi, X, r, tr, {"alpha": np.full(a.size, s)})
    assert g["estimate"] == 1.3 and "errors_in_variables" not in g["evidence"]
