"""6-DOF rigid-body equations of a fixed-wing aircraft (JAX, flat earth, quaternion attitude).

State ``x`` of shape (13,): NED position ``pn pe pd`` (m), body-axis velocity
over the ground ``u v w`` (m/s), attitude quaternion ``q0 q1 q2 q3`` (scalar
first, body -> NED), body rates ``p q r`` (rad/s). Controls ``delta`` of shape
(4,): ``delta_e delta_a delta_r`` (rad, the actual surface positions) and
``delta_t`` (0..1). Equations (Stevens, Lewis and Johnson, *Aircraft Control and
Simulation*, 3rd ed., 2016, sec. 1.8 and 2.5; Beard and McLain, *Small Unmanned
Aircraft*, 2012, ch. 3)::

    d(pos_ned)/dt = C(q) v
    dv/dt         = F / m + C(q)^T g_ned - omega x v
    dq/dt         = 0.5 q (x) [0, omega] + k (1 - |q|^2) q
    d(omega)/dt   = J^-1 (M - omega x J omega)

F is the aerodynamic force ``qbar S (CX, CY, CZ)`` plus thrust along body x
(airframe ThrustModel), M the aero moment ``qbar S (b Cl, c Cm, b Cn)`` about the
model's reference point (the nominal CG) moved to the true CG:
``M_cg = M_ref - d x F`` with ``d`` = true CG - nominal CG. Air-relative velocity
``v_air = v - C^T wind_ned - gust_body`` gives V, alpha = atan2(w_a, u_a),
beta = asin(v_a / V) and the regressors of :data:`gcs_sysid.aero.table.REGRESSORS`.
Density from the ISA at altitude ``-pd``.
"""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp
import numpy as np

from ..airframe import Airframe
from .environment import G0, isa_jax
from .model_file import AeroModel, evaluate_weights

__all__ = ["Params", "make_params", "dcm", "euler_from_quat", "quat_from_euler", "air_data",
           "forces_moments", "derivative", "rk4_step"]


class Params(NamedTuple):
    """Everything the dynamics need, as arrays (a pytree: no recompiling when values change).

    Attributes: mass (kg), J (3, 3) and J_inv (3, 3) kg m^2, S b c (m^2, m, m),
    W (66, 6) model weights, thrust (3,) = (T_static N, V_zero m/s, exponent),
    has_thrust (0/1), cg (3,) true CG - nominal CG in m.
    """

    mass: jnp.ndarray
    J: jnp.ndarray
    J_inv: jnp.ndarray
    S: jnp.ndarray
    b: jnp.ndarray
    c: jnp.ndarray
    W: jnp.ndarray
    thrust: jnp.ndarray
    has_thrust: jnp.ndarray
    cg: jnp.ndarray


def make_params(airframe: Airframe, model: AeroModel, cg_offset=(0.0, 0.0, 0.0)) -> Params:
    """Params of an airframe (the truth one) and aero model."""
    J = airframe.inertia
    th = airframe.thrust
    return Params(
        jnp.asarray(airframe.mass), jnp.asarray(J), jnp.asarray(np.linalg.inv(J)), jnp.asarray(airframe.S),
        jnp.asarray(airframe.b), jnp.asarray(airframe.c), jnp.asarray(model.weights()),
        jnp.asarray([th.T_static, th.V_zero, th.exponent] if th else [0.0, 1.0, 1.0]),
        jnp.asarray(1.0 if th else 0.0), jnp.asarray(np.asarray(cg_offset, float)),
    )


def dcm(q):
    """Body -> NED rotation matrix (3, 3) of a unit quaternion (q0 q1 q2 q3); numpy or JAX."""
    xp = jnp if type(q).__module__.startswith("jax") else np
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    r = [
        [q0**2 + q1**2 - q2**2 - q3**2, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), q0**2 - q1**2 + q2**2 - q3**2, 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0**2 - q1**2 - q2**2 + q3**2],
    ]
    return xp.stack([xp.stack(row, -1) for row in r], -2)


def euler_from_quat(q):
    """(phi, theta, psi) in rad, 3-2-1 Euler angles of quaternions (..., 4); numpy or JAX."""
    xp = jnp if type(q).__module__.startswith("jax") else np
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    phi = xp.arctan2(2 * (q0 * q1 + q2 * q3), 1 - 2 * (q1**2 + q2**2))
    theta = xp.arcsin(xp.clip(2 * (q0 * q2 - q1 * q3), -1.0, 1.0))
    psi = xp.arctan2(2 * (q0 * q3 + q1 * q2), 1 - 2 * (q2**2 + q3**2))
    return phi, theta, psi


