"""Least-squares derivatives of a JSBSim flight's exact truth, shared by the harness tests."""

import numpy as np

from benchmarks.jsbsim_harness.truth import truth_coefficients, truth_regressors


def derivative_slopes(rec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Slopes of the exact Cm, Cl, Cn on their leading regressors (intercept fitted, not returned).

    Args:
        rec: a harness ``Recording``.

    Returns:
        ``(cm, cl, cn)``: Cm on (alpha, q_hat, delta_e); Cl and Cn each on (beta, p_hat, r_hat,
        delta_a, delta_r); 1/rad.
    """
    X, Y = truth_regressors(rec), truth_coefficients(rec)

    def slopes(y, cols):
        A = np.c_[np.ones(len(y)), X[:, cols]]
        return np.linalg.lstsq(A, y, rcond=None)[0][1:]

    return (slopes(Y[:, 4], [0, 3, 5]), slopes(Y[:, 3], [1, 2, 4, 6, 7]), slopes(Y[:, 5], [1, 2, 4, 6, 7]))
