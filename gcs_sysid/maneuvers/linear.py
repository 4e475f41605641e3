"""Derivative estimates and the linear models around a flight condition: mode frequencies and responses.

1. Derivatives by ordinary least squares on the training rows (equation error, Morelli and Klein,
   *Aircraft System Identification*, 2nd ed., 2016, ch. 5); a derivative with the wrong sign or
   |t| < 2 is replaced by a typical small-UAV value (Beard and McLain, *Small Unmanned Aircraft*,
   2012, app. E, Aerosonde) and listed as assumed.
2. Short-period model (alpha, q) for the elevator and the lateral-directional model (beta, p, r,
   phi, with Ixz) for aileron and rudder (Etkin and Reid, *Dynamics of Flight*, 3rd ed., 1996,
   ch. 6 and 9), discretised exactly (zero-order hold).
3. Modes from the eigenvalues: short period and Dutch roll natural frequencies, roll subsidence
   inverse time constant (rad/s).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.linalg import expm

from ..aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from ..airframe import Airframe

__all__ = ["G", "derivative_estimates", "linear_models", "mode_omega", "modes", "response", "zoh_simulate",
           "zoh_simulate_stepwise"]

G = 9.80665
#: Typical values (Beard and McLain 2012, app. E, Aerosonde), signs per docs/conventions.md.
PRIOR = {("CZ", "alpha"): -5.6, ("CZ", "q_hat"): -7.9, ("CZ", "delta_e"): -0.13, ("Cm", "alpha"): -2.7,
         ("Cm", "q_hat"): -38.0, ("Cm", "delta_e"): -0.99, ("CY", "beta"): -0.98, ("CY", "delta_r"): 0.17,
         ("Cl", "beta"): -0.12, ("Cl", "p_hat"): -0.51, ("Cl", "r_hat"): 0.25, ("Cl", "delta_a"): -0.17,
         ("Cn", "beta"): 0.073, ("Cn", "p_hat"): -0.069, ("Cn", "r_hat"): -0.095, ("Cn", "delta_r"): -0.069}
LIN = ("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a", "delta_r", "delta_t")


def derivative_estimates(table: CoefficientTable, mask: np.ndarray) -> tuple[dict[tuple[str, str], float],
                                                                              dict[str, float], list[str]]:
    """Equation-error least squares of each coefficient on the linear regressors.

    Args:
        table: coefficient table (T rows). mask: (T,) bool rows to use.

    Returns:
        (derivs, at_ref, assumed): ``derivs[(coef, regressor)]`` (per rad, or per unit of the
        normalised rate); ``at_ref[coef]`` the fitted coefficient at the median regressors;
        ``assumed`` names like ``"Cm_q"`` replaced by typical values (wrong sign, |t| < 2 or no data).

    Source: Morelli and Klein (2016), ch. 5 (ordinary least squares, parameter standard errors).
    """
    rows = mask & np.all(np.isfinite(table.X), axis=1)
    cols = [REGRESSORS.index(r) for r in LIN]
    X = table.X[rows][:, cols]
    ref = np.median(X, axis=0) if len(X) else np.zeros(len(cols))
    derivs: dict[tuple[str, str], float] = {}
    at_ref: dict[str, float] = {}
    assumed: list[str] = []
    for j, c in enumerate(COEFFICIENTS):
        y = table.Y[rows, j]
        ok = np.isfinite(y)
        theta = np.full(len(cols), np.nan)
        tstat = np.zeros(len(cols))
        if ok.sum() > len(cols) + 2:
            A = np.column_stack([np.ones(ok.sum()), X[ok] - ref])
            sd = A.std(0)
            live = np.r_[True, sd[1:] > 1e-9]
            As = A[:, live] / np.where(sd[live] > 0, sd[live], 1.0)
            th, *_ = np.linalg.lstsq(As, y[ok], rcond=None)
            res = y[ok] - As @ th
            s2 = float(res @ res) / max(1, len(res) - As.shape[1])
            cov = s2 * np.linalg.pinv(As.T @ As)
            th_full = np.zeros(A.shape[1])
            se_full = np.full(A.shape[1], np.inf)
            th_full[live] = th / np.where(sd[live] > 0, sd[live], 1.0)
            se_full[live] = np.sqrt(np.maximum(np.diag(cov), 0)) / np.where(sd[live] > 0, sd[live], 1.0)
            at_ref[c] = float(th_full[0])
            theta = th_full[1:]
            tstat = np.abs(theta) / np.where(se_full[1:] > 0, se_full[1:], np.inf)
            theta[~live[1:]] = np.nan
        else:
            at_ref[c] = 0.0
        for k, r in enumerate(LIN):
            v = theta[k]
            prior = PRIOR.get((c, r))
            if prior is not None and (not np.isfinite(v) or np.sign(v) != np.sign(prior) or tstat[k] < 2.0):
                derivs[(c, r)] = prior
                assumed.append(f"{c}_{r.replace('_hat', '')}")
            else:
                derivs[(c, r)] = float(v) if np.isfinite(v) else 0.0
    return derivs, at_ref, assumed


def linear_models(d: dict[tuple[str, str], float], airframe: Airframe, V: float, rho: float,
                  alpha0: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Continuous linear models around a flight condition.

    Args:
        d: derivatives from :func:`derivative_estimates`. airframe: mass, inertia, geometry.
        V: airspeed m/s. rho: air density kg/m^3. alpha0: trim alpha, rad (= pitch in level flight).

    Returns:
        ``{"lon": (A (2,2), B (2,1)), "lat": (A (4,4), B (4,2))}``: longitudinal states
        (alpha, q) with input delta_e; lateral states (beta, p, r, phi) with inputs (delta_a, delta_r).

    Source: Etkin and Reid (1996) sec. 6.2 (short period), sec. 6.7-6.8 and 9 (lateral, Ixz via the
    inverse inertia).
    """
    qS = 0.5 * rho * V**2 * airframe.S
    m, b, c = airframe.mass, airframe.b, airframe.c
    Za, Zq, Zde = qS * d[("CZ", "alpha")] / m, qS * d[("CZ", "q_hat")] * c / (2 * V) / m, qS * d[("CZ", "delta_e")] / m
    Ma = qS * c * d[("Cm", "alpha")] / airframe.Iyy
    Mq = qS * c * d[("Cm", "q_hat")] * c / (2 * V) / airframe.Iyy
    Mde = qS * c * d[("Cm", "delta_e")] / airframe.Iyy
    A_lon = np.array([[Za / V, 1.0 + Zq / V], [Ma, Mq]])
    B_lon = np.array([[Zde / V], [Mde]])
    Iinv = np.linalg.inv(np.array([[airframe.Ixx, -airframe.Ixz], [-airframe.Ixz, airframe.Izz]]))
    row = lambda coef: np.array([d[(coef, "beta")], d[(coef, "p_hat")] * b / (2 * V),  # noqa: E731
                                 d[(coef, "r_hat")] * b / (2 * V), d[(coef, "delta_a")], d[(coef, "delta_r")]])
    LN = Iinv @ (qS * b * np.vstack([row("Cl"), row("Cn")]))          # (2, 5): beta p r da dr
    Y = qS / m * row("CY")
    th = alpha0
    A_lat = np.array([
        [Y[0] / V, Y[1] / V + np.sin(alpha0), Y[2] / V - np.cos(alpha0), G * np.cos(th) / V],
        [LN[0, 0], LN[0, 1], LN[0, 2], 0.0],
        [LN[1, 0], LN[1, 1], LN[1, 2], 0.0],
        [0.0, 1.0, np.tan(th), 0.0],
    ])
    B_lat = np.array([[Y[3] / V, Y[4] / V], [LN[0, 3], LN[0, 4]], [LN[1, 3], LN[1, 4]], [0.0, 0.0]])
    return {"lon": (A_lon, B_lon), "lat": (A_lat, B_lat)}


