"""Linear smoothers: body rates and angular accelerations, slowly varying levels, velocity and accel bias.

See :mod:`gcs_sysid.estimation.ekf` for the order of work and ``docs/estimation.md``
for the choices. References as there, plus Harvey, *Forecasting, Structural Time
Series Models and the Kalman Filter*, CUP 1989 (local level model, concentrated likelihood).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.common import Q_continuous_white_noise

from .ekf import G0
from .kalman import kalman_filter, rts_smoother, steady_state, steady_state_smoother
from .nodes import fill_between_nodes, integrate, interp_nodes, node_indices, segments, to_nodes

__all__ = ["BANDWIDTHS_HZ", "RateEstimate", "smooth_rates", "smooth_level", "VelocityEstimate", "smooth_velocity"]

#: Candidate bandwidths (Hz) of the rate smoother; those above 0.35 x grid rate are dropped.
BANDWIDTHS_HZ = (0.5, 1.0, 1.5, 2.5, 4.0, 6.0, 9.0, 13.0)


# ---------------------------------------------------------------------------- rates


@dataclass
class RateEstimate:
    """Smoothed body rates and angular accelerations.

    Attributes:
        rate, rate_sigma: (T, 3) p q r and 1-sigma, rad/s (NaN where no gyro).
        accel, accel_sigma: (T, 3) p_dot q_dot r_dot and 1-sigma, rad/s^2.
        bandwidth_hz: (3,) smoother bandwidth chosen per axis (maximum likelihood).
        noise_std: (3,) gyro white-noise standard deviation (maximum likelihood), rad/s.
    """

    rate: np.ndarray
    rate_sigma: np.ndarray
    accel: np.ndarray
    accel_sigma: np.ndarray
    bandwidth_hz: np.ndarray
    noise_std: np.ndarray


def smooth_rates(dt: float, rates: np.ndarray, noise_floor: float = 2e-4,
                 bandwidths_hz: tuple[float, ...] = BANDWIDTHS_HZ) -> RateEstimate:
    """Body rates and their derivatives from bias-corrected gyro samples.

    Per axis the state is ``[w, w_dot, w_ddot]`` with white snap of spectral
    density ``q``; the measurement is ``w`` with white noise ``sigma^2``. The
    smoother's bandwidth is about ``omega_c = (q / (sigma^2 dt))^(1/6)`` and its
    means depend only on that ratio, so each candidate bandwidth fixes the ratio
    and the scale ``sigma^2`` is profiled out of the innovation likelihood
    (``sigma^2 = mean(y^2 / S)``); the best candidate per axis is smoothed.
    Records are split at gaps (NaN) and each piece smoothed on its own.

    Args:
        dt: grid step, s.
        rates: (T, 3) gyro minus bias, rad/s, NaN where missing.
        noise_floor: smallest gyro noise assumed, rad/s (quantisation).
        bandwidths_hz: candidate bandwidths, Hz.

    Returns:
        :class:`RateEstimate`.

    Source: Bar-Shalom et al. (2001) ch. 6 (white-noise kinematic models);
    Klein and Morelli (2006) ch. 10 (smoothed derivatives, no phase lag);
    Harvey, *Forecasting, Structural Time Series Models and the Kalman Filter*,
    CUP 1989, ch. 3 (concentrating the scale out of the likelihood).
    """
    T = len(rates)
    F = np.array([[1.0, dt, 0.5 * dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
    H = np.array([[1.0, 0.0, 0.0]])
    bws = np.array([f for f in bandwidths_hz if f < 0.35 / dt] or [min(bandwidths_hz)])
    nb = len(bws)
    q0 = Q_continuous_white_noise(dim=3, dt=dt, spectral_density=1.0)
    # unit measurement noise; q = dt * omega_c^6 sets the ratio
    gains = [steady_state(F, dt * (2 * np.pi * f) ** 6 * q0, H, np.eye(1)) for f in bws]
    out = {k: np.full((T, 3), np.nan) for k in ("w", "ws", "wd", "wds")}
    bw_best = np.full(3, np.nan)
    sig_best = np.full(3, np.nan)
    S = np.array([g.S[0, 0] for g in gains])
    for i in range(3):
        segs = segments(np.isfinite(rates[:, i]), 10)
        if not segs:
            continue
        ssq = np.zeros(nb)
        n = 0
        for sg in segs:   # forward passes of all candidates: innovations only
            z = rates[sg, i][:, None]
            x0 = np.array([z[0, 0], 0.0, 0.0])
            for c, g in enumerate(gains):
                _, innov = steady_state_smoother(F, g, H, z, x0, smooth=False)
                ssq[c] += float((innov[:, 0] ** 2).sum()) / S[c]
            n += len(z)
        s2 = np.maximum(ssq / n, noise_floor**2)     # profiled measurement-noise variance
        ll = -0.5 * n * (np.log(s2) + np.log(S))
        b = int(np.argmax(ll))
        bw_best[i] = bws[b]
        sig_best[i] = math.sqrt(s2[b])
        g = gains[b]
        for sg in segs:
            z = rates[sg, i][:, None]
            xs, _ = steady_state_smoother(F, g, H, z, np.array([z[0, 0], 0.0, 0.0]))
            out["w"][sg, i] = xs[:, 0]
            out["wd"][sg, i] = xs[:, 1]
            out["ws"][sg, i] = math.sqrt(s2[b] * g.Ps[0, 0])
            out["wds"][sg, i] = math.sqrt(s2[b] * g.Ps[1, 1])
    return RateEstimate(out["w"], out["ws"], out["wd"], out["wds"], bw_best, sig_best)


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
