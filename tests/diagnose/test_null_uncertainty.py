"""The air angles' type-B uncertainty under no change (``sparse.THRESHOLDS["coverage_under_null"]``).

The naming test's reference is the estimate when nothing changed: the unchanged model seen through an angle whose
scale (offset) differs from the reference's by ``s`` (``o``), carried through the search's fit
(:mod:`gcs_sysid.diagnose.null_uncertainty`). Checked against hand cases: a model quadratic in alpha on a symmetric
alpha gives ``c2 ((1 + u)^-2 - (1 - u)^-2) / 2`` on ``alpha^2``; an offset of a linear model is only a constant;
unlike the type-B component on the term's own column (``test_coverage_type_a.py``) it does not grow with the
change. Fast (synthetic arrays, < 0.1 s)."""

import numpy as np
import pytest

from gcs_sysid.diagnose.null_uncertainty import angle_null_sensitivity, null_residual
from gcs_sysid.diagnose.sparse import THRESHOLDS, beyond_expanded_uncertainty
from gcs_sysid.diagnose.uncertainty import angle_sensitivity

T = 2000


def _X():
    X = np.zeros((T, 10))
    X[:, 0] = 0.05 * np.sin(np.arange(T) / 37.0)                    # alpha, rad, symmetric about 0 over the rows
    return X


def _predict(c1=0.0, c2=0.0):
    def predict(X):
        out = np.zeros((len(X), 6))
        out[:, 4] = c1 * X[:, 0] + c2 * X[:, 0] ** 2                # Cm
        return out
    return predict


def _cols(X):
    return np.column_stack([np.ones(len(X)), X[:, 0] ** 2])


def test_a_quadratic_model_under_an_alpha_scale_error_reads_its_own_curvature_change():
    X, rows, u, c2 = _X(), np.arange(T), 0.3, -2.0
    mean = X[:, 0].mean()
    got = angle_null_sensitivity(_predict(c2=c2), X, _cols(X), 1, 4, rows, 0, u, 0.0)
    # about the flight mean (not exactly 0 over the rows): alpha^2 -> ((alpha - m)/(1+s) + m)^2,
    # refitted on [1, alpha^2]
    ref = []
    for s in (u, -u):
        r = c2 * ((X[:, 0] - mean) / (1 + s) + mean) ** 2 - c2 * X[:, 0] ** 2
        ref.append(np.linalg.lstsq(_cols(X), r, rcond=None)[0][1])
    assert got["scale"] == pytest.approx(abs(ref[0] - ref[1]) / 2, rel=1e-9)
    assert got["scale"] == pytest.approx(abs(c2 * ((1 + u) ** -2 - (1 - u) ** -2) / 2), rel=1e-2)   # mean ~0
    assert got["offset"] == 0.0


def test_an_offset_of_a_linear_model_is_only_a_constant_and_a_nuisance_is_applied():
    X, rows = _X(), np.arange(T)
    got = angle_null_sensitivity(_predict(c1=-1.0), X, _cols(X), 1, 4, rows, 0, 0.0, 0.01)
    assert got["scale"] == 0.0 and got["offset"] < 1e-9
    # a nuisance that removes everything leaves nothing
    gone = angle_null_sensitivity(_predict(c2=-2.0), X, _cols(X), 1, 4, rows, 0, 0.3, 0.0, lambda R: 0.0 * R)
    assert gone["scale"] == 0.0
    with pytest.raises(ValueError):
        null_residual(_predict(), X, rows, 0, "gain", 0.1)


def test_unlike_the_own_column_component_it_does_not_grow_with_the_change():
    X, rows, u = _X(), np.arange(T), 0.43
    X[:, 0] += 0.01                                                  # a mean alpha, so alpha^2 holds a linear part
    A = np.column_stack([np.ones(T), X[:, 0], X[:, 0] ** 2])

    def columns(Xp):
        return np.column_stack([np.ones(T), Xp[:, 0], Xp[:, 0] ** 2])

    null = angle_null_sensitivity(_predict(c1=-1.0, c2=-1.0), X, A, 2, 4, rows, 0, u, 0.0)["scale"]
    own = [angle_sensitivity(columns, X, k * X[:, 0] ** 2, rows, 2, 0, u, 0.0)["scale"] for k in (-4.0, -16.0)]
    assert own[1] > 3.5 * own[0] > 3.5 * null                       # the own-column component scales with k
    assert null == pytest.approx(abs(-1.0 * ((1 + u) ** -2 - (1 - u) ** -2) / 2), rel=0.05)


def test_the_coverage_test_reads_the_uncertainty_under_no_change_when_asked():
    # on by default since the twentieth session (branch i9-curv), with alpha's curvature carried under no change
    assert THRESHOLDS["coverage_under_null"] == "alpha" and THRESHOLDS["coverage_curvature"] is True
    unc = {"type_b": {"alpha_scale": 7.044}, "combined": 7.054, "type_b_under_no_change": {"alpha_scale": 0.665},
           "combined_under_no_change": 0.764}
    f = {"estimate": -5.41, "model_value": 0.0, "std_error": 7.054, "evidence": {"uncertainty": unc}}
    assert not beyond_expanded_uncertainty(f, 2.0)["beyond"]
    d = beyond_expanded_uncertainty(f, 2.0, under_null=True)
    assert d["beyond"] and d["combined_std_uncertainty"] == pytest.approx(0.764)
    assert not beyond_expanded_uncertainty(dict(f, estimate=-1.2), 2.0, under_null=True)["beyond"]
    # a finding without the null uncertainty is judged as before
    old = {"estimate": -5.41, "model_value": 0.0, "std_error": 7.054,
           "evidence": {"uncertainty": {"type_b": {"alpha_scale": 7.044}, "combined": 7.054}}}
    assert not beyond_expanded_uncertainty(old, 2.0, under_null=True)["beyond"]


def test_the_alpha_variant_reads_the_alpha_components_under_no_change_only():
    unc = {"combined": 0.20, "combined_under_no_change": 0.42, "combined_under_no_change_alpha": 0.05}
    f = {"estimate": 1.3, "model_value": 1.0, "std_error": 0.20, "evidence": {"uncertainty": unc}}
    assert not beyond_expanded_uncertainty(f, 2.0, under_null=True)["beyond"]
    assert beyond_expanded_uncertainty(f, 2.0, under_null="alpha")["beyond"]
