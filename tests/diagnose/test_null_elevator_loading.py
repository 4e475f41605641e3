"""The aided alpha's elevator loading under no change (``sparse.THRESHOLDS["coverage_map_delta_e"]``, on since
the forty-sixth session).

The alpha aiding's force model ``CZ = c0 + CZ_alpha alpha + ... + CZ_delta_e delta_e`` is fitted per flight; an error
``e`` in its ``CZ_delta_e`` is an aided-alpha error ``-e / CZ_alpha * delta_e``
(:func:`gcs_sysid.diagnose.uncertainty.elevator_loading`). Two clean flights whose aidings load the elevator
differently (JSBSim c172p: 0.151 for the reference, 0.277 for clean seed 13) read an unchanged ``Cm_delta_e`` as a
change of ``-Cm_alpha (l - l_ref)`` (+0.19 there). Carried under no change
(:func:`gcs_sysid.diagnose.null_uncertainty.angle_null_sensitivity` ``map_delta_e``) it is covered, while a real
elevator-power change of -15 % stays beyond. Synthetic arrays, < 0.1 s."""

import numpy as np
import pytest

from gcs_sysid.diagnose.null_uncertainty import angle_null_sensitivity, null_residual
from gcs_sysid.diagnose.sparse import THRESHOLDS, beyond_expanded_uncertainty
from gcs_sysid.diagnose.uncertainty import air_data_uncertainty, combine, elevator_loading
from gcs_sysid.estimation.airangles import AxisFit

T = 3000
CZ_A, CM_A, CM_DE = -4.95, -1.8, -1.0          # 1/rad (the c172p's aiding slope, its Cm_alpha and Cm_delta_e)


def _signals():
    """(alpha_true, delta_e), rad: the elevator trims alpha (Cm = 0) and carries a sweep of its own."""
    t = np.arange(T) * 0.02
    sweep = 0.03 * np.sin(2 * np.pi * (0.1 + 0.01 * t) * t)
    de = 0.04 + 0.02 * np.sin(2 * np.pi * 0.05 * t) + sweep
    a = -(0.1 + CM_DE * de) / CM_A + 0.005 * np.sin(2 * np.pi * 0.7 * t + 0.3)
    return a, de


def _fit(loading):
    """The alpha aiding's AxisFit whose CZ_delta_e loads the aided alpha by ``loading`` rad/rad."""
    return AxisFit("alpha", True, "", ("1", "alpha", "(alpha - alpha0)^2", "q_hat", "delta_e"),
                   np.array([-0.25, CZ_A, 1.3, -0.5, -loading * CZ_A]), np.array([np.nan, 0.004, 0.05, 0.11, 0.003]))


def _predict(X):
    out = np.zeros((len(X), 6))
    out[:, 4] = CM_A * X[:, 0] + CM_DE * X[:, 5]
    return out


def _cm_delta_e(cm, x, de):
    """The Cm fit's delta_e coefficient on [1, alpha, delta_e] (the search's column), and the columns."""
    A = np.column_stack([np.ones(T), x, de])
    return float(np.linalg.lstsq(A, cm, rcond=None)[0][2]), A


def test_the_aidings_elevator_loading_and_the_pairs_difference():
    assert THRESHOLDS["coverage_map_delta_e"] is True               # the default since the forty-sixth session
    assert elevator_loading(_fit(0.277)) == pytest.approx(0.277)
    assert elevator_loading(AxisFit("alpha", False, "not aided", ("1", "alpha", "delta_e"), np.zeros(3),
                                    np.zeros(3))) is None
    assert elevator_loading(AxisFit("alpha", True, "", ("1", "alpha"), np.array([0.0, CZ_A]), np.ones(2))) is None
    u = air_data_uncertainty({"alpha": _fit(0.277)}, {"alpha": _fit(0.151)})["alpha"]
    assert u["map_delta_e"] == pytest.approx(0.126) and "loading_delta_e" not in u
    a, de = _signals()
    X = np.column_stack([a] + [np.zeros(T)] * 4 + [de] + [np.zeros(T)] * 4)
    d = null_residual(_predict, X, np.arange(T), 0, "along", 0.1, along=5)
    assert np.allclose(d[:, 4], -CM_A * 0.1 * (de - de.mean()), rtol=1e-9)
    with pytest.raises(ValueError):
        null_residual(_predict, X, np.arange(T), 0, "along", 0.1)


def test_a_clean_pair_with_other_elevator_loadings_is_covered_and_a_real_elevator_change_is_not():
    a, de = _signals()
    rows = np.arange(T)
    l_ref, l_test = 0.151, 0.277                 # the c172p reference's and clean seed 13's aiding loadings
    x_ref, x = a + l_ref * (de - de.mean()), a + l_test * (de - de.mean())
    u = air_data_uncertainty({"alpha": _fit(l_test)}, {"alpha": _fit(l_ref)})["alpha"]
    cm = CM_A * a + CM_DE * de
    ref, _ = _cm_delta_e(cm, x_ref, de)
    test, A = _cm_delta_e(cm, x, de)
    change = test - ref
    assert change == pytest.approx(CM_A * -(l_test - l_ref), rel=0.05)     # +0.23: an elevator "weaker" by a fifth
    X = np.column_stack([x] + [np.zeros(T)] * 4 + [de] + [np.zeros(T)] * 4)
    type_a = 0.02

    def finding(est, with_map):
        s = angle_null_sensitivity(_predict, X, A, 2, 4, rows, 0, u["scale"], u["offset_rad"],
                                   map_delta_e=u["map_delta_e"] if with_map else 0.0, k_delta_e=5)
        assert ("map_delta_e" in s) == with_map
        u0 = combine({"flight": type_a, **{f"alpha_{k}": v for k, v in s.items()}})
        return {"estimate": est, "model_value": 0.0, "std_error": 1.0,
                "evidence": {"uncertainty": {"combined": 1.0, "combined_under_no_change_alpha": u0}}}

    assert beyond_expanded_uncertainty(finding(change, False), 2.0, under_null="alpha")["beyond"]
    assert not beyond_expanded_uncertainty(finding(change, True), 2.0, under_null="alpha")["beyond"]
    # the same pair with the elevator really weaker by 0.6 (the test flight's Cm_delta_e -0.4): still named
    real, _ = _cm_delta_e(CM_A * a + (CM_DE + 0.6) * de, x, de)
    assert beyond_expanded_uncertainty(finding(real - ref, True), 2.0, under_null="alpha")["beyond"]
