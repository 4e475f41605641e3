"""Kernels against their pairwise definitions; the sparse global layer against the exact dense GP."""

import jax.numpy as jnp
import numpy as np
import pytest

import jax

from gcs_sysid.gp import exact, sparse
from gcs_sysid.gp.kernels import ARDSquaredExponential, GibbsKernel, coregionalisation, pairwise
from gcs_sysid.gp.sparse import GlobalParams, add_stats
from gp_data import exact_gp_data

# compiled once per shape: far cheaper than op-by-op dispatch
elbo, posterior, stats_of = jax.jit(sparse.elbo), jax.jit(sparse.posterior), jax.jit(sparse.stats_of)
predict_global_chunk = jax.jit(sparse.predict_global_chunk)
exact_log_marginal, exact_predict = jax.jit(exact.exact_log_marginal), jax.jit(exact.exact_predict)


def _params(X, Z, jitter=1e-10, prior_std=1.0):
    L = np.array([[0.9], [0.7], [-0.3]])
    B = coregionalisation(jnp.asarray(L), jnp.array([0.1, 0.2, 0.05]))
    return GlobalParams(lengthscale=jnp.array([0.8, 1.3]), A=jnp.linalg.cholesky(B),
                        noise=jnp.array([0.01, 0.03, 0.02]),
                        Z=jnp.asarray(Z), prior_std=jnp.asarray(prior_std), jitter=jnp.asarray(jitter))


@pytest.fixture(scope="module")
def data():
    return exact_gp_data()


def test_kernel_matrices_equal_pairwise_definitions():
    rng = np.random.default_rng(0)
    X1, X2 = jnp.asarray(rng.normal(size=(5, 3))), jnp.asarray(rng.normal(size=(4, 3)))
    se = ARDSquaredExponential(jnp.array([0.5, 1.0, 2.0]))
    np.testing.assert_allclose(se(X1, X2), pairwise(se.evaluate, X1, X2), rtol=1e-12, atol=1e-14)
    A1 = jnp.concatenate([X1, jnp.asarray(rng.normal(size=(5, 1)))], 1)
    A2 = jnp.concatenate([X2, jnp.asarray(rng.normal(size=(4, 1)))], 1)
    gibbs = GibbsKernel(jnp.array([0.5, 1.0, 2.0]), jnp.asarray(0.8))
    np.testing.assert_allclose(gibbs(A1, A2), pairwise(gibbs.evaluate, A1, A2), rtol=1e-12, atol=1e-14)
    # beta = 0: the stationary kernel
    np.testing.assert_allclose(GibbsKernel(se.lengthscale, jnp.asarray(0.0))(A1, A2), se(X1, X2), rtol=1e-12)


def test_gibbs_kernel_is_positive_semidefinite_with_varying_lengthscale():
    rng = np.random.default_rng(1)
    A = jnp.asarray(np.column_stack([rng.uniform(-1, 1, (60, 2)), 2 * rng.normal(size=60)]))
    K = GibbsKernel(jnp.array([0.3, 0.6]), jnp.asarray(1.2))(A, A)
    assert np.linalg.eigvalsh(np.asarray(K)).min() > -1e-10
    np.testing.assert_allclose(np.diag(K), 1.0)


def test_sparse_with_inducing_points_at_the_data_equals_exact_gp(data):
    X, Y, Xq = data
    p = _params(X, X)
    st = stats_of(p, jnp.asarray(X), jnp.asarray(Y))
    exact = float(exact_log_marginal(p, jnp.asarray(X), jnp.asarray(Y)))
    assert float(elbo(p, st)) == pytest.approx(exact, rel=1e-6)
    m, v = predict_global_chunk(p, posterior(p, st), jnp.asarray(Xq))
    me, ve = exact_predict(p, jnp.asarray(X), jnp.asarray(Y), jnp.asarray(Xq))
    np.testing.assert_allclose(m, me, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v, ve, rtol=1e-5, atol=1e-8)


def test_vfe_bound_is_below_exact_log_marginal_likelihood(data):
    X, Y, _ = data
    exact = float(exact_log_marginal(_params(X, X), jnp.asarray(X), jnp.asarray(Y)))
    bounds = []
    for m in (3, 8, 15):
        # pad Z by repeating a point: one compiled shape, and a repeated inducing point adds nothing
        p = _params(X, np.vstack([X[:m], np.repeat(X[m - 1:m], 15 - m, 0)]), jitter=1e-8)
        bounds.append(float(elbo(p, stats_of(p, jnp.asarray(X), jnp.asarray(Y)))))
    assert all(b <= exact + 1e-8 for b in bounds)
    assert bounds[0] < bounds[-1]  # more inducing points, tighter bound


def test_statistics_are_additive_so_conditioning_in_pieces_equals_all_at_once(data):
    X, Y, Xq = data
    p = _params(X, X[:10], jitter=1e-8)
    whole = stats_of(p, jnp.asarray(X), jnp.asarray(Y))
    parts = add_stats(stats_of(p, jnp.asarray(X[:11]), jnp.asarray(Y[:11])),
                      stats_of(p, jnp.asarray(X[11:]), jnp.asarray(Y[11:])))
    a = predict_global_chunk(p, posterior(p, whole), jnp.asarray(Xq))
    b = predict_global_chunk(p, posterior(p, parts), jnp.asarray(Xq))
    np.testing.assert_allclose(a[0], b[0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a[1], b[1], rtol=1e-9, atol=1e-12)
