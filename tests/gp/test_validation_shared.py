"""The held-back blocks' local stores from one shared neighbour search (gcs_sysid.gp.validation.block_stores)
equal the stores built block by block (gcs_sysid.gp.local.build_store), bit for bit, and gate_local
decides and predicts as the block-by-block loop did.

The cases are chosen to exercise every branch of the sharing: a trajectory that revisits the same
inputs (most rows' neighbours lie in other blocks), exact duplicate rows (ties at distance 0 and
between neighbours), rows whose shared neighbours lie almost all inside a block (the fallback
query), and a set smaller than the shared query (every row's neighbours are all rows).
"""

import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.gp import validation
from gcs_sysid.gp.batching import local_predict
from gcs_sysid.gp.local import LocalParams, build_store
from gcs_sysid.gp.validation import (LOCAL_MARGIN, LOCAL_OFF, _val_rows, block_folds, block_stores, gate_local,
                                      shared_search, store_without)


def _rows(n, seed, dup=0):
    """Time-ordered ``(X (n, 3), resid (n, 2))``: a slow sweep repeated with noise, ``dup`` rows copied."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    X = np.column_stack([np.sin(2 * np.pi * t / 211.0), np.cos(2 * np.pi * t / 97.0), 0.3 * rng.standard_normal(n)])
    if dup:
        src = rng.choice(n, dup, replace=False)
        X[rng.choice(n, dup, replace=False)] = X[src]           # exact copies: ties at distance 0
        X[: dup // 2] = np.round(X[: dup // 2], 1)               # coarse grid: many ties between neighbours
    resid = np.column_stack([np.sin(3 * X[:, 0]) + 0.05 * rng.standard_normal(n), rng.standard_normal(n)])
    return X, resid


def _per_block_gate(local, Xs, resid, metric, k, folds, batch, val_max=1000, seed=0):
    """gate_local as it was: one store built per held-back block (the reference)."""
    n, P = resid.shape
    rng = np.random.default_rng(seed + 29)
    per = max(1, val_max // max(folds, 1))
    with_l, without, means = np.zeros(P), np.zeros(P), []
    for a, b in block_folds(n, folds):
        keep_rows = np.r_[0:a, b:n]
        if len(keep_rows) < 2:
            continue
        store = build_store(Xs[keep_rows], resid[keep_rows], metric, k)
        rows = _val_rows(a, b, per, rng)
        m, _ = local_predict(local, store, Xs[rows], batch)
        means.append(m)
        with_l += np.sum((resid[rows] - m) ** 2, 0)
        without += np.sum(resid[rows] ** 2, 0)
    return with_l / np.maximum(without, 1e-300), np.concatenate(means)


@pytest.mark.parametrize("n, k, folds, dup, seed", [(3000, 16, 5, 0, 1), (1500, 8, 4, 300, 2), (40, 16, 3, 10, 3),
                                                     (600, 16, 7, 0, 4)])
def test_block_stores_equal_per_block_stores(n, k, folds, dup, seed):
    X, resid = _rows(n, seed, dup)
    metric = np.array([2.0, 1.5, 0.7])
    blocks = [(a, b) for a, b in block_folds(n, folds) if n - (b - a) >= 2]
    for (a, b), s in zip(blocks, block_stores(X, resid, metric, k, blocks), strict=True):
        keep = np.r_[0:a, b:n]
        ref = build_store(X[keep], resid[keep], metric, k)
        assert np.array_equal(s.z, ref.z) and s.z_mean == ref.z_mean and s.k == ref.k
        assert np.array_equal(s.X, ref.X) and np.array_equal(s.resid, ref.resid)
        assert np.array_equal(s.tree.data, ref.tree.data)
    full = store_without(shared_search(X, metric, k), X, resid, 0, 0)     # the store of all rows
    ref = build_store(X, resid, metric, k)
    assert np.array_equal(full.z, ref.z) and full.z_mean == ref.z_mean and full.k == ref.k
    assert np.array_equal(full.tree.data, ref.tree.data) and np.array_equal(full.X, X)


def test_fallback_query_is_used_and_exact(monkeypatch):
    """With the shared search cut to k + 1 neighbours most rows near the blocks need their own
    query; the stores stay equal."""
    monkeypatch.setattr(validation, "SHARED_NEIGHBOURS", 1)
    X, resid = _rows(2000, 5, dup=200)
    metric = np.ones(3)
    blocks = block_folds(2000, 5)
    for (a, b), s in zip(blocks, block_stores(X, resid, metric, 16, blocks)):
        keep = np.r_[0:a, b:2000]
        assert np.array_equal(s.z, build_store(X[keep], resid[keep], metric, 16).z)


def test_gate_local_decisions_and_predictions_unchanged():
    X, resid = _rows(3000, 7, dup=100)
    metric = np.array([3.0, 3.0, 0.5])
    local = LocalParams(lengthscale=jnp.array([0.3, 0.3, 2.0]), beta=jnp.asarray(0.2), amp=jnp.array([0.5, 0.5]),
                        noise=jnp.array([0.01, 0.5]))
    ratio_ref, _ = _per_block_gate(local, X, resid, metric, 16, 5, 256)
    gated, keep, ratio = gate_local(local, X, resid, metric, k=16, folds=5, batch=256)
    assert np.array_equal(ratio, ratio_ref)                 # the same predictions, summed the same way
    assert keep.tolist() == (ratio_ref < LOCAL_MARGIN).tolist() == [True, False]
    np.testing.assert_array_equal(np.asarray(gated.amp), [0.5, 0.5 * LOCAL_OFF])


def test_fitted_model_store_equals_build_store(fitted):
    """fit_gp builds the store of all rows from the validation's shared search: as build_store would."""
    model, history = fitted
    assert "local_kept" in history.validation                # the blocked validation ran (shared search)
    st = model.store
    ref = build_store(st.X, st.resid, st.metric, st.k)
    assert np.array_equal(st.z, ref.z) and st.z_mean == ref.z_mean
