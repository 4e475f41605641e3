"""Issue 8: per-output length-scales by a linear model of coregionalisation (LMC) in the global layer."""

import json
from dataclasses import replace

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.gp import exact, fit_gp, load_gp, sparse
from gcs_sysid.gp.inputnoise import mean_gradient
from gcs_sysid.gp.kernels import coregionalisation
from gcs_sysid.gp.sparse import GlobalParams

from gp_data import FAST


def _lmc_params(Z):
    B = [coregionalisation(jnp.asarray(L), jnp.asarray(k)) for L, k in (
        ([[0.9], [0.1], [-0.3]], [0.1, 0.02, 0.05]), ([[0.2], [0.8], [0.3]], [0.05, 0.2, 0.05]),
        ([[0.1], [0.2], [0.7]], [0.05, 0.05, 0.1]))]
    return GlobalParams(lengthscale=jnp.array([0.4, 0.9]), A=jnp.linalg.cholesky(B[0]),
                        noise=jnp.array([0.01, 0.03, 0.02]),
                        Z=jnp.asarray(Z), prior_std=jnp.asarray(1.0), jitter=jnp.asarray(1e-10),
                        lmc_lengthscale=jnp.array([[2.0, 1.5], [1.0, 0.3]]),
                        lmc_A=jnp.linalg.cholesky(jnp.stack(B[1:])))


def test_lmc_sparse_at_the_data_equals_the_exact_gp():
    """Three kernels with different length-scales (``sum_j B_j kron K_j`` in the exact GP): with the
    inducing points at the data the bound is the exact log marginal likelihood, the posterior the exact
    one, and the closed-form slope of the mean equals autodiff."""
    rng = np.random.default_rng(3)
    X = rng.uniform(-2, 2, (25, 2))
    Y = np.column_stack([np.sin(3 * X[:, 0]), np.sin(0.5 * X[:, 0]) + 0.3 * X[:, 1], np.cos(X[:, 1])])
    Y = Y + 0.1 * rng.standard_normal(Y.shape)
    Xq = rng.uniform(-2.5, 2.5, (7, 2))
    p = _lmc_params(X)
    assert p.n_kernels == 3 and p.lengthscales.shape == (3, 2)

    @jax.jit
    def both(p, X, Y, Xq):        # one compiled program for the sparse and the exact sides
        st = sparse.stats_of(p, X, Y)
        post = sparse.posterior(p, st)
        slope = jax.vmap(jax.jacfwd(lambda x: sparse.mean_global_chunk(p, post, x[None])[0]))(Xq)
        return (st.C.shape[0], sparse.elbo(p, st), exact.exact_log_marginal(p, X, Y),
                sparse.predict_global_chunk(p, post, Xq), exact.exact_predict(p, X, Y, Xq), post, slope)

    nC, bound, ex, (m, v), (me, ve), post, slope = both(p, jnp.asarray(X), jnp.asarray(Y), jnp.asarray(Xq))
    assert nC == 75                                                   # stacked features of 3 kernels
    assert float(bound) == pytest.approx(float(ex), rel=1e-7)
    np.testing.assert_allclose(m, me, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v, ve, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(mean_gradient(p, post, Xq, batch=8), np.asarray(slope), rtol=1e-8, atol=1e-10)


def test_lmc_projection_is_exact_when_the_old_rows_are_the_old_inducing_inputs():
    """The streaming projection of an LMC is block-diagonal, one Bui et al. (2017) projection per
    kernel; the cross-kernel blocks of ``C`` move with it, exactly for rows in the old features' span."""
    from gcs_sysid.gp.batching import global_stats
    from gcs_sysid.gp.model import _projection_all
    from gcs_sysid.gp.streaming import project_stats

    rng = np.random.default_rng(2)
    Z_old = rng.uniform(-2, 2, (12, 2))
    p = _lmc_params(Z_old)
    Z_new = Z_old.copy()
    Z_new[:3] = rng.uniform(-3, 3, (3, 2))
    R = _projection_all(p, Z_new, np.asarray(p.lengthscales))
    assert R.shape == (36, 36) and np.allclose(R[:12, 12:], 0.0)
    Y = rng.standard_normal((12, 3))
    carried = project_stats(global_stats(p, Z_old, Y, 256), R)
    direct = global_stats(replace(p, Z=jnp.asarray(Z_new)), Z_old, Y, 256)
    for name in ("C", "E", "Rphi"):
        np.testing.assert_allclose(getattr(carried, name), np.asarray(getattr(direct, name)), atol=1e-7)


CFG = replace(FAST, local=False, input_noise=False)


@pytest.fixture(scope="module")
def two_scales():
    """Two outputs of the same input at different length-scales (sin 3x and 1.5 cos 0.7x: standardised
    length-scales ~0.4 and ~1.6), independent noise of std 0.3, 120 rows; ICM and two-kernel LMC fits."""
    rng = np.random.default_rng(21)
    n = 120
    X = rng.uniform(-2, 2, (n + 300, 2))
    F = np.column_stack([np.sin(3 * X[:, 0]), 1.5 * np.cos(0.7 * X[:, 0])])
    Y = F + 0.3 * rng.standard_normal(F.shape)
    icm, _ = fit_gp(X[:n], Y[:n], CFG)
    lmc, _ = fit_gp(X[:n], Y[:n], replace(CFG, latent_kernels=2))
    return X, Y, F, n, icm, lmc


def test_lmc_recovers_per_output_lengthscales(two_scales):
    """Each output is carried by its own kernel, the short one by the short output (measured: x0
    length-scales 0.53 and 1.84 standardised, shares 0.83 and 0.96), the bound beats the ICM's
    (measured -181.5 vs -186.6), and with independent noise and unrelated functions no learned output
    correlation exceeds 0.5."""
    X, Y, F, n, icm, lmc = two_scales
    p = lmc.params
    ls = np.asarray(p.lengthscales)[:, 0]                            # (J,), input x0
    share = np.asarray(p.B_parts).diagonal(axis1=1, axis2=2)          # (J, P)
    share = share / share.sum(0)
    k0, k1 = int(np.argmax(share[:, 0])), int(np.argmax(share[:, 1]))
    assert k0 != k1 and share[k0, 0] > 0.75 and share[k1, 1] > 0.75
    assert ls[k0] < 0.8 and ls[k1] > 2.0 * ls[k0]
    assert lmc.elbo() > icm.elbo() + 2.0
    assert np.max(np.abs(lmc.output_correlation() - np.eye(2))) < 0.5
    s = lmc.summary()
    assert len(s["latent_kernels"]) == 2 and "2 latent kernels" in s["approximation"]
    assert icm.summary()["latent_kernels"] is None


def test_lmc_streaming_update_is_exact_conditioning(two_scales):
    """Without an exchange an update adds statistics: the posterior equals the one from the statistics
    of all rows; the maneuver ranking's batched variance falls back to exact conditioning for an LMC."""
    from gcs_sysid.gp.batching import global_stats

    X, Y, F, n, _, lmc = two_scales
    new = lmc.update(X[n:n + 60], Y[n:n + 60], exchange=False)
    ref = lmc._with_stats(global_stats(lmc.params, lmc.scaler.x(X[:n + 60]), lmc.scaler.y(Y[:n + 60]), 256))
    Xq = X[-50:]
    for a, b in zip(new.predict_global(Xq), ref.predict_global(Xq)):
        np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-10)
    far = np.column_stack([np.linspace(2.0, 3.0, 10), np.linspace(-2, 2, 10)])
    [(v0, v1)] = lmc.global_variance_after_many([far], [Xq])
    np.testing.assert_allclose(v1, lmc.update(far, np.zeros((10, 2)), exchange=False).predict_global(Xq, False)[1],
                               rtol=1e-7)
    assert np.all(v1 <= v0 + 1e-12) and np.any(v1 < 0.9 * v0)


