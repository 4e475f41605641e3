"""The fitted local + global model: accuracy, incremental update, expected variance, summary, errors."""

import json
from dataclasses import replace

import numpy as np
import pytest

from gp_data import DERIVATIVES, FAST, flight_regressors, linear_truth
from gcs_sysid.errors import DataError, InputError
from gcs_sysid.gp import GPConfig, LocalGlobalGP, fit_gp
from gcs_sysid.gp.batching import global_posterior, global_predict, global_stats
from gcs_sysid.gp.local import build_store


def error_pct(est, ref):
    return 100 * np.sqrt(np.mean((est - ref) ** 2, 0)) / np.sqrt(np.mean(ref**2, 0))


def test_fit_predicts_held_out_rows_with_calibrated_variance(flight, fitted):
    X, Y, Yt = flight
    model, history = fitted
    assert isinstance(model, LocalGlobalGP)
    assert 10 <= len(history.elbo) <= FAST.steps and history.elbo[-1] > history.elbo[0]
    mean, var = model.predict(X[400:])
    assert mean.shape == var.shape == (200, 6) and np.all(var > 0)
    assert np.all(error_pct(mean, Yt[400:]) < 10.0), error_pct(mean, Yt[400:])
    z = (Y[400:] - mean) / np.sqrt(var)
    assert 0.3 < np.mean(z**2) < 3.0  # variance neither wildly over- nor under-confident


def test_linear_function_of_ten_inputs_is_recovered_to_one_percent():
    X = flight_regressors(400, seed=5)
    Yt = linear_truth(X)
    Y = Yt + 1e-3 * Yt.std(0) * np.random.default_rng(6).standard_normal(Yt.shape)
    model, _ = fit_gp(X[:300], Y[:300], FAST)
    mean, _ = model.predict(X[300:])
    assert np.all(error_pct(mean, Yt[300:]) < 1.0), error_pct(mean, Yt[300:])
    intercept, slopes = model.linear_derivatives()
    big = np.abs(DERIVATIVES[:, 1:]) > 0.05
    np.testing.assert_allclose(slopes[big], DERIVATIVES[:, 1:][big], rtol=0.02)


def test_update_equals_conditioning_on_all_rows_with_the_same_hyperparameters(flight, fitted):
    X, Y, _ = flight
    model, _ = fitted
    updated = model.update(X[400:500], Y[400:500], exchange=False)
    assert updated.n_used == 500 and model.n_used == 400  # immutable: the original is unchanged
    # reference: statistics of all 500 rows at once, local store rebuilt from scratch
    Xs, Ys = model.scaler.x(X[:500]), model.scaler.y(Y[:500])
    stats = global_stats(model.params, Xs, Ys, 64)
    post = global_posterior(model.params, stats)
    resid = Ys - global_predict(model.params, post, Xs, 64)[0]
    ref = replace(model, stats=stats, _post=post, _store=build_store(Xs, resid, model.store.metric, model.store.k))
    for a, b in zip(updated.predict(X[500:]), ref.predict(X[500:])):
        np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-12)
    for a, b in zip(updated.predict_global(X[500:]), ref.predict_global(X[500:])):
        np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-12)


def test_variance_after_shrinks_variance_near_new_points_only(flight, fitted):
    X, Y, _ = flight
    model, _ = fitted
    far = X[:5] + 6 * X.std(0)          # outside the envelope: the model knows little there
    X_extra = np.repeat(far, 3, axis=0)
    before = model.predict(np.vstack([far, X[:5]]), include_noise=False, input_noise=False, model_error=False)[1]
    after = model.variance_after(X_extra, np.vstack([far, X[:5]]), include_noise=False)
    assert np.all(after[:5] < 0.5 * before[:5])
    # near the data the variance hardly moves: by < 5 %, or, for outputs the blocked validation left
    # (almost) linear (gcs_sysid.gp.validation), by < 1 % of the noise variance (far rows have
    # leverage on a linear model's slopes, and its variance near the data is ~1e-3 of the noise's)
    noise = np.asarray(model.params.noise) * model.scaler.y_std**2
    np.testing.assert_array_less(np.abs(after[5:] - before[5:]), 0.05 * before[5:] + 0.01 * noise[None, :])
    # it is the variance of the model updated with any values at X_extra
    upd = model.update(X_extra, np.zeros((len(X_extra), 6)), exchange=False).predict(
        np.vstack([far, X[:5]]), include_noise=False, input_noise=False, model_error=False)[1]
    np.testing.assert_allclose(after, upd, rtol=1e-7)


