"""The rate of change of the angle of attack from the equations of motion, not by differentiation.

``alpha = atan2(w_a, u_a)`` with ``(u_a, v_a, w_a)`` the air-relative body velocity. Its derivative
follows from the body-axis force equations (Stevens, Lewis and Johnson, *Aircraft Control and
Simulation*, 3rd ed., Wiley 2016, sec. 2.5; Morelli and Klein, *Aircraft System Identification*,
2nd ed., AIAA 2016, ch. 3, the alpha equation)::

    u_dot = f_x + g_x + r v - q w                 (body axes, over the Earth; f the specific force,
    w_dot = f_z + g_z + q u - p v                  g the gravity in body axes, u v w the ground velocity)
    alpha_dot = (u_a w_dot - w_a u_dot) / (u_a^2 + w_a^2)

with the steady wind's change in body axes left out (a wind fixed over the Earth does not
accelerate the aircraft). Every term is a measured or smoothed signal: the accelerometers, the gyros,
the attitude and the GPS velocity, so nothing is differentiated and the accelerometer's white noise
enters only divided by the airspeed. This is also the form flight simulators evaluate for the
``alpha_dot`` terms of their aerodynamic models (JSBSim's ``aero/alphadot-rad_sec``,
``FGAuxiliary``: the air-relative velocity with the time derivative of the ground velocity), so it
excludes the rate of change of the gust itself: ``d/dt`` of a reconstructed ``alpha`` would add the
gust's derivative, the noisiest part of the air data.

The non-dimensional regressor is ``alpha_dot_hat = alpha_dot c / (2 V)`` (Etkin, *Dynamics of
Atmospheric Flight*, Wiley 1972, ch. 5: ``CL_alpha_dot``, ``Cm_alpha_dot``, the downwash lag).
"""

from __future__ import annotations

import numpy as np

from .ekf import G0

__all__ = ["kinematic_alpha_rate"]


def kinematic_alpha_rate(C: np.ndarray, v_ned: np.ndarray, f_body: np.ndarray, rates: np.ndarray,
                         V: np.ndarray, alpha: np.ndarray, beta: np.ndarray, g: float = G0) -> np.ndarray:
    """``alpha_dot`` from the force equations (module docstring).

    Args:
        C: (T, 3, 3) body-to-NED direction cosine matrices (``v_ned = C @ v_body``).
        v_ned: (T, 3) ground velocity, NED, m/s.
        f_body: (T, 3) specific force at the CG, body axes, m/s^2 (accelerometer minus bias).
        rates: (T, 3) body rates p q r, rad/s.
        V: (T,) true airspeed, m/s. alpha, beta: (T,) air angles, rad.
        g: gravity, m/s^2 (down in NED).

    Returns:
        (T,) ``alpha_dot`` in rad/s; NaN where an input is not finite or ``u_a^2 + w_a^2`` is below 1 m^2/s^2.

    Source: Stevens, Lewis and Johnson (2016) sec. 2.5; Morelli and Klein (2016) ch. 3.
    """
    vb = np.einsum("tji,tj->ti", C, v_ned)                     # C^T v_ned: ground velocity, body axes
    gb = g * C[:, 2, :]                                        # C^T (0, 0, g)
    p, q, r = rates[:, 0], rates[:, 1], rates[:, 2]
    u, v, w = vb[:, 0], vb[:, 1], vb[:, 2]
    u_dot = f_body[:, 0] + gb[:, 0] + r * v - q * w
    w_dot = f_body[:, 2] + gb[:, 2] + q * u - p * v
    ua = V * np.cos(alpha) * np.cos(beta)
    wa = V * np.sin(alpha) * np.cos(beta)
    den = ua**2 + wa**2
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den >= 1.0, (ua * w_dot - wa * u_dot) / den, np.nan)