@pytest.mark.slow
def test_lmc_streaming_exchange_and_refresh(two_scales):
    """A new region streamed in twice (the first batch joins the row store that stands for the data in
    the exchange criterion, the second then earns inducing points there): the old rows' statistics
    carried by the per-kernel projection stay close to those computed again at the new points; a
    hyperparameter refresh keeps the two kernels."""
    from gcs_sysid.gp.batching import global_stats

    X, Y, F, n, _, lmc = two_scales
    Xq = X[-50:]
    far = np.column_stack([np.linspace(2.0, 3.0, 40), np.linspace(-2, 2, 40)])
    Yfar = np.column_stack([np.sin(3 * far[:, 0]), 1.5 * np.cos(0.7 * far[:, 0])])
    moved = replace(lmc, config=replace(lmc.config, swap_max=4, swap_threshold=0.05))
    moved = moved.update(far[::2], Yfar[::2]).update(far[1::2], Yfar[1::2])
    assert not np.allclose(np.asarray(moved.params.Z), np.asarray(lmc.params.Z))
    Xall, Yall = np.vstack([X[:n], far[::2], far[1::2]]), np.vstack([Y[:n], Yfar[::2], Yfar[1::2]])
    exact_new = moved._with_stats(global_stats(moved.params, moved.scaler.x(Xall), moved.scaler.y(Yall), 256))
    m1, _ = moved.predict_global(Xq)
    m2, _ = exact_new.predict_global(Xq)
    assert np.sqrt(np.mean((m1 - m2) ** 2)) < 0.05 * np.std(Y[:n])
    back = moved.refresh_hyperparameters()
    assert back.params.n_kernels == 2
    assert np.all(np.isfinite(back.predict(Xq)[0]))


def test_lmc_saves_as_version_4_and_version_3_files_load(two_scales, tmp_path):
    X, _, _, _, icm, lmc = two_scales
    Xq = X[-20:]
    path = lmc.save(tmp_path / "lmc")
    assert json.loads((tmp_path / "lmc.json").read_text())["version"] == 4
    back = load_gp(path)
    assert back.params.n_kernels == 2
    for a, b in zip(lmc.predict(Xq), back.predict(Xq)):
        np.testing.assert_allclose(a, b, rtol=1e-9)
    # an ICM model written as version 3 (no lmc arrays) reads as before
    icm.save(tmp_path / "v3")
    js = tmp_path / "v3.json"
    meta = json.loads(js.read_text())
    meta["version"] = 3
    meta["config"].pop("latent_kernels")
    js.write_text(json.dumps(meta))
    with np.load(tmp_path / "v3.npz") as f:
        assert not any("lmc" in k for k in f.files)
    old = load_gp(tmp_path / "v3")
    assert old.params.n_kernels == 1 and old.config.latent_kernels == 1
    for a, b in zip(icm.predict(Xq), old.predict(Xq)):
        np.testing.assert_allclose(a, b, rtol=1e-9)
