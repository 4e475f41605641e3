"""`benchmarks/eval_common.truth_residual_correlation` (the eval rows' `truth_resid_corr`): the truth's own coupling
between two coefficients beyond a linear model of the regressors (issue 8's "where the truth has none"): a shared
nonlinear term reads near 1, independent residuals near 0, and a shared linear term (which the regressors explain) does
not count."""

import numpy as np

from benchmarks.eval_common import truth_residual_correlation


def test_shared_nonlinear_residual_reads_as_a_coupling_and_linear_terms_do_not():
    rng = np.random.default_rng(2)
    T = 4000
    X = rng.standard_normal((T, 10))
    shared = X[:, 0] ** 2                          # no linear model of X explains it
    Y = np.zeros((T, 6))
    Y[:, 2] = -5.0 * X[:, 0] + 0.5 * shared + 0.01 * rng.standard_normal(T)      # CZ
    Y[:, 4] = -1.0 * X[:, 0] - 0.3 * shared + 0.01 * rng.standard_normal(T)      # Cm: the same term
    Y[:, 0] = 2.0 * X[:, 3] + 0.1 * rng.standard_normal(T)                        # CX: linear + its own noise
    Y[:, 1] = 2.0 * X[:, 3] + 0.1 * rng.standard_normal(T)                        # CY: the same linear term
    Y[:, 3], Y[:, 5] = rng.standard_normal(T), rng.standard_normal(T)
    rows = np.ones(T, bool)
    rows[::7] = False
    X[5, 2] = np.nan                               # a row with a missing regressor is left out, not propagated
    c = truth_residual_correlation(X, Y, rows)
    assert c["CZ-Cm"] > 0.95
    assert c["CX-CY"] < 0.1 and c["Cl-Cn"] < 0.1
    assert set(c) == {f"{a}-{b}" for i, a in enumerate(("CX", "CY", "CZ", "Cl", "Cm", "Cn"))
                      for j, b in enumerate(("CX", "CY", "CZ", "Cl", "Cm", "Cn")) if i < j}
