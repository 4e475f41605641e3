"""TEST HELPER: a synthetic sideslip record whose error is a known Gauss-Markov gust (the side-force aiding's tests).

The aircraft's heading is a lightly damped directional oscillator (0.2 Hz, damping 0.2; Etkin, *Dynamics of
Atmospheric Flight*, 1972, sec. 9.4) forced by the rudder and by the sideslip a first-order Gauss-Markov lateral gust
adds; the rudder flies doublets every 10 s, plus an optional yaw damper against the yaw rate. The kinematic
(inertial) sideslip is then a regressor whose error, the gust angle, is correlated with it. Production code never
imports this module.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter


def directional_record(seed: int, n: int, dt: float, gust_tau_s: float, damper: float = 0.0):
    """Integrate the oscillator (explicit Euler, step ``dt`` s, ``n`` samples).

    Args:
        seed: NumPy generator seed. n: samples. dt: step, s. gust_tau_s: the gust's correlation time, s (1-deg SD).
        damper: yaw-damper gain, rad of rudder per rad/s of yaw rate (0: doublets alone).

    Returns:
        ``(rng, beta_kin, g, r, dr)``: the generator after the gust's draws (for the caller's measurement noise), the
        kinematic sideslip, the gust angle, the yaw rate (rad/s) and the rudder (rad), each (n,).
    """
    rng = np.random.default_rng(seed)
    cmd = np.zeros(n)
    for k0 in range(100, n, 500):
        cmd[k0:k0 + 50], cmd[k0 + 50:k0 + 100] = 0.05, -0.05
    phi = np.exp(-dt / gust_tau_s)
    g = lfilter([np.sqrt(1 - phi * phi)], [1, -phi], rng.standard_normal(n)) * np.radians(1.0)   # gust angle
    w, zeta = 2 * np.pi * 0.2, 0.2
    psi, r, dr = np.zeros(n), np.zeros(n), np.zeros(n)
    for k in range(1, n):           # psi'' = w^2 (beta_air + N dr) - 2 zeta w psi', beta_air = -psi + g
        dr[k - 1] = cmd[k - 1] - damper * r[k - 1]
        r[k] = r[k - 1] + (w * w * (-psi[k - 1] + g[k - 1] - 0.5 * dr[k - 1]) - 2 * zeta * w * r[k - 1]) * dt
        psi[k] = psi[k - 1] + r[k] * dt
    dr[-1] = cmd[-1] - damper * r[-1]
    return rng, -psi, g, r, dr