def test_batched_global_variance_after_equals_updated_global_layer(flight, fitted):
    X, _, _ = flight
    model, _ = fitted
    far = X[:5] + 6 * X.std(0)
    queries = np.vstack([far, X[:5], [np.full(10, np.nan)]])
    extras = [np.repeat(far, 3, axis=0), X[200:260], X[:0]]
    out = model.global_variance_after_many(extras, [queries] * 3)
    assert len(out) == 3
    before0 = model.predict_global(queries, include_noise=False)[1]
    for Xe, (before, after) in zip(extras, out):
        np.testing.assert_allclose(before, before0, rtol=1e-8, equal_nan=True)
        ref = before0 if len(Xe) == 0 else \
            model.update(Xe, np.zeros((len(Xe), 6)), exchange=False).predict_global(queries, include_noise=False)[1]
        np.testing.assert_allclose(after, ref, rtol=1e-6, equal_nan=True)
        assert np.all(np.isnan(after[-1])) and np.all(after[:-1] <= before[:-1] * (1 + 1e-9))
    assert np.all(out[0][1][:5] < 0.5 * out[0][0][:5])     # observing far away shrinks the variance there
    noisy = model.global_variance_after_many(extras[:1], [queries], include_noise=True)[0]
    noise = np.asarray(model.params.noise) * model.scaler.y_std**2
    np.testing.assert_allclose(noisy[1][:-1], out[0][1][:-1] + noise, rtol=1e-9)


def test_batched_variance_after_square_root_fallback_gives_the_same_numbers(flight, fitted, monkeypatch):
    """When the Cholesky factor of I + Psi^T Lambda^{-1} Psi fails (huge standardised features), the
    SVD form is used; forced here on ordinary data, it must agree with the product form."""
    import gcs_sysid.gp.ranking as ranking

    X, _, _ = flight
    model, _ = fitted
    queries = np.vstack([X[:5] + 6 * X.std(0), X[:5]])
    extras = [X[200:260], np.repeat(X[:5] + 6 * X.std(0), 3, axis=0)]
    ref = model.global_variance_after_many(extras, [queries] * 2)

    def fail(*args, **kwargs):
        raise np.linalg.LinAlgError("forced")

    monkeypatch.setattr(ranking, "cho_factor", fail)
    got = model.global_variance_after_many(extras, [queries] * 2)
    for (b0, a0), (b1, a1) in zip(ref, got):
        np.testing.assert_allclose(b1, b0, rtol=1e-12)
        np.testing.assert_allclose(a1, a0, rtol=1e-6)
    # far outside the data (standardised values ~1e4) it still returns finite variances in [0, before]
    far = model.global_variance_after_many([X[:64] * 1e4], [X[:5] * 1e4])[0]
    assert np.all(np.isfinite(far[1])) and np.all(far[1] <= far[0] * (1 + 1e-9))


def test_batched_variance_after_compresses_a_candidate_without_moving_the_numbers(flight, fitted, monkeypatch):
    """A candidate's rows enter only through U_e U_e^T: its SVD's leading columns give the same variances
    (rotation only: to round-off; the left-out directions: below machine epsilon), and rows that repeat a
    few points keep only as many directions as there are distinct points."""
    import gcs_sysid.gp.ranking as ranking

    X, _, _ = flight
    model, _ = fitted
    queries = np.vstack([X[:5] + 6 * X.std(0), X[:40]])
    extras = [X[200:264], np.repeat(X[300:304], 16, axis=0), np.repeat(X[:5] + 6 * X.std(0), 3, axis=0)]
    got = model.global_variance_after_many(extras, [queries] * 3)
    kept = []
    real = ranking._compressed

    def whole(Ue, drop):                     # every column kept, unrotated: the product form as it was
        kept.append((real(Ue, drop).shape[1], Ue, drop))
        return Ue

    monkeypatch.setattr(ranking, "_compressed", whole)
    ref = model.global_variance_after_many(extras, [queries] * 3)
    for (b0, a0), (b1, a1) in zip(ref, got):
        np.testing.assert_array_equal(b1, b0)
        np.testing.assert_allclose(a1, a0, rtol=1e-10)
        assert np.all(a1 <= b1 * (1 + 1e-9)) and np.any(a1 < 0.99 * b1)
    assert kept[1][0] == 4                    # 64 rows of 4 distinct points: 4 directions
    _, Ue, drop = kept[1]
    Uc = real(Ue, drop)
    assert Uc.shape == (Ue.shape[0], 4) and 0 < drop < 1e-12
    np.testing.assert_allclose(Uc @ Uc.T, Ue @ Ue.T, atol=1e-10 * np.abs(Ue @ Ue.T).max())
    assert real(Ue, 0.0).shape == (Ue.shape[0], min(Ue.shape))   # nothing left out: the thin SVD only