def mode_omega(models: dict, control: str) -> float:
    """Natural frequency (rad/s) of the mode a control excites, from the model's eigenvalues.

    delta_e: short period (largest |eigenvalue| of the (alpha, q) model); delta_a: roll subsidence
    (fastest real eigenvalue of the lateral model, i.e. 1/tau); delta_r: Dutch roll (the complex pair).
    """
    if control == "delta_e":
        ev = np.linalg.eigvals(models["lon"][0])
        return float(np.max(np.abs(ev)))
    ev = np.linalg.eigvals(models["lat"][0])
    if control == "delta_a":
        real = ev[np.abs(ev.imag) < 1e-9]
        return float(np.max(np.abs(real))) if real.size else float(np.max(np.abs(ev)))
    cplx = ev[np.abs(ev.imag) > 1e-9]
    return float(np.max(np.abs(cplx))) if cplx.size else float(np.median(np.abs(ev)))


def modes(models: dict) -> dict[str, float]:
    """The three modes a maneuver designer needs, in Hz (``omega / 2 pi``) with damping where oscillatory.

    Returns:
        ``short_period_hz``, ``short_period_zeta``, ``dutch_roll_hz``, ``dutch_roll_zeta``,
        ``roll_subsidence_hz`` (1 / (2 pi tau)), ``roll_tau_s``. NaN damping for a real pair.
    """
    out: dict[str, float] = {}
    for name, ctl, key in (("short_period", "delta_e", "lon"), ("dutch_roll", "delta_r", "lat")):
        w = mode_omega(models, ctl)
        ev = np.linalg.eigvals(models[key][0])
        near = ev[np.argmin(np.abs(np.abs(ev) - w))]
        out[f"{name}_hz"] = w / (2 * np.pi)
        out[f"{name}_zeta"] = float(-near.real / abs(near)) if abs(near.imag) > 1e-9 else float("nan")
    w = mode_omega(models, "delta_a")
    out["roll_subsidence_hz"] = w / (2 * np.pi)
    out["roll_tau_s"] = 1.0 / max(w, 1e-9)
    return out


