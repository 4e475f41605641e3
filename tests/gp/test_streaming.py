"""The bounded streaming GP: exact conditioning against a dense VFE reference, the streaming projection
against Bui et al.'s formula, the region-thinned row store, flat saved state, and the envelope expansion."""

from dataclasses import replace

import jax
import numpy as np
from scipy.linalg import block_diag

from gp_data import FAST, envelope_expansion_case, error_pct, flight_regressors, nonlinear_truth
from gcs_sysid.gp import fit_gp, load_gp
from gcs_sysid.gp import sparse
from gcs_sysid.gp.rowstore import RowStore, per_cell_limit
from gcs_sysid.gp.sparse import GlobalParams, add_stats
from gcs_sysid.gp.streaming import exchange_inducing, project_stats, projection, se_kernel

posterior, stats_of, predict_chunk = jax.jit(sparse.posterior), jax.jit(sparse.stats_of), \
    jax.jit(sparse.predict_global_chunk)


def dense_vfe_predict(params, Xs, Ys, Xq):
    """Titsias (2009) VFE predictive mean and latent variance, written the obvious way: the exact GP with
    the Nystrom covariance ``Q = K_xz K_zz^{-1} K_zx`` on the training rows (ICM ``B kron Q`` plus the
    linear mean's ``v Xa Xa^T`` plus noise), and the prior rest ``B_pp (k - Q)`` added at the query."""
    p = jax.tree_util.tree_map(np.asarray, params)
    ls, Z, B = p.lengthscale, p.Z, p.A @ p.A.T
    S2 = np.broadcast_to(np.asarray(p.prior_std, float), (B.shape[0], Z.shape[1] + 1)) ** 2   # per output and term
    Kzz = se_kernel(Z, Z, ls) + float(p.jitter) * np.eye(len(Z))

    def Q(X1, X2):
        return se_kernel(X1, Z, ls) @ np.linalg.solve(Kzz, se_kernel(Z, X2, ls))

    def xa(X):
        return np.column_stack([np.ones(len(X)), X])

    def lin(X1, X2):                      # blockdiag_p(Xa V_p Xa^T), V_p = diag(prior std of output p)^2
        return block_diag(*[(xa(X1) * S2[q]) @ xa(X2).T for q in range(len(S2))])

    N, P = len(Xs), B.shape[0]
    # Sigma kron I (full noise)
    K = np.kron(B, Q(Xs, Xs)) + lin(Xs, Xs) + np.kron(np.asarray(params.noise_cov()), np.eye(N))
    Kq = np.kron(B, Q(Xq, Xs)) + lin(Xq, Xs)
    mean = (Kq @ np.linalg.solve(K, Ys.T.reshape(-1))).reshape(P, -1).T
    qq = np.sum(se_kernel(Xq, Z, ls) * np.linalg.solve(Kzz, se_kernel(Z, Xq, ls)).T, 1)
    prior_q = np.kron(np.diag(B), qq) + ((xa(Xq) ** 2) @ S2.T).T.reshape(-1)
    var = prior_q - np.sum(Kq * np.linalg.solve(K, Kq.T).T, 1)
    var = var.reshape(P, -1).T + np.diag(B)[None, :] * (1.0 - qq)[:, None]
    return mean, var


def test_streamed_updates_equal_the_dense_batch_vfe_posterior(flight, fitted):
    """Nothing evicted, no exchange, same hyperparameters: streaming 2 x 50 rows equals the batch VFE fit."""
    X, Y, _ = flight
    model, _ = fitted
    streamed = model
    for a in (400, 450):
        streamed = streamed.update(X[a:a + 50], Y[a:a + 50], exchange=False)
    sc = model.scaler
    mean, var = dense_vfe_predict(model.params, sc.x(X[:500]), sc.y(Y[:500]), sc.x(X[500:520]))
    got_m, got_v = streamed.predict_global(X[500:520], include_noise=False)
    np.testing.assert_allclose(got_m, mean * sc.y_std + sc.y_mean, rtol=1e-6, atol=1e-9 * np.max(sc.y_std))
    np.testing.assert_allclose(got_v, var * sc.y_std**2, rtol=1e-5)
    assert streamed.n_used == 500 and streamed.rows.seen == 500 and len(streamed.rows) == 500


