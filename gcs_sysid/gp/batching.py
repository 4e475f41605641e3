"""Chunked, compiled evaluation of the layers over many rows (one compiled shape per chunk size).

Host (NumPy) arrays go to the compiled functions as they are: ``jnp.asarray`` of a NumPy array
would compile a small conversion program per shape in every fresh process.
"""

from __future__ import annotations

import jax
import numpy as np

from ..jaxconfig import stored_jit
from .local import LocalParams, LocalStore, local_predict_chunk, neighbours
from .sparse import (GlobalParams, GlobalPosterior, Stats, add_stats, mean_global_chunk, posterior,
                     predict_global_chunk, stats_of)

__all__ = ["global_stats", "global_predict", "global_mean", "local_predict", "global_posterior", "LOCAL_CHUNK"]

#: Most query rows per compiled chunk of the local layer. Its per-query Gibbs-kernel solves keep
#: ``O(Q K^2 P)`` working arrays: ~66 MiB resident for a 2,048-row chunk against ~13 MiB for 512
#: rows (``docs/benchmarks.md``, soak memory), and 512-row chunks are no slower.
LOCAL_CHUNK = 512

_stats_jit = stored_jit(stats_of)
_predict_jit = stored_jit(predict_global_chunk)
_mean_jit = stored_jit(mean_global_chunk)
global_posterior = stored_jit(posterior)
_add_jit = stored_jit(add_stats)


def _chunks(n: int, size: int):
    for start in range(0, n, size):
        yield start, min(start + size, n)


def _pad(a: np.ndarray, size: int) -> np.ndarray:
    if len(a) == size:
        return a
    pad = np.zeros((size - len(a),) + a.shape[1:], a.dtype)
    return np.concatenate([a, pad], 0)


def _bucket(n: int) -> int:
    """Chunk length for ``n`` rows: the next power of two (at least 16), so that updates of varying
    sizes reuse a few compiled programs instead of compiling one per size."""
    return max(16, 1 << (max(int(n), 1) - 1).bit_length())


def global_stats(params: GlobalParams, Xs: np.ndarray, Ys: np.ndarray, batch: int,
                 weight: np.ndarray | None = None) -> Stats:
    """Sufficient statistics of all rows, accumulated over zero-padded chunks of ``batch`` rows
    (fewer rows: one chunk padded to the next power of two). ``weight (N,)``: each row counted
    that many times (default 1). A NaN in ``Ys`` marks a missing output of that row: the statistics
    are then in the per-output form (:class:`gcs_sysid.gp.sparse.Stats`; heterotopic data)."""
    size = int(min(batch, _bucket(len(Xs))))
    missing = not np.all(np.isfinite(Ys))
    total = None
    for a, b in _chunks(len(Xs), size):
        w = _pad(np.ones(b - a) if weight is None else np.asarray(weight[a:b], float), size)
        if missing:
            ok = np.isfinite(Ys[a:b])
            st = _stats_jit(params, _pad(Xs[a:b], size), _pad(np.where(ok, Ys[a:b], 0.0), size), w,
                            _pad(ok.astype(float), size))
        else:
            st = _stats_jit(params, _pad(Xs[a:b], size), _pad(Ys[a:b], size), w)
        total = st if total is None else _add_jit(total, st)
    if total is None:
        st = _stats_jit(params, np.zeros((1, Xs.shape[1])), np.zeros((1, Ys.shape[1])), np.zeros(1))
        total = st
    return total


def global_predict(params: GlobalParams, post: GlobalPosterior, Xs: np.ndarray, batch: int,
                   scale: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Latent mean and variance ``(N, P)`` of the global layer at standardised ``Xs``; ``scale (P,)``
    multiplies the explained part of the variance (:func:`gcs_sysid.gp.sparse.predict_global_chunk`)."""
    P = params.A.shape[0]
    mean, var = np.empty((len(Xs), P)), np.empty((len(Xs), P))
    size = int(min(batch, _bucket(len(Xs))))
    for a, b in _chunks(len(Xs), size):
        m, v = _predict_jit(params, post, _pad(Xs[a:b], size), scale)
        mean[a:b], var[a:b] = np.asarray(m)[: b - a], np.asarray(v)[: b - a]
    return mean, var


def global_mean(params: GlobalParams, post: GlobalPosterior, Xs: np.ndarray, batch: int) -> np.ndarray:
    """Latent mean ``(N, P)`` of the global layer at standardised ``Xs`` (no variance: cheaper)."""
    mean = np.empty((len(Xs), params.A.shape[0]))
    size = int(min(batch, _bucket(len(Xs))))
    for a, b in _chunks(len(Xs), size):
        mean[a:b] = np.asarray(_mean_jit(params, post, _pad(Xs[a:b], size)))[: b - a]
    return mean


def local_predict(params: LocalParams, store: LocalStore, Xs: np.ndarray, batch: int
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Latent mean and variance ``(N, P)`` of the local layer at standardised ``Xs``, in chunks of at
    most ``min(batch, LOCAL_CHUNK)`` rows (bounded working memory)."""
    P = store.resid.shape[1]
    mean, var = np.empty((len(Xs), P)), np.empty((len(Xs), P))
    size = int(min(batch, LOCAL_CHUNK, _bucket(len(Xs))))
    pending = None
    for a, b in _chunks(len(Xs), size):
        # the neighbour search of this chunk runs while XLA solves the previous one (dispatched
        # asynchronously; its results are read after): the same calls, overlapped
        idx, zq = neighbours(store, Xs[a:b])
        args = (_pad(Xs[a:b], size), _pad(zq, size), _pad(store.X[idx], size), _pad(store.z[idx], size),
                _pad(store.resid[idx], size))
        out = (a, b, local_predict_chunk(params, *args))
        if pending is not None:
            _store_rows(mean, var, *pending)
        pending = out
    if pending is not None:
        _store_rows(mean, var, *pending)
    return mean, var


def _store_rows(mean: np.ndarray, var: np.ndarray, a: int, b: int, mv) -> None:
    mean[a:b], var[a:b] = np.asarray(mv[0])[: b - a], np.asarray(mv[1])[: b - a]
