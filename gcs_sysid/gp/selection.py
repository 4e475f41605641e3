"""Choosing inducing points: greedy mutual information, k-means and random.

The greedy mutual-information rule of Krause, Singh and Guestrin (2008),
"Near-optimal sensor placements in Gaussian processes: theory, efficient
algorithms and empirical studies", JMLR 9, Algorithm 1: from candidates ``V``,
repeatedly add the point ``y`` that maximises

    delta(y) = H(y | A) - H(y | V \\ (A + y)) = 0.5 log(sigma^2_{y|A} / sigma^2_{y|V\\(A+y)})

so a point is taken when it is uncertain given the chosen set *and* well explained
by the points left out, which keeps the selection inside the data cloud instead of on
its boundary (the weakness of maximum entropy / variance sampling). ``sigma^2_{y|A}``
is maintained by an incremental (pivoted) Cholesky factor, ``sigma^2_{y|rest}`` from the
precision matrix of the unselected set (``1 / P_yy``), down-dated by one Schur
complement per step: O(n^3) once and O(n^2) per selected point for ``n`` candidates.

The thesis's DGP sampling uses an MI criterion over the dependent outputs; with the
intrinsic coregionalisation model all outputs share ``k(x, x')``, so the criterion is
applied to ``k`` with a nugget that plays the part of the (relative) noise.
"""

from __future__ import annotations

import numpy as np
from scipy.cluster.vq import kmeans2
from scipy.linalg import cho_factor, cho_solve

__all__ = ["greedy_mutual_information", "kmeans_points", "random_points", "select_inducing"]


def greedy_mutual_information(K: np.ndarray, m: int, nugget: float = 1e-2) -> np.ndarray:
    """Indices of ``m`` candidates chosen greedily by mutual information.

    Args:
        K: ``(n, n)`` prior covariance of the candidates (unit diagonal or not).
        m: number to choose, ``m <= n``.
        nugget: variance added to the diagonal (observation noise; keeps the precision finite).

    Returns:
        ``(m,)`` integer indices in the order chosen.

    Both conditional variances are kept by rank-one updates of stored vectors, never of
    ``n x n`` matrices: ``sigma^2_{y|A}`` by the columns of the incremental Cholesky factor of
    the chosen set, and the precision of the unselected set as ``P_0 - U U^T``, where each
    Schur-complement down-date adds the column ``u = P[:, y] / sqrt(P_yy)`` to ``U``. One
    ``O(n^3)`` factorisation, then ``O(n j)`` for the ``j``-th point: ``O(n^3 + n m^2)`` in
    all instead of ``O(n^2 m)``.

    Source: Krause, Singh and Guestrin (2008), JMLR 9:235-284, Algorithm 1 and eq. 6.
    """
    n = K.shape[0]
    m = int(min(m, n))
    Kn = np.array(K, float)                                     # K + nugget I, without an (n, n) eye
    Kn[np.diag_indices(n)] += nugget
    prec0 = cho_solve(cho_factor(Kn, lower=True), np.eye(n), overwrite_b=True)   # precision of all candidates
    prec_diag = np.diag(prec0).copy()                           # diag of the unselected set's precision
    cond_var = np.diag(Kn).copy()                               # sigma^2_{y|A}, A empty
    factor = np.zeros((n, m))                                   # incremental Cholesky columns (chosen set)
    down = np.zeros((n, m))                                     # Schur down-dates of the precision
    remaining = np.ones(n, bool)
    chosen = np.empty(m, int)
    for j in range(m):
        # sigma^2_{y | rest} = 1 / prec_yy; delta ~ log(cond_var * prec_yy)
        score = np.log(np.maximum(cond_var, 1e-300)) + np.log(np.maximum(prec_diag, 1e-300))
        score[~remaining] = -np.inf
        y = int(np.argmax(score))
        chosen[j] = y
        # condition the chosen-set variances on y (one Cholesky column)
        col = (Kn[:, y] - factor[:, :j] @ factor[y, :j]) / np.sqrt(max(cond_var[y], 1e-300))
        factor[:, j] = col
        cond_var = np.maximum(cond_var - col**2, 0.0)
        # remove y from the unselected set: Schur complement of prec_yy, as one stored column
        py = prec0[:, y] - down[:, :j] @ down[y, :j]
        u = py / np.sqrt(max(py[y], 1e-300))
        down[:, j] = u
        prec_diag -= u * u
        remaining[y] = False
    return chosen


def kmeans_points(Xs: np.ndarray, m: int, seed: int = 0) -> np.ndarray:
    """``(m, D)`` k-means centres of the rows of ``Xs`` (scipy ``kmeans2``, k-means++ start)."""
    m = int(min(m, len(Xs)))
    centres, _ = kmeans2(Xs, m, minit="++", seed=np.random.default_rng(seed))
    return centres


def random_points(n: int, m: int, seed: int = 0) -> np.ndarray:
    """``(m,)`` indices drawn without replacement from ``range(n)``."""
    return np.sort(np.random.default_rng(seed).choice(n, int(min(m, n)), replace=False))


def select_inducing(Xs: np.ndarray, m: int, lengthscale: np.ndarray, method: str = "mi", pool: int = 1500,
                    nugget: float = 1e-2, seed: int = 0) -> np.ndarray:
    """Inducing inputs ``(m, D)`` chosen from the standardised data ``Xs (N, D)``.

    Args:
        method: ``"mi"`` (greedy mutual information on a random pool of ``pool`` rows, with
            the ARD SE kernel of length-scales ``lengthscale (D,)``), ``"kmeans"`` or ``"random"``.
        nugget: relative noise for the MI criterion.

    Raises:
        ValueError: unknown method.
    """
    rng_pool = random_points(len(Xs), pool, seed)
    if method == "random":
        return Xs[random_points(len(Xs), m, seed + 1)]
    if method == "kmeans":
        return kmeans_points(Xs[rng_pool], m, seed)
    if method != "mi":
        raise ValueError(f"gp: unknown inducing-point selection {method!r} (expected 'mi', 'kmeans' or 'random')")
    cand = Xs[rng_pool]
    a = cand / lengthscale
    sq = np.sum(a * a, 1)
    K = sq[:, None] + sq[None, :]                 # the (pool, pool) kernel built in place: the same
    G = a @ a.T                                   # operations as exp(-0.5 max(|a|^2 + |b|^2 - 2 a.b, 0))
    G *= 2.0                                      # with two arrays alive instead of five
    K -= G
    del G
    np.maximum(K, 0.0, out=K)
    K *= -0.5
    np.exp(K, out=K)
    return cand[greedy_mutual_information(K, m, nugget)]
