"""Attitude and gyro bias by an EKF (filterpy) + extended RTS; frames and Euler kinematics.

The first of three smoothers run in sequence on the common grid (the other two
are in :mod:`gcs_sysid.estimation.smoothers`), each followed by a
Rauch-Tung-Striebel pass (offline, zero phase lag):

1. :func:`smooth_attitude` (here): an extended Kalman filter (``filterpy.kalman.
   ExtendedKalmanFilter``) on ``[phi, theta, psi, b_p, b_q, b_r]``, driven by the
   gyro through the Euler-angle kinematics and updated by the autopilot's
   attitude, then an extended RTS pass over its stored predicted means and
   Jacobians. It runs on *nodes* at most ``node_hz`` (10 Hz), integrating the
   gyro over the grid steps in between; the full-rate attitude is the
   bias-corrected gyro integral between nodes with the smoothed node values as
   end conditions (drift-corrected integration). The bias and the node attitude
   are slow; the fast part comes from the gyro, as it would in the full-rate filter.
2. :func:`~gcs_sysid.estimation.rates.smooth_rates`: per axis, a linear rate / acceleration / jerk model
   (white snap) measured by the bias-corrected gyro, at the full grid rate with
   steady-state gains (:func:`~gcs_sysid.estimation.kalman.steady_state_smoother`,
   exact for this time-invariant model). The smoother bandwidth is chosen per
   axis by maximum (profile) likelihood over a ladder of bandwidths.
3. :func:`~gcs_sysid.estimation.smoothers.smooth_velocity`: a linear time-varying filter on ``[vn, ve, vd, b_ax,
   b_ay, b_az]`` on the same nodes, driven by the accelerometer (rotated to NED,
   plus gravity) and updated by GPS velocity; full rate by drift-corrected
   integration of the bias-corrected acceleration.

References:
    Stevens, Lewis and Johnson, *Aircraft Control and Simulation*, 3rd ed., 2016,
    ch. 1 (direction cosines, Euler-angle kinematics).
    Klein and Morelli, *Aircraft System Identification*, AIAA 2006, ch. 10
    (data compatibility: kinematic filtering and smoothing of flight data).
    Sarkka, *Bayesian Filtering and Smoothing*, CUP 2013, ch. 9 (extended RTS smoother).
    Bar-Shalom, Li and Kirubarajan, *Estimation with Applications to Tracking and
    Navigation*, Wiley 2001, ch. 6 (white-noise kinematic models).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter

from .kalman import FilterResult, rts_smoother
from .nodes import fill_between_nodes, integrate, interp_nodes, node_indices, to_nodes

__all__ = ["G0", "dcm", "euler_rates", "AttitudeEstimate", "smooth_attitude"]

G0 = 9.80665  #: standard gravity, m/s^2
_COS_MIN = 0.05  # |cos(theta)| floor in the Euler kinematics (|theta| < 87 deg)


def _wrap(a):
    return np.mod(a + np.pi, 2 * np.pi) - np.pi


def dcm(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Body-to-NED direction cosine matrices for 3-2-1 Euler angles.

    Args:
        phi, theta, psi: roll, pitch, yaw in rad, shape (T,).

    Returns:
        Array (T, 3, 3) with ``v_ned = C @ v_body`` (Stevens et al. ch. 1).
    """
    cf, sf = np.cos(phi), np.sin(phi)
    ct, st = np.cos(theta), np.sin(theta)
    cp, sp = np.cos(psi), np.sin(psi)
    C = np.empty(np.shape(phi) + (3, 3))
    C[..., 0, 0] = ct * cp
    C[..., 0, 1] = sf * st * cp - cf * sp
    C[..., 0, 2] = cf * st * cp + sf * sp
    C[..., 1, 0] = ct * sp
    C[..., 1, 1] = sf * st * sp + cf * cp
    C[..., 1, 2] = cf * st * sp - sf * cp
    C[..., 2, 0] = -st
    C[..., 2, 1] = sf * ct
    C[..., 2, 2] = cf * ct
    return C


