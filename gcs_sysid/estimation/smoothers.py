"""Linear smoothers: slowly varying levels, velocity and accel bias (rates: :mod:`.rates`).

See :mod:`gcs_sysid.estimation.ekf` for the order of work and ``docs/estimation.md``
for the choices. References as there, plus Harvey, *Forecasting, Structural Time
Series Models and the Kalman Filter*, CUP 1989 (local level model, concentrated likelihood),
and Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed., Artech House 2013, sec. 2.4.7 (WGS-84 normal gravity) and sec. 5.4 (the local-navigation-frame
velocity equation: Coriolis and transport rate).

The Earth model matters for the *force* coefficients: the velocity filter's accelerometer bias takes
whatever the kinematic model leaves out. With a flat, non-rotating Earth and standard gravity the
Coriolis acceleration ``-2 omega_ie x v`` (about 0.006 m/s^2 across the track at 40 m/s and 47 deg
latitude) and the gravity difference (9.8038 vs 9.80665 m/s^2 at 1.8 km there) end up in the bias,
and so, with the opposite sign, in the bias-corrected specific force: on JSBSim's c172x that was a
0.006 m/s^2 offset in ``ay``, 2.9 % of the lateral force's RMS (docs/estimation.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .ekf import G0
from .kalman import kalman_filter, rts_smoother, steady_state, steady_state_smoother
from .nodes import fill_between_nodes, integrate, interp_nodes, node_indices, segments, to_nodes

__all__ = ["smooth_level", "VelocityEstimate", "smooth_velocity", "normal_gravity", "earth_acceleration",
           "OMEGA_IE"]

#: Earth rotation rate (WGS-84), rad/s.
OMEGA_IE = 7.292115e-5
_A, _B = 6378137.0, 6356752.31425          # WGS-84 semi-major / semi-minor axes, m
_F, _E2 = 1.0 / 298.257223563, 6.69437999014e-3   # flattening, first eccentricity squared
_MU = 3.986004418e14                       # Earth gravitational constant, m^3/s^2


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


# ---------------------------------------------------------------------------- Earth model


def normal_gravity(lat: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Magnitude of the WGS-84 normal gravity (gravitation plus centrifugal) along the local down axis.

    Somigliana's formula on the ellipsoid, then the second-order height correction.

    Args:
        lat: geodetic latitude, rad, any shape.
        h: height above the ellipsoid, m, same shape (AMSL is close enough: the geoid height changes g
            by less than 3e-5 m/s^2).

    Returns:
        gravity, m/s^2, the shape of ``lat`` (9.7803 at the equator, 9.8322 at the poles, at h = 0).

    Source: Groves (2013) eqs. 2.134 (Somigliana) and 2.139 (height dependence).
    """
    s2 = np.sin(lat) ** 2
    g0 = 9.7803253359 * (1.0 + 0.001931853 * s2) / np.sqrt(1.0 - _E2 * s2)
    m = OMEGA_IE**2 * _A**2 * _B / _MU
    return g0 * (1.0 - 2.0 / _A * (1.0 + _F + m - 2.0 * _F * s2) * h + 3.0 * h**2 / _A**2)


def earth_acceleration(lat: np.ndarray, h: np.ndarray, v_ned: np.ndarray) -> np.ndarray:
    """What the Earth adds to ``C f`` in the NED velocity equation: gravity, Coriolis and transport rate.

    ``v_dot = C f + g(lat, h) - (2 omega_ie + omega_en) x v`` with ``omega_ie`` the Earth rate and
    ``omega_en`` the transport rate (the NED frame turning as the aircraft moves over the curved Earth),
    both in NED.

    Args:
        lat: (T,) geodetic latitude, rad.
        h: (T,) height, m.
        v_ned: (T, 3) ground velocity vn ve vd, m/s.

    Returns:
        (T, 3) acceleration, NED, m/s^2 (the down component is about +9.8).

    Source: Groves (2013) eq. 5.54 (local-navigation-frame velocity update), eqs. 2.105-2.106 (radii of
    curvature), 5.44 (transport rate).
    """
    lat, h = np.asarray(lat, float), np.asarray(h, float)
    sl, cl = np.sin(lat), np.cos(lat)
    d = np.sqrt(1.0 - _E2 * sl**2)
    RN, RE = _A * (1.0 - _E2) / d**3, _A / d          # meridian and transverse radii of curvature
    vn, ve, vd = v_ned[:, 0], v_ned[:, 1], v_ned[:, 2]
    w_ie = np.stack([OMEGA_IE * cl, np.zeros_like(cl), -OMEGA_IE * sl], axis=1)
    w_en = np.stack([ve / (RE + h), -vn / (RN + h), -ve * np.tan(lat) / (RE + h)], axis=1)
    out = -np.cross(2.0 * w_ie + w_en, v_ned)
    out[:, 2] += normal_gravity(lat, h)
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
                    node_hz: float = 10.0, lat: np.ndarray | None = None,
                    alt: np.ndarray | None = None) -> VelocityEstimate:
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
        lat: optional (T,) geodetic latitude, rad (NaN where missing: interpolated; all NaN: flat Earth).
        alt: optional (T,) height, m, with ``lat`` (NaN interpolated; missing: 0).

    Returns:
        :class:`VelocityEstimate`.

    Raises:
        ValueError: ``lat`` or ``alt`` not of length T.

    Source: Klein and Morelli (2006) ch. 10 (flight-path reconstruction);
    Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
    Systems*, 2nd ed. 2013, ch. 14 (loosely coupled velocity aiding).
    """
    T = len(f_body)
    good = np.isfinite(f_body).all(axis=1) & np.isfinite(C).all(axis=(1, 2))
    Cz = np.where(good[:, None, None], C, 0.0)
    a = np.einsum("tij,tj->ti", Cz, np.nan_to_num(f_body))
    a += _earth_term(T, lat, alt, v_meas)
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


def _fill(x: np.ndarray) -> np.ndarray | None:
    """(T,) with NaN linearly interpolated (ends held); None if nothing is finite."""
    ok = np.isfinite(x)
    if not ok.any():
        return None
    i = np.arange(len(x))
    return np.interp(i, i[ok], x[ok])


def _earth_term(T: int, lat, alt, v_meas: np.ndarray) -> np.ndarray:
    """(T, 3) gravity (+ Coriolis and transport rate where the latitude is known), NED, m/s^2."""
    flat = np.zeros((T, 3))
    flat[:, 2] = G0
    if lat is None:
        return flat
    for name, x in (("lat", lat), ("alt", alt)):
        if x is not None and len(x) != T:
            raise ValueError(f"smooth_velocity: {name} has {len(x)} samples, expected {T} (one per grid step)")
    la = _fill(np.asarray(lat, float))
    if la is None:
        return flat
    h = _fill(np.asarray(alt, float)) if alt is not None else None
    h = np.zeros(T) if h is None else h
    v = np.stack([_fill(v_meas[:, i]) if np.isfinite(v_meas[:, i]).any() else np.zeros(T) for i in range(3)], 1)
    return earth_acceleration(la, h, v)
