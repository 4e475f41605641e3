"""Missing outputs (heterotopic data): the sparse layer's per-output statistics against the exact GP
restricted to the observed entries, and the joint model borrowing from the observed outputs."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.gp import exact, sparse
from gcs_sysid.gp.kernels import coregionalisation
from gcs_sysid.gp.sparse import GlobalParams, add_stats

elbo, posterior = jax.jit(sparse.elbo), jax.jit(sparse.posterior)
stats_of = jax.jit(sparse.stats_of)
predict_global_chunk = jax.jit(sparse.predict_global_chunk)


def _params(Z, lmc=False):
    L = np.array([[0.9], [0.7], [-0.3]])
    B = coregionalisation(jnp.asarray(L), jnp.array([0.1, 0.2, 0.05]))
    extra = {}
    if lmc:
        B2 = coregionalisation(jnp.asarray(np.array([[0.2], [-0.5], [0.6]])), jnp.array([0.05, 0.02, 0.1]))
        extra = {"lmc_lengthscale": jnp.array([[2.5, 0.6]]), "lmc_A": jnp.linalg.cholesky(B2)[None]}
    return GlobalParams(lengthscale=jnp.array([0.8, 1.3]), A=jnp.linalg.cholesky(B), noise=jnp.array([0.01, 0.03, 0.02]),
                        Z=jnp.asarray(Z), prior_std=jnp.asarray(1.0), jitter=jnp.asarray(1e-10), **extra)


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(3)
    X = rng.uniform(-2, 2, (25, 2))
    f = np.sin(2 * X[:, 0]) + 0.5 * X[:, 1]
    Y = np.column_stack([f, 0.7 * f + 0.2 * X[:, 0], -0.3 * f + np.cos(X[:, 1])]) + 0.1 * rng.standard_normal((25, 3))
    mask = np.ones_like(Y, bool)
    mask[X[:, 0] > 0.5, 1] = False          # output 1 missing over part of the envelope
    mask[::4, 2] = False
    Xq = rng.uniform(-2.5, 2.5, (7, 2))
    return X, Y, mask, Xq


@pytest.mark.parametrize("lmc", [False, True])
def test_per_output_statistics_equal_the_exact_gp_on_the_observed_entries(data, lmc):
    X, Y, mask, Xq = data
    p = _params(X, lmc)
    Yn = np.where(mask, Y, np.nan)                        # missing entries may hold NaN
    st = stats_of(p, jnp.asarray(X), jnp.asarray(Yn), None, jnp.asarray(mask, float))
    assert st.per_output and st.C.shape[0] == 3
    np.testing.assert_allclose(st.n, mask.sum(0))
    ex = float(exact.exact_log_marginal(p, jnp.asarray(X), jnp.asarray(Y), mask))
    assert float(elbo(p, st)) == pytest.approx(ex, rel=1e-6)
    m, v = predict_global_chunk(p, posterior(p, st), jnp.asarray(Xq))
    me, ve = exact.exact_predict(p, jnp.asarray(X), jnp.asarray(Y), jnp.asarray(Xq), mask)
    np.testing.assert_allclose(m, me, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v, ve, rtol=1e-5, atol=1e-8)


def test_complete_and_per_output_forms_add_and_agree(data):
    X, Y, mask, Xq = data
    p = _params(X[:12])
    full = stats_of(p, jnp.asarray(X), jnp.asarray(Y))
    ones = stats_of(p, jnp.asarray(X), jnp.asarray(Y), None, jnp.ones(Y.shape))
    assert float(elbo(p, ones)) == pytest.approx(float(elbo(p, full)), rel=1e-10)
    m1, v1 = predict_global_chunk(p, posterior(p, full), jnp.asarray(Xq))
    m2, v2 = predict_global_chunk(p, posterior(p, ones), jnp.asarray(Xq))
    np.testing.assert_allclose(m1, m2, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(v1, v2, rtol=1e-9, atol=1e-12)
    # a complete part plus a masked part: the complete form broadcasts into the per-output one
    a = stats_of(p, jnp.asarray(X[:10]), jnp.asarray(Y[:10]))
    b = stats_of(p, jnp.asarray(X[10:]), jnp.asarray(Y[10:]), None, jnp.asarray(mask[10:], float))
    whole = stats_of(p, jnp.asarray(X), jnp.asarray(Y), None, jnp.asarray(np.r_[np.ones((10, 3)), mask[10:]]))
    both = add_stats(a, b)
    for k in ("C", "E", "F", "Rphi", "Rx", "yy", "n"):
        np.testing.assert_allclose(getattr(both, k), getattr(whole, k), rtol=1e-12, atol=1e-12)
