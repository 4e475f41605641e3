"""Exact dense GP with the same prior as the global layer: the slow, obvious reference.

Covariance of the stacked outputs (output-major, ``y = [y_1; ...; y_P]`` of length ``N P``)::

    K = B kron Kxx + blockdiag_p(Xa V_p Xa^T) + diag(sigma^2) kron I_N,   V_p = diag(prior std of output p's weights)^2

(for a linear model of coregionalisation ``sum_j B_j kron K_j`` in place of ``B kron Kxx``)

O(N^3 P^3) time and O(N^2 P^2) memory; for tests and benchmark baselines only
(Rasmussen and Williams 2006, eqs. 2.25-2.26 and 2.30).
"""

from __future__ import annotations

import jax
import jax.scipy.linalg
import jax.numpy as jnp
import numpy as np
from jax.scipy.linalg import cho_solve, solve_triangular

from .kernels import ARDSquaredExponential
from .sparse import GlobalParams, design, prior_scales

__all__ = ["exact_covariance", "exact_log_marginal", "exact_predict"]


def exact_covariance(params: GlobalParams, X1: jnp.ndarray, X2: jnp.ndarray) -> jnp.ndarray:
    """Noise-free prior covariance ``(P*N1, P*N2)`` of ``xa^T W_p + f_p`` (output-major)."""
    S2 = prior_scales(params) ** 2                                   # (P, D+1)
    xa1, xa2 = design(X1), design(X2)
    P = params.A.shape[0]
    out = jax.scipy.linalg.block_diag(*[(xa1 * S2[p]) @ xa2.T for p in range(P)])
    for Bj, ls in zip(params.B_parts, params.lengthscales):
        out = out + jnp.kron(Bj, ARDSquaredExponential(ls)(X1, X2))
    return out


def _observed(Ys: jnp.ndarray, mask) -> np.ndarray:
    """Indices of the observed entries of the output-major stacked ``Ys (N, P)`` (all without ``mask``);
    ``mask`` is a concrete (host) array, so the functions can be compiled with it closed over."""
    n_all = Ys.shape[0] * Ys.shape[1]
    return np.arange(n_all) if mask is None else np.flatnonzero(np.asarray(mask, bool).T.reshape(-1))


def _noisy(params: GlobalParams, Xs, keep):
    N, P = Xs.shape[0], params.A.shape[0]
    K = exact_covariance(params, Xs, Xs) + jnp.kron(params.noise_cov(), jnp.eye(N, dtype=Xs.dtype))
    return jnp.linalg.cholesky(K[np.ix_(keep, keep)]), N, P


def exact_log_marginal(params: GlobalParams, Xs: jnp.ndarray, Ys: jnp.ndarray, mask=None) -> jnp.ndarray:
    """Log marginal likelihood ``log N(y | 0, K)`` of ``Ys (N, P)`` at ``Xs (N, D)``, a scalar.

    ``mask`` ``(N, P)`` bool (True: observed): the likelihood of the observed entries only
    (heterotopic data: the stacked vector and ``K`` restricted to them); a host array, closed over
    when compiled (``jax.jit(partial(exact_log_marginal, mask=mask))``).
    """
    keep = _observed(Ys, mask)
    L, N, P = _noisy(params, Xs, keep)
    y = Ys.T.reshape(-1)[keep]
    c = solve_triangular(L, y, lower=True)
    return -0.5 * (c @ c) - jnp.sum(jnp.log(jnp.diag(L))) - 0.5 * keep.shape[0] * jnp.log(2.0 * jnp.pi)


def exact_predict(params: GlobalParams, Xs: jnp.ndarray, Ys: jnp.ndarray, Xq: jnp.ndarray, mask=None
                  ) -> tuple[jnp.ndarray, jnp.ndarray]:
    """Latent predictive mean and variance ``(Q, P)`` at ``Xq (Q, D)`` (noise not included);
    ``mask`` as :func:`exact_log_marginal` (condition on the observed entries only)."""
    keep = _observed(Ys, mask)
    L, N, P = _noisy(params, Xs, keep)
    Q = Xq.shape[0]
    Ks = exact_covariance(params, Xq, Xs)[:, keep]              # (P Q, observed entries)
    alpha = cho_solve((L, True), Ys.T.reshape(-1)[keep])
    mean = (Ks @ alpha).reshape(P, Q).T
    V = solve_triangular(L, Ks.T, lower=True)
    xa = design(Xq)
    prior = (jnp.diag(params.B)[:, None] + (prior_scales(params) ** 2) @ (xa * xa).T).reshape(-1)   # (P, Q) flat
    var = prior - jnp.sum(V * V, 0)
    return mean, var.reshape(P, Q).T
