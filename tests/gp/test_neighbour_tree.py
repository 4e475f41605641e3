"""The local layer's k-d tree (gcs_sysid.gp.local.neighbour_tree: sliding-midpoint cells, 64 points per leaf)
returns what scipy's default tree (median cells, 16 per leaf) returns, bit for bit: the same neighbours in the
same order and the same distances, for queries on, near and far from the stored rows."""

import numpy as np
from scipy.spatial import cKDTree

from gcs_sysid.gp.local import NEIGHBOUR_TREE, build_store, neighbour_tree, neighbours


def _trajectory(n, d, seed):
    """``(n, d)`` rows along a smooth trajectory with noise (a flight's regressors, standardised)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 60.0, n)
    f = rng.uniform(0.05, 1.5, d)
    return np.sin(np.outer(t, f) + rng.uniform(0, np.pi, d)) + 0.05 * rng.standard_normal((n, d))


def test_the_tree_is_built_with_its_options():
    tree = neighbour_tree(_trajectory(500, 4, 0))
    assert NEIGHBOUR_TREE == {"leafsize": 64, "balanced_tree": False}
    assert tree.leafsize == 64


def test_queries_equal_the_default_tree_bit_for_bit():
    pts = _trajectory(6000, 10, 1)
    rng = np.random.default_rng(2)
    queries = np.vstack([pts[rng.choice(len(pts), 700, replace=False)],          # on the rows
                         pts[:700] + 0.1 * rng.standard_normal((700, 10)),        # near them
                         rng.uniform(-3.0, 3.0, (700, 10))])                       # far from them (a map's grid)
    for k in (1, 16, 49):
        d0, i0 = cKDTree(pts).query(queries, k=k)
        d1, i1 = neighbour_tree(pts).query(queries, k=k, workers=-1)
        assert np.array_equal(i0, i1)
        assert np.array_equal(d0, d1)       # the same arithmetic on the same two points: the same bits


def test_the_store_and_its_neighbours_use_it():
    X = _trajectory(3000, 6, 3)
    metric = np.linspace(0.5, 2.0, 6)
    store = build_store(X, np.zeros((3000, 2)), metric, 16)
    assert store.tree.leafsize == NEIGHBOUR_TREE["leafsize"]
    q = X[::7] + 0.02
    idx, z = neighbours(store, q)
    dist, ref = cKDTree(X * metric).query(q * metric, k=16)
    assert np.array_equal(idx, ref)
    assert np.array_equal(z, np.log(np.maximum(dist.mean(1), 1e-12)) - store.z_mean)
