"""Streaming sparse GP: moving the global layer's statistics to new inducing points, and choosing them.

With fixed hyperparameters and inducing inputs ``Z`` the global layer's statistics
(:class:`gcs_sysid.gp.sparse.Stats`) are sums over rows, so conditioning on new rows is exact
(Titsias 2009's collapsed VFE posterior of all rows at once). Replacing an inducing point or
changing the kernel's length-scales changes the features ``phi(x) = Lm^{-1} k(Z, x)`` of rows that
are no longer kept. Bui, Nguyen and Turner (2017), "Streaming sparse Gaussian process
approximations", NIPS 30, sec. 3.1, carry the old approximate posterior ``q_old(a)`` over the old
inducing outputs ``a = g(Z_old)`` into the new variational problem: the old data enter only through
the factor ``q_old(a) / p_old(a)``, and the optimal ``q_new(b)`` over the new inducing outputs
``b = g(Z_new)`` is that of a model in which this factor is evaluated at the conditional mean
``a = K_ab K_bb^{-1} b`` (the trace term ``-1/2 tr(D_a^{-1} (K_aa - Q_aa))`` of their bound does not
depend on ``q(b)``). In this package's whitened feature space the old factor is
``exp(-1/2 w_a^T J w_a + h^T w_a)`` with ``w_a = Lm_a^{-1} a``, so with

    R = Lm_a^{-1} K'(Z_old, Z_new) Lm_b'^{-T}     (M_old, M_new),   w_a = R w_b

(``K'``, ``Lm_b'`` under the new length-scales), the old rows' statistics become those of the
projected features ``R^T phi_old(x) = Lm_b'^{-1} K'_ba K_aa^{-1} k_a(x)``:

    C -> R^T C R,   E -> R^T E,   Rphi -> R^T Rphi,   F, Rx, yy, n unchanged.

It is exact when the old rows' features lie in the span (e.g. the old rows are the old inducing
inputs, a test) and otherwise Bui et al.'s approximation. Because the statistics are data
moments, not the posterior itself, the coregionalisation ``B``, the noise and the linear-mean prior
can change afterwards with no further approximation.

Choosing which point to replace: the mutual-information criterion of Krause, Singh and Guestrin
(2008), JMLR 9, eq. 6, ``delta(s) = H(s | A) - H(s | V \\ (A + s))``, evaluated for every point of
``S = Z + {c}`` with ``A = S - {s}`` and, for the unselected set ``V``, a random pool of stored rows
(:mod:`gcs_sysid.gp.rowstore`, a region-thinned sample of everything flown). The point of ``S`` with
the smallest ``delta`` (the most redundant given the rest) leaves; if it is the candidate itself,
nothing changes. Candidates are the new rows least explained by ``Z`` (largest
``sigma^2(c | Z)``), considered only above a threshold, so an update in a region already covered
does no selection work.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.linalg import cho_factor, cho_solve, solve_triangular

from .sparse import Stats

__all__ = ["se_kernel", "chol_kmm", "projection", "project_stats", "exchange_inducing", "RefreshBudget",
           "light_refresh"]


def se_kernel(X1: np.ndarray, X2: np.ndarray, lengthscale: np.ndarray) -> np.ndarray:
    """ARD squared-exponential ``(N1, N2)`` in NumPy (unit variance; as :class:`ARDSquaredExponential`)."""
    a, b = X1 / lengthscale, X2 / lengthscale
    d2 = np.sum(a * a, 1)[:, None] + np.sum(b * b, 1)[None, :] - 2.0 * a @ b.T
    return np.exp(-0.5 * np.maximum(d2, 0.0))


def chol_kmm(Z: np.ndarray, lengthscale: np.ndarray, jitter: float) -> np.ndarray:
    """Lower Cholesky factor ``(M, M)`` of ``k(Z, Z) + jitter I``."""
    return np.linalg.cholesky(se_kernel(Z, Z, lengthscale) + jitter * np.eye(len(Z)))


def projection(Lm_old: np.ndarray, Z_old: np.ndarray, Z_new: np.ndarray, lengthscale_new: np.ndarray,
               jitter: float) -> np.ndarray:
    """``R = Lm_old^{-1} K'(Z_old, Z_new) Lm_new^{-T}`` of shape ``(M_old, M_new)`` (Bui et al. 2017, sec. 3.1).

    Args:
        Lm_old: ``(M_old, M_old)`` Cholesky factor of the old ``Kmm`` (old length-scales).
        Z_old: ``(M_old, D)``, Z_new: ``(M_new, D)`` inducing inputs (standardised).
        lengthscale_new: ``(D,)`` length-scales of the new kernel ``K'``.
    """
    Lm_new = chol_kmm(Z_new, lengthscale_new, jitter)
    T = solve_triangular(Lm_old, se_kernel(Z_old, Z_new, lengthscale_new), lower=True, check_finite=False)
    return solve_triangular(Lm_new, T.T, lower=True, check_finite=False).T


def project_stats(stats: Stats, R: np.ndarray) -> Stats:
    """Statistics of the old rows seen through ``w_old = R w_new`` (``R (M_old, M_new)``); NumPy arrays."""
    C = np.asarray(stats.C)
    return Stats(C=R.T @ C @ R, E=R.T @ np.asarray(stats.E), F=np.asarray(stats.F), Rphi=R.T @ np.asarray(stats.Rphi),
                 Rx=np.asarray(stats.Rx), yy=np.asarray(stats.yy), n=np.asarray(stats.n))


def _variance_given(pool: np.ndarray, X: np.ndarray, ls: np.ndarray, nugget: float) -> np.ndarray:
    """``sigma^2(x | pool)`` ``(N,)`` for unit prior variance plus ``nugget`` (noisy pool observations).

    Pool rows equal to one of ``X`` are left out (the criterion conditions on the *other* points).
    """
    K = se_kernel(pool, X, ls)
    other = ~np.any(K > 1.0 - 1e-12, axis=1)
    pool, K = pool[other], K[other]
    if len(pool) == 0:
        return np.full(len(X), 1.0 + nugget)
    Lp = cho_factor(se_kernel(pool, pool, ls) + nugget * np.eye(len(pool)), lower=True)
    return np.maximum(1.0 + nugget - np.sum(K * cho_solve(Lp, K), 0), 1e-12)


def exchange_inducing(Z: np.ndarray, lengthscale: np.ndarray, candidates: np.ndarray, pool: np.ndarray,
                      nugget: float, threshold: float, max_tries: int) -> tuple[np.ndarray, int]:
    """Replace inducing points by new candidates where mutual information says so (Krause et al. 2008, eq. 6).

    Repeatedly (at most ``max_tries`` times): the candidate ``c`` with the largest
    ``sigma^2(c | Z)`` (unit prior variance plus ``nugget``) is considered if that exceeds
    ``threshold``; for ``S = Z + {c}`` each point's ``delta(s) = log sigma^2(s | S - s) -
    log sigma^2(s | pool)`` is computed (the first from the diagonal of ``(K_SS + nugget I)^{-1}``,
    bordered from ``Z``'s factor; the second from one factor of the pool) and the point with the
    smallest ``delta`` is dropped. A candidate that would drop itself is discarded.

    Args:
        Z: ``(M, D)`` inducing inputs (standardised). lengthscale: ``(D,)``.
        candidates: ``(E, D)`` new rows. pool: ``(Q, D)`` rows standing for the unselected set.
        nugget: relative noise of the criterion. threshold: least ``sigma^2(c | Z)`` considered.
        max_tries: most candidates evaluated.

    Returns:
        ``(Z_new (M, D), swaps)``: a new array (equal to ``Z`` when ``swaps == 0``).
    """
    if len(candidates) == 0 or max_tries <= 0 or len(Z) == 0:
        return Z, 0
    ls = np.asarray(lengthscale)
    Z = np.array(Z, float)
    M = len(Z)
    cand = np.array(candidates, float)
    alive = np.ones(len(cand), bool)
    rest_z = rest_c = None
    swaps = 0
    for _ in range(int(max_tries)):
        if not alive.any():
            break
        Kz = cho_factor(se_kernel(Z, Z, ls) + nugget * np.eye(M), lower=True)
        Kzc = se_kernel(Z, cand, ls)
        sol = cho_solve(Kz, Kzc)                                   # (M, E): Kzz^{-1} k_Z(c)
        var_c = np.where(alive, 1.0 + nugget - np.sum(Kzc * sol, 0), -np.inf)
        j = int(np.argmax(var_c))
        if var_c[j] < threshold + nugget:
            break                                                  # every new row is explained by Z
        alive[j] = False
        if rest_z is None:                                         # sigma^2(. | pool): the rest of the data cloud
            rest_z, rest_c = np.split(_variance_given(pool, np.vstack([Z, cand]), ls, nugget), [M])
        # diag of (K_SS + nugget I)^{-1} by the bordered inverse: for z in Z, inv_zz + sol_z^2 / s; 1/s for c
        s = var_c[j]
        inv_diag = np.diag(cho_solve(Kz, np.eye(M))) + sol[:, j] ** 2 / s
        loo = np.concatenate([1.0 / inv_diag, [s]])
        delta = np.log(np.maximum(loo, 1e-300)) - np.log(np.concatenate([rest_z, [rest_c[j]]]))
        drop = int(np.argmin(delta))
        if drop == M:
            continue                                               # the candidate is the most redundant
        Z[drop] = cand[j]
        rest_z[drop] = rest_c[j]
        swaps += 1
    return Z, swaps


@dataclass(frozen=True)
class RefreshBudget:
    """How much a light hyperparameter refresh (:func:`light_refresh`) may do.

    Attributes:
        steps: most Adam steps on the VFE bound (the full refresh: ``GPConfig.steps``, 200).
        rows: random stored rows the bound is evaluated on (full: ``n_train_max``, 1000).
        local_steps: most Adam steps of the local layer, from its variogram start as in a fit (full:
            ``local_steps``, 40); its store is rebuilt on the new global residuals either way.
        reselect: choose the ``M`` inducing inputs again by mutual information (full: yes). Without it
            the streamed exchange (:func:`exchange_inducing`) has already kept them on the envelope.
    """

    steps: int = 40
    rows: int = 1000
    local_steps: int = 40
    reselect: bool = False


def light_refresh(model, budget: RefreshBudget = RefreshBudget()):
    """A hyperparameter refresh at a fraction of a full one's cost: warm start, few steps, a subset.

    The refresh of :meth:`gcs_sysid.gp.LocalGlobalGP.refresh_hyperparameters` (Adam on the VFE bound,
    then the statistics again, the local layer again) run under a smaller budget: ``budget.steps``
    Adam steps (one run, no halfway re-selection) warm-started from the current hyperparameters on
    ``budget.rows`` random stored rows, the inducing inputs kept unless ``budget.reselect``. A warm
    start is most of the work already done: the bound is near its optimum except along the
    length-scales the new region changed, which the first tens of steps move (Adam at the fit's
    learning rate, 0.05 in log length-scale per step). The statistics are still recomputed exactly
    for the stored rows (``O(store_max M^2)``; the projection for evicted rows as before).

    Args:
        model: a :class:`gcs_sysid.gp.LocalGlobalGP` with stored rows.
        budget: :class:`RefreshBudget`.

    Returns:
        The refreshed model, with the original :class:`~gcs_sysid.gp.GPConfig`.

    Raises:
        DataError: fewer than 3 stored rows (as the full refresh).
    """
    cfg = model.config
    light = replace(cfg, steps=int(budget.steps), n_train_max=int(min(budget.rows, cfg.n_train_max)),
                    reselect=False, local_steps=int(budget.local_steps))
    new = replace(model, config=light).refresh_hyperparameters(reselect=budget.reselect)
    return replace(new, config=cfg)
