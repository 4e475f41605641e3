"""A small stabilising autopilot, like ArduPlane's FBWA/cruise loops, that holds the aircraft between maneuvers.

Loops (evaluated at the plan rate from the true state, i.e. an ideal AHRS):

- altitude -> climb-rate demand ``hdot_c = clip(K_h (h_c - h), +-hdot_max)``, pitch demand
  ``theta_c = theta_ff + hdot_c / V + K_g (hdot_c - hdot) / V`` (limited);
- pitch: desired ``dCm = K_th e_th + K_ith int(e_th) - K_q q``, ``delta_e = de_ff + dCm / Cm_delta_e``;
- heading -> bank demand ``phi_c = clip(K_psi wrap(psi_c - psi), +-phi_max)``;
- roll: ``dCl = K_phi e_phi + K_iphi int(e_phi) - K_p p``, ``delta_a = da_ff + dCl / Cl_delta_a``;
- yaw damper: ``dCn = -K_r (r - r_turn)``, ``delta_r = dr_ff + dCn / Cn_delta_r``;
- airspeed: ``delta_t = dt_ff + K_V e_V + K_iV int(e_V)``.

Working in coefficient increments and dividing by the model's own control
derivatives makes the loop signs follow the model's sign conventions and keeps
the loop gains sensible for any airframe of trainer size; the feedback moment
grows with qbar like the aircraft's own (ArduPlane scales its gains with
airspeed for the same reason). Maneuver inputs are added to the outputs
(``closed`` mode, like ArduPilot's system-identification injection) or, in
``open`` mode, the channel's output is frozen at its value when the maneuver
starts and its integrator is held.
"""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp

from .dynamics import dcm, euler_from_quat
from .model_file import AeroModel

__all__ = ["Gains", "default_gains", "autopilot_step"]


class Gains(NamedTuple):
    """Loop gains (floats; a pytree). See the module docstring for the laws."""

    K_th: float = 0.9        # dCm per rad of pitch error
    K_ith: float = 0.3       # dCm per rad s
    K_q: float = 0.07        # dCm per rad/s
    K_phi: float = 0.15      # dCl per rad of bank error
    K_iphi: float = 0.03
    K_p: float = 0.02        # dCl per rad/s
    K_r: float = 0.015       # dCn per rad/s
    K_psi: float = 0.8       # rad bank per rad heading error
    K_h: float = 0.3         # 1/s, climb-rate demand per m of altitude error
    K_g: float = 0.5         # pitch per climb-rate error (times 1/V)
    K_V: float = 0.06        # throttle per m/s
    K_iV: float = 0.03       # throttle per m
    hdot_max: float = 3.0    # m/s
    phi_max: float = 0.45    # rad
    theta_max: float = 0.3   # rad (pitch demand excursion from feed-forward)
    dC_max: float = 0.07     # limit of the pitch loop's dCm (half of it for the roll loop's dCl)
    Cm_de: float = -0.9      # control derivatives used to turn dC into deflections
    Cl_da: float = -0.25
    Cn_dr: float = -0.06


def default_gains(model: AeroModel) -> Gains:
    """Gains with the control derivatives taken from ``model`` (defaults where a derivative is ~0)."""
    g = Gains()

    def pick(c, term, default):
        v = model.value(c, term)
        return v if abs(v) > 1e-3 else default

    return g._replace(Cm_de=pick("Cm", "delta_e", g.Cm_de), Cl_da=pick("Cl", "delta_a", g.Cl_da),
                      Cn_dr=pick("Cn", "delta_r", g.Cn_dr))


def autopilot_step(g: Gains, x, V, sp, ff, integ, held, openm, dt, lo, hi):
    """One autopilot update.

    Args:
        g: gains.
        x: true state (13,) (see ``dynamics``); V: true airspeed m/s.
        sp: setpoints (3,): airspeed m/s, altitude m, heading rad.
        ff: feed-forward (6,): theta rad, delta_e delta_a delta_r rad, delta_t, phi rad.
        integ: integrator states (3,): pitch, roll, airspeed errors.
        held: (4,) outputs frozen for open-loop maneuvers; openm (4,) 1.0 where open.
        dt: update interval s; lo, hi: (4,) command limits.

    Returns:
        (commands (4,) before maneuver inputs, new integ (3,), new held (4,), demand (4,)): demand is
        what ArduPlane reports in NAV_CONTROLLER_OUTPUT: bank and pitch demands (rad), altitude
        error (m) and airspeed error (m/s), both target minus current.
    """
    phi, theta, psi = euler_from_quat(x[6:10])
    p, q, r = x[10], x[11], x[12]
    hdot = -(dcm(x[6:10]) @ x[3:6])[2]
    Vs = jnp.maximum(V, 5.0)
    e_h = sp[1] + x[2]
    hdot_c = jnp.clip(g.K_h * e_h, -g.hdot_max, g.hdot_max)
    theta_c = ff[0] + jnp.clip(hdot_c / Vs + g.K_g * (hdot_c - hdot) / Vs, -g.theta_max, g.theta_max)
    e_psi = jnp.arctan2(jnp.sin(sp[2] - psi), jnp.cos(sp[2] - psi))
    phi_c = ff[5] + jnp.clip(g.K_psi * e_psi, -g.phi_max, g.phi_max)
    e_th, e_phi, e_V = theta_c - theta, phi_c - phi, sp[0] - V
    frozen = jnp.stack([openm[0], openm[1], openm[3]])
    integ = integ + (1.0 - frozen) * dt * jnp.stack([e_th, e_phi, e_V])
    integ = jnp.clip(integ, jnp.array([-0.3, -0.5, -10.0]), jnp.array([0.3, 0.5, 10.0]))
    dCm = jnp.clip(g.K_th * e_th + g.K_ith * integ[0] - g.K_q * q, -g.dC_max, g.dC_max)
    dCl = jnp.clip(g.K_phi * e_phi + g.K_iphi * integ[1] - g.K_p * p, -0.5 * g.dC_max, 0.5 * g.dC_max)
    r_turn = 9.80665 * jnp.sin(phi) * jnp.cos(theta) / Vs
    dCn = -g.K_r * (r - r_turn)
    cmd = jnp.stack([ff[1] + dCm / g.Cm_de, ff[2] + dCl / g.Cl_da, ff[3] + dCn / g.Cn_dr,
                     ff[4] + g.K_V * e_V + g.K_iV * integ[2]])
    cmd = jnp.clip(cmd, lo, hi)
    out = jnp.where(openm > 0.5, held, cmd)
    return out, integ, out, jnp.stack([phi_c, theta_c, e_h, e_V])