def _small_params(Z, ls=(0.8, 1.3), prior_std=0.0, P=1):
    A = np.linalg.cholesky(np.array([[0.9]]) if P == 1 else 0.3 * np.eye(P) + 0.2)
    return GlobalParams(lengthscale=np.asarray(ls), A=A, noise=np.full(P, 0.02), Z=np.asarray(Z),
                        prior_std=np.asarray(prior_std), jitter=np.asarray(1e-8))


def test_projection_equals_bui_streaming_posterior():
    """One output, no linear mean: the old rows' statistics carried to new inducing points (and new
    length-scales) give Bui, Nguyen and Turner's (2017) q(b), computed here from its formula:
    precision K_bb^-1 + P^T J_a P + K_bb^-1 K_bf K_fb K_bb^-1 / s2 with P = K_ab K_bb^-1,
    J_a = S_a^-1 - K_aa^-1 and h_a = S_a^-1 m_a from the old VFE posterior q(a) = N(m_a, S_a)."""
    rng = np.random.default_rng(7)
    X1, X2 = rng.uniform(-2, 0.5, (40, 2)), rng.uniform(0, 2.5, (30, 2))
    f = lambda X: np.sin(2 * X[:, :1]) + 0.5 * X[:, 1:]  # noqa: E731
    Y1, Y2 = f(X1) + 0.1 * rng.standard_normal((40, 1)), f(X2) + 0.1 * rng.standard_normal((30, 1))
    Za, Zb = rng.uniform(-2, 0.5, (8, 2)), np.vstack([rng.uniform(-2, 0.5, (4, 2)), rng.uniform(0, 2.5, (5, 2))])
    pa, pb = _small_params(Za), _small_params(Zb, ls=(0.9, 1.1))
    Xq = rng.uniform(-2, 2.5, (6, 2))
    # streaming: statistics of X1 under (Za, old ls), projected, plus X2's under (Zb, new ls)
    st1 = stats_of(pa, X1, Y1)
    R = projection(np.asarray(posterior(pa, st1).Lm), Za, Zb, np.asarray(pb.lengthscale), 1e-8)
    st = add_stats(jax.tree_util.tree_map(np.asarray, project_stats(st1, R)), stats_of(pb, X2, Y2))
    got = np.asarray(predict_chunk(pb, posterior(pb, st), Xq)[0])[:, 0]
    # Bui et al. (2017), dense
    b, s2 = 0.9, 0.02
    kA = lambda U, V: b * se_kernel(U, V, np.asarray(pa.lengthscale))  # noqa: E731
    kB = lambda U, V: b * se_kernel(U, V, np.asarray(pb.lengthscale))  # noqa: E731
    Kaa = kA(Za, Za) + b * 1e-8 * np.eye(8)
    Kaf = kA(Za, X1)
    Sa_inv = np.linalg.inv(Kaa) + np.linalg.inv(Kaa) @ Kaf @ Kaf.T @ np.linalg.inv(Kaa) / s2
    ma = np.linalg.solve(Sa_inv, np.linalg.inv(Kaa) @ Kaf @ Y1[:, 0] / s2)
    Ja, ha = Sa_inv - np.linalg.inv(Kaa), Sa_inv @ ma
    Kbb_inv = np.linalg.inv(kB(Zb, Zb) + b * 1e-8 * np.eye(9))
    Pm = kB(Za, Zb) @ Kbb_inv
    Kbf = kB(Zb, X2)
    prec = Kbb_inv + Pm.T @ Ja @ Pm + Kbb_inv @ Kbf @ Kbf.T @ Kbb_inv / s2
    mb = np.linalg.solve(prec, Pm.T @ ha + Kbb_inv @ Kbf @ Y2[:, 0] / s2)
    ref = kB(Xq, Zb) @ Kbb_inv @ mb
    np.testing.assert_allclose(got, ref, rtol=1e-6, atol=1e-8)


