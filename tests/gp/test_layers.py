"""What each part adds: the local layer on a short-scale bump, the coregionalisation on coupled outputs,
the mutual-information selection against random choice."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gp_data import FAST, flight_regressors, linear_truth
from gcs_sysid.gp import fit_gp
from gcs_sysid.gp import sparse
from gcs_sysid.gp.selection import greedy_mutual_information, select_inducing


def error_pct(est, ref):
    return 100 * np.sqrt(np.mean((est - ref) ** 2, 0)) / np.sqrt(np.mean(ref**2, 0))


def test_local_layer_captures_a_short_scale_bump_the_global_layer_misses():
    X = flight_regressors(450, seed=21)
    alpha = X[:, 0]
    bump = np.exp(-0.5 * ((alpha - np.median(alpha)) / np.radians(0.15)) ** 2)   # 0.15 deg wide
    Yt = linear_truth(X)
    Yt += bump[:, None] * Yt.std(0)
    Y = Yt + 0.02 * Yt.std(0) * np.random.default_rng(3).standard_normal(Yt.shape)
    test = np.arange(450) % 3 == 0   # interleaved hold-out: 300 training rows, the shapes of the other fits
    model, _ = fit_gp(X[~test], Y[~test], FAST)
    near = bump[test] > 0.3
    assert near.sum() >= 5
    both = error_pct(model.predict(X[test])[0][near], Yt[test][near])
    glob = error_pct(model.predict_global(X[test])[0][near], Yt[test][near])
    assert np.all(both < 0.5 * glob), (both, glob)
    assert model.summary()["local"]["lengthscales"]["alpha"] < np.radians(1.0)


def test_coregionalisation_learns_the_coupling_of_two_outputs():
    X = flight_regressors(300, seed=31)
    rng = np.random.default_rng(4)
    g = np.sin(30 * X[:, 0]) + np.cos(20 * X[:, 5])
    h = np.sin(30 * X[:, 0] + 1.7) + np.cos(20 * X[:, 5] + 2.1)   # same kind of function, not coupled to g
    rest = 0.05 * rng.standard_normal((300, 4)) + X[:, 6:] * [1.0, 10.0, 1.0, 0.1]

    def fitted_corr(second):
        # the pair as outputs 0 and 2 (CX and CZ by the default names: one axis, so the test holds with
        # GPConfig.output_groups="axes" too)
        Y = np.column_stack([g, rest[:, 0], second, rest[:, 1:]]) + 0.05 * rng.standard_normal((300, 6))
        return fit_gp(X, Y, FAST)[0].output_correlation()[0, 2]

    coupled = fitted_corr(0.9 * g + 0.1 * h)
    uncoupled = fitted_corr(h)
    assert coupled > 0.9
    assert abs(uncoupled) < 0.5, uncoupled


def _brute_force_mi_order(K, m, nugget):
    Kn = K + nugget * np.eye(len(K))
    chosen = []
    for _ in range(m):
        best, best_score = None, -np.inf
        for y in range(len(K)):
            if y in chosen:
                continue
            A = chosen
            rest = [i for i in range(len(K)) if i not in chosen and i != y]

            def cond(S):
                if not S:
                    return Kn[y, y]
                return Kn[y, y] - Kn[y, S] @ np.linalg.solve(Kn[np.ix_(S, S)], Kn[S, y])
            score = cond(A) / cond(rest)
            if score > best_score:
                best, best_score = y, score
        chosen.append(best)
    return chosen


def test_greedy_mutual_information_matches_its_definition():
    rng = np.random.default_rng(5)
    X = rng.uniform(-1, 1, (14, 2))
    K = np.exp(-0.5 * np.sum((X[:, None] - X[None]) ** 2, -1) / 0.4**2)
    assert list(greedy_mutual_information(K, 6, 0.05)) == _brute_force_mi_order(K, 6, 0.05)


def test_mutual_information_selection_beats_random_selection():
    elbo = jax.jit(sparse.elbo)
    stats_of = jax.jit(sparse.stats_of)
    ls = np.array([0.6, 0.6])
    wins, gaps = 0, []
    for seed in range(5):
        rng = np.random.default_rng(seed)
        # a dense cluster and a wide sparse cloud (a long trim segment plus a few maneuvers)
        X = np.vstack([rng.normal(0, 0.2, (400, 2)), rng.uniform(-3, 3, (100, 2))])
        Y = (np.sin(2 * X[:, 0]) * np.cos(1.5 * X[:, 1]))[:, None] + 0.05 * rng.standard_normal((500, 1))
        values = {}
        for method in ("mi", "random"):
            Z = select_inducing(X, 20, ls, method, pool=500, nugget=0.01, seed=seed)
            p = sparse.GlobalParams(jnp.asarray(ls), jnp.eye(1), jnp.array([0.0025]), jnp.asarray(Z), jnp.asarray(0.0),
                                    jnp.asarray(1e-6))
            values[method] = float(elbo(p, stats_of(p, jnp.asarray(X), jnp.asarray(Y))))
        wins += values["mi"] > values["random"]
        gaps.append(values["mi"] - values["random"])
    assert wins >= 4 and np.mean(gaps) > 0, gaps


def test_unknown_selection_method_is_rejected():
    with pytest.raises(ValueError, match="unknown inducing-point selection"):
        select_inducing(np.zeros((5, 2)), 2, np.ones(2), "best")