def euler_rates(phi: np.ndarray, theta: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Euler-angle rates (T, 3) for body rates ``w`` (T, 3), rad/s (Stevens et al. ch. 1).

    ``|cos(theta)|`` is floored at 0.05 (|theta| < 87 deg) to stay finite near the singularity.
    """
    sf, cf = np.sin(phi), np.cos(phi)
    ct = np.cos(theta)
    ct = np.where(ct < 0, -1.0, 1.0) * np.maximum(np.abs(ct), _COS_MIN)
    a = sf * w[:, 1] + cf * w[:, 2]
    return np.stack([w[:, 0] + np.sin(theta) / ct * a, cf * w[:, 1] - sf * w[:, 2], a / ct], axis=1)


# ---------------------------------------------------------------------------- attitude EKF


@dataclass
class AttitudeEstimate:
    """Smoothed attitude and gyro bias on the grid.

    Attributes:
        euler: (T, 3) phi, theta, psi in rad (psi wrapped to (-pi, pi]).
        euler_sigma: (T, 3) 1-sigma, rad.
        gyro_bias: (T, 3) b_p, b_q, b_r in rad/s (measured gyro = true rate + bias).
        gyro_bias_sigma: (T, 3) rad/s.
    """

    euler: np.ndarray
    euler_sigma: np.ndarray
    gyro_bias: np.ndarray
    gyro_bias_sigma: np.ndarray


class _EulerEKF(ExtendedKalmanFilter):
    """filterpy EKF whose prediction integrates the Euler kinematics over a block of gyro samples."""

    def __init__(self, dt: float):
        super().__init__(dim_x=6, dim_z=3)
        self.dt = dt

    def predict_x(self, u=0):
        """``u``: (n, 3) mean gyro rate of each grid step in the block (rad/s)."""
        x = self.x[:, 0].copy()
        bp, bq, br = float(x[3]), float(x[4]), float(x[5])
        ph, th, ps = float(x[0]), float(x[1]), float(x[2])
        dt = self.dt
        # Python floats, not NumPy scalars: the same IEEE arithmetic, several times cheaper per operation
        for wp, wq, wr in np.asarray(u, dtype=float).tolist():   # Euler steps: x += dt * E(phi, theta) (g - b)
            p, q, r = wp - bp, wq - bq, wr - br
            sf, cf, ct = math.sin(ph), math.cos(ph), math.cos(th)
            ct = math.copysign(max(abs(ct), _COS_MIN), ct)
            a = sf * q + cf * r
            ph, th, ps = ph + dt * (p + math.sin(th) / ct * a), th + dt * (cf * q - sf * r), ps + dt * a / ct
        x[0], x[1], x[2] = ph, th, math.remainder(ps, 2 * math.pi)
        self.x = x[:, None]


def _euler_jacobian(phi, theta, w, DT):
    """Jacobian (6, 6) of a prediction over ``DT`` s with mean bias-corrected rate ``w``."""
    sf, cf = math.sin(phi), math.cos(phi)
    ct = math.cos(theta)
    ct = math.copysign(max(abs(ct), _COS_MIN), ct)
    st = math.sin(theta)
    tt = st / ct
    a = sf * w[1] + cf * w[2]
    da = cf * w[1] - sf * w[2]                     # d a / d phi
    J = np.eye(6)
    J[0, 0] += DT * tt * da
    J[1, 0] -= DT * a
    J[2, 0] += DT * da / ct
    J[0, 1] += DT * a / ct**2
    J[2, 1] += DT * a * st / ct**2
    J[:3, 3:] = -DT * np.array([[1.0, sf * tt, cf * tt], [0.0, cf, -sf], [0.0, sf / ct, cf / ct]])
    return J


_H_ATT = np.hstack([np.eye(3), np.zeros((3, 3))])


def _att_residual(a, b):
    return _wrap(a - b)


def smooth_attitude(dt: float, gyro: np.ndarray, att: np.ndarray, sigma_gyro: float, sigma_att: float = 0.005,
                    sigma_bias_walk: float = 2e-4, node_hz: float = 10.0) -> AttitudeEstimate:
    """Attitude and gyro bias by an EKF (filterpy) with an extended RTS smoother.

    Args:
        dt: grid step, s.
        gyro: (T, 3) measured body rates p q r, rad/s, NaN where missing.
        att: (T, 3) attitude measurements phi theta psi, rad, NaN at grid points
            without a sample (see :func:`gcs_sysid.estimation.align.events`).
        sigma_gyro: gyro white noise per grid sample, rad/s.
        sigma_att: attitude measurement noise, rad.
        sigma_bias_walk: gyro bias random walk, rad/s/sqrt(s).
        node_hz: highest rate of the EKF nodes, Hz.

    Returns:
        :class:`AttitudeEstimate`.

    Raises:
        ValueError: ``att`` has no finite row.

    Source: Stevens, Lewis and Johnson (2016) ch. 1; Sarkka (2013) ch. 9.
    """
    T = len(gyro)
    ok_att = np.isfinite(att).all(axis=1)
    if not ok_att.any():
        raise ValueError("no attitude measurement to start the attitude EKF")
    nodes = node_indices(T, dt, node_hz)
    J = len(nodes)
    gmid = gyro.copy()
    gmid[1:] = 0.5 * (gyro[1:] + gyro[:-1])        # mean rate over the step into k
    g_ok = np.isfinite(gmid).all(axis=1)
    # measurements at nodes: samples between nodes moved forward with the raw gyro's Euler rates
    att_u = att.copy()
    att_u[ok_att, 2] = np.unwrap(att[ok_att, 2])
    k_att = np.nonzero(ok_att)[0]
    ang_i = np.stack([np.interp(np.arange(T), k_att, att_u[ok_att, i]) for i in range(3)], axis=1)
    # a first, constant bias guess (median of gyro minus the rates implied by the attitude) so that
    # moving samples to their node does not carry the bias along
    b0 = np.zeros(3)
    if len(k_att) >= 10:
        ed = np.gradient(ang_i, dt, axis=0)
        sf, cf = np.sin(ang_i[:, 0]), np.cos(ang_i[:, 0])
        st, ct = np.sin(ang_i[:, 1]), np.cos(ang_i[:, 1])
        w_att = np.stack([ed[:, 0] - ed[:, 2] * st, ed[:, 1] * cf + ed[:, 2] * sf * ct,
                          -ed[:, 1] * sf + ed[:, 2] * cf * ct], axis=1)
        diff = gyro - w_att
        if np.isfinite(diff).any(axis=0).all():
            b0 = np.nanmedian(diff, axis=0)
    z = to_nodes(att_u, integrate(euler_rates(ang_i[:, 0], ang_i[:, 1], np.nan_to_num(gyro - b0)), dt), nodes)
    ekf = _EulerEKF(dt)
    x0 = np.zeros(6)
    x0[:3] = att[np.argmax(ok_att)]
    x0[3:] = b0
    ekf.x = x0[:, None]
    ekf.P = np.diag([0.05**2, 0.05**2, 0.2**2] + [0.05**2] * 3)
    ekf.R = np.eye(3) * sigma_att**2
    xf = np.empty((J, 1, 6))
    Pf = np.empty((J, 1, 6, 6))
    xp = np.empty((J, 1, 6))
    Pp = np.empty((J, 1, 6, 6))
    Fs = np.empty((J, 6, 6))
    hj = lambda x: _H_ATT  # noqa: E731
    hx = lambda x: x[:3]   # noqa: E731
    n_ok = np.concatenate([[0], np.cumsum(g_ok)])            # gyro samples present before each grid index
    z_ok = np.isfinite(z).all(axis=1)
    for j in range(J):
        blk = slice(nodes[j - 1] + 1, nodes[j] + 1) if j else slice(0, 0)
        n = blk.stop - blk.start
        nok = int(n_ok[blk.stop] - n_ok[blk.start])
        b = ekf.x[3:, 0]
        gb = gmid[blk]
        # missing gyro: hold the attitude (w - b = 0); a complete block is the gyro as it is
        w = gb if nok == n else np.where(g_ok[blk][:, None], gb, b[None, :])
        x = ekf.x[:, 0]
        Fk = _euler_jacobian(x[0], x[1], (w.mean(0) - b) if n else np.zeros(3), n * dt)
        qa = (sigma_gyro * dt) ** 2 * nok + (1.0 * dt) ** 2 * (n - nok)
        ekf.F = Fk
        ekf.Q = np.diag([qa] * 3 + [sigma_bias_walk**2 * dt * n] * 3)
        ekf.predict(u=w)
        Fs[j] = Fk
        xp[j, 0] = ekf.x[:, 0]
        Pp[j, 0] = ekf.P
        if z_ok[j]:
            zj = z[j].copy()
            zj[2] = _wrap(zj[2])
            ekf.update(zj[:, None], hj, hx, residual=_att_residual)
            ekf.x[2, 0] = _wrap(ekf.x[2, 0])
        xf[j, 0] = ekf.x[:, 0]
        Pf[j, 0] = ekf.P
    xs, Ps = rts_smoother(FilterResult(xf, Pf, xp, Pp, np.zeros(1)), Fs, wrap=(0, 1, 2))
    xs, Ps = xs[:, 0], Ps[:, 0]
    sd = np.sqrt(np.maximum(np.diagonal(Ps, axis1=1, axis2=2), 0.0))
    # full rate: bias-corrected gyro integral between the smoothed nodes
    xs[:, 2] = np.unwrap(xs[:, 2])
    bias = interp_nodes(nodes, xs[:, 3:], T)
    ang = interp_nodes(nodes, xs[:, :3], T)
    erate = euler_rates(ang[:, 0], ang[:, 1], gmid - bias)
    erate[~g_ok] = np.nan
    euler = fill_between_nodes(nodes, xs[:, :3], integrate(erate, dt))
    euler[:, 2] = _wrap(euler[:, 2])
    return AttitudeEstimate(euler, interp_nodes(nodes, sd[:, :3], T), bias, interp_nodes(nodes, sd[:, 3:], T))
