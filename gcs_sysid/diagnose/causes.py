"""How each cause of the catalogue changes the equation-error residual.

Every cause is a parametric correction: given its parameters it says how the
residual ``R = Y_measured - model(X)`` (T, 6) would change if the cause were
taken into account, ``R_after = R + delta(params)``. The physics of each:

* ``<coef>:<term>`` missing or wrong aero term: ``delta_c = -theta * term(X)``.
* ``bias:airspeed`` b / ``scale:airspeed`` s: the measured V is ``V_true + b`` or
  ``s * V_true``; qbar, the normalised rates and the thrust used for CX were
  computed with it, so ``C_true = C_meas (V_meas / V_true)^2`` (plus the thrust
  difference) and ``p_hat_true = p_hat (V_meas / V_true)``. The bias is taken out of
  the body-x air velocity, where the estimation put the pitot's excess, so alpha and
  beta move with V (``alpha_true ~ alpha (V + b) / V``).
* ``bias:alpha`` / ``bias:beta`` b: the regressor is shifted, ``alpha_true = alpha - b``.
* ``bias:gyro_x`` (y, z) b: the rate regressor and the gyroscopic terms of
  Euler's equations used ``p + b``.
* ``bias:accel_x`` (y, z) b: ``CX_meas = CX_true + m b / (qbar S)``.
* ``wind`` (w_N, w_E): an unmodelled steady wind turns the air-relative velocity,
  ``v_air_true = v_air - C_bn w``, changing alpha and beta by heading-dependent amounts.
* ``mass`` m_true: force coefficients computed with the airframe's mass m are
  ``(m / m_true)`` times the truth (thrust kept apart).
* ``inertia:Ixx`` (Iyy, Izz, Ixz) I_true: Euler's equations with the wrong inertia,
  ``C_meas - C_true = (I - I_true) w_dot / (qbar S l) + ...`` (linear in the error).
* ``cg_offset`` (dx, dy, dz): the CG lies at ``d`` from the aero reference point;
  moments about it gain ``-d x F`` and the accelerometer lever arm is off by ``d``.

Delay and stuck surfaces are scanned over their time parameter in
:mod:`gcs_sysid.diagnose.candidates`.
"""

from __future__ import annotations

import numpy as np

from ..aero.table import REGRESSORS
from .context import DiagContext, euler_moments

__all__ = ["SensorCause", "transforms"]

iV, iA, iB, iP, iQ, iR = (REGRESSORS.index(k) for k in ("V", "alpha", "beta", "p_hat", "q_hat", "r_hat"))
FORCES = [0, 1, 2]
MOMENTS = [3, 4, 5]


def _reference_lengths(ctx: DiagContext) -> np.ndarray:
    a = ctx.airframe
    return np.array([a.b, a.c, a.b])


def _airspeed(ctx: DiagContext, V_true: np.ndarray):
    """(X_new, Y_new) when the true airspeed is ``V_true`` instead of the measured V."""
    V = ctx.x("V")
    k = V / np.maximum(V_true, 1e-3)
    X = ctx.X.copy()
    X[:, iV] = V_true
    for i in (iP, iQ, iR):
        X[:, i] = ctx.X[:, i] * k
    Y = ctx.Y * (k**2)[:, None]
    S = ctx.airframe.S
    qbar_true = ctx.qbar / k**2
    Y[:, 0] += (ctx.thrust() - ctx.thrust(V=V_true)) / (qbar_true * S)
    return X, Y


def _air_velocity_body(ctx) -> np.ndarray:
    """(T, 3) air-relative velocity in body axes from V, alpha, beta, m/s."""
    V, al, be = ctx.x("V"), ctx.x("alpha"), ctx.x("beta")
    return np.column_stack([V * np.cos(al) * np.cos(be), V * np.sin(be), V * np.sin(al) * np.cos(be)])


