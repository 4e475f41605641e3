"""Missing outputs (heterotopic data): the sparse layer's per-output statistics against the exact GP
restricted to the observed entries, and the joint model borrowing from the observed outputs."""

from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.gp import exact, sparse
from gcs_sysid.gp.kernels import coregionalisation
from gcs_sysid.gp.sparse import GlobalParams, add_stats
from gp_data import exact_gp_data

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
    return GlobalParams(lengthscale=jnp.array([0.8, 1.3]), A=jnp.linalg.cholesky(B),
                        noise=jnp.array([0.01, 0.03, 0.02]),
                        Z=jnp.asarray(Z), prior_std=jnp.asarray(1.0), jitter=jnp.asarray(1e-10), **extra)


@pytest.fixture(scope="module")
def data():
    X, Y, Xq = exact_gp_data()
    mask = np.ones_like(Y, bool)
    mask[X[:, 0] > 0.5, 1] = False          # output 1 missing over part of the envelope
    mask[::4, 2] = False
    return X, Y, mask, Xq


@pytest.mark.parametrize("lmc", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_per_output_statistics_equal_the_exact_gp_on_the_observed_entries(data, lmc):
    X, Y, mask, Xq = data
    p = _params(X, lmc)
    Yn = np.where(mask, Y, np.nan)                        # missing entries may hold NaN
    st = stats_of(p, jnp.asarray(X), jnp.asarray(Yn), None, jnp.asarray(mask, float))
    assert st.per_output and st.C.shape[0] == 3
    np.testing.assert_allclose(st.n, mask.sum(0))
    ex = float(jax.jit(partial(exact.exact_log_marginal, mask=mask))(p, jnp.asarray(X), jnp.asarray(Y)))
    assert float(elbo(p, st)) == pytest.approx(ex, rel=1e-6)
    m, v = predict_global_chunk(p, posterior(p, st), jnp.asarray(Xq))
    me, ve = jax.jit(partial(exact.exact_predict, mask=mask))(p, jnp.asarray(X), jnp.asarray(Y), jnp.asarray(Xq))
    np.testing.assert_allclose(m, me, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v, ve, rtol=1e-5, atol=1e-8)


@pytest.mark.slow
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


def _shared_case(n=600, seed=5):
    """Three outputs sharing one nonlinear latent function of two smooth flight-like inputs; output 1
    missing where ``x0 > 0.4`` (a third of the envelope, as moments rejected over part of a flight)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 20
    X = np.column_stack([np.sin(0.31 * t) + 0.3 * np.sin(1.7 * t), np.cos(0.23 * t + 1) + 0.2 * np.sin(2.3 * t)])
    f = np.sin(3 * X[:, 0]) * np.exp(-0.5 * X[:, 1] ** 2)
    Yt = np.column_stack([f + 0.3 * X[:, 1], 0.8 * f - 0.5 * X[:, 0], -0.6 * f + 0.2 * X[:, 1]])
    Y = Yt + 0.03 * rng.standard_normal(Yt.shape)
    miss = X[:, 0] > 0.4
    Ym = Y.copy()
    Ym[miss, 1] = np.nan
    return X, Y, Ym, Yt, miss


@pytest.mark.slow
def test_joint_fit_predicts_a_missing_output_from_the_others_where_an_independent_gp_cannot(tmp_path):
    from gcs_sysid.gp import fit_gp, load_gp

    from gp_data import FAST

    X, Y, Ym, Yt, miss = _shared_case()
    model, _ = fit_gp(X, Ym, FAST)
    assert any("miss some outputs" in n for n in model.notes)
    assert model.stats.per_output and model.n_used == len(X)
    err = lambda a, b: 100 * np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b ** 2))  # noqa: E731
    mu, var = model.predict(X[miss], include_noise=False)
    joint = err(mu[:, 1], Yt[miss, 1])
    indep, _ = fit_gp(X[~miss], Y[~miss][:, [1]], FAST)
    alone = err(indep.predict(X[miss])[0][:, 0], Yt[miss, 1])
    # measured 1.5 % (joint) against 66 % (output 1's own GP, extrapolating)
    assert joint < 5.0 and alone > 5 * joint
    # the band is honest where the output was never seen: most of the truth inside it
    assert np.mean(np.abs(mu[:, 1] - Yt[miss, 1]) <= 1.96 * np.sqrt(var[:, 1])) > 0.8
    # the coupling does it: the same model with the outputs made independent extrapolates like the lone GP
    from gcs_sysid.gp.joint import decoupled_model

    dec = err(decoupled_model(model).predict(X[miss])[0][:, 1], Yt[miss, 1])
    assert dec > 5 * joint
    # saved and loaded with its per-output statistics; updated with more partial rows
    loaded = load_gp(model.save(tmp_path / "m"))
    import json

    assert json.loads((tmp_path / "m.json").read_text())["version"] == 5 and loaded.stats.per_output
    np.testing.assert_allclose(loaded.predict(X[:50])[0], model.predict(X[:50])[0], rtol=1e-8, atol=1e-10)
    more = model.update(X[:40], Ym[:40])
    assert more.n_used == len(X) + 40 and np.isfinite(more.predict(X[miss][:20])[0]).all()


def test_local_layer_skips_a_neighbours_missing_output():
    from gcs_sysid.gp.local import LocalParams, local_predict_chunk

    rng = np.random.default_rng(2)
    lp = LocalParams(lengthscale=jnp.array([0.7, 1.1]), beta=jnp.asarray(0.3), amp=jnp.array([0.5, 0.2]),
                     noise=jnp.array([0.01, 0.02]))
    Xq, zq = rng.normal(size=(3, 2)), rng.normal(size=3) * 0.1
    Xn, zn, rn = rng.normal(size=(3, 6, 2)), rng.normal(size=(3, 6)) * 0.1, rng.normal(size=(3, 6, 2))
    rn_missing = rn.copy()
    rn_missing[:, 2, 0] = np.nan                       # neighbour 2 misses output 0
    m, v = local_predict_chunk(lp, Xq, zq, Xn, zn, rn_missing)
    keep = [0, 1, 3, 4, 5]
    m5, v5 = local_predict_chunk(lp, Xq, zq, Xn[:, keep], zn[:, keep], rn[:, keep])
    m6, v6 = local_predict_chunk(lp, Xq, zq, Xn, zn, rn)
    np.testing.assert_allclose(m[:, 0], m5[:, 0], rtol=1e-6, atol=1e-8)     # output 0: as without the neighbour
    np.testing.assert_allclose(v[:, 0], v5[:, 0], rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(m[:, 1], m6[:, 1], rtol=1e-12)                 # output 1: every neighbour


@pytest.mark.slow
def test_coupling_gate_on_missing_outputs_keeps_a_coupling_that_fills_the_gap():
    """With missing outputs the coupling gate scores each output's gap (its block entries held back
    alone, the others kept): where the others carry it, the coupling stays and the gap is filled."""
    from dataclasses import replace

    from gcs_sysid.gp import fit_gp

    from gp_data import FAST

    X, Y, Ym, Yt, miss = _shared_case()
    model, hist = fit_gp(X, Ym, replace(FAST, coupling_validation=True))
    assert hist.validation["coupled"][1] and hist.validation["ratio"][1] < 0.8     # measured 0.35
    mu = model.predict(X[miss], include_noise=False)[0]
    assert 100 * np.sqrt(np.mean((mu[:, 1] - Yt[miss, 1]) ** 2)) / np.sqrt(np.mean(Yt[miss, 1] ** 2)) < 5.0
