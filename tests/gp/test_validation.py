"""Blocked cross-validation (gcs_sysid.gp.validation): the latent GP and the local layer are kept per
output only where they predict time blocks they were not conditioned on.

The gates are checked on fixed hyperparameters (no fitting: fast and exact about what is tested):
one output whose residual from the linear mean is a smooth function of the input (the GP must stay),
one whose residual is coloured noise along the time-ordered trajectory (an AR(1) process that lasts
hundreds of rows, as a gust does; the GP fits it where it was seen and must be dropped elsewhere).
"""

import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.gp import GPConfig, fit_gp, load_gp
from gcs_sysid.gp.local import LocalParams
from gcs_sysid.gp.sparse import GlobalParams
from gcs_sysid.gp.validation import GLOBAL_GRID, LOCAL_OFF, block_folds, gate_global, gate_local, scale_latent


def _case(n=1000, seed=3):
    """Time-ordered rows ``x (n, 1)`` of a trajectory that sweeps the same range many times, and two
    outputs: ``y0`` linear + sin (structure the GP must keep), ``y1`` linear + AR(1) noise with a
    correlation time of 150 rows (coloured error the GP must not keep)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    x = np.sin(2 * np.pi * t / 97.0) + 0.3 * np.sin(2 * np.pi * t / 31.0)
    ar = np.zeros(n)
    phi = np.exp(-1.0 / 150.0)
    for i in range(1, n):
        ar[i] = phi * ar[i - 1] + np.sqrt(1 - phi**2) * rng.standard_normal()
    y0 = 0.5 * x + 0.6 * np.sin(3.0 * x) + 0.02 * rng.standard_normal(n)
    y1 = 0.5 * x + 0.5 * ar + 0.02 * rng.standard_normal(n)
    X = x[:, None]
    Y = np.column_stack([y0, y1])
    return (X - X.mean(0)) / X.std(0), (Y - Y.mean(0)) / Y.std(0)


def _global_params(M=20):
    Z = np.linspace(-1.8, 1.8, M)[:, None]
    return GlobalParams(lengthscale=jnp.array([0.15]), A=jnp.eye(2) * 0.7, noise=jnp.array([0.01, 0.01]),
                        Z=jnp.asarray(Z), prior_std=jnp.asarray(3.0), jitter=jnp.asarray(1e-6))


def test_block_folds_cover_rows_in_order():
    assert block_folds(10, 3) == [(0, 3), (3, 7), (7, 10)]
    assert sum(b - a for a, b in block_folds(1001, 5)) == 1001


def test_scale_latent_scales_rows_of_B():
    p = _global_params()
    A = np.array([[1.0, 0.0], [0.5, 0.8]])
    q = scale_latent(GlobalParams(**{**p.__dict__, "A": jnp.asarray(A)}), np.array([1.0, 0.1]))
    S = np.diag([1.0, 0.1])
    np.testing.assert_allclose(np.asarray(q.B), S @ (A @ A.T) @ S, atol=1e-12)


def test_global_gate_keeps_structure_and_drops_coloured_noise():
    X, Y = _case()
    params, stats, s, sse = gate_global(_global_params(), X, Y, folds=5, batch=256, val_max=1000)
    assert s[0] == 1.0                                  # the sin: the GP earns its place
    assert s[1] < 1.0                                   # the AR(1) error: shrunk towards the linear model
    assert sse[list(GLOBAL_GRID).index(1.0), 1] > sse[list(GLOBAL_GRID).index(s[1]), 1]
    assert float(stats.n) == len(X)                     # the statistics of every row, for the posterior
    np.testing.assert_allclose(np.asarray(params.A)[1], s[1] * 0.7 * np.eye(2)[1])


def test_local_gate_keeps_structure_and_drops_coloured_noise():
    X, Y = _case()
    resid = Y - 0.5 * X                                 # what a global linear model would leave (roughly)
    local = LocalParams(lengthscale=jnp.array([0.05]), beta=jnp.asarray(0.0), amp=jnp.array([0.3, 0.3]),
                        noise=jnp.array([0.01, 0.01]))
    gated, keep, ratio = gate_local(local, X, resid, np.array([1.0]), k=16, folds=5, batch=256)
    assert keep.tolist() == [True, False]
    assert ratio[0] < 0.5 and ratio[1] > 1.0
    np.testing.assert_allclose(np.asarray(gated.amp), [0.3, 0.3 * LOCAL_OFF])


@pytest.fixture(scope="module")
def coloured_fit():
    """The whole fit on the two-output case (small settings)."""
    X, Y = _case(n=800)
    cfg = GPConfig(n_inducing=16, n_inducing_hyper=16, n_train_max=300, steps=60, learning_rate=0.1, mi_pool=200,
                   local_batch=32, local_steps=20, batch_size=256)
    return X, Y, cfg, fit_gp(X, Y, cfg, input_names=["x"], output_names=["y0", "y1"])


def test_fit_applies_the_gates_it_records(fitted):
    """The shared fixture's fit (conftest, 400 time-ordered rows): the recorded choice is in the model."""
    model, hist = fitted
    v = hist.validation
    assert len(v["latent_scale"]) == 6 and set(v["latent_scale"]) <= set(GLOBAL_GRID)
    amp = np.asarray(model.local_params.amp)
    off = ~np.asarray(v["local_kept"])
    assert np.all((np.asarray(v["local_ratio"]) < 0.99) == ~off)
    if off.any() and (~off).any():
        assert amp[off].max() < 1e-3 * amp[~off].min()


@pytest.mark.slow
def test_fit_records_the_gates_and_the_model_round_trips(coloured_fit, tmp_path):
    X, Y, cfg, (model, hist) = coloured_fit
    v = hist.validation
    assert set(v) == {"latent_scale", "local_kept", "local_ratio"}
    assert v["latent_scale"][1] < 1.0 and not v["local_kept"][1]
    amp = np.asarray(model.local_params.amp)
    assert amp[1] < 1e-3 * amp[0] or not v["local_kept"][0]
    model.save(tmp_path / "gp")                         # format unchanged: the gates live in A and amp
    m2 = load_gp(tmp_path / "gp")
    np.testing.assert_allclose(m2.predict(X[:50])[0], model.predict(X[:50])[0], rtol=1e-9, atol=1e-12)


@pytest.mark.slow
def test_fit_without_validation_is_the_model_before(coloured_fit):
    X, Y, cfg, (model, hist) = coloured_fit
    from dataclasses import replace

    plain, h0 = fit_gp(X, Y, replace(cfg, validation_folds=0), input_names=["x"], output_names=["y0", "y1"])
    assert h0.validation == {}
    np.testing.assert_allclose(np.asarray(plain.params.lengthscale), np.asarray(model.params.lengthscale))
    # the gated output's latent prior is smaller than learned, the other's unchanged where kept
    s = np.asarray(hist.validation["latent_scale"])
    np.testing.assert_allclose(np.diag(np.asarray(model.params.B)), s**2 * np.diag(np.asarray(plain.params.B)),
                               rtol=1e-9)