#: Steps propagated per block by :func:`zoh_simulate` (one matrix product per block).
ZOH_BLOCK = 64


@lru_cache(maxsize=256)
def _zoh_blocks(key: bytes, n: int, m: int, dt: float, L: int) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Exact zero-order-hold discretisation and the block operators of :func:`zoh_simulate` (cached).

    Args:
        key: ``A.tobytes() + B.tobytes()`` (float64, C order) of the continuous model, A (n, n), B (n, m).
        n, m: state and input sizes. dt: step, s. L: steps per block.

    Returns:
        (Ad (n, n), Hp (L n, n), G (L n, L m)), or None when a power of ``Ad`` up to ``L`` is not finite
        or exceeds 1e150 (a model that diverges that fast is simulated step by step): ``Hp`` stacks
        ``Ad^1 .. Ad^L`` and ``G`` is the block lower-triangular Toeplitz matrix of
        ``Ad^(i-j) Bd`` (row block i = step s+i+1, column block j = input at s+j, j <= i), so that a
        block's states are ``Hp x_s + G u_block``.

    Source: Franklin, Powell and Workman, *Digital Control of Dynamic Systems*, 3rd ed., 1998, sec. 4.3
    (zero-order-hold equivalent by the matrix exponential of ``[[A, B], [0, 0]] dt``, and the
    convolution sum of the discrete state equation).
    """
    A = np.frombuffer(key[:8 * n * n]).reshape(n, n)
    B = np.frombuffer(key[8 * n * n:]).reshape(n, m)
    M = expm(np.block([[A, B], [np.zeros((m, n + m))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n:]
    P = np.empty((L + 1, n, n))
    P[0] = np.eye(n)
    for i in range(1, L + 1):
        P[i] = Ad @ P[i - 1]
    if not (np.all(np.isfinite(P)) and np.max(np.abs(P)) < 1e150):
        return None
    PB = P[:L] @ Bd                                # (L, n, m): Ad^j Bd
    G = np.zeros((L, n, L, m))
    for i in range(L):
        G[i, :, :i + 1, :] = PB[i::-1].transpose(1, 0, 2)   # input j acts on step i through Ad^(i-j) Bd
    return Ad, P[1:].reshape(L * n, n), G.reshape(L * n, L * m)


def zoh_simulate(A: np.ndarray, B: np.ndarray, U: np.ndarray, dt: float) -> np.ndarray:
    """Zero-order-hold response of ``x' = A x + B u`` from x = 0.

    The discrete recursion ``x[k] = Ad x[k-1] + Bd u[k-1]`` is evaluated ``ZOH_BLOCK`` steps at a time
    (one product with the block operators of :func:`_zoh_blocks`, cached per model and step) instead of
    one small product per step; the result equals the step-by-step recursion
    (:func:`zoh_simulate_stepwise`) to rounding (relative 1e-12 on the maneuver designs' models,
    checked in ``tests/test_maneuver_zoh.py``).

    Args:
        A: (n, n) state matrix, 1/s. B: (n, m) input matrix. U: (K, m) inputs, held over each step.
        dt: step, s.

    Returns:
        x (K, n), ``x[0] = 0``; rows from the first whose magnitude reaches 1e6 (divergence) are NaN.

    Source: Franklin, Powell and Workman (1998) sec. 4.3.
    """
    A = np.ascontiguousarray(A, dtype=float)
    B = np.ascontiguousarray(B, dtype=float)
    n, m = B.shape
    K = len(U)
    ops = _zoh_blocks(A.tobytes() + B.tobytes(), n, m, float(dt), ZOH_BLOCK) if K > 1 else None
    if ops is None:
        return zoh_simulate_stepwise(A, B, U, dt)
    _, Hp, G = ops
    L = ZOH_BLOCK
    nb = -(-(K - 1) // L)                          # blocks covering steps 1 .. K-1
    Upad = np.zeros((nb * L, m))
    Upad[:K - 1] = np.asarray(U, dtype=float)[:K - 1]
    Ub = Upad.reshape(nb, L * m)
    forced = Ub @ G.T                              # (nb, L n): every block's response from rest
    out = np.empty((nb * L + 1, n))
    out[0] = 0.0
    xs = np.zeros(n)
    with np.errstate(over="ignore", invalid="ignore"):   # a diverging model overflows; it is cut below
        for j in range(nb):
            blk = Hp @ xs + forced[j]
            out[1 + j * L:1 + (j + 1) * L] = blk.reshape(L, n)
            xs = out[(j + 1) * L]
        x = out[:K]
        bad = ~np.all(np.abs(x) < 1e6, axis=1)
    if bad.any():
        x[int(np.argmax(bad)):] = np.nan
    return x


def zoh_simulate_stepwise(A: np.ndarray, B: np.ndarray, U: np.ndarray, dt: float) -> np.ndarray:
    """:func:`zoh_simulate` one step at a time (the reference the block form is checked against).

    Args and returns as :func:`zoh_simulate`.
    """
    n, m = B.shape
    M = expm(np.block([[A, B], [np.zeros((m, n + m))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n:]
    x = np.zeros((len(U), n))
    with np.errstate(over="ignore", invalid="ignore"):   # a diverging model overflows; it is cut below
        for k in range(1, len(U)):
            x[k] = Ad @ x[k - 1] + Bd @ U[k - 1]
        bad = ~np.all(np.abs(x) < 1e6, axis=1)   # one check after the loop, not one per step (3x faster)
    if bad.any():
        x[int(np.argmax(bad)):] = np.nan
    return x


def response(models: dict, u: dict[str, np.ndarray], t: np.ndarray) -> dict[str, np.ndarray] | None:
    """Deviations from trim of alpha, q, beta, p, r, phi (rad, rad/s), each (K,), for control deviations
    ``u`` (rad, (K,) each, on the uniform grid ``t``); None when the linear model diverges."""
    dt = t[1] - t[0]
    z = np.zeros(len(t))
    A, B = models["lon"]
    lon = zoh_simulate(A, B, u.get("delta_e", z)[:, None], dt)
    A, B = models["lat"]
    lat = zoh_simulate(A, B, np.column_stack([u.get("delta_a", z), u.get("delta_r", z)]), dt)
    if not (np.isfinite(lon).all() and np.isfinite(lat).all()):
        return None
    return {"alpha": lon[:, 0], "q": lon[:, 1], "beta": lat[:, 0], "p": lat[:, 1], "r": lat[:, 2], "phi": lat[:, 3]}
