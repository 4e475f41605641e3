"""Blocked cross-validation: each nonparametric part of the GP must earn its place, per output.

The global layer is a Bayesian linear (stability-and-control-derivative) model plus a latent GP
``f_p = a_p^T g``; the local layer adds nearest-neighbour GPs on its residual. Both are fitted by
marginal likelihood with independent noise from row to row. Flight data break that assumption:
a gust, the air-angle estimate's lag or the angular-acceleration smoother's error moves hundreds
of consecutive 50 Hz rows together. To the likelihood such a coloured error looks like signal, so
the latent GP and, above all, the local layer (whose neighbours are mostly the rows just before
and after) learn it, and predict it where it is not: on rows of another time. Measured on the
JSBSim flights (``docs/benchmarks.md``, eval_gp_jsbsim, "The GP earns its place"): without the
local layer the held-out errors fell on 30 of 36 flight x coefficient pairs (5 equal to 0.1 %, 1
higher), and on the moments, whose truth is linear in the regressors plus the turbulence's
rotational rates (which no regressor carries), a plain linear fit beat the GP.

The check here asks the data the question the held-out segment asks: the training rows, in time
order, are cut into ``k`` contiguous blocks; each block is predicted by the model conditioned on
the other blocks only (for fixed hyperparameters the global layer's statistics are sums over
rows, so "all rows minus block b" is exact and costs one posterior, not one fit). Per output:

* global layer: the latent GP's prior scale ``s_p`` (rows of the coregionalisation factor ``A``
  multiplied by ``s_p``, so ``B -> S B S``) is chosen on the grid :data:`GLOBAL_GRID` by the
  blocked squared error; ``s_p`` small leaves a Bayesian linear regression for that output (the
  smallest value is kept above 0 so that ``B`` stays positive definite);
* local layer: kept for output ``p`` only when it lowers the blocked squared error of the global
  residual by at least 1 % (:data:`LOCAL_MARGIN`); otherwise its signal variance ``amp_p`` is
  multiplied by :data:`LOCAL_OFF` (mean and variance of that output's local part ~0).

This is the k-fold cross-validation of Rasmussen and Williams (2006), *Gaussian Processes for
Machine Learning*, sec. 5.3, with contiguous blocks as for dependent data (Roberts et al. 2017,
"Cross-validation strategies for data with temporal, spatial, hierarchical, or phylogenetic
structure", Ecography 40(8):913-929, doi:10.1111/ecog.02881); the scales are selected, not
optimised by gradient, to keep the cost to a few posteriors. The rows must be in time order (a
flight's table is); shuffled rows make every block look like the training rows, and the check
then keeps (almost) everything.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import jax
import jax.numpy as jnp
import numpy as np

from ..jaxconfig import stored_jit
from jax.scipy.linalg import cho_solve

from .batching import _add_jit, global_stats, local_predict
from .local import LocalParams, LocalStore, neighbour_tree, own_neighbours
from .sparse import GlobalParams, Stats, _assemble, _chol_kmm, _concrete, _selectors, design, features

__all__ = ["GLOBAL_GRID", "LOCAL_OFF", "LOCAL_MARGIN", "SHARED_NEIGHBOURS", "block_folds", "scale_latent",
           "gate_global", "gate_local", "gate_mean_only",
           "NeighbourSearch", "shared_search", "store_without", "block_stores"]

#: Candidate scales ``s_p`` of the latent GP's prior std per output (1: as learned).
GLOBAL_GRID: tuple[float, ...] = (0.05, 0.3, 1.0)

#: Factor on a rejected output's local signal variance ``amp_p`` (its local mean and variance ~0).
LOCAL_OFF = 1e-6

#: The local layer is kept for an output when its blocked squared error is below this share of the
#: error without it: it must earn its place by a margin, not by a rounding-level difference (on
#: smooth synthetic data the ratio sits at 0.9996-1.0025 for outputs the layer has nothing to add).
LOCAL_MARGIN = 0.99

#: The stores of the held-back blocks share one neighbour search of all rows for this many times
#: ``k`` neighbours each (plus the row itself); a row left with fewer than ``k + 1`` neighbours
#: outside a block is searched again in that block's own tree (:func:`block_stores`). 3 leaves
#: ~0.2 % of the rows to search again on the 10-minute benchmark flight (2: ~4 %, 1: ~30 %).
SHARED_NEIGHBOURS = 3


def block_folds(n: int, k: int) -> list[tuple[int, int]]:
    """``k`` contiguous ``(start, stop)`` blocks covering ``range(n)`` (sizes differ by at most 1)."""
    edges = np.linspace(0, n, k + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def scale_latent(params: GlobalParams, s) -> GlobalParams:
    """``params`` with the latent GP's prior std of output ``p`` multiplied by ``s[p]`` (``s (P,)``).

    Rows of every coregionalisation factor are scaled (``A_j -> diag(s) A_j``, so
    ``B_j -> S B_j S``); a lower-triangular factor stays lower-triangular.
    """
    if _concrete(params.A, params.lmc_A):
        # values: the products on the host (one rounding each, as XLA's), moved back; no eager program compiled
        s = np.asarray(s, np.asarray(params.A).dtype)
        lmc = None if params.lmc_A is None else jax.device_put(np.asarray(params.lmc_A) * s[None, :, None])
        return replace(params, A=jax.device_put(np.asarray(params.A) * s[:, None]), lmc_A=lmc)
    s = jnp.asarray(s, params.A.dtype)
    lmc = None if params.lmc_A is None else params.lmc_A * s[None, :, None]
    return replace(params, A=params.A * s[:, None], lmc_A=lmc)


@stored_jit
def _mean_weights(params: GlobalParams, st: Stats) -> jax.Array:
    """Predictive-mean weights ``(J*M+D+1, P)`` on ``u = [phi; xa]`` (as :func:`sparse.posterior`,
    without the covariance)."""
    lam, b = _assemble(params, st)
    L = jnp.linalg.cholesky(lam)
    mu = cho_solve((L, True), b)
    return jnp.einsum("pkj,k->jp", _selectors(params, params.Z.shape[0]), mu)


@stored_jit
def _design_u(params: GlobalParams, Xs: jax.Array) -> jax.Array:
    """``u = [phi(x); xa(x)]`` of shape ``(N, J*M+D+1)``; independent of ``A`` (the features use
    only the length-scales and the inducing inputs)."""
    Lm = _chol_kmm(params)
    return jnp.concatenate([features(params, Lm, Xs), design(Xs).T], axis=0).T


@stored_jit
def _sub(a: Stats, b: Stats) -> Stats:
    """``a - b`` leaf by leaf, as one compiled program (eager, each leaf's shape compiles its own)."""
    return jax.tree_util.tree_map(jnp.subtract, a, b)


def _val_rows(a: int, b: int, most: int, rng: np.random.Generator) -> np.ndarray:
    """Up to ``most`` rows of the block ``[a, b)`` (all of them when it is small), sorted."""
    if b - a <= most:
        return np.arange(a, b)
    return np.sort(rng.choice(np.arange(a, b), most, replace=False))


def gate_global(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, folds: int, batch: int,
                val_max: int = 1000, seed: int = 0) -> tuple[GlobalParams, Stats, np.ndarray, np.ndarray]:
    """Choose the latent GP's prior scale per output by blocked cross-validation.

    Args:
        params: learned global hyperparameters.
        Xs: ``(N, D)``, Ys: ``(N, P)`` standardised training rows in time order.
        folds: contiguous blocks ``k`` (at least 2).
        batch: rows per compiled chunk for the statistics.
        val_max: most validation rows in all (spread evenly over the blocks).
        seed: seed of the choice of validation rows.

    Returns:
        ``(params_scaled, stats, s, sse)``: the scaled parameters (:func:`scale_latent`), the
        statistics of all rows (they do not depend on ``A``: the fit's posterior uses them),
        the chosen scales ``s (P,)`` (from :data:`GLOBAL_GRID`) and the blocked squared errors
        ``sse (G, P)`` per grid value (standardised units, summed over the validation rows).
    """
    n, P = Ys.shape
    blocks = block_folds(n, folds)
    parts = [global_stats(params, Xs[a:b], Ys[a:b], batch) for a, b in blocks]
    total = parts[0]
    for st in parts[1:]:
        total = _add_jit(total, st)           # the chunks' sum program of global_stats: no new compilation
    rng = np.random.default_rng(seed + 23)
    per = max(1, val_max // len(blocks))
    grid = [scale_latent(params, np.full(P, g)) for g in GLOBAL_GRID]
    sse = np.zeros((len(GLOBAL_GRID), P))
    for (a, b), st in zip(blocks, parts):
        rest = _sub(total, st)
        rows = _val_rows(a, b, per, rng)
        U = np.asarray(_design_u(params, Xs[rows]))
        for g, pg in enumerate(grid):
            W = np.asarray(_mean_weights(pg, rest))
            sse[g] += np.nansum((Ys[rows] - U @ W) ** 2, 0)      # NaN: a missing output
    s = np.asarray(GLOBAL_GRID)[np.argmin(sse, 0)]
    return scale_latent(params, s), total, s, sse


def gate_mean_only(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, cols, folds: int, batch: int,
                   val_max: int = 1000, seed: int = 0) -> tuple[GlobalParams, np.ndarray, np.ndarray]:
    """Keep the mean-only inputs ``cols`` (``GPConfig.mean_only_inputs``) in an output's linear mean only where
    they lower its blocked cross-validation error (``docs/gp.md``, "Mean-only inputs").

    The same blocks and validation rows as :func:`gate_global` (same ``seed``): for each held-back block the
    posterior mean of the other blocks with those weights' prior std as it is, and with it set to 0 (the
    statistics do not depend on it: a posterior-only change, as ``linear_terms = "validated"``). A term that
    is significant in a least-squares fit on every row can still be a proxy that does not predict held-back
    time: on the f16 (no ``Cm_alpha_dot`` in its aerodynamics) ``alpha_dot_hat`` took 3.4-3.8 per rad of Cm's
    ``q_hat`` slope and raised the held-out Cm error by 0.2-0.4 points with this gate passed (ratio 0.68-0.71);
    the pre-fit partner rule (``GPConfig.mean_only_partners``, :func:`gcs_sysid.gp.fit.mean_only_masks`) now
    keeps it out there.

    Args:
        params: the global hyperparameters after :func:`gate_global` (``prior_std`` ``(P, D+1)`` or scalar).
        Xs: ``(N, D)``, Ys: ``(N, P)`` standardised training rows in time order.
        cols: indices ``d`` (into ``D``) of the mean-only inputs.
        folds, batch, val_max, seed: as :func:`gate_global`.

    Returns:
        ``(params, keep (P,) bool, ratio (P,))``: ``prior_std`` with those weights at 0 for the outputs where the
        blocked squared error with them is not below that without (``keep`` False; outputs that carry none of
        them keep ``True``), and ``ratio`` the error with over without (NaN where they carry none).
    """
    n, P = Ys.shape
    D = Xs.shape[1]
    S = np.array(np.broadcast_to(np.asarray(params.prior_std, float), (P, D + 1)))
    idx = 1 + np.asarray(list(cols), int)
    carry = np.any(S[:, idx] > 0, axis=1)
    keep, ratio = np.ones(P, bool), np.full(P, np.nan)
    if not carry.any():
        return params, keep, ratio
    S0 = S.copy()
    S0[:, idx] = 0.0
    with_p = replace(params, prior_std=jax.device_put(S))
    without = replace(params, prior_std=jax.device_put(S0))
    blocks = block_folds(n, folds)
    parts = [global_stats(params, Xs[a:b], Ys[a:b], batch) for a, b in blocks]
    total = parts[0]
    for st in parts[1:]:
        total = _add_jit(total, st)
    rng = np.random.default_rng(seed + 23)
    per = max(1, val_max // len(blocks))
    sse1, sse0 = np.zeros(P), np.zeros(P)
    for (a, b), st in zip(blocks, parts):
        rest = _sub(total, st)
        rows = _val_rows(a, b, per, rng)
        U = np.asarray(_design_u(params, Xs[rows]))
        sse1 += np.nansum((Ys[rows] - U @ np.asarray(_mean_weights(with_p, rest))) ** 2, 0)
        sse0 += np.nansum((Ys[rows] - U @ np.asarray(_mean_weights(without, rest))) ** 2, 0)
    ratio[carry] = sse1[carry] / np.maximum(sse0[carry], 1e-300)
    keep[carry] = sse1[carry] < sse0[carry]
    S[~keep] = S0[~keep]
    return replace(params, prior_std=jax.device_put(S)), keep, ratio


def gate_local(local: LocalParams, Xs: np.ndarray, resid: np.ndarray, metric: np.ndarray, k: int, folds: int,
               batch: int, val_max: int = 1000, seed: int = 0, search: NeighbourSearch | None = None
               ) -> tuple[LocalParams, np.ndarray, np.ndarray]:
    """Keep the local layer per output only where it predicts held-back blocks of the global residual.

    Args:
        local: learned local hyperparameters.
        Xs: ``(N, D)`` standardised rows in time order; resid: ``(N, P)`` their global residuals.
        metric: ``(D,)`` the neighbour metric (1 / the global length-scales); k: neighbours.
        folds, batch, val_max, seed: as :func:`gate_global`.
        search: :func:`shared_search` of ``Xs`` with ``metric`` and ``k`` when the caller made one
            (e.g. for the store of all rows); made here otherwise.

    Returns:
        ``(local_gated, keep, ratio)``: parameters with ``amp_p`` times :data:`LOCAL_OFF` where
        rejected, ``keep (P,)`` bool (``ratio < LOCAL_MARGIN``), and ``ratio (P,)`` the blocked
        squared error with the local layer over that without it (< 1: it helps).
    """
    n, P = resid.shape
    rng = np.random.default_rng(seed + 29)
    per = max(1, val_max // max(folds, 1))
    with_l = np.zeros(P)
    without = np.zeros(P)
    blocks = [(a, b) for a, b in block_folds(n, folds) if n - (b - a) >= 2]
    for (a, b), store in zip(blocks, block_stores(Xs, resid, metric, k, blocks, search)):
        rows = _val_rows(a, b, per, rng)
        m, _ = local_predict(local, store, Xs[rows], batch)
        with_l += np.nansum((resid[rows] - m) ** 2, 0)            # NaN: a missing output
        without += np.nansum(resid[rows] ** 2, 0)
    ratio = with_l / np.maximum(without, 1e-300)
    keep = ratio < LOCAL_MARGIN
    amp = np.where(keep, np.asarray(local.amp), np.asarray(local.amp) * LOCAL_OFF)
    return replace(local, amp=jax.device_put(amp)), keep, ratio   # device_put: jnp.asarray compiles a copy


@dataclass(frozen=True)
class NeighbourSearch:
    """One k-d tree query of all rows, shared by the local stores of all rows and of the rows outside
    each held-back block (:func:`shared_search`).

    Attributes:
        pts: ``(N, D)`` the rows in the neighbour metric (``Xs * metric``). tree: the k-d tree on them.
        dist, idx: ``(N, W)`` distances and indices of each row's ``W`` nearest rows (itself included).
        metric: ``(D,)`` the metric. k: neighbours per local query.
    """

    pts: np.ndarray
    tree: object
    dist: np.ndarray
    idx: np.ndarray
    metric: np.ndarray
    k: int


def shared_search(Xs: np.ndarray, metric: np.ndarray, k: int) -> NeighbourSearch:
    """The ``min(N, SHARED_NEIGHBOURS * k + 1)`` nearest rows of every row of ``Xs (N, D)`` in the
    metric ``metric (D,)`` (one k-d tree query; :func:`store_without` builds stores from it)."""
    n = len(Xs)
    pts = Xs * metric
    tree = neighbour_tree(pts)
    wide = min(n, SHARED_NEIGHBOURS * int(k) + 1)
    dist, idx = tree.query(pts, k=wide, workers=-1)
    return NeighbourSearch(pts, tree, np.asarray(dist).reshape(n, wide), np.asarray(idx).reshape(n, wide),
                           np.asarray(metric), int(k))


def store_without(search: NeighbourSearch, Xs: np.ndarray, resid: np.ndarray, a: int, b: int) -> LocalStore:
    """The local store of the rows outside ``[a, b)`` (all rows when ``a == b``), equal to
    :func:`gcs_sysid.gp.local.build_store` of those rows with ``search``'s metric and ``k``.

    A store's log spacing ``z`` needs, for every stored row, the distances to its ``k + 1`` nearest
    stored rows (itself included). Those are the first ``k + 1`` rows *outside the block* among the
    row's shared neighbours, where at least ``k + 1`` of them lie outside; the other rows are queried
    again in the store's own tree. Any stored row not among a row's shared neighbours is at least as
    far as the last of them, so the kept distances are the ``k + 1`` smallest (ties give equal
    values), and each pair's distance is computed from the same two points in either tree: ``z``
    equals ``build_store``'s bit for bit (``tests/gp/test_validation_shared.py``).

    Args:
        search: :func:`shared_search` of ``Xs``. Xs: ``(N, D)`` standardised rows; resid: ``(N, P)``.
        a, b: the held-back rows ``[a, b)``; at least 2 rows must lie outside.
    """
    n = len(Xs)
    keep_rows = np.r_[0:a, b:n]
    m = len(keep_rows)
    kb = int(max(1, min(search.k, m)))
    kk = min(kb + 1, m)                                       # <= the shared width: m <= N, kb <= k
    p_keep = search.pts[keep_rows]
    tree = search.tree if m == n else neighbour_tree(p_keep)
    ii = search.idx[keep_rows]
    outside = (ii < a) | (ii >= b)
    # the first kk neighbours outside the block, in distance order (stable: the query's order)
    first = np.argsort(~outside, axis=1, kind="stable")[:, :kk]
    dist = np.take_along_axis(search.dist[keep_rows], first, axis=1)
    short = np.flatnonzero(outside.sum(1) < kk)
    if len(short):
        again, _ = tree.query(p_keep[short], k=kk, workers=-1)
        dist[short] = np.asarray(again).reshape(len(short), kk)
    logrho = np.log(np.maximum(dist[:, 1:].mean(1) if kk > 1 else np.ones(m), 1e-12))
    z_mean = float(logrho.mean())
    # the store of every row (the model's) keeps each row's own kb nearest rows (itself first), as a kb-query of
    # its tree returns them (``LocalStore.own_idx``); a block's store is queried at the block's rows, none stored
    own = own_neighbours(search.idx, dist, kb) if m == n else (None, None, None)
    return LocalStore(Xs[keep_rows], resid[keep_rows], search.metric, logrho - z_mean, z_mean, kb, tree, *own)


def block_stores(Xs: np.ndarray, resid: np.ndarray, metric: np.ndarray, k: int, blocks: list[tuple[int, int]],
                 search: NeighbourSearch | None = None):
    """The local stores of all rows but each block, equal to ``build_store`` of those rows, from one
    shared neighbour search (:func:`shared_search`, :func:`store_without`).

    Args:
        Xs: ``(N, D)`` standardised rows; resid: ``(N, P)`` their residuals.
        metric: ``(D,)`` the neighbour metric; k: neighbours per query.
        blocks: ``(start, stop)`` row ranges, each leaving at least 2 rows outside.
        search: :func:`shared_search` of ``Xs`` with ``metric`` and ``k`` when already made.

    Yields:
        one :class:`~gcs_sysid.gp.local.LocalStore` per block, of the rows ``r_[0:start, stop:N]``
        in that order.
    """
    search = shared_search(Xs, metric, k) if search is None else search
    for a, b in blocks:
        yield store_without(search, Xs, resid, a, b)
