"""Linear smoothers: slowly varying levels, velocity and accel bias (rates: :mod:`.rates`).

See :mod:`gcs_sysid.estimation.ekf` for the order of work and ``docs/estimation.md``
for the choices. References as there, plus Harvey, *Forecasting, Structural Time
Series Models and the Kalman Filter*, CUP 1989 (local level model, concentrated likelihood).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .ekf import G0
from .kalman import kalman_filter, rts_smoother, steady_state, steady_state_smoother
from .nodes import fill_between_nodes, integrate, interp_nodes, node_indices, segments, to_nodes

__all__ = ["smooth_level", "VelocityEstimate", "smooth_velocity"]


def smooth_level(dt: float, z: np.ndarray, bandwidths_hz: tuple[float, ...] = (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 4.0),
                 min_len: int = 10) -> np.ndarray:
    """Zero-phase smoothing of a slowly varying signal in white noise (local-level model + RTS).

    State: a random walk ``x`` measured with white noise; each candidate
    bandwidth ``f`` fixes the ratio ``q / r = (2 pi f dt)^2``, the scale is
    profiled out and the candidate with the highest likelihood smooths the
    record (steady-state gains; records split at NaN).

    Args:
        dt: grid step, s.
        z: (T,) samples, NaN where missing.
        bandwidths_hz: candidate bandwidths, Hz.
        min_len: shortest piece smoothed; shorter pieces stay NaN.

    Returns:
        (T,) smoothed values, NaN where ``z`` had no usable piece.

    Source: Harvey (1989) ch. 2 (local level model); Simon (2006) ch. 9.
    """
    F, H = np.eye(1), np.eye(1)
    cands = [f for f in bandwidths_hz if f < 0.35 / dt] or [min(bandwidths_hz)]
    gains = [steady_state(F, np.eye(1) * (2 * np.pi * f * dt) ** 2, H, np.eye(1)) for f in cands]
    segs = segments(np.isfinite(z), min_len)
    out = np.full(len(z), np.nan)
    if not segs:
        return out
    ssq, n = np.zeros(len(gains)), 0
    for sg in segs:
        for c, g in enumerate(gains):
            _, innov = steady_state_smoother(F, g, H, z[sg, None], np.array([z[sg][0]]), smooth=False)
            ssq[c] += float((innov**2).sum()) / g.S[0, 0]
        n += sg.stop - sg.start
    ll = -0.5 * n * (np.log(np.maximum(ssq / n, 1e-300)) + np.log([g.S[0, 0] for g in gains]))
    g = gains[int(np.argmax(ll))]
    for sg in segs:
        xs, _ = steady_state_smoother(F, g, H, z[sg, None], np.array([z[sg][0]]))
        out[sg] = xs[:, 0]
    return out


# ---------------------------------------------------------------------------- velocity


@dataclass
class VelocityEstimate:
    """Smoothed NED ground velocity and accelerometer bias.

    Attributes:
        v_ned, v_sigma: (T, 3) vn ve vd and 1-sigma, m/s.
        accel_bias, accel_bias_sigma: (T, 3) body-axis accelerometer bias, m/s^2
            (measured specific force = true + bias).
    """

    v_ned: np.ndarray
    v_sigma: np.ndarray
    accel_bias: np.ndarray
    accel_bias_sigma: np.ndarray


def smooth_velocity(dt: float, C: np.ndarray, f_body: np.ndarray, v_meas: np.ndarray, sigma_accel: float,
                    sigma_vel: float = 0.15, sigma_bias_walk: float = 2e-3, sigma_bias0: float = 0.3,
                    node_hz: float = 10.0) -> VelocityEstimate:
    """Ground velocity and accelerometer bias by a linear time-varying Kalman filter + RTS.

    State ``[vn, ve, vd, b_x, b_y, b_z]`` on nodes (at most ``node_hz``); between
    nodes ``v_j = v_{j-1} + sum_k dt (C_k (f_k - b) + g)`` (trapezoid), ``g = [0, 0, g0]``;
    GPS velocity samples are moved to their next node with the integrated
    acceleration and averaged there. The full-rate velocity is the integral of
    the bias-corrected acceleration passed through the smoothed node velocities.

    Args:
        dt: grid step, s.
        C: (T, 3, 3) body-to-NED direction cosines from the smoothed attitude.
        f_body: (T, 3) specific force at the CG, body axes, m/s^2 (NaN where missing).
        v_meas: (T, 3) measured NED velocity at grid points with a sample, NaN elsewhere.
        sigma_accel: accelerometer white noise per grid sample, m/s^2.
        sigma_vel: velocity measurement noise, m/s.
        sigma_bias_walk: accel bias random walk, m/s^2/sqrt(s).
        sigma_bias0: prior 1-sigma of the accel bias, m/s^2.
        node_hz: highest node rate, Hz.

    Returns:
        :class:`VelocityEstimate`.

    Source: Klein and Morelli (2006) ch. 10 (flight-path reconstruction);
    Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
    Systems*, 2nd ed. 2013, ch. 14 (loosely coupled velocity aiding).
    """
    T = len(f_body)
    good = np.isfinite(f_body).all(axis=1) & np.isfinite(C).all(axis=(1, 2))
    Cz = np.where(good[:, None, None], C, 0.0)
    a = np.einsum("tij,tj->ti", Cz, np.nan_to_num(f_body))
    a[:, 2] += G0
    a[~good] = 0.0
    nodes = node_indices(T, dt, node_hz)
    J = len(nodes)
    Ia = integrate(a, dt)
    Ic = np.zeros((T, 3, 3))
    Ic[1:] = np.cumsum(0.5 * dt * (Cz[1:] + Cz[:-1]), axis=0)
    F = np.tile(np.eye(6), (J, 1, 1))
    F[1:, :3, 3:] = -(Ic[nodes[1:]] - Ic[nodes[:-1]])        # d v / d b = -sum dt C
    u = np.zeros((J, 1, 6))
    u[1:, 0, :3] = Ia[nodes[1:]] - Ia[nodes[:-1]]
    nstep = np.diff(nodes, prepend=0)
    nbad = np.diff(np.concatenate([[0], np.cumsum(~good)])[nodes], prepend=0)
    s_a = max(sigma_accel, 0.05)
    qv = (s_a * dt) ** 2 * (nstep - nbad) + (5.0 * dt) ** 2 * nbad   # no accel: a loose random walk
    Q = np.zeros((J, 1, 6, 6))
    Q[:, 0, [0, 1, 2], [0, 1, 2]] = qv[:, None]
    Q[:, 0, [3, 4, 5], [3, 4, 5]] = (sigma_bias_walk**2 * dt * nstep)[:, None]
    z = to_nodes(v_meas, Ia, nodes)
    x0 = np.zeros((1, 6))
    okz = np.isfinite(z).all(axis=1)
    if okz.any():
        x0[0, :3] = z[np.argmax(okz)]
    P0 = np.diag([5.0**2] * 3 + [sigma_bias0**2] * 3)
    H = np.hstack([np.eye(3), np.zeros((3, 3))])
    res = kalman_filter(x0, P0, F, Q, H, np.eye(3) * sigma_vel**2, z[:, None, :], u=u)
    xs, Ps = rts_smoother(res, F)
    xs, Ps = xs[:, 0], Ps[:, 0]
    sd = np.sqrt(np.maximum(np.diagonal(Ps, axis1=1, axis2=2), 0.0))
    bias = interp_nodes(nodes, xs[:, 3:], T)
    a_corr = a - np.einsum("tij,tj->ti", Cz, bias)
    v = fill_between_nodes(nodes, xs[:, :3], integrate(a_corr, dt))
    return VelocityEstimate(v, interp_nodes(nodes, sd[:, :3], T), bias, interp_nodes(nodes, sd[:, 3:], T))
