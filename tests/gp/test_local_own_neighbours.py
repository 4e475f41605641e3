"""A query equal to a stored row takes the row's own neighbours from the store's search
(gcs_sysid.gp.local.LocalStore.own_idx) instead of searching the k-d tree again: the same neighbours and
distances as the tree's k-query, so the same local predictions; other queries are searched as before."""

import numpy as np
import pytest

from gcs_sysid.gp.batching import local_predict
from gcs_sysid.gp.local import LocalParams, build_store, neighbours
from gcs_sysid.gp.validation import shared_search, store_without


def _rows(n, seed, dup=0):
    """A slow trajectory ``X (n, 3)`` with noise and residuals ``(n, 2)``; ``dup`` rows repeated exactly and
    ``dup`` rows on a coarse grid (ties at distance 0 and between neighbours)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    X = np.column_stack([np.sin(2 * np.pi * t / 211.0), np.cos(2 * np.pi * t / 97.0), 0.3 * rng.standard_normal(n)])
    if dup:
        X[rng.choice(n, dup, replace=False)] = X[rng.choice(n, dup, replace=False)]
        X[:dup] = np.round(X[:dup], 1)
    return X, np.column_stack([np.sin(3 * X[:, 0]), rng.standard_normal(n)])


def _tree_query(store, Xq):
    d, i = store.tree.query(Xq * store.metric, k=store.k)
    return i.reshape(len(Xq), store.k), np.log(np.maximum(d.reshape(len(Xq), store.k).mean(1), 1e-12)) - store.z_mean


@pytest.mark.parametrize("shared", [False, True])
@pytest.mark.parametrize("n, k, dup", [(2000, 16, 0), (12, 16, 0), (1500, 8, 300)])
def test_stored_rows_take_their_own_neighbours(n, k, dup, shared):
    X, resid = _rows(n, 5, dup)
    metric = np.array([2.0, 1.5, 0.7])
    store = (store_without(shared_search(X, metric, k), X, resid, 0, 0) if shared
             else build_store(X, resid, metric, k))
    assert store.own_idx is not None and store.own_idx.shape == (n, min(k, n))
    rng = np.random.default_rng(1)
    # stored rows, new points and stored rows again, interleaved
    Xq = np.vstack([X[rng.choice(n, min(n, 300), replace=False)], X[:5] + 1e-3, X[-7:]])
    Xq = Xq[rng.permutation(len(Xq))]
    own = store.own_rows(Xq)
    assert np.array_equal(X[own[own >= 0]], Xq[own >= 0])
    # found: exactly the queries equal to a stored row whose k + 1 nearest have no ties (a repeated row has)
    expected = [any(store.own_unique[j] for j in np.flatnonzero(np.all(X == q, axis=1))) for q in Xq]
    assert np.array_equal(own >= 0, expected) and sum(expected) > (0.9 if dup == 0 else 0.1) * len(Xq) - 5
    assert (dup == 0) == bool(store.own_unique.all())
    idx, z = neighbours(store, Xq)
    idx_t, z_t = _tree_query(store, Xq)
    assert np.array_equal(idx, idx_t) and np.array_equal(z, z_t)
    params = LocalParams(lengthscale=np.full(3, 0.3), beta=np.float64(0.2), amp=np.array([1.0, 0.5]),
                         noise=np.array([0.01, 0.02]))
    m, v = local_predict(params, store, Xq, 64)
    plain = build_store(X, resid, metric, k)
    object.__setattr__(plain, "own_idx", None)     # the tree for every query
    m_t, v_t = local_predict(params, plain, Xq, 64)
    assert np.array_equal(m, m_t) and np.array_equal(v, v_t)


def test_a_block_store_keeps_no_own_neighbours_and_other_dtypes_search_the_tree():
    X, resid = _rows(500, 6)
    metric = np.ones(3)
    search = shared_search(X, metric, 8)
    assert store_without(search, X, resid, 100, 200).own_idx is None     # queried at the block's rows only
    store = build_store(X, resid, metric, 8)
    assert store.own_rows(X[:10].astype(np.float32)) is None
    idx, z = neighbours(store, X[:10].astype(np.float32))
    assert idx.shape == (10, 8) and np.isfinite(z).all()
