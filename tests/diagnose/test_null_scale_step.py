"""The alpha scale's no-change component at a stated scale uncertainty near 1 (``sparse.THRESHOLDS
["coverage_scale_step"]``).

:func:`gcs_sysid.diagnose.null_uncertainty.null_residual` reads the unchanged model at ``x_true = mean + (x - mean) /
(1 +- u)``. With ``u`` near 1 the minus branch is the pole of that parametrization: on the JSBSim c172p's seed 2 with
the alpha aiding profiled (``ALPHA_PROFILE_COLUMNS``) the two flights' stated alpha scale uncertainty was 0.976, alpha's
excursions were read 42 times larger, and ``Cn:delta_a`` -0.0585 got +- 0.104 under no change where its fits give
0.0017. With the step capped the component is the first-order sensitivity times ``u`` (GUM JCGM 100:2008 eq. 10).
Synthetic arrays, < 0.1 s."""

import numpy as np
import pytest

from gcs_sysid.diagnose.null_uncertainty import angle_null_sensitivity
from gcs_sysid.diagnose.sparse import THRESHOLDS

T = 2000
CM_A = -0.45                          # 1/rad, an unchanged model linear in alpha


def _predict(X):
    out = np.zeros((len(X), 6))
    out[:, 4] = CM_A * X[:, 0]
    return out


def _setup():
    t = np.arange(T) * 0.02
    X = np.zeros((T, 10))
    X[:, 0] = 0.05 + 0.03 * np.sin(2 * np.pi * 0.21 * t)
    A = np.column_stack([np.ones(T), X[:, 0]])
    return X, A, np.arange(T)


def test_the_scale_step_gives_the_first_order_component_near_a_unit_scale_uncertainty():
    X, A, rows = _setup()
    u = 0.97
    # as before (step u): |CM_A| u / (1 - u^2), 16 times the first-order value
    wide = angle_null_sensitivity(_predict, X, A, 1, 4, rows, 0, u, 0.0)["scale"]
    assert wide == pytest.approx(abs(CM_A) * u / (1 - u**2), rel=1e-6)
    assert wide > 10 * abs(CM_A) * u
    # capped at 0.1: the derivative times u (1 / (1 + s) within 1 % of linear there)
    first = angle_null_sensitivity(_predict, X, A, 1, 4, rows, 0, u, 0.0, scale_step=0.1)["scale"]
    assert first == pytest.approx(abs(CM_A) * u, rel=0.02)
    # below the cap nothing changes
    small = angle_null_sensitivity(_predict, X, A, 1, 4, rows, 0, 0.05, 0.0, scale_step=0.1)["scale"]
    assert small == angle_null_sensitivity(_predict, X, A, 1, 4, rows, 0, 0.05, 0.0)["scale"]
    assert THRESHOLDS["coverage_scale_step"] == 0.0          # off by default (opt-in)
