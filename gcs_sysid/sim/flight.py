"""Public entry points of the simulation: :func:`simulate` a plan, :func:`propagate` given controls.

``simulate`` flies a plan (``plan.py``) with the truth airframe and model (the
nominal ones with the plan's or the caller's :class:`Effects` applied), the
stabilising autopilot, actuator models, steady wind and Dryden turbulence, and
returns the truth and the simulated sensors as a :class:`SimResult`.
``propagate`` is the deterministic simulation driven by given control histories
from a given state (no autopilot, sensors or turbulence): the output-error
comparison of ``diagnose`` uses it, with :func:`state_from_measurements` to
build the initial state.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import jax
import jax.numpy as jnp
import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from ..airframe import CONTROLS, Airframe
from ..errors import DataError, InputError
from ..jaxconfig import enable_x64
from ..signals import waveform
from .autopilot import default_gains
from .core import Loop, Schedule, run_loop, turbulence_init
from .dynamics import Params, air_data, dcm, derivative, euler_from_quat, forces_moments, make_params, quat_from_euler
from .effects import CONTROL_NAMES, Effects
from .environment import dryden_scales
from .model_file import AeroModel
from .plan import Plan
from .sensors import SensorConfig, make_sensors
from .trim import Trim, trim

__all__ = ["SimResult", "simulate", "propagate", "state_from_measurements", "control_limits", "TRUTH_KEYS"]

#: Keys of ``SimResult.truth``: STATE_KEYS of the estimation layer plus NED position (m), body-axis
#: gust (m/s), thrust (N) and the attitude quaternion (scalar first, body -> NED).
TRUTH_KEYS = ("phi", "theta", "psi", "p", "q", "r", "p_dot", "q_dot", "r_dot", "u", "v", "w", "vn", "ve", "vd",
              "ax", "ay", "az", "V", "alpha", "beta", "qbar", "rho", "wn", "we", "wd", "alt",
              "delta_e", "delta_a", "delta_r", "delta_t", "pn", "pe", "pd", "gust_u", "gust_v", "gust_w", "thrust",
              "quat0", "quat1", "quat2", "quat3")
_HIST = 16      # command ring buffer, ticks (grown in steps of 16 for long delays)


@dataclass
class SimResult:
    """A simulated flight.

    Attributes:
        t: vehicle time of the samples, s, shape (T,).
        rate_hz: sample rate.
        truth: key (TRUTH_KEYS) -> (T,) true values, SI; controls are the actual surface
            positions; ax ay az the specific force at the true CG; wn we wd steady wind + gusts.
        X: (T, 10) true regressors (REGRESSORS). Y: (T, 6) true coefficients (COEFFICIENTS),
            about the nominal CG (the model's reference point).
        commands: control name -> (T,) commanded outputs (autopilot + maneuvers), the values the
            autopilot logs as SERVO_OUTPUT_RAW.
        sensors: stream -> {"t", fields} (see ``sensors.make_sensors``).
        plan, effects, seed: what was flown.
        airframe, model: nominal inputs; truth_airframe, truth_model: with the effects applied.
        trims: the trim of each setpoint.
        demand: what the autopilot asked for (NAV_CONTROLLER_OUTPUT): ``roll`` and ``pitch`` demands
            (rad), ``alt_error`` (m) and ``aspd_error`` (m/s), target minus current, each (T,).
    """

    t: np.ndarray
    rate_hz: float
    truth: dict[str, np.ndarray]
    X: np.ndarray
    Y: np.ndarray
    commands: dict[str, np.ndarray]
    sensors: dict[str, dict[str, np.ndarray]]
    plan: Plan
    effects: Effects
    seed: int
    airframe: Airframe
    model: AeroModel
    truth_airframe: Airframe
    truth_model: AeroModel
    trims: list[Trim] = field(default_factory=list)
    demand: dict[str, np.ndarray] = field(default_factory=dict)

    def save_truth(self, path: str | Path) -> None:
        """Write truth, regressors, coefficients and commands to a compressed ``.npz``.

        Arrays: ``t``, ``X``, ``Y``, every truth key, ``cmd_<control>``; ``meta`` is a JSON string
        (plan name, seed, effects, causes, regressor and coefficient names).
        """
        meta = {"plan": self.plan.name, "seed": self.seed, "effects": self.effects.to_dict(),
                "causes": self.effects.causes(), "regressors": list(REGRESSORS), "coefficients": list(COEFFICIENTS),
                "airframe": self.airframe.name, "model": self.model.name}
        arrays = {"t": self.t, "X": self.X, "Y": self.Y, **self.truth,
                  **{f"cmd_{k}": v for k, v in self.commands.items()}}
        np.savez_compressed(path, meta=json.dumps(meta, default=str), **arrays)


def control_limits(airframe: Airframe) -> tuple[np.ndarray, np.ndarray]:
    """Position limits (lo, hi) of (delta_e, delta_a, delta_r, delta_t) from the servo limits and mixing."""
    hi = np.zeros(4)
    for i, c in enumerate(CONTROLS):
        hi[i] = sum(abs(s.mix.get(c, 0.0)) * min(-s.limit_min, s.limit_max) for s in airframe.servos)
    lo = -hi
    hi[3] = 1.0 if airframe.throttle is not None else 0.0
    return lo, hi


@jax.jit
def _post(P: Params, x, act, wind, gust):
    def one(xk, ak, gk):
        xd, F = derivative(P, xk, ak, wind, gk)
        _, _, X, Y, V, rho = forces_moments(P, xk, ak, wind, gk)
        _, alpha, beta, _ = air_data(xk, wind, gk)
        C = dcm(xk[6:10])
        phi, theta, psi = euler_from_quat(xk[6:10])
        return {"phi": phi, "theta": theta, "psi": psi, "p": xk[10], "q": xk[11], "r": xk[12],
                "p_dot": xd[10], "q_dot": xd[11], "r_dot": xd[12], "u": xk[3], "v": xk[4], "w": xk[5],
                "vn": xd[0], "ve": xd[1], "vd": xd[2], "ax": F[0] / P.mass, "ay": F[1] / P.mass,
                "az": F[2] / P.mass, "V": V, "alpha": alpha, "beta": beta, "qbar": 0.5 * rho * V**2, "rho": rho,
                "wn": wind[0] + (C @ gk)[0], "we": wind[1] + (C @ gk)[1], "wd": wind[2] + (C @ gk)[2],
                "alt": -xk[2], "delta_e": ak[0], "delta_a": ak[1], "delta_r": ak[2], "delta_t": ak[3],
                "pn": xk[0], "pe": xk[1], "pd": xk[2], "gust_u": gk[0], "gust_v": gk[1], "gust_w": gk[2],
                "thrust": F[0] - 0.5 * rho * V**2 * P.S * Y[0], "quat0": xk[6], "quat1": xk[7], "quat2": xk[8],
                "quat3": xk[9], "X": X, "Y": Y}

    return jax.vmap(one)(x, act, gust)


def _loop(t0, dt, effects: Effects, lo, hi, rate, wind, L, sigma) -> Loop:
    f = lambda v: jnp.asarray(np.asarray(v, float))  # noqa: E731
    return Loop(f(t0), f(dt), f(effects.delay), f(effects.lag), f(rate), f(lo), f(hi), f(effects.stuck), f(wind),
                f(L), f(sigma), f(effects.disable), f(effects.disable_at))


def _hist_len(effects: Effects, dt: float) -> int:
    need = int(math.ceil(max(effects.delay) / dt)) + 2
    return _HIST * int(math.ceil(need / _HIST))


def _split(out: Mapping[str, Any]) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    d = {k: np.asarray(v) for k, v in out.items()}
    X, Y = d.pop("X"), d.pop("Y")
    return d, X, Y


def simulate(airframe: Airframe, model: AeroModel, plan: Plan, effects: Effects | None = None,
             seed: int | None = None) -> SimResult:
    """Fly a plan.

    Args:
        airframe: the nominal airframe (what the engineer believes; the log's servo map).
        model: the nominal aero model.
        plan: the plan (``load_plan``).
        effects: truth deviations; None: the plan's ``[effects]``.
        seed: random seed for noise and turbulence; None: the plan's.

    Returns:
        the :class:`SimResult`.

    Raises:
        DataError: the aircraft cannot be trimmed at a setpoint.
        InputError: invalid effects or sensor settings.
    """
    enable_x64()
    eff = plan.effects if effects is None else effects
    seed = plan.seed if seed is None else int(seed)
    rng = np.random.default_rng(seed)
    sens_cfg = SensorConfig.from_dict(plan.sensors, plan.source or "<plan>")
    af_true, m_true = eff.apply_airframe(airframe), eff.apply_model(model)
    P = make_params(af_true, m_true, eff.cg_offset)
    lo, hi = control_limits(airframe)
    T, dt = plan.n_ticks, 1.0 / plan.rate_hz
    t = plan.start_time + dt * np.arange(T)
    trims = []
    for i, s in enumerate(plan.setpoints):
        try:
            trims.append(trim(P, s.airspeed, s.altitude, s.heading, lo, hi))
        except DataError as e:
            where = "[initial]" if i == 0 else f"[[setpoint]] #{i}"
            raise DataError(f"{plan.source or '<plan>'}: {where} {e}") from None
    k_sp = np.searchsorted([sp.start for sp in plan.setpoints], t + 1e-9, side="right") - 1
    sp = np.array([[s.airspeed, s.altitude, s.heading] for s in plan.setpoints])[k_sp]
    ff = np.array([[tr.theta, *tr.controls, 0.0] for tr in trims])[k_sp]
    man, openm = np.zeros((T, 4)), np.zeros((T, 4))
    for m in plan.maneuvers:
        for i, (c, a) in enumerate(zip(m.controls, m.amplitude)):
            j = CONTROL_NAMES.index(c)
            man[:, j] += waveform(m.kind, t, m.start, a, m.pulse, m.duration, m.band, len(m.controls), i)
            if m.mode == "open":
                openm[(t >= m.start - 1e-9) & (t < m.end + m.settle), j] = 1.0
    wind = np.asarray(plan.wind_ned) + np.asarray(eff.wind_ned)
    L, sigma = dryden_scales(plan.setpoints[0].altitude - plan.home[2], plan.w20)
    turb0 = turbulence_init(rng.normal(size=5), L, sigma, plan.setpoints[0].airspeed)
    noise = rng.normal(size=(T, 3))
    tr0 = trims[0]
    x0 = tr0.x.copy()
    x0[3:6] += dcm(x0[6:10]).T @ wind
    act0 = jnp.asarray(tr0.controls)
    sched = Schedule(*(jnp.asarray(a) for a in (man, openm, sp, ff, noise, np.zeros((T, 4)))))
    loop = _loop(plan.start_time, dt, eff, lo, hi, plan.rate_limit, wind, L, sigma)
    out = run_loop(P, loop, default_gains(model), sched, jnp.asarray(x0), act0, turb0,
                   n_sub=int(round(plan.internal_rate_hz / plan.rate_hz)), hist_len=_hist_len(eff, dt),
                   use_autopilot=True)
    truth, X, Y = _split(_post(P, out["x"], out["act"], jnp.asarray(wind), out["gust"]))
    cmd = np.asarray(out["cmd"])
    dem = np.asarray(out["demand"])
    sensors = make_sensors(t, truth, np.asarray(airframe.imu_lever_arm), eff, sens_cfg, rng, plan.rate_hz,
                           plan.home, tuple(wind))
    return SimResult(t, plan.rate_hz, truth, X, Y, {c: cmd[:, i] for i, c in enumerate(CONTROL_NAMES)}, sensors,
                     plan, eff, seed, airframe, model, af_true, m_true, trims,
                     {k: dem[:, i] for i, k in enumerate(("roll", "pitch", "alt_error", "aspd_error"))})


def state_from_measurements(phi: float, theta: float, psi: float, p: float, q: float, r: float, alt: float,
                            u: float | None = None, v: float | None = None, w: float | None = None,
                            V: float | None = None, alpha: float | None = None, beta: float | None = None,
                            wind_ned=(0.0, 0.0, 0.0), pn: float = 0.0, pe: float = 0.0) -> np.ndarray:
    """Initial state (13,) for :func:`propagate` from measured states.

    Give either the body velocity over the ground ``u v w`` (m/s) or the air data
    ``V alpha beta`` (m/s, rad); with air data, ``wind_ned`` (m/s) turns air-relative
    into ground velocity. Angles in rad, rates in rad/s, ``alt`` in m AMSL.

    Raises:
        InputError: neither (u, v, w) nor (V, alpha, beta) complete.
    """
    qt = quat_from_euler(phi, theta, psi)
    if u is not None and v is not None and w is not None:
        vb = np.array([u, v, w], float)
    elif V is not None and alpha is not None and beta is not None:
        vb = V * np.array([np.cos(alpha) * np.cos(beta), np.sin(beta), np.sin(alpha) * np.cos(beta)])
        vb = vb + dcm(qt).T @ np.asarray(wind_ned, float)
    else:
        raise InputError("state_from_measurements needs u, v, w or V, alpha, beta")
    return np.concatenate([[pn, pe, -alt], vb, qt, [p, q, r]]).astype(float)


def propagate(airframe: Airframe, model: AeroModel, x0: np.ndarray, t: np.ndarray, controls: np.ndarray,
              wind_ned=(0.0, 0.0, 0.0), effects: Effects | None = None, internal_rate_hz: float | None = None
              ) -> dict[str, np.ndarray]:
    """Deterministic simulation driven by given controls (no autopilot, sensors or turbulence).

    Args:
        airframe, model: the airframe and aero model to simulate.
        x0: initial state (13,) (:func:`state_from_measurements`), or (N, 13) for N runs at once (vmap).
        t: uniform sample times, s, shape (T,) (vehicle time; matters for ``effects.stuck``).
        controls: commanded (delta_e, delta_a, delta_r, delta_t), (T, 4) or (N, T, 4), held over
            each sample interval.
        wind_ned: steady wind, m/s (added to ``effects.wind_ned``).
        effects: optional truth deviations to simulate (aero terms, actuator delay / lag / stuck,
            mass, inertia, CG offset, wind); sensor effects do not apply.
        internal_rate_hz: RK4 rate; default 4x the sample rate.

    Returns:
        dict with the TRUTH_KEYS arrays (T,) (or (N, T)), plus ``t``, ``X`` (T, 10) and ``Y`` (T, 6)
        (leading N when batched).

    Raises:
        InputError: non-uniform ``t`` or arrays of mismatched shapes.
    """
    enable_x64()
    eff = effects or Effects()
    t = np.asarray(t, float)
    if t.ndim != 1 or len(t) < 2 or np.ptp(np.diff(t)) > 1e-6 * max(1.0, abs(t[1] - t[0])) or t[1] <= t[0]:
        raise InputError("propagate: t must be a uniform, increasing time grid of at least 2 samples")
    dt = float(np.mean(np.diff(t)))
    x0, u = np.asarray(x0, float), np.asarray(controls, float)
    batched = x0.ndim == 2
    if x0.shape[-1] != 13 or u.shape[-2:] != (len(t), 4) or (batched and u.shape[0] != x0.shape[0]) \
            or u.ndim != x0.ndim + 1:
        raise InputError(f"propagate: x0 must be (13,) or (N, 13) and controls (T, 4) or (N, T, 4) with T = {len(t)}; "
                         f"got {x0.shape} and {u.shape}")
    P = make_params(eff.apply_airframe(airframe), eff.apply_model(model), eff.cg_offset)
    lo, hi = control_limits(airframe)
    wind = np.asarray(wind_ned, float) + np.asarray(eff.wind_ned)
    z3 = np.zeros(3)
    loop = _loop(t[0], dt, eff, lo, hi, np.full(4, np.inf), wind, np.ones(3), z3)
    T = len(t)
    base = Schedule(*(jnp.zeros((T, n)) for n in (4, 4, 3, 6, 3, 4)))
    n_sub = int(round((internal_rate_hz or 4.0 / dt) * dt))
    gains = default_gains(model)

    def run(xi, ui):
        ui = jnp.asarray(ui)
        out = run_loop(P, loop, gains, base._replace(u_ext=ui), jnp.asarray(xi), ui[0], jnp.zeros(5),
                       n_sub=max(1, n_sub), hist_len=_hist_len(eff, dt), use_autopilot=False)
        return _post(P, out["x"], out["act"], jnp.asarray(wind), out["gust"])

    res = jax.vmap(run)(x0, u) if batched else run(x0, u)
    out = {k: np.asarray(v) for k, v in res.items()}
    out["t"] = t
    return out
