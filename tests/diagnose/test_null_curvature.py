"""The aided alpha's curvature uncertainty under no change (``sparse.THRESHOLDS["coverage_curvature"]``).

The aiding's fitted lift curvature ``CZ_alpha2`` and a curvature error of the aided alpha are one to the aiding: a
flight whose alpha reads ``alpha_true + c (alpha - mean)^2`` fits ``CZ_alpha2 = -CZ_alpha c``
(:attr:`gcs_sysid.estimation.airangles.AxisFit.curvature_sigma`). Between two clean flights with different ``c``
the unchanged linear lift reads as a ``CZ:alpha^2`` change of ``-CZ_alpha (c - c_ref)`` (JSBSim t6 clean seed 14:
-5.45); with the stated curvature carried under no change
(:func:`gcs_sysid.diagnose.null_uncertainty.angle_null_sensitivity`) it is covered, while an injected
``Cm:alpha^2`` (Cm's slope is a tenth of CZ's) stays beyond. Synthetic arrays, < 0.1 s."""

import numpy as np
import pytest

from gcs_sysid.diagnose.null_uncertainty import angle_null_sensitivity, null_residual
from gcs_sysid.diagnose.sparse import THRESHOLDS, beyond_expanded_uncertainty
from gcs_sysid.diagnose.uncertainty import air_data_uncertainty, combine
from gcs_sysid.estimation.airangles import AxisFit

T = 3000
CZ_A, CM_A = -4.65, -0.45                      # 1/rad (the t6's aiding slope; a Cm slope)


def _alpha_true():
    t = np.arange(T) * 0.02
    return 0.008 + 0.03 * np.sin(2 * np.pi * 0.21 * t) + 0.012 * np.sin(2 * np.pi * 0.53 * t + 1.0)


def _measured(a, c):
    """The aided alpha with a flight-common curvature error ``c`` (1/rad), centred (no mean moved)."""
    d2 = (a - a.mean()) ** 2
    return a + c * (d2 - d2.mean())


def _fit(c, c2_se=0.05):
    """The alpha aiding's AxisFit as such a flight leaves it: CZ_alpha2 = -CZ_alpha c."""
    return AxisFit("alpha", True, "", ("1", "alpha", "(alpha - alpha0)^2", "q_hat", "delta_e"),
                   np.array([-0.25, CZ_A, -CZ_A * c, 0.1, 0.2]), np.array([np.nan, 0.004, c2_se, 0.11, 0.003]))


def _predict(X):
    out = np.zeros((len(X), 6))
    out[:, 2] = CZ_A * X[:, 0]
    out[:, 4] = CM_A * X[:, 0]
    return out


def _change(y, x):
    """The selected fit's alpha^2 coefficient on [1, alpha, alpha^2] (the search's named change)."""
    A = np.column_stack([np.ones(T), x, x**2])
    return float(np.linalg.lstsq(A, y, rcond=None)[0][2]), A


def test_the_aidings_fitted_curvature_is_stated_as_the_angles():
    assert _fit(-0.98).curvature_sigma == pytest.approx(np.hypot(CZ_A * 0.98, 0.05) / abs(CZ_A))
    assert np.isnan(AxisFit("beta", True, "", ("1", "beta"), np.array([0.0, -1.0]), np.ones(2)).curvature_sigma)
    assert np.isnan(AxisFit("alpha", False, "not aided", ("1", "alpha", "(alpha - alpha0)^2"),
                            np.zeros(3), np.zeros(3)).curvature_sigma)
    u = air_data_uncertainty({"alpha": _fit(-0.98)}, {"alpha": _fit(0.36)})
    assert u["alpha"]["curvature"] == pytest.approx(np.hypot(_fit(-0.98).curvature_sigma, _fit(0.36).curvature_sigma))
    assert "curvature" not in u["beta"]
    c = 0.5
    a = _alpha_true()
    d = null_residual(_predict, np.column_stack([_measured(a, 0.0)] + [np.zeros(T)] * 9), np.arange(T), 0,
                      "curvature", c)
    assert np.allclose(d[:, 2], -CZ_A * c * ((a - a.mean()) ** 2 - np.mean((a - a.mean()) ** 2)), rtol=1e-9)


def test_a_clean_pair_with_a_curvature_error_is_covered_and_an_injected_cm_alpha2_is_not():
    assert THRESHOLDS["coverage_curvature"] is True                 # on by default (twentieth session)
    a, rows = _alpha_true(), np.arange(T)
    c_ref, c_test = 0.36, -0.78                 # JSBSim t6: the reference's and clean seed 14's curvature error
    x = _measured(a, c_test)
    X = np.column_stack([x] + [np.zeros(T)] * 9)
    # the reference model fitted on its own alpha: CZ = CZ_A (x_ref - c_ref d2) ~ CZ_A x_ref + (-CZ_A c_ref) d2
    fits = ({"alpha": _fit(c_test)}, {"alpha": _fit(c_ref)})
    u = air_data_uncertainty(*fits)["alpha"]
    cz_ref, _ = _change(CZ_A * a, _measured(a, c_ref))
    cz_test, A = _change(CZ_A * a, x)
    change = cz_test - cz_ref                                      # -CZ_A (c_test - c_ref) = -5.3
    assert change == pytest.approx(-CZ_A * (c_test - c_ref), rel=0.05)
    type_a = 0.3                                                   # this flight's and the reference's fit

    def finding(est, j, curv):
        s = angle_null_sensitivity(_predict, X, A, 2, j, rows, 0, u["scale"], u["offset_rad"],
                                   curvature=u["curvature"] if curv else 0.0)
        u0 = combine({"flight": type_a, **{f"alpha_{k}": v for k, v in s.items()}})
        return {"estimate": est, "model_value": 0.0, "std_error": 1.0,
                "evidence": {"uncertainty": {"combined": 1.0, "combined_under_no_change_alpha": u0}}}

    # without the stated curvature the clean flight's CZ:alpha^2 is named, with it not
    assert beyond_expanded_uncertainty(finding(change, 2, False), 2.0, under_null="alpha")["beyond"]
    assert not beyond_expanded_uncertainty(finding(change, 2, True), 2.0, under_null="alpha")["beyond"]
    # an injected Cm:alpha^2 of -4 on the same pair (read short, as the aided alpha's scale makes it) stays named
    cm_ref, _ = _change(CM_A * a, _measured(a, c_ref))
    cm_test, _ = _change(CM_A * a - 4.0 * (a - a.mean()) ** 2, x)
    assert beyond_expanded_uncertainty(finding(cm_test - cm_ref, 4, True), 2.0, under_null="alpha")["beyond"]
