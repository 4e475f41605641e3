"""Delete-a-block jackknife of least-squares coefficients on time-ordered, dependent data.

A low-level helper with no project imports, so that both the estimation layer
(:func:`gcs_sysid.estimation.airangles._scale_disagreement`, the aided angle's scale against the
kinematic one) and the diagnosis (:mod:`gcs_sysid.diagnose.uncertainty`,
:func:`gcs_sysid.diagnose.differential.block_jackknife_se`) use the same estimator. Moved here from
``gcs_sysid/diagnose/uncertainty.py`` in the tenth session (branch i9-alias); the diagnosis re-exports it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["block_jackknife_cov"]


def block_jackknife_cov(t: np.ndarray, A: np.ndarray, r: np.ndarray, block_s: float = 15.0,
                        min_rows: int = 50) -> np.ndarray | None:
    """Delete-a-block jackknife covariance of least-squares coefficients on dependent data.

    The rows (in time order) are cut into contiguous blocks of ``block_s`` seconds counted from the first
    finite row's time ``t[0]``; the least-squares
    solution ``theta_i`` is recomputed with block ``i`` left out, and
    ``Cov = (B - 1)/B sum (theta_i - mean theta)(theta_i - mean theta)'`` (Kuensch 1989; Efron and
    Tibshirani, *An Introduction to the Bootstrap*, 1993, sec. 11.5 for the delete-one form).

    Args:
        t: (N,) time of the rows, s. A: (N, P) regressors (a constant column included by the caller).
        r: (N,) response. block_s: block length, s. min_rows: a block with fewer rows is left with its
            neighbours (it is never left out on its own).

    Returns:
        (P, P) covariance, or None with fewer than 3 blocks or a singular fit.
    """
    t, A, r = np.asarray(t, float), np.asarray(A, float), np.asarray(r, float)
    ok = np.isfinite(t) & np.all(np.isfinite(A), axis=1) & np.isfinite(r)
    t, A, r = t[ok], A[ok], r[ok]
    if t.size < 3 * min_rows or block_s <= 0:
        return None
    k = np.floor((t - t[0]) / block_s).astype(int)
    labels = [b for b in np.unique(k) if np.sum(k == b) >= min_rows]
    if len(labels) < 3:
        return None
    G, g = A.T @ A, A.T @ r
    th = []
    for b in labels:
        m = k == b
        try:
            th.append(np.linalg.solve(G - A[m].T @ A[m], g - A[m].T @ r[m]))
        except np.linalg.LinAlgError:
            return None
    th = np.asarray(th)
    B = th.shape[0]
    d = th - th.mean(axis=0)
    return (B - 1) / B * (d.T @ d)
