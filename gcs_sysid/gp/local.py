"""Local layer: nearest-neighbour GPs with a non-stationary covariance on the global residual.

The global sparse GP is smooth (its length-scales are limited by the inducing points);
fast variations are left in its residual ``r = y - m_global(x)``. The local layer
models ``r_p`` with an independent GP per output on the ``K`` nearest stored points of
each query (Vecchia-style local conditioning; Gramacy and Apley 2015, "Local Gaussian
process approximation for large computer experiments", JCGS 24(2)), with the
non-stationary Gibbs / Paciorek-Schervish kernel (:class:`GibbsKernel`) whose
length-scale follows the local data spacing ``rho(x)`` (mean distance to the ``K``
neighbours): ``l(x) = l0 exp(beta (log rho(x) - mean log rho))``. This is the thesis's
local layer ("local GP with a non-stationary covariance for fast variations"), summed
with the global layer.

Neighbours are searched with a k-d tree in the global layer's metric (standardised
inputs divided by the global length-scales), built by :func:`neighbour_tree`. Local
hyperparameters maximise a composite likelihood: the sum of exact log marginal
likelihoods over random neighbourhoods.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import jax
import jax.numpy as jnp
import numpy as np
from scipy.spatial import cKDTree

from ..jaxconfig import stored_jit

from .kernels import GibbsKernel

__all__ = ["LocalParams", "LocalStore", "build_store", "neighbours", "neighbour_tree", "own_neighbours",
           "NEIGHBOUR_TREE", "local_predict_chunk", "local_objective", "shared_nll", "MISSING_NOISE"]

#: Noise variance of a neighbour's missing output, in units of that output's ``amp + noise``.
MISSING_NOISE = 1e8

#: How the neighbour search's k-d trees are built (``scipy.spatial.cKDTree`` keyword arguments): cells cut at the
#: sliding midpoint of their longest side instead of at the median (``balanced_tree=False``; Maneewongvatana and
#: Mount 1999, "It's okay to be skinny, if your friends are fat"), 64 points per leaf instead of 16. The tree only
#: decides which cells are visited: every returned distance is computed from the same two points by the same
#: arithmetic, so a query returns the same neighbours and the same distances bit for bit, in the same order (two
#: stored points at exactly the same distance from a query, i.e. duplicated rows, could come in another order).
#: The rows of a flight lie along a trajectory in the 10-D regressor space, where median cuts make many thin
#: cells: on the 10-minute benchmark flight (24,000 stored rows, 16 neighbours) the confidence map's 4,096
#: queries take 0.32 -> 0.12 CPU s, the 30,000 predictions 0.34 -> 0.17 and the validation's shared search (49
#: neighbours of every row) 0.67 -> 0.38 (``docs/benchmarks.md``, "Thirty-third session, speed33").
NEIGHBOUR_TREE = {"leafsize": 64, "balanced_tree": False}


def neighbour_tree(pts: np.ndarray) -> cKDTree:
    """The k-d tree of the local layer's neighbour searches on ``pts (N, D)`` (the rows in the neighbour metric),
    built with :data:`NEIGHBOUR_TREE`."""
    return cKDTree(pts, **NEIGHBOUR_TREE)


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class LocalParams:
    """Hyperparameters of the local layer.

    Attributes:
        lengthscale: ``(D,)`` base length-scales ``l0`` (standardised inputs).
        beta: scalar length-scale modulation exponent.
        amp: ``(P,)`` signal variances of the residual GPs.
        noise: ``(P,)`` noise variances left after the local layer.
    """

    lengthscale: jax.Array
    beta: jax.Array
    amp: jax.Array
    noise: jax.Array


@dataclass(frozen=True)
class LocalStore:
    """Points the local layer conditions on.

    Attributes:
        X: ``(N, D)`` standardised inputs. resid: ``(N, P)`` residuals of the global mean.
        metric: ``(D,)`` scale dividing ``X`` for the neighbour search.
        z: ``(N,)`` centred log local spacing. z_mean: the centring constant.
        k: neighbours per query. tree: the k-d tree on ``X * metric``.
        own_idx, own_dist: ``(N, k)`` each stored row's ``k`` nearest stored rows (itself first) and their
            distances, as ``tree.query`` returns them, or None: kept from the query that gave ``z`` so that
            :func:`neighbours` need not search again for a query that is a stored row (e.g. the predictions
            at the training rows). own_unique: ``(N,)`` bool, where the row's ``k + 1`` nearest distances
            rise strictly (no ties, e.g. no repeated row): only there are its ``k`` nearest and their order
            the same from any k-query, so only those rows' own neighbours are used.
    """

    X: np.ndarray
    resid: np.ndarray
    metric: np.ndarray
    z: np.ndarray
    z_mean: float
    k: int
    tree: cKDTree
    own_idx: np.ndarray | None = field(default=None, repr=False)
    own_dist: np.ndarray | None = field(default=None, repr=False)
    own_unique: np.ndarray | None = field(default=None, repr=False)

    def own_rows(self, Xq: np.ndarray) -> np.ndarray | None:
        """``(Q,)`` the stored row equal bit for bit to each row of ``Xq (Q, D)``, -1 where none; None when the
        store kept no neighbours of its own rows (``own_idx``) or ``Xq`` is not of the stored rows' dtype."""
        if self.own_idx is None or self.own_unique is None or Xq.dtype != self.X.dtype or Xq.ndim != 2 \
                or len(Xq) == 0:
            return None
        lookup = self.__dict__.get("_row_lookup")
        if lookup is None:        # built on first use: the row's bytes -> its index (rows without ties)
            rows = np.flatnonzero(self.own_unique)
            lookup = dict(zip(_row_keys(self.X[rows]), rows.tolist()))
            object.__setattr__(self, "_row_lookup", lookup)
        return np.fromiter((lookup.get(b, -1) for b in _row_keys(Xq)), dtype=np.intp, count=len(Xq))