def t_bias_airspeed(ctx, p):
    """A pitot reading ``b`` m/s high. The estimation layer builds the air-relative velocity from GPS
    minus wind and adds the pitot's excess along the body x axis (``gcs_sysid.estimation.estimate``), so
    the bias sits in ``u``: the true air velocity is ``(u - b, v, w)``, which moves V, alpha and beta
    together (alpha by about ``-alpha b / V``). Checked against JSBSim's exact truth: V +2.00 m/s,
    alpha -0.26 deg at 6.5 deg, every coefficient times ``(V / (V + b))^2``."""
    va = _air_velocity_body(ctx)
    vt = va - np.array([p[0], 0.0, 0.0])[None, :]
    V_true = np.maximum(np.linalg.norm(vt, axis=1), 1e-3)
    X, Y = _airspeed(ctx, V_true)
    X[:, iA] = np.arctan2(vt[:, 2], vt[:, 0])
    X[:, iB] = np.arcsin(np.clip(vt[:, 1] / V_true, -1.0, 1.0))
    return X, Y


def t_scale_airspeed(ctx, p):
    return _airspeed(ctx, ctx.x("V") / p[0])


def _shift(ctx, col, b):
    X = ctx.X.copy()
    X[:, col] = X[:, col] - b
    return X, ctx.Y


def t_bias_alpha(ctx, p):
    return _shift(ctx, iA, p[0])


def t_bias_beta(ctx, p):
    return _shift(ctx, iB, p[0])


def _gyro(ctx, axis, b):
    a = ctx.airframe
    V = np.maximum(ctx.x("V"), 1e-3)
    X = ctx.X.copy()
    ref = [a.b, a.c, a.b][axis]
    X[:, (iP, iQ, iR)[axis]] -= b * ref / (2 * V)
    w = ctx.rates()
    w_true = w.copy()
    w_true[:, axis] -= b
    I = a.inertia
    zero = np.zeros_like(w)
    dM = euler_moments(I, w_true, zero) - euler_moments(I, w, zero)
    Y = ctx.Y.copy()
    Y[:, MOMENTS] += dM / ctx.moment_scale()
    return X, Y


def _accel(ctx, axis, b):
    Y = ctx.Y.copy()
    Y[:, axis] -= ctx.airframe.mass * b / (ctx.qbar * ctx.airframe.S)
    return ctx.X, Y


def _axis_bias(transform, axis: int):
    """The cause transform ``(ctx, p) -> transform(ctx, axis, p[0])``: a bias ``p[0]`` on one axis (0 x, 1 y, 2 z)
    of the gyro (:func:`_gyro`, rad/s) or the accelerometer (:func:`_accel`, m/s^2)."""
    return lambda ctx, p: transform(ctx, axis, p[0])


def _dcm_nb(phi, theta, psi):
    """(T, 3, 3) rotation NED -> body (3-2-1 Euler angles)."""
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    return np.stack([
        np.stack([ct * cp, ct * sp, -st], -1),
        np.stack([sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct], -1),
        np.stack([cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct], -1),
    ], -2)


def t_wind(ctx, p):
    V, al, be = ctx.x("V"), ctx.x("alpha"), ctx.x("beta")
    va = np.column_stack([V * np.cos(al) * np.cos(be), V * np.sin(be), V * np.sin(al) * np.cos(be)])
    C = _dcm_nb(ctx.states["phi"], ctx.states["theta"], ctx.states["psi"])
    w = np.array([p[0], p[1], 0.0])
    vt = va - C @ w
    X = ctx.X.copy()
    X[:, iA] = np.arctan2(vt[:, 2], vt[:, 0])
    X[:, iB] = np.arcsin(np.clip(vt[:, 1] / np.maximum(np.linalg.norm(vt, axis=1), 1e-3), -1, 1))
    return X, ctx.Y


def t_mass(ctx, p):
    S = ctx.airframe.S
    Y = ctx.Y.copy()
    T = ctx.thrust()
    force = Y[:, FORCES] * (ctx.qbar * S)[:, None]
    force[:, 0] += T
    force *= p[0] / ctx.airframe.mass
    force[:, 0] -= T
    Y[:, FORCES] = force / (ctx.qbar * S)[:, None]
    return ctx.X, Y


def _inertia(ctx, which, value):
    a = ctx.airframe
    dI = np.zeros((3, 3))
    d = a.__getattribute__(which) - value                 # error of the airframe's value
    if which == "Ixx":
        dI[0, 0] = d
    elif which == "Iyy":
        dI[1, 1] = d
    elif which == "Izz":
        dI[2, 2] = d
    else:
        dI[0, 2] = dI[2, 0] = -d
    w = ctx.rates()
    wd = np.column_stack([ctx.states[k] for k in ("p_dot", "q_dot", "r_dot")])
    Y = ctx.Y.copy()
    Y[:, MOMENTS] -= euler_moments(dI, w, wd) / ctx.moment_scale()
    return ctx.X, Y


