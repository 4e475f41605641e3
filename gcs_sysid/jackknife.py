"""Delete-a-block jackknife of least-squares coefficients on time-ordered, dependent data.

A low-level helper with no project imports, so that both the estimation layer
(:func:`gcs_sysid.estimation.airangles._scale_disagreement`, the aided angle's scale against the
kinematic one) and the diagnosis (:mod:`gcs_sysid.diagnose.uncertainty`,
:func:`gcs_sysid.diagnose.differential.block_jackknife_se`) use the same estimator. Moved here from
``gcs_sysid/diagnose/uncertainty.py`` in the tenth session (branch i9-alias); the diagnosis re-exports it.
The same blocks (:func:`block_labels`) serve the scalar form, :func:`block_jackknife_var`, for a statistic that is
not a least-squares coefficient (thirty-sixth session: the moment cross-check's ``lambda``,
:func:`gcs_sysid.estimation.airangles.moment_lambda`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["block_jackknife_cov", "block_jackknife_var", "block_jackknife_vars", "block_labels",
           "slope_second_moment"]


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
    k, labels = block_labels(t, block_s, min_rows)
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


def slope_second_moment(t: np.ndarray, A: np.ndarray, y: np.ndarray, block_s: float = 15.0) -> np.ndarray | None:
    """``M M^T + Cov_jk(M)``: the second moment of the least-squares slopes ``M`` of ``y`` on the centred columns
    ``A``, their delete-a-block jackknife covariance (:func:`block_jackknife_cov`, an intercept added) standing for
    their sampling error (zero where the jackknife has too few blocks).

    A flight-common linear error ``e(x) = M (x - mean x)`` stated with this second moment is what the band at exact
    conditions carries for the aided air angles (:func:`gcs_sysid.estimation.airangles._map_disagreement`) and the
    gyro's yaw rate (:func:`gcs_sysid.aero.rateerrors.yaw_rate_map`).

    Args:
        t: ``(N,)`` the rows' times, s. A: ``(N, K)`` centred regressors. y: ``(N,)`` the response (its mean is
            taken out for the slopes; the jackknife's intercept absorbs it). block_s: block length, s.

    Returns:
        ``(K, K)``, or None when ``A`` is rank-deficient.
    """
    y = np.asarray(y, float)
    M, _, rank, _ = np.linalg.lstsq(A, y - y.mean(), rcond=None)
    if rank < A.shape[1]:
        return None
    cov = block_jackknife_cov(t, np.column_stack([np.ones(len(y)), A]), y, block_s)
    jk = cov[1:, 1:] if cov is not None and np.isfinite(cov).all() else np.zeros((len(M), len(M)))
    return np.outer(M, M) + jk


def block_labels(t: np.ndarray, block_s: float, min_rows: int = 50) -> tuple[np.ndarray, list[int]]:
    """The delete-a-block jackknife's blocks: contiguous ``block_s``-second blocks counted from ``t[0]``.

    Args:
        t: (N,) time of the rows in time order, s (finite).
        block_s: block length, s. min_rows: blocks with fewer rows are never left out on their own.

    Returns:
        (k, labels): (N,) block index of each row, and the indices of the blocks that may be left out
        (empty with fewer than ``3 * min_rows`` rows or ``block_s <= 0``).
    """
    t = np.asarray(t, float)
    if t.size < 3 * min_rows or block_s <= 0:
        return np.zeros(t.size, int), []
    k = np.floor((t - t[0]) / block_s).astype(int)
    return k, [int(b) for b in np.unique(k) if np.sum(k == b) >= min_rows]


def block_jackknife_var(t: np.ndarray, statistic, block_s: float = 15.0, min_rows: int = 50) -> float:
    """Delete-a-block jackknife variance of a scalar statistic of time-ordered, dependent rows.

    The statistic is recomputed with each block left out, ``s_i``, and
    ``Var = (B - 1)/B sum (s_i - mean s)^2`` (Kuensch 1989, the same blocks as :func:`block_jackknife_cov`;
    Efron and Tibshirani 1993 sec. 11.5). For smooth statistics of the rows (a ratio of least-squares
    coefficients, :func:`gcs_sysid.estimation.airangles.moment_lambda`).

    Args:
        t: (N,) time of the rows in time order, s (finite).
        statistic: callable taking an (N,) bool mask of the rows kept and returning a float.
        block_s: block length, s. min_rows: as :func:`block_labels`.

    Returns:
        the variance, or NaN with fewer than 3 blocks or a non-finite leave-one-out value.
    """
    v = block_jackknife_vars(t, lambda keep: [float(statistic(keep))], block_s, min_rows)
    return float(v[0]) if v is not None else float("nan")


def block_jackknife_vars(t: np.ndarray, statistic, block_s: float = 15.0, min_rows: int = 50) -> np.ndarray | None:
    """Delete-a-block jackknife variances of a vector statistic of time-ordered, dependent rows.

    As :func:`block_jackknife_var`, element by element (the same blocks): for the coefficients of a fit that is not
    plain least squares, or is refitted whole (the sideslip aiding's first pass, two-stage or least squares:
    :attr:`gcs_sysid.estimation.airangles.AxisFit.slope_jackknife`).

    Args:
        t: (N,) time of the rows in time order, s (finite).
        statistic: callable taking an (N,) bool mask of the rows kept and returning a (P,) array.
        block_s: block length, s. min_rows: as :func:`block_labels`.

    Returns:
        (P,) variances, or None with fewer than 3 blocks or a non-finite leave-one-out value.
    """
    k, labels = block_labels(t, block_s, min_rows)
    if len(labels) < 3:
        return None
    s = np.array([np.asarray(statistic(k != b), float) for b in labels])
    if not np.all(np.isfinite(s)):
        return None
    B = s.shape[0]
    return (B - 1) / B * np.sum((s - s.mean(axis=0)) ** 2, axis=0)