def _row_keys(X: np.ndarray) -> list[bytes]:
    """Each row of ``X (N, D)`` as bytes (a dictionary key)."""
    X = np.ascontiguousarray(X)
    return X.view(np.dtype((np.void, X.shape[1] * X.itemsize))).ravel().tolist()


def build_store(Xs: np.ndarray, resid: np.ndarray, metric: np.ndarray, k: int) -> LocalStore:
    """Index the points ``Xs (N, D)`` with residuals ``resid (N, P)`` for ``k``-neighbour queries."""
    k = int(max(1, min(k, len(Xs))))
    pts = Xs * metric
    tree = neighbour_tree(pts)
    kk = min(k + 1, len(Xs))
    dist, idx = tree.query(pts, k=kk, workers=-1)
    dist, idx = np.asarray(dist).reshape(len(Xs), kk), np.asarray(idx).reshape(len(Xs), kk)
    logrho = np.log(np.maximum(dist[:, 1:].mean(1) if kk > 1 else np.ones(len(Xs)), 1e-12))
    z_mean = float(logrho.mean())
    # the first k of each row's k + 1 nearest are what a k-query of that row returns (itself first)
    return LocalStore(Xs, resid, metric, logrho - z_mean, z_mean, k, tree, *own_neighbours(idx, dist, k))


