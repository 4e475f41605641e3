"""Node bookkeeping shared by the smoothers: running integrals, drift-corrected integration, runs.

The attitude and velocity filters run on *nodes* (every n-th grid point, at most
10 Hz); between nodes the fast part of a state comes from integrating its rate
(gyro, accelerometer) and the smoothed node values remove the integral's drift
(:func:`fill_between_nodes`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["integrate", "node_indices", "to_nodes", "fill_between_nodes", "interp_nodes", "segments"]


def integrate(rate: np.ndarray, dt: float) -> np.ndarray:
    """Trapezoid running integral (T, d) of ``rate`` (T, d); NaN samples count as 0."""
    r = np.nan_to_num(rate)
    out = np.zeros_like(r)
    out[1:] = np.cumsum(0.5 * dt * (r[1:] + r[:-1]), axis=0)
    return out


def node_indices(T: int, dt: float, node_hz: float) -> np.ndarray:
    """Grid indices (J,) of the nodes: every n-th point, n = round(1 / (dt node_hz)) >= 1."""
    n = max(1, int(round(1.0 / (dt * node_hz))))
    return np.arange(0, T, n)


def to_nodes(ev: np.ndarray, integ: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Move event samples (T, d) to their next node using the integral ``integ`` (T, d); mean per node."""
    J, d = len(nodes), ev.shape[1]
    m = np.nonzero(np.isfinite(ev).all(axis=1))[0]
    out = np.full((J, d), np.nan)
    if len(m) == 0:
        return out
    j = np.minimum(np.searchsorted(nodes, m, side="left"), J - 1)
    shifted = ev[m] + integ[nodes[j]] - integ[m]
    cnt = np.bincount(j, minlength=J)
    has = cnt > 0
    for i in range(d):
        out[has, i] = np.bincount(j, shifted[:, i], minlength=J)[has] / cnt[has]
    return out


def fill_between_nodes(nodes: np.ndarray, node_vals: np.ndarray, integ: np.ndarray) -> np.ndarray:
    """Drift-corrected integration: ``integ`` (T, d) shifted to pass through the node values (J, d)."""
    k = np.arange(len(integ))
    D = node_vals - integ[nodes]
    return integ + np.stack([np.interp(k, nodes, D[:, i]) for i in range(D.shape[1])], axis=1)


def interp_nodes(nodes: np.ndarray, vals: np.ndarray, T: int) -> np.ndarray:
    """Node values (J, d) linearly interpolated to all T grid points."""
    k = np.arange(T)
    return np.stack([np.interp(k, nodes, vals[:, i]) for i in range(vals.shape[1])], axis=1)


def segments(ok: np.ndarray, min_len: int) -> list[slice]:
    """Runs of True in ``ok`` at least ``min_len`` long."""
    d = np.diff(np.concatenate([[0], ok.astype(np.int8), [0]]))
    starts, stops = np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]
    return [slice(a, b) for a, b in zip(starts, stops) if b - a >= min_len]