def test_projection_is_exact_when_the_old_rows_are_the_old_inducing_inputs():
    rng = np.random.default_rng(8)
    Za = rng.uniform(-2, 2, (10, 2))
    Y = np.column_stack([np.sin(Za[:, 0]), np.cos(Za[:, 1]), Za[:, 0] * Za[:, 1]])
    Zb = np.vstack([Za[:6], rng.uniform(-2, 2, (4, 2))])       # four points replaced
    pa, pb = _small_params(Za, prior_std=1.0, P=3), _small_params(Zb, ls=(1.1, 0.9), prior_std=1.0, P=3)
    st = stats_of(pa, Za, Y)
    R = projection(np.asarray(posterior(pa, st).Lm), Za, Zb, np.asarray(pb.lengthscale), 1e-8)
    moved = project_stats(st, R)
    direct = stats_of(pb, Za, Y)
    for name in ("C", "E", "Rphi", "F", "Rx", "yy", "n"):
        np.testing.assert_allclose(getattr(moved, name), np.asarray(getattr(direct, name)), rtol=1e-6, atol=1e-7)


def _brute_force_drop(Z, c, pool, ls, nugget):
    """Krause et al. (2008) eq. 6 by definition: the point of S = Z + {c} with the least
    H(s | S - s) - H(s | pool), conditional variances by explicit solves."""
    S = np.vstack([Z, c[None]])
    Kn = lambda U, V: se_kernel(U, V, ls) + nugget * (U is V) * np.eye(len(U))  # noqa: E731

    def cond(x, A):
        k = se_kernel(x[None], A, ls)[0]
        return 1 + nugget - k @ np.linalg.solve(Kn(A, A), k)
    delta = [np.log(cond(S[i], np.delete(S, i, 0))) - np.log(cond(S[i], pool)) for i in range(len(S))]
    return int(np.argmin(delta))


def test_exchange_follows_the_mutual_information_criterion_and_only_for_a_new_region():
    rng = np.random.default_rng(9)
    g = np.linspace(-1, 1, 6)
    Z = np.vstack([np.stack(np.meshgrid(g, g), -1).reshape(-1, 2), [[g[2] + 1e-3, g[3]]]])   # + a near-duplicate
    pool = rng.uniform(-1, 1, (100, 2))
    ls, nugget = np.array([0.5, 0.5]), 0.01
    same, n_same = exchange_inducing(Z, ls, rng.uniform(-0.9, 0.9, (20, 2)), pool, nugget, 0.5, 3)
    assert n_same == 0 and np.array_equal(same, Z)            # the covered region: nothing to do
    far = np.array([[3.0, 3.0], [3.1, 2.9]])
    pool_new = np.vstack([pool, far[0] + 0.1 * rng.standard_normal((10, 2))])   # the new region has data
    new, n = exchange_inducing(Z, ls, far, pool_new, nugget, 0.5, 1)
    assert n == 1
    changed = np.flatnonzero(np.any(new != Z, 1))
    entered = new[changed[0]]
    assert len(changed) == 1 and np.any(np.all(entered == far, 1))
    assert changed[0] == _brute_force_drop(Z, entered, pool_new, ls, nugget)
    # an isolated candidate with no data around it is the most redundant by the criterion: not taken
    lone, n_lone = exchange_inducing(Z, ls, np.array([[-4.0, 4.0]]), pool, nugget, 0.5, 1)
    assert n_lone == 0 and _brute_force_drop(Z, np.array([-4.0, 4.0]), pool, ls, nugget) == len(Z)


def test_per_cell_limit_is_the_largest_feasible_water_level():
    counts = np.array([1, 3, 7, 20, 2])
    for cap in range(1, 34):
        L = per_cell_limit(counts, cap)
        assert np.minimum(counts, L).sum() <= cap and (L >= counts.max() or np.minimum(counts, L + 1).sum() > cap)


