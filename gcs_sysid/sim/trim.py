"""Trim: the steady, wings-level, level-flight equilibrium at a given airspeed and altitude.

Unknowns ``(alpha, beta, delta_e, delta_a, delta_r, delta_t)``, with bank
``phi = 0``, flight-path angle 0 (so ``theta = alpha``), body rates 0 and no
wind; equations: the six body-axis accelerations ``du/dt, dv/dt, dw/dt,
dp/dt, dq/dt, dr/dt`` of :func:`gcs_sysid.sim.dynamics.derivative` vanish.
Solved by Levenberg-Marquardt (``scipy.optimize.least_squares``) with a
central-difference Jacobian of the compiled JAX residual (Stevens, Lewis and
Johnson, *Aircraft Control and Simulation*, 3rd ed., sec. 3.6, trimming by
numerical optimisation).
"""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import least_squares

from ..errors import DataError
from .dynamics import Params, derivative

__all__ = ["Trim", "trim_state", "trim"]


@dataclass(frozen=True)
class Trim:
    """A trimmed flight condition.

    Attributes:
        airspeed: true airspeed, m/s. altitude: m (AMSL). heading: rad.
        alpha, beta, theta: rad. controls: (delta_e, delta_a, delta_r, delta_t).
        x: the trimmed state (13,) (see ``dynamics``), no wind.
        residual: max |acceleration| left, m/s^2 or rad/s^2.
    """

    airspeed: float
    altitude: float
    heading: float
    alpha: float
    beta: float
    theta: float
    controls: tuple[float, float, float, float]
    x: np.ndarray
    residual: float


def trim_state(z, V, alt, psi):
    """State (13,) for trim unknowns ``z = (alpha, beta, ...)``: level, wings level, no rates (JAX)."""
    alpha, beta = z[0], z[1]
    th = alpha
    u, v, w = V * jnp.cos(alpha) * jnp.cos(beta), V * jnp.sin(beta), V * jnp.sin(alpha) * jnp.cos(beta)
    ct, st, cp, sp = jnp.cos(th / 2), jnp.sin(th / 2), jnp.cos(psi / 2), jnp.sin(psi / 2)
    q = jnp.stack([ct * cp, -st * sp, st * cp, ct * sp])
    return jnp.concatenate([jnp.stack([0.0, 0.0, -alt, u, v, w]), q, jnp.zeros(3)])


@jax.jit
def _residual(P: Params, z, V, alt, psi):
    x = trim_state(z, V, alt, psi)
    delta = z[2:6]
    xd, _ = derivative(P, x, delta, jnp.zeros(3), jnp.zeros(3))
    return jnp.concatenate([xd[3:6], xd[10:13]])


def _jac(fun, z, step=1e-6):
    """Central-difference Jacobian (6, 6) of ``fun`` at ``z`` (the compiled residual is cheap)."""
    cols = []
    for i in range(len(z)):
        dz = np.zeros_like(z)
        dz[i] = step
        cols.append((fun(z + dz) - fun(z - dz)) / (2 * step))
    return np.stack(cols, 1)


def trim(P: Params, airspeed: float, altitude: float, heading: float = 0.0,
         lo: np.ndarray | None = None, hi: np.ndarray | None = None) -> Trim:
    """Trim the aircraft of ``P`` in level flight.

    Args:
        P: dynamics parameters (truth airframe and model).
        airspeed: m/s (true). altitude: m AMSL. heading: rad.
        lo, hi: (4,) control limits to check the result against.

    Returns:
        the :class:`Trim`.

    Raises:
        DataError: no equilibrium found (residual above 1e-6) or it needs controls beyond the limits.
    """
    V, alt, psi = float(airspeed), float(altitude), float(heading)
    z0 = np.array([0.05, 0.0, 0.0, 0.0, 0.0, 0.5])
    fun = lambda z: np.asarray(_residual(P, jnp.asarray(z), V, alt, psi))  # noqa: E731
    res = least_squares(fun, z0, jac=lambda z: _jac(fun, z),
                        method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=200)
    z = res.x
    resid = float(np.max(np.abs(res.fun)))
    if resid > 1e-6 or abs(z[0]) > 0.35:
        raise DataError(f"cannot trim at {V:g} m/s, {alt:g} m: no level-flight equilibrium "
                        f"(residual {resid:.2g}; not enough thrust or control power at this speed?)")
    if lo is not None and hi is not None:
        names = ("delta_e", "delta_a", "delta_r", "delta_t")
        for i, n in enumerate(names):
            if not lo[i] - 1e-9 <= z[2 + i] <= hi[i] + 1e-9:
                raise DataError(f"cannot trim at {V:g} m/s: needs {n} = {z[2 + i]:.3g}, outside "
                                f"[{lo[i]:.3g}, {hi[i]:.3g}]")
    x = np.asarray(trim_state(jnp.asarray(z), V, alt, psi))
    return Trim(V, alt, psi, float(z[0]), float(z[1]), float(z[0]), tuple(float(v) for v in z[2:6]), x, resid)
