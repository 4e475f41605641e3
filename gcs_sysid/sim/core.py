"""The compiled simulation loop: autopilot, actuators, turbulence and RK4 in one ``jax.lax.scan``.

Timing: the outer scan runs at the plan rate (one *tick* = one logged sample,
``dt`` s); each tick runs ``n_sub`` RK4 sub-steps of ``h = dt / n_sub``. At the
start of tick k the autopilot (or the given external command) produces the
command ``u_k``, held over the tick (zero-order hold, as an autopilot's servo
output). Each sub-step first updates the actuators, in discrete time at the
sub-step rate:

- pure delay ``d``: the input at time s is the command of the latest tick j with
  ``t_j + d <= s`` (ring buffer of ``hist_len`` ticks);
- first-order lag ``tau``: ``a <- u + (a - u) exp(-h / tau)`` (exact for held u; tau = 0: a = u);
- rate limit ``|da/dt| <= rate`` and position limits ``[lo, hi]``;
- stuck: from vehicle time ``stuck`` on, the surface stays where it is;

then integrates the rigid body over ``h`` with the surfaces held (RK4). Dryden
gusts (``environment``) are propagated once per tick (implicit Euler) with the
current airspeed; within the tick the gust moves linearly from its value at
``t_k`` to the one at ``t_k + dt`` (held over each sub-step), so the truth has
no 50 Hz steps that no real turbulence has. The sampled outputs of tick k are the
state at ``t_k`` and the surface positions acting on ``[t_k, t_k + h)``.
"""

from __future__ import annotations

from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp

from .autopilot import Gains, autopilot_step
from .dynamics import Params, air_data, rk4_step

__all__ = ["Loop", "Schedule", "run_loop", "turbulence_init"]


class Loop(NamedTuple):
    """Per-flight constants (arrays): t0 vehicle time of tick 0 (s), dt tick (s),
    delay tau rate lo hi stuck (4,) per control, wind (3,) steady NED m/s,
    turb_L turb_sigma (3,) Dryden scale lengths (m) and rms (m/s), disable disable_at (4,):
    ArduPlane-like output failure, the vehicle time (s) from which a channel's output
    (what is logged and what the actuator receives) is held at ``disable_at`` while the
    autopilot's demand goes on (inf: never)."""

    t0: jnp.ndarray
    dt: jnp.ndarray
    delay: jnp.ndarray
    tau: jnp.ndarray
    rate: jnp.ndarray
    lo: jnp.ndarray
    hi: jnp.ndarray
    stuck: jnp.ndarray
    wind: jnp.ndarray
    turb_L: jnp.ndarray
    turb_sigma: jnp.ndarray
    disable: jnp.ndarray
    disable_at: jnp.ndarray


class Schedule(NamedTuple):
    """Per-tick inputs, leading axis T: man (T,4) maneuver inputs, openm (T,4) 1.0 where a
    channel is flown open-loop, sp (T,3) airspeed / altitude / heading setpoints, ff (T,6)
    trim feed-forward (theta, delta_e, delta_a, delta_r, delta_t, phi), noise (T,3) unit normal
    turbulence noise, u_ext (T,4) external commands (used when the autopilot is off)."""

    man: jnp.ndarray
    openm: jnp.ndarray
    sp: jnp.ndarray
    ff: jnp.ndarray
    noise: jnp.ndarray
    u_ext: jnp.ndarray


def _gust(turb, L, sigma, V):
    b = L / jnp.maximum(V, 5.0)
    gu = sigma[0] * jnp.sqrt(2 * b[0]) * turb[0]
    gv = sigma[1] * jnp.sqrt(b[1]) * (turb[1] + jnp.sqrt(3.0) * b[1] * turb[2])
    gw = sigma[2] * jnp.sqrt(b[2]) * (turb[3] + jnp.sqrt(3.0) * b[2] * turb[4])
    return jnp.stack([gu, gv, gw]), b


def _turb_update(turb, b, zeta, dt):
    """Implicit-Euler step of the forming filters (stable for any dt / b), unit-intensity white input:
    x_u' = (-x_u + eta) / b;  x1' = x2,  x2' = (-x1 - 2 b x2 + eta) / b^2."""
    sq = jnp.sqrt(dt)
    xu = (turb[0] + sq * zeta[0] / b[0]) / (1.0 + dt / b[0])

    def second(x1, x2, bb, z):
        x2 = x2 + sq * z / bb**2
        det = 1.0 + 2 * dt / bb + dt**2 / bb**2
        return ((1 + 2 * dt / bb) * x1 + dt * x2) / det, (-dt / bb**2 * x1 + x2) / det

    v1, v2 = second(turb[1], turb[2], b[1], zeta[1])
    w1, w2 = second(turb[3], turb[4], b[2], zeta[2])
    return jnp.stack([xu, v1, v2, w1, w2])