def own_neighbours(idx: np.ndarray, dist: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``LocalStore``'s ``(own_idx (N, k), own_dist (N, k), own_unique (N,))`` from each stored row's query of its
    ``min(k + 1, N)`` nearest stored rows, ``idx`` and ``dist`` ``(N, >= min(k + 1, N))`` in distance order."""
    kk = min(k + 1, idx.shape[1])
    unique = np.all(np.diff(dist[:, :kk], axis=1) > 0, axis=1)
    return np.ascontiguousarray(idx[:, :k]), np.ascontiguousarray(dist[:, :k]), unique


def neighbours(store: LocalStore, Xq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices ``(Q, k)`` of the stored neighbours of ``Xq (Q, D)`` and the queries' ``z (Q,)``.

    A query equal bit for bit to a stored row takes that row's own neighbours (``LocalStore.own_idx``,
    from the store's own search, the same neighbours and distances a k-query returns); the others are
    searched in the k-d tree."""
    own = store.own_rows(Xq)
    if own is None or not (hit := own >= 0).any():
        dist, idx = store.tree.query(Xq * store.metric, k=store.k, workers=-1)
        dist = np.asarray(dist).reshape(len(Xq), store.k)
        idx = np.asarray(idx).reshape(len(Xq), store.k)
    else:
        at = np.maximum(own, 0)                       # the misses' rows are overwritten below
        idx, dist = store.own_idx[at], store.own_dist[at]
        if not hit.all():
            miss = ~hit
            d, i = store.tree.query(Xq[miss] * store.metric, k=store.k, workers=-1)
            dist[miss] = np.asarray(d).reshape(-1, store.k)
            idx[miss] = np.asarray(i).reshape(-1, store.k)
    z = np.log(np.maximum(dist.mean(1), 1e-12)) - store.z_mean
    return idx, z


def _aug(X, z):
    return jnp.concatenate([X, z[..., None]], axis=-1)


def _shared_eig(Kc):
    w, U = jnp.linalg.eigh(Kc)
    return jnp.maximum(w, 0.0), U


@jax.custom_vjp
def shared_nll(Kc, amp, noise, R):
    """``-log N(R_p | 0, amp_p Kc + noise_p I)`` for every output, shape ``(P,)``.

    One eigendecomposition ``Kc = U diag(w) U^T`` serves all outputs
    (``amp_p Kc + noise_p I = U diag(amp_p w + noise_p) U^T``). The gradient is the
    closed form ``dNLL/dK = 0.5 (K^{-1} - alpha alpha^T)`` (Rasmussen and Williams 2006,
    eq. 5.9), which needs no eigenvalue gaps (a plain eigh gradient is NaN when
    eigenvalues repeat, e.g. for repeated points).

    Args:
        Kc: ``(K, K)`` unit-amplitude covariance. amp, noise: ``(P,)``. R: ``(P, K)`` targets.
    """
    return _shared_nll_fwd(Kc, amp, noise, R)[0]


def _shared_nll_fwd(Kc, amp, noise, R):
    w, U = _shared_eig(Kc)
    lam = amp[:, None] * w[None, :] + noise[:, None]                 # (P, K)
    c = R @ U                                                          # (P, K): U^T r_p
    nll = 0.5 * jnp.sum(c * c / lam, 1) + 0.5 * jnp.sum(jnp.log(lam), 1) + 0.5 * Kc.shape[0] * jnp.log(2 * jnp.pi)
    return nll, (U, w, lam, c, amp)


def _shared_nll_bwd(res, g):
    U, w, lam, c, amp = res
    a = c / lam                                                        # alpha_p in the eigenbasis
    inner = 0.5 * (jnp.einsum("p,pk->k", g * amp, 1.0 / lam)[:, None] * jnp.eye(w.shape[0], dtype=w.dtype)
                   - jnp.einsum("p,pk,pj->kj", g * amp, a, a))
    dKc = U @ inner @ U.T
    damp = 0.5 * g * jnp.sum(w[None, :] / lam - a * a * w[None, :], 1)
    dnoise = 0.5 * g * jnp.sum(1.0 / lam - a * a, 1)
    dR = g[:, None] * (a @ U.T)
    return dKc, damp, dnoise, dR


shared_nll.defvjp(_shared_nll_fwd, _shared_nll_bwd)


def _one_query(params: LocalParams, xq, zq, Xn, zn, rn):
    """Mean and variance ``(P,)`` of the residual at one query from its ``K`` neighbours.

    One Cholesky factor ``L_p L_p^T = amp_p Kc + noise_p I`` per output and one triangular
    solve for ``[k_*, r_p]`` give ``mean_p = amp_p v_p^T u_p`` and ``var_p = amp_p - amp_p^2
    v_p^T v_p`` with ``v_p = L_p^{-1} k_*``, ``u_p = L_p^{-1} r_p`` (Rasmussen and Williams
    2006, Algorithm 2.1). On CPU the ``P`` batched ``K x K`` factorisations cost about half of
    one symmetric eigendecomposition shared by the outputs (measured at ``K = 16, P = 6``).
    A NaN residual (a missing output of that neighbour) gets the noise variance
    :data:`MISSING_NOISE` times ``amp_p + noise_p``: its weight in the prediction is ~1e-8 of an
    observed neighbour's, i.e. the output's GP conditions on its observed neighbours only.
    """
    kern = GibbsKernel(params.lengthscale, params.beta)
    An = _aug(Xn, zn)
    Kc = kern(An, An)                                                  # (K, K)
    kq = kern(_aug(xq[None], zq[None]), An)[0]                         # (K,)
    eye = jnp.eye(Kc.shape[0], dtype=Kc.dtype)
    ok = jnp.isfinite(rn)                                              # (K, P)
    rn = jnp.where(ok, rn, 0.0)
    extra = jnp.where(ok.T, 0.0, MISSING_NOISE * (params.amp + params.noise)[:, None])     # (P, K)
    L = jnp.linalg.cholesky(params.amp[:, None, None] * Kc[None] + params.noise[:, None, None] * eye
                            + extra[:, :, None] * eye[None])
    rhs = jnp.stack([jnp.broadcast_to(kq, rn.T.shape), rn.T], -1)     # (P, K, 2)
    S = jax.scipy.linalg.solve_triangular(L, rhs, lower=True)
    v, u = S[..., 0], S[..., 1]
    mean = params.amp * jnp.sum(v * u, 1)
    var = params.amp - params.amp**2 * jnp.sum(v * v, 1)
    return mean, jnp.maximum(var, 1e-12 * params.amp)


@stored_jit
def local_predict_chunk(params: LocalParams, Xq, zq, Xn, zn, rn):
    """Local residual mean and variance ``(Q, P)``, latent (noise not included).

    Args:
        Xq: ``(Q, D)`` queries, zq ``(Q,)``; Xn ``(Q, K, D)``, zn ``(Q, K)``, rn ``(Q, K, P)``: neighbours.
    """
    return jax.vmap(lambda a, b, c, d, e: _one_query(params, a, b, c, d, e))(Xq, zq, Xn, zn, rn)


def local_objective(params: LocalParams, Xn, zn, rn) -> jax.Array:
    """Mean over neighbourhoods, outputs and points of ``-log N(r | 0, amp Kgibbs + noise I)``.

    Args: Xn ``(S, K, D)``, zn ``(S, K)``, rn ``(S, K, P)`` for ``S`` neighbourhoods.
    """
    def one(Xb, zb, rb):
        An = _aug(Xb, zb)
        return shared_nll(GibbsKernel(params.lengthscale, params.beta)(An, An), params.amp, params.noise, rb.T)

    return jnp.mean(jax.vmap(one)(Xn, zn, rn)) / Xn.shape[1]
