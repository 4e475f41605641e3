"""The sideslip's error along a finding's term, fitted beside the other named findings
(``sparse.THRESHOLDS["angle_error_beside_named"]``, ``differential.angle_scale_allowance(beside=...)``).

The JSBSim ultrastick's ``Cn:delta_a`` flights also named ``CY:p_hat``: the aided sideslip's error follows ``p_hat``
more on those flights than on the reference (1.24-1.27 against 0.785 rad per unit, measured against the truth), which
moves CY by ``-CY_beta`` and Cn by ``-Cn_beta`` times that. The error is fitted on Cn, whose residual also holds the
real ``delta_a`` change, correlated with ``p_hat`` through the roll response; fitted beside that change it explains
CY's ``p_hat`` "change", fitted without it it does not. Fast (synthetic arrays, < 0.5 s)."""

import numpy as np

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.diagnose.differential import angle_scale_allowance


def _flight(seed=3):
    rng = np.random.default_rng(seed)
    T = 6000
    X = np.zeros((T, 10))
    t = np.arange(T) / 50.0
    da = 0.08 * np.sin(2 * np.pi * 0.3 * t) + 0.02 * rng.standard_normal(T)
    X[:, REGRESSORS.index("delta_a")] = da
    X[:, REGRESSORS.index("p_hat")] = 0.6 * da + 0.01 * rng.standard_normal(T)     # the roll response
    X[:, REGRESSORS.index("beta")] = 0.03 * np.sin(2 * np.pi * 0.11 * t + 1.0)
    X[:, REGRESSORS.index("V")] = 28.0
    model = {"CY": {"beta": -0.19}, "Cn": {"beta": 0.053}, "Cl": {"beta": -0.002}}
    s = 0.47                                        # the sideslip's error along p_hat (true = measured + s p_hat)
    R = np.zeros((T, 6))
    p = X[:, REGRESSORS.index("p_hat")]
    R[:, COEFFICIENTS.index("CY")] = -0.19 * s * p
    R[:, COEFFICIENTS.index("Cn")] = 0.053 * s * p - 0.06 * da                     # and a real Cn:delta_a change
    R[:, COEFFICIENTS.index("Cl")] = -0.002 * s * p
    R += 2e-4 * rng.standard_normal(R.shape)
    train = np.arange(T) < 4800
    return X, R, train, ~train, model, da


def test_the_error_along_p_hat_beside_the_named_delta_a_change_explains_the_side_force():
    X, R, train, test, model, da = _flight()
    alone = angle_scale_allowance(X, R, train, test, model, "CY", "p_hat", "beta", along_term=True)
    beside = angle_scale_allowance(X, R, train, test, model, "CY", "p_hat", "beta", along_term=True,
                                   beside={"Cn": da[:, None]})
    assert not alone["scale_only"]                  # the Cn change read as the sideslip's error: CY left unexplained
    assert beside["scale_only"]                     # fitted beside it: CY:p_hat is the sideslip's error
    assert abs(beside["error_along_term"] - 0.47) < 0.05 * 0.47
