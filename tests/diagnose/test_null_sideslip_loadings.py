"""The aided sideslip's loadings on its side-force model's other columns under no change
(``sparse.THRESHOLDS["coverage_beta_along"]``).

The sideslip aiding's side-force model ``CY = c0 + CY_beta beta + CY_r_hat r_hat + ...`` is fitted per flight; the
aided angle is the side force's excursion less the model's other terms over the slope, so an error ``e`` of the
fitted ``CY_r_hat`` is a sideslip error ``-e / CY_beta r_hat``, and a side-force fit on that sideslip gives the
aiding's ``CY_r_hat`` back. Two clean flights whose aidings read ``CY_r_hat`` -0.54 and -1.07 (JSBSim SGS 1-26,
reference and clean seed 12: its side force has no yaw-rate term) then show a ``CY:r_hat`` "change" of -0.53 that
the fits' own standard errors (0.003) call certain. The first aiding pass's jackknife (0.30, 0.49) carried under no
change (:func:`gcs_sysid.diagnose.null_uncertainty.angle_null_sensitivity` ``along``) covers it; a real yaw-rate
side force of -2.5 stays beyond. Synthetic arrays, < 0.1 s."""

import numpy as np
import pytest

from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.diagnose.null_uncertainty import angle_null_sensitivity
from gcs_sysid.diagnose.sparse import THRESHOLDS, beyond_expanded_uncertainty
from gcs_sysid.diagnose.uncertainty import air_data_uncertainty, combine, sideslip_loadings
from gcs_sysid.estimation.airangles import AxisFit

T = 4000
CY_B = -0.97                                   # 1/rad: the SGS 1-26's aiding slope (about)
KB, KR = REGRESSORS.index("beta"), REGRESSORS.index("r_hat")


def _fit(cy_r, jk_r):
    """The sideslip aiding's AxisFit with ``CY_r_hat = cy_r`` and a first-pass jackknife of ``jk_r`` on it."""
    cols = ("1", "beta", "p_hat", "r_hat", "delta_a", "delta_r")
    return AxisFit("beta", True, "", cols, np.array([0.0, CY_B, 0.54, cy_r, 0.03, -0.02]),
                   np.array([np.nan, 0.002, 0.006, 0.01, 0.001, 0.001]), scale_sigma=0.46,
                   slope_jackknife=np.array([np.nan, 0.1, 0.2, jk_r, 0.02, np.nan]))


def _signals():
    t = np.arange(T) * 0.02
    r_hat = 0.02 * np.sin(2 * np.pi * 0.15 * t) + 0.01 * np.sin(2 * np.pi * 0.55 * t + 1.0)
    beta = 0.03 * np.sin(2 * np.pi * 0.25 * t + 0.4) + 0.4 * r_hat
    return beta, r_hat


def _predict(X):
    out = np.zeros((len(X), 6))
    out[:, 1] = CY_B * X[:, KB]                     # the model's side force: sideslip only, as JSBSim's
    return out


def test_the_loadings_of_one_flight_and_of_a_pair():
    assert THRESHOLDS["coverage_beta_along"] == "columns"          # on, for a named term that is an along column
    u = sideslip_loadings(_fit(-1.07, 0.49))
    assert set(u) == {"p_hat", "r_hat", "delta_a"}          # delta_r's jackknife is NaN: left out
    assert u["r_hat"] == pytest.approx(0.49 / 0.97)
    assert sideslip_loadings(AxisFit("beta", False, "not aided")) == {}
    assert sideslip_loadings(AxisFit("beta", True, "", ("1", "beta"), np.array([0.0, CY_B]), np.ones(2))) == {}
    pair = air_data_uncertainty({"beta": _fit(-1.07, 0.49)}, {"beta": _fit(-0.54, 0.30)})["beta"]
    assert pair["along_r_hat"] == pytest.approx(np.hypot(0.49, 0.30) / 0.97)
    # a column only one flight's aiding had counts 0 on the other
    other = _fit(-0.54, 0.30)
    other.slope_jackknife = np.array([np.nan, 0.1, np.nan, 0.30, np.nan, np.nan])
    pair = air_data_uncertainty({"beta": _fit(-1.07, 0.49)}, {"beta": other})["beta"]
    assert pair["along_p_hat"] == pytest.approx(0.2 / 0.97) and pair["along_r_hat"] > pair["along_p_hat"]


def test_a_clean_pair_whose_aidings_read_the_yaw_rate_differently_is_covered_and_a_real_change_is_not():
    beta, r_hat = _signals()
    rows = np.arange(T)
    cy_r_ref, cy_r_test = -0.54, -1.07
    # each flight's aided sideslip carries its aiding's yaw-rate loading (the side force has none)
    x_ref, x_test = beta - cy_r_ref / CY_B * r_hat, beta - cy_r_test / CY_B * r_hat

    def cy_r(cy, x):
        A = np.column_stack([np.ones(T), x, r_hat])
        return float(np.linalg.lstsq(A, cy, rcond=None)[0][2]), A

    cy = CY_B * beta
    ref, _ = cy_r(cy, x_ref)
    test, A = cy_r(cy, x_test)
    assert ref == pytest.approx(cy_r_ref, rel=1e-6) and test - ref == pytest.approx(-0.53, rel=1e-6)
    u = air_data_uncertainty({"beta": _fit(cy_r_test, 0.49)}, {"beta": _fit(cy_r_ref, 0.30)})["beta"]
    X = np.zeros((T, len(REGRESSORS)))
    X[:, KB], X[:, KR] = x_test, r_hat

    def finding(change, with_along):
        along = {k[6:]: (REGRESSORS.index(k[6:]), v) for k, v in u.items() if k.startswith("along_")}
        s = angle_null_sensitivity(_predict, X, A, 2, 1, rows, KB, u["scale"], 0.0, along=along if with_along else None)
        assert ("along_r_hat" in s) == with_along
        # the along_r_hat part is the jackknife's, |CY_beta| times the loading: the fits' own 0.003 stays beside it
        if with_along:
            assert s["along_r_hat"] == pytest.approx(np.hypot(0.49, 0.30), rel=1e-6)
        u0 = combine({"flight": 0.002, "reference": 0.002, "beta_scale": 0.0,
                      **{f"beta_{k}": v for k, v in s.items() if k.startswith("along_")}})
        return {"estimate": change, "model_value": 0.0, "std_error": 1.0,
                "evidence": {"uncertainty": {"combined": 1.0, "combined_under_no_change_alpha": u0}}}

    assert beyond_expanded_uncertainty(finding(test - ref, False), 2.0, under_null="alpha")["beyond"]
    assert not beyond_expanded_uncertainty(finding(test - ref, True), 2.0, under_null="alpha")["beyond"]
    # the same pair with a real yaw-rate side force of -2.5 on the test flight: still named
    real, _ = cy_r(cy - 2.5 * r_hat, x_test)
    assert beyond_expanded_uncertainty(finding(real - ref, True), 2.0, under_null="alpha")["beyond"]