def t_cg(ctx, p):
    a = ctx.airframe
    d = np.asarray(p[:3], float)
    CF = ctx.Y[:, FORCES].copy()
    CF[:, 0] += ctx.thrust() / (ctx.qbar * a.S)
    Y = ctx.Y.copy()
    # the measured moment is about the true CG; the model's about the reference point:
    # M_cg = M_ref - d x F  ->  C_ref = C_meas + (d x C_F) / l
    Y[:, MOMENTS] += np.cross(d[None, :], CF) / _reference_lengths(ctx)[None, :]
    if ctx.has("p_dot", "q_dot", "r_dot"):
        w = ctx.rates()
        wd = np.column_stack([ctx.states[k] for k in ("p_dot", "q_dot", "r_dot")])
        acc = np.cross(wd, d[None, :]) + np.cross(w, np.cross(w, d[None, :]))
        Y[:, FORCES] += a.mass * acc / (ctx.qbar * a.S)[:, None]
    return ctx.X, Y


class SensorCause:
    """A cause given by a transform ``(ctx, params) -> (X_true, Y_true)``.

    Attributes:
        cause: catalogue name. p0: starting parameters. needs: state keys required.
        scale: typical parameter size (for the optimiser). labels: parameter names.
    """

    def __init__(self, cause, fn, p0, needs=(), scale=None, labels=None):
        self.cause, self.fn, self.p0 = cause, fn, np.asarray(p0, float)
        self.needs = tuple(needs)
        self.scale = np.asarray(scale if scale is not None else np.ones_like(self.p0), float)
        self.labels = labels or [cause]

    @property
    def n_params(self) -> int:
        return len(self.p0)

    def delta(self, ctx: DiagContext, params) -> np.ndarray:
        """Change of the residual (T, 6) when the cause with ``params`` is accounted for."""
        X, Y = self.fn(ctx, params)
        return (Y - ctx.model_values(X)) - (ctx.Y - ctx.model_values())


def transforms(ctx: DiagContext) -> list[SensorCause]:
    """The sensor, wind and mass-property causes applicable to ``ctx``."""
    a = ctx.airframe
    V0 = float(np.median(ctx.x("V")[ctx.valid])) if ctx.valid.any() else 15.0
    out = [
        SensorCause("bias:airspeed", t_bias_airspeed, [0.0], scale=[1.0]),
        SensorCause("scale:airspeed", t_scale_airspeed, [1.0], scale=[0.05]),
        SensorCause("bias:alpha", t_bias_alpha, [0.0], scale=[0.02]),
        SensorCause("bias:beta", t_bias_beta, [0.0], scale=[0.02]),
        *(SensorCause(f"bias:gyro_{ax}", _axis_bias(_gyro, i), [0.0], scale=[0.02]) for i, ax in enumerate("xyz")),
        *(SensorCause(f"bias:accel_{ax}", _axis_bias(_accel, i), [0.0], scale=[0.3]) for i, ax in enumerate("xyz")),
        SensorCause("mass", t_mass, [a.mass], scale=[0.1 * a.mass]),
        SensorCause("cg_offset", t_cg, [0.0, 0.0, 0.0], scale=[0.02, 0.02, 0.02],
                    labels=["dx", "dy", "dz"]),
        SensorCause("wind", t_wind, [0.0, 0.0], needs=("phi", "theta", "psi"), scale=[0.1 * V0, 0.1 * V0],
                    labels=["wn", "we"]),
    ]
    for which in ("Ixx", "Iyy", "Izz", "Ixz"):
        val = getattr(a, which)
        out.append(SensorCause(f"inertia:{which}", lambda c, p, w=which: _inertia(c, w, p[0]), [val],
                               needs=("p_dot", "q_dot", "r_dot"), scale=[0.1 * max(abs(val), 0.01 * a.Ixx)]))
    return [c for c in out if ctx.has(*c.needs)]