def quat_from_euler(phi, theta, psi) -> np.ndarray:
    """Unit quaternion (..., 4) from 3-2-1 Euler angles (rad), numpy (Stevens et al. eq. 1.8-18)."""
    cf, sf = np.cos(np.asarray(phi) / 2), np.sin(np.asarray(phi) / 2)
    ct, st = np.cos(np.asarray(theta) / 2), np.sin(np.asarray(theta) / 2)
    cp, sp = np.cos(np.asarray(psi) / 2), np.sin(np.asarray(psi) / 2)
    return np.stack([cf * ct * cp + sf * st * sp, sf * ct * cp - cf * st * sp,
                     cf * st * cp + sf * ct * sp, cf * ct * sp - sf * st * cp], -1)


def air_data(x, wind_ned, gust_b):
    """(V m/s, alpha rad, beta rad, v_air (3,)) from state (13,), wind (3,) NED and body gust (3,)."""
    C = dcm(x[6:10])
    v_air = x[3:6] - C.T @ wind_ned - gust_b
    V = jnp.sqrt(jnp.sum(v_air**2) + 1e-12)
    alpha = jnp.arctan2(v_air[2], v_air[0])
    beta = jnp.arcsin(jnp.clip(v_air[1] / V, -1.0, 1.0))
    return V, alpha, beta, v_air


def forces_moments(P: Params, x, delta, wind_ned, gust_b):
    """Non-gravitational force (N) and moment about the true CG (N m), body axes.

    Returns:
        (F (3,), M (3,), X (10,) regressors, Y (6,) coefficients, V, rho).
    """
    V, alpha, beta, _ = air_data(x, wind_ned, gust_b)
    rho = isa_jax(-x[2])
    qbar = 0.5 * rho * V**2
    p, q, r = x[10], x[11], x[12]
    X = jnp.stack([alpha, beta, p * P.b / (2 * V), q * P.c / (2 * V), r * P.b / (2 * V),
                   delta[0], delta[1], delta[2], delta[3], V])
    Y = evaluate_weights(X, P.W)
    T_static, V_zero, expo = P.thrust[0], P.thrust[1], P.thrust[2]
    thrust = P.has_thrust * T_static * jnp.clip(delta[3], 0.0, 1.0) ** expo * jnp.maximum(0.0, 1.0 - V / V_zero)
    F = qbar * P.S * Y[:3] + jnp.stack([thrust, 0.0, 0.0])
    M_ref = qbar * P.S * jnp.stack([P.b * Y[3], P.c * Y[4], P.b * Y[5]])
    M = M_ref - jnp.cross(P.cg, F)
    return F, M, X, Y, V, rho


def derivative(P: Params, x, delta, wind_ned, gust_b):
    """State derivative (13,) and the non-gravitational force F (3,) N (specific force F/m)."""
    F, M, *_ = forces_moments(P, x, delta, wind_ned, gust_b)
    qt = x[6:10]
    C = dcm(qt)
    v, w = x[3:6], x[10:13]
    pos_dot = C @ v
    v_dot = F / P.mass + C.T @ jnp.array([0.0, 0.0, G0]) - jnp.cross(w, v)
    q0, q1, q2, q3 = qt
    p, q, r = w
    norm_err = 1.0 - jnp.sum(qt**2)
    q_dot = 0.5 * jnp.stack([-p * q1 - q * q2 - r * q3, p * q0 + r * q2 - q * q3,
                             q * q0 - r * q1 + p * q3, r * q0 + q * q1 - p * q2]) + 1.0 * norm_err * qt
    w_dot = P.J_inv @ (M - jnp.cross(w, P.J @ w))
    return jnp.concatenate([pos_dot, v_dot, q_dot, w_dot]), F


def rk4_step(P: Params, x, delta, wind_ned, gust_b, h):
    """One classical Runge-Kutta step of length ``h`` s with inputs held over the step."""
    f = lambda s: derivative(P, s, delta, wind_ned, gust_b)[0]  # noqa: E731
    k1 = f(x)
    k2 = f(x + 0.5 * h * k1)
    k3 = f(x + 0.5 * h * k2)
    k4 = f(x + h * k3)
    return x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