def test_save_and_load_round_trip(tmp_path, flight, fitted):
    from gcs_sysid.gp import load_gp

    X, _, _ = flight
    model, _ = fitted
    path = model.save(tmp_path / "model" / "gp")
    assert path.endswith(".npz") and (tmp_path / "model" / "gp.json").is_file()
    loaded = load_gp(tmp_path / "model" / "gp.npz")
    for a, b in zip(model.predict(X[400:450]), loaded.predict(X[400:450])):
        np.testing.assert_allclose(a, b, rtol=1e-10)
    assert json.dumps(loaded.summary()) == json.dumps(model.summary())
    with pytest.raises(InputError, match="not found"):
        load_gp(tmp_path / "nothing")
    (tmp_path / "bad.json").write_text("{}")
    (tmp_path / "bad.npz").write_bytes(b"")
    with pytest.raises(InputError, match="not a gcs-sysid GP model"):
        load_gp(tmp_path / "bad")


def test_summary_is_json_and_reports_the_coupling(fitted):
    model, _ = fitted
    s = json.loads(json.dumps(model.summary()))
    assert s["n_inducing"] == FAST.n_inducing and s["n_used"] == 400
    corr = np.array(s["global"]["output_correlation"])
    np.testing.assert_allclose(corr, model.output_correlation())
    np.testing.assert_allclose(np.diag(corr), 1.0)
    assert np.all(np.linalg.eigvalsh(corr) > -1e-9)
    assert set(s["global"]["lengthscales"]) == {"alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a",
                                                 "delta_r", "delta_t", "V"}
    assert s["local"]["neighbours"] == FAST.local_neighbours


def test_constant_input_and_nan_rows_are_handled(flight):
    X, Y, _ = flight
    X = X[:301].copy()     # 300 finite rows: the shapes of the other fits (no new compile)
    Yb = Y[:301].copy()
    X[:, 7] = 0.01       # delta_r never moved
    X[5, 0] = np.nan     # a gap
    model, history = fit_gp(X, Yb, FAST)
    assert any("delta_r is constant" in n for n in history.notes)
    assert any("dropped 1 of 301 rows" in n for n in history.notes)
    assert model.summary()["inactive_inputs"] == ["delta_r"]
    assert model.summary()["global"]["lengthscales"]["delta_r"] is None
    Xq = X[10:13].copy()
    Xq[1, 2] = np.nan
    Xq[2, 7] = 0.2       # a value never seen: ignored, not an error
    mean, var = model.predict(Xq)
    assert np.isnan(mean[1]).all() and np.isfinite(mean[[0, 2]]).all() and np.isfinite(var[[0, 2]]).all()


def test_bad_inputs_give_clear_errors(fitted):
    model, _ = fitted
    with pytest.raises(InputError, match=r"shape \(N, D\)"):
        fit_gp(np.zeros(10), np.zeros((10, 6)))
    with pytest.raises(InputError, match="same number of rows"):
        fit_gp(np.zeros((10, 10)), np.zeros((9, 6)))
    with pytest.raises(DataError, match="finite rows"):
        fit_gp(np.full((10, 10), np.nan), np.zeros((10, 6)))
    with pytest.raises(InputError, match="10 columns"):
        model.predict(np.zeros((3, 9)))
    with pytest.raises(InputError, match="6 columns"):
        model.update(np.zeros((3, 10)), np.zeros((3, 5)))
    with pytest.raises(InputError, match="GPConfig.inducing"):
        GPConfig(inducing="best")
