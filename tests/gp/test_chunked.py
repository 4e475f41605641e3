"""Bounded-memory evaluation: chunked predictions equal one call on all rows (to 1e-9).

The confidence map predicts in fixed-size chunks (``envelope.variance_in_chunks``) and the local
layer in chunks of at most ``batching.LOCAL_CHUNK`` rows, so that the live learner's working arrays
stay bounded (issue 10, soak memory). Rows are predicted independently, so neither may change a value
beyond rounding.
"""

import numpy as np
import pytest

from gcs_sysid.aero.table import CoefficientTable
from gcs_sysid.envelope import EnvelopeConfig, confidence_map, model_variance, variance_in_chunks
from gcs_sysid.errors import InputError
from gcs_sysid.gp import batching


def _close(a, b, tol=1e-9):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape
    scale = np.maximum(np.abs(b), 1e-300)
    assert np.all(np.abs(a - b) <= tol * scale), float(np.max(np.abs(a - b) / scale))


def test_variance_in_chunks_equals_one_call(fitted, flight):
    model, _ = fitted
    X = flight[0][100:403]                        # 303 rows: 4 full chunks of 64, 47 rows padded to 48
    whole = model_variance(model.predict, X)
    calls = []

    def spy(Xq, include_noise=True, input_noise=True):
        calls.append(len(Xq))
        return model.predict(Xq, include_noise=include_noise, input_noise=input_noise)

    chunked = variance_in_chunks(spy, X, chunk=64)
    _close(chunked, whole)
    assert calls == [64] * 4 + [48]               # padded to a multiple of chunk / 4: few shapes
    assert variance_in_chunks(model.predict, X[:0], chunk=64).shape[0] == 0
    with pytest.raises(InputError):
        variance_in_chunks(model.predict, X, chunk=0)


def test_local_layer_chunk_cap_changes_nothing(fitted, flight, monkeypatch):
    model, _ = fitted
    Xs, _ = model._standardise_query(flight[0])   # 600 rows
    capped = batching.local_predict(model.local_params, model.store, Xs, 1024)
    monkeypatch.setattr(batching, "LOCAL_CHUNK", 1 << 20)
    whole = batching.local_predict(model.local_params, model.store, Xs, 1024)
    for a, b in zip(capped, whole):
        _close(a, b)


def test_confidence_map_chunked_equals_unchunked(fitted, flight):
    model, _ = fitted
    X, Y, _ = flight
    n = 400
    table = CoefficientTable(np.arange(n) * 0.05, X[:n], Y[:n], np.ones(n, bool), np.full(n, np.nan))
    small = EnvelopeConfig(n_grid=12, chunk=100)              # 7 * 144 + 400 rows: 15 chunks
    whole = EnvelopeConfig(n_grid=12, chunk=10**6)            # one call on all rows
    a = confidence_map(model, table, table.valid, small)
    b = confidence_map(model, table, table.valid, whole)
    for sa, sb in zip(a.slices, b.slices):
        for c in a.outputs:
            _close(sa.sigma[c], sb.sigma[c])
            assert np.array_equal(sa.labels[c], sb.labels[c])
    assert [(r.coefficient, r.axes, r.n_cells) for r in a.regions] == \
        [(r.coefficient, r.axes, r.n_cells) for r in b.regions]
    for c in a.outputs:
        assert abs(a.scores[c] - b.scores[c]) < 1e-9


def test_cross_covariances_blockwise_equal_one_solve(fitted):
    from scipy.linalg import solve_triangular

    from gcs_sysid.gp import ranking

    model, _ = fitted
    Hc = ranking.cross_covariances(model)                   # solved one output's block at a time
    V = solve_triangular(np.asarray(model.post.L), ranking._selectors(model), lower=True)
    np.testing.assert_allclose(Hc, V.T @ V, rtol=0, atol=1e-9 * float(np.max(np.abs(Hc))))
    P = model.n_outputs
    J = Hc.shape[0] // P
    H = np.asarray(model.post.H)
    for p in range(P):
        np.testing.assert_allclose(Hc[p * J:(p + 1) * J, p * J:(p + 1) * J], H[p], rtol=1e-8,
                                   atol=1e-10 * float(np.max(np.abs(H[p]))))