def turbulence_init(normals, L, sigma, V):
    """Stationary initial Dryden state (5,) from 5 unit normals (numpy or JAX)."""
    b = L / max(float(V), 5.0)
    # variances of the states of the forming filters driven by unit-intensity white noise
    s_u = (1 / (2 * b[0])) ** 0.5
    s_x1 = [(1 / (4 * bb)) ** 0.5 for bb in b[1:]]
    s_x2 = [(1 / (4 * bb**3)) ** 0.5 for bb in b[1:]]
    n = normals
    return jnp.asarray([s_u * n[0], s_x1[0] * n[1], s_x2[0] * n[2], s_x1[1] * n[3], s_x2[1] * n[4]])


@partial(jax.jit, static_argnames=("n_sub", "hist_len", "use_autopilot"))
def run_loop(P: Params, loop: Loop, gains: Gains, sched: Schedule, x0, act0, turb0, *, n_sub: int,
             hist_len: int, use_autopilot: bool):
    """Run the whole flight.

    Args:
        P: dynamics parameters (truth airframe and model).
        loop: per-flight constants.
        gains: autopilot gains.
        sched: per-tick inputs (T rows).
        x0: initial state (13,); act0: initial surfaces and command (4,); turb0: (5,).
        n_sub: RK4 sub-steps per tick. hist_len: command ring-buffer length (ticks).
        use_autopilot: True: autopilot + maneuvers; False: commands ``sched.u_ext``.

    Returns:
        dict of arrays with leading axis T: ``x`` (T,13), ``act`` (T,4), ``cmd`` (T,4), ``gust`` (T,3),
        ``demand`` (T,4) the autopilot's bank / pitch demand (rad), altitude and airspeed errors (zeros
        without the autopilot).
    """
    h = loop.dt / n_sub
    idx4 = jnp.arange(4)

    def substep(c, n):
        x, act, hist, t_k = c
        s = t_k + n * h
        m = jnp.clip(jnp.ceil((loop.delay - n * h) / loop.dt - 1e-9), 0, hist_len - 1).astype(jnp.int32)
        u = hist[hist_len - 1 - m, idx4]
        decay = jnp.where(loop.tau > 0, jnp.exp(-h / jnp.where(loop.tau > 0, loop.tau, 1.0)), 0.0)
        a_new = u + (act - u) * decay
        a_new = act + jnp.clip(a_new - act, -loop.rate * h, loop.rate * h)
        a_new = jnp.clip(a_new, loop.lo, loop.hi)
        a_new = jnp.where(s >= loop.stuck, act, a_new)
        return (x, a_new, hist, t_k), a_new

    def tick(carry, inp):
        x, act, hist, integ, held, turb, k = carry
        man, openm, sp, ff, zeta, u_ext = inp
        t_k = loop.t0 + k * loop.dt
        V0, *_ = air_data(x, loop.wind, jnp.zeros(3))
        on = loop.turb_sigma > 0
        gust, b = _gust(turb, loop.turb_L, loop.turb_sigma, V0)
        gust = jnp.where(on, gust, 0.0)
        turb = _turb_update(turb, b, zeta, loop.dt)
        gust_next = jnp.where(on, _gust(turb, loop.turb_L, loop.turb_sigma, V0)[0], 0.0)
        if use_autopilot:
            V, *_ = air_data(x, loop.wind, gust)
            ap, integ, held, demand = autopilot_step(gains, x, V, sp, ff, integ, held, openm, loop.dt, loop.lo,
                                                     loop.hi)
            cmd = jnp.clip(ap + man, loop.lo, loop.hi)
        else:
            cmd = u_ext
            demand = jnp.zeros(4)
        cmd = jnp.where(t_k >= loop.disable, loop.disable_at, cmd)      # the output fails, the demand goes on
        hist = jnp.concatenate([hist[1:], cmd[None]], axis=0)

        def body(c, n):
            c, a = substep(c, n)
            x_, a_, hist_, t_ = c
            g_n = gust + (n / n_sub) * (gust_next - gust)        # gusts linear over the tick
            x_ = rk4_step(P, x_, a_, loop.wind, g_n, h)
            return (x_, a_, hist_, t_), a

        (x_new, act_new, hist, _), acts = jax.lax.scan(body, (x, act, hist, t_k), jnp.arange(n_sub))
        out = {"x": x, "act": acts[0], "cmd": cmd, "gust": gust, "demand": demand}
        return (x_new, act_new, hist, integ, held, turb, k + 1), out

    hist0 = jnp.tile(act0[None], (hist_len, 1))
    carry0 = (x0, act0, hist0, jnp.zeros(3), act0, turb0, jnp.asarray(0, dtype=jnp.int32))
    _, out = jax.lax.scan(tick, carry0, (sched.man, sched.openm, sched.sp, sched.ff, sched.noise, sched.u_ext))
    return out
