"""Covariance functions of the GP layers, as small immutable pytrees.

Each kernel evaluates one pair of points (``evaluate(x1, x2)``) and builds a
matrix by vmapping it, as tinygp's ``Kernel`` does; the squared exponential
overrides the matrix form with the usual ``|a|^2 + |b|^2 - 2 a.b`` expansion
(same values, one matrix product, no ``(N, M, D)`` temporary).

Kernels here have unit variance: amplitudes live in the coregionalisation
matrix ``B`` (global layer) or in per-output scales (local layer).
"""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.numpy as jnp

__all__ = ["ARDSquaredExponential", "GibbsKernel", "coregionalisation", "pairwise"]


def pairwise(evaluate, X1: jax.Array, X2: jax.Array) -> jax.Array:
    """Matrix ``K[i, j] = evaluate(X1[i], X2[j])`` of shape ``(N1, N2)`` by a double vmap."""
    return jax.vmap(lambda a: jax.vmap(lambda b: evaluate(a, b))(X2))(X1)


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class ARDSquaredExponential:
    """Stationary ARD squared-exponential kernel ``k(x, x') = exp(-0.5 sum_d ((x_d - x'_d)/l_d)^2)``.

    Rasmussen and Williams (2006), *Gaussian Processes for Machine Learning*, eq. 5.1.

    Attributes:
        lengthscale: ``(D,)`` length-scales in the (standardised) input units.
    """

    lengthscale: jax.Array

    def evaluate(self, x1: jax.Array, x2: jax.Array) -> jax.Array:
        """Covariance of one pair of points ``x1, x2`` of shape ``(D,)``; a scalar."""
        r = (x1 - x2) / self.lengthscale
        return jnp.exp(-0.5 * jnp.dot(r, r))

    def __call__(self, X1: jax.Array, X2: jax.Array) -> jax.Array:
        """Covariance matrix ``(N1, N2)`` between ``X1 (N1, D)`` and ``X2 (N2, D)``."""
        a = X1 / self.lengthscale
        b = X2 / self.lengthscale
        d2 = jnp.sum(a * a, 1)[:, None] + jnp.sum(b * b, 1)[None, :] - 2.0 * a @ b.T
        return jnp.exp(-0.5 * jnp.maximum(d2, 0.0))


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class GibbsKernel:
    """Non-stationary squared exponential with an input-dependent length-scale (Gibbs 1997).

    The length-scale matrix at ``x`` is ``Sigma(x) = g(x)^2 diag(l^2)`` with
    ``g(x) = exp(beta * z(x))``, where ``z`` is a scalar covariate carried as the
    last input column (the local layer uses the log local data spacing, so the
    length-scale shrinks where data are dense and grows where they are sparse).
    Paciorek and Schervish (2004), "Nonstationary covariance functions for Gaussian
    process regression", NIPS 16, eq. 5, with ``Q = (x - x')^T ((Sigma_i + Sigma_j)/2)^{-1} (x - x')``
    and the factor 1/2 of this package's SE convention:

        k = (2 g g' / (g^2 + g'^2))^{D/2} exp(-0.5 * sum_d (x_d - x'_d)^2 / (l_d^2 (g^2 + g'^2) / 2))

    It is positive definite for any ``g`` and reduces to the ARD SE kernel when
    ``beta = 0``.

    Attributes:
        lengthscale: ``(D,)`` base length-scales.
        beta: scalar, exponent of the length-scale modulation.
    """

    lengthscale: jax.Array
    beta: jax.Array

    def evaluate(self, x1: jax.Array, x2: jax.Array) -> jax.Array:
        """Covariance of one pair of augmented points ``[x (D), z]`` of shape ``(D + 1,)``."""
        g1 = jnp.exp(self.beta * x1[-1])
        g2 = jnp.exp(self.beta * x2[-1])
        s = 0.5 * (g1 * g1 + g2 * g2)
        r = (x1[:-1] - x2[:-1]) / self.lengthscale
        dim = x1.shape[0] - 1
        return (g1 * g2 / s) ** (0.5 * dim) * jnp.exp(-0.5 * jnp.dot(r, r) / s)

    def __call__(self, X1: jax.Array, X2: jax.Array) -> jax.Array:
        """Covariance matrix ``(N1, N2)`` between augmented inputs ``(N1, D+1)`` and ``(N2, D+1)``.

        Same values as ``pairwise(self.evaluate, X1, X2)``, written with broadcasting.
        """
        g1 = jnp.exp(self.beta * X1[:, -1])[:, None]
        g2 = jnp.exp(self.beta * X2[:, -1])[None, :]
        s = 0.5 * (g1 * g1 + g2 * g2)
        a, b = X1[:, :-1] / self.lengthscale, X2[:, :-1] / self.lengthscale
        d2 = jnp.sum(a * a, 1)[:, None] + jnp.sum(b * b, 1)[None, :] - 2.0 * a @ b.T
        dim = X1.shape[1] - 1
        return (g1 * g2 / s) ** (0.5 * dim) * jnp.exp(-0.5 * jnp.maximum(d2, 0.0) / s)


def coregionalisation(L: jax.Array, kappa: jax.Array) -> jax.Array:
    """Coregionalisation matrix ``B = L L^T + diag(kappa)`` of shape ``(P, P)``.

    Intrinsic coregionalisation model: ``cov(f_i(x), f_j(x')) = B[i, j] k(x, x')``.
    Alvarez, Rosasco and Lawrence (2012), "Kernels for vector-valued functions: a
    review", Found. Trends Mach. Learn. 4(3), sec. 4.2, eq. 21 (arXiv:1106.6251).

    Args:
        L: ``(P, R)`` low-rank factor (R = rank of the shared part).
        kappa: ``(P,)`` positive independent variances.
    """
    return L @ L.T + jnp.diag(kappa)