def test_row_store_thins_dense_regions_and_keeps_sparse_ones():
    rng = np.random.default_rng(10)
    store = RowStore.empty(2, 1, np.ones(2), cell_width=0.5, capacity=400, seed=1)
    dense = rng.normal(0, 0.3, (3000, 2))                     # a long trim segment
    for a in range(0, 3000, 100):
        store = store.add(dense[a:a + 100], dense[a:a + 100, :1])
    edge = rng.uniform(3, 5, (60, 2))                          # a region explored once, late
    store = store.add(edge, edge[:, :1])
    assert len(store) <= 400 and store.seen == 3060
    kept_edge = np.sum(store.X[:, 0] >= 3)
    assert kept_edge == 60 or kept_edge >= 40                  # the sparse region keeps (nearly) all its rows
    np.testing.assert_allclose(store.weight.sum(), 3060)       # every row seen is represented
    # the dense part is a sample over the whole stream, not its end: early rows survive
    early = np.isin(store.X[:, 0], dense[:1500, 0]).sum()
    late = np.isin(store.X[:, 0], dense[1500:, 0]).sum()
    assert 0.6 < early / late < 1.6


def test_state_is_bounded_once_the_budget_is_full(tmp_path):
    X = flight_regressors(1500, seed=51)
    Yt = nonlinear_truth(X)
    Y = Yt + 0.02 * Yt.std(0) * np.random.default_rng(52).standard_normal(Yt.shape)
    cfg = replace(FAST, store_max=250)
    model, _ = fit_gp(X[:300], Y[:300], cfg)
    sizes, stored = [], []
    for a in range(300, 1500, 100):
        model = model.update(X[a:a + 100], Y[a:a + 100])
        path = model.save(tmp_path / f"gp{a}")
        with np.load(path) as f:
            sizes.append(sum(f[k].nbytes for k in f.files))
        stored.append(len(model.rows))
    assert max(stored) <= 250 and model.rows.seen == 1500 and model.n_used == 1500
    # flat once full (here after ~300 rows): the store holds 95-100 % of its capacity after a thinning,
    # so the size varies by a few stored rows, and does not grow with the rows seen
    assert max(sizes[4:]) <= 1.03 * max(sizes[:4]) and max(sizes[4:]) <= 1.03 * min(sizes[4:])
    loaded = load_gp(path)
    for a, b in zip(model.predict(X[:50]), loaded.predict(X[:50])):
        np.testing.assert_allclose(a, b, rtol=1e-9)
    again_a = model.update(X[:60], Y[:60])                      # and it keeps streaming after a reload
    again_b = loaded.update(X[:60], Y[:60])
    np.testing.assert_allclose(again_a.predict(X[:20])[0], again_b.predict(X[:20])[0], rtol=1e-8)


def test_envelope_expansion_streamed_is_within_20_percent_of_a_full_refit():
    """The issue's case: a model fitted on the envelope flown (alpha below its 70th percentile) is
    updated, 50 rows at a time as on a link, on a region not flown before (higher alpha, where the
    lift curve bends); the hyperparameters refresh on schedule (every 400 rows). Its held-out error
    there is within 20 % of a full refit on all the rows (the cost of both: benchmarks/bench_gp_stream.py)."""
    X, Yt, Y, flown, test, train_new = envelope_expansion_case()
    cfg = replace(FAST, hyper_every=400)
    model, _ = fit_gp(X[flown], Y[flown], cfg)
    before = error_pct(model.predict(X[test])[0], Yt[test])
    for a in range(0, len(train_new), 50):
        rows = train_new[a:a + 50]
        model = model.update(X[rows], Y[rows])
    assert model.since_refresh == len(train_new) - 400          # refreshed once, on schedule
    streamed = error_pct(model.predict(X[test])[0], Yt[test])
    refit, _ = fit_gp(np.vstack([X[flown], X[train_new]]), np.vstack([Y[flown], Y[train_new]]), cfg)
    full = error_pct(refit.predict(X[test])[0], Yt[test])
    assert np.mean(streamed) <= 1.2 * np.mean(full), (streamed, full)
    assert np.mean(before) > 5 * np.mean(streamed)               # the region was new to the model
