"""Body-axis aerodynamic coefficients and regressors from smoothed flight states.

Forces from the specific force at the CG (the accelerometer measures
``(aerodynamic + thrust force) / m``)::

    CX = (m ax - T) / (qbar S),   CY = m ay / (qbar S),   CZ = m az / (qbar S)

with ``T`` the thrust along body x from the airframe's thrust model (without
one, CX includes thrust). Moments from Euler's equations with the full inertia
tensor ``[[Ixx, 0, -Ixz], [0, Iyy, 0], [-Ixz, 0, Izz]]`` (``M = I w_dot + w x I w``)::

    L = Ixx p_dot - Ixz (r_dot + p q) + (Izz - Iyy) q r
    M = Iyy q_dot + (Ixx - Izz) p r + Ixz (p^2 - r^2)
    N = Izz r_dot - Ixz (p_dot - q r) + (Iyy - Ixx) p q
    Cl = L / (qbar S b),   Cm = M / (qbar S c),   Cn = N / (qbar S b)

Regressors: alpha, beta, ``p_hat = p b / (2V)``, ``q_hat = q c / (2V)``,
``r_hat = r b / (2V)``, delta_e, delta_a, delta_r, delta_t, V.

References:
    Stevens, Lewis and Johnson, *Aircraft Control and Simulation*, 3rd ed.,
    Wiley 2016, ch. 1 (rigid-body moment equations with Ixz).
    Klein and Morelli, *Aircraft System Identification*, AIAA 2006, ch. 3
    (equations of motion; coefficients from measured accelerations and rates).
"""

from __future__ import annotations

import numpy as np

from ..airframe import Airframe
from ..estimation.states import FlightStates
from .table import REGRESSORS, CoefficientTable

__all__ = ["compute_coefficients", "aero_moments", "stated_input_variance", "stated_scale_variance",
           "stated_map_covariance", "stated_output_variance", "QBAR_MIN", "STATED_INPUT_NOISE"]

QBAR_MIN = 5.0  #: Pa; rows with a smaller dynamic pressure are not valid (coefficients blow up)
#: Regressors whose per-row error variance the estimator states for the GP's band (``CoefficientTable.x_var``):
#: the air angles, the only regressors built partly from the measured coefficients themselves (the
#: specific-force aiding), so that their errors hide in the GP's residuals (``docs/gp.md``).
STATED_INPUT_NOISE = ("alpha", "beta")


def stated_input_variance(states: FlightStates) -> np.ndarray | None:
    """Per-row variance of the regressors' errors that the estimator states, beyond their flight-common offset.

    For each regressor in :data:`STATED_INPUT_NOISE` with a smoothed 1-sigma in ``states.sigma`` (rad):
    ``sigma^2 - offset^2`` (``states.offsets``, rad; ``sigma`` holds the offset in quadrature, and a common
    offset cancels at the flight's own regressors, so it belongs to the band at exact conditions instead),
    floored at 0. Other columns, and rows where no sigma is stated (the angle was not aided), are NaN.

    Args:
        states: smoothed states with ``sigma`` and ``offsets``.

    Returns:
        ``(T, 10)`` in the regressors' units squared (columns :data:`~gcs_sysid.aero.table.REGRESSORS`), or
        None when no such sigma is stated.
    """
    sig = getattr(states, "sigma", None) or {}
    keys = [k for k in STATED_INPUT_NOISE if k in sig]
    if not keys:
        return None
    offsets = getattr(states, "offsets", None) or {}
    out = np.full((len(states), len(REGRESSORS)), np.nan)
    for k in keys:
        s = np.asarray(sig[k], float)
        with np.errstate(invalid="ignore"):
            out[:, REGRESSORS.index(k)] = np.maximum(s**2 - float(offsets.get(k, 0.0)) ** 2, 0.0)
    return out


def stated_scale_variance(states: FlightStates) -> np.ndarray | None:
    """Variance of the aided air angles' relative scale error, common to the flight, ``(10,)``.

    The aided angle's scale is set by the force slope (``CZ_alpha``, ``CY_beta``) fitted on this flight,
    which errors in variables bias; the estimator states its standard uncertainty as the aided and the
    kinematic angle's disagreement in scale (:attr:`gcs_sysid.estimation.airangles.AxisFit.scale_sigma`).
    A model learned on angles scaled by ``1 + s`` is off by ``-dm/dx s (x - mean x)`` at exact conditions.

    Args:
        states: smoothed states with ``angle_fits``.

    Returns:
        ``(10,)`` ``scale_sigma^2`` in the alpha / beta columns of an aided axis, 0 elsewhere; None when no
        axis was aided.
    """
    fits = getattr(states, "angle_fits", None) or {}
    out = np.zeros(len(REGRESSORS))
    for k, fit in fits.items():
        s = float(getattr(fit, "scale_sigma", np.nan))
        if k in REGRESSORS and getattr(fit, "used", False) and np.isfinite(s):
            out[REGRESSORS.index(k)] = s**2
    return out if np.any(out) else None


def stated_map_covariance(states: FlightStates) -> np.ndarray | None:
    """Second moment of the aided air angles' flight-common linear error, ``(10, 10, 10)``.

    An aided angle's error that follows the manoeuvre, ``e_j(x) = sum_d M_jd (x_d - mean x_d)`` (the force
    model's slopes biased by errors in variables: the scale, and e.g. alpha's error along ``q_hat`` and
    ``delta_e``), as the estimator states it (:attr:`gcs_sysid.estimation.airangles.AxisFit.map_cov`). A model
    learned on such angles is off by ``-dm/dx_j e_j(x)`` at exact conditions; at the flight's own
    regressors it cancels (``docs/estimation.md``, "The aided angles' common linear error").

    Args:
        states: smoothed states with ``angle_fits``.

    Returns:
        ``(10, 10, 10)``: ``[j]`` the ``(10, 10)`` second moment of ``M_j.`` for aided angle ``j`` (units of
        ``x_j^2 / (x_d x_e)``; columns :data:`~gcs_sysid.aero.table.REGRESSORS`), zeros for the other
        regressors and terms; None when no axis stated one.
    """
    fits = getattr(states, "angle_fits", None) or {}
    D = len(REGRESSORS)
    out = np.zeros((D, D, D))
    for k, fit in fits.items():
        cols, C = tuple(getattr(fit, "map_columns", ())), np.asarray(getattr(fit, "map_cov", np.zeros((0, 0))), float)
        if (k not in REGRESSORS or not getattr(fit, "used", False) or not cols or C.shape != (len(cols),) * 2
                or not np.isfinite(C).all() or any(c not in REGRESSORS for c in cols)):
            continue
        idx = [REGRESSORS.index(c) for c in cols]
        out[REGRESSORS.index(k)][np.ix_(idx, idx)] = C
    return out if np.any(out) else None


def stated_output_variance(states: FlightStates, airframe: Airframe) -> np.ndarray | None:
    """Per-row variance of the measured coefficients' errors that the estimator's smoothers state.

    The forces from the smoothed specific force's 1-sigma (``states.sigma["ax" | "ay" | "az"]``, m/s^2):
    ``(m sigma_a / (qbar S))^2``; the moments from the angular accelerations' (``"p_dot" | "q_dot" | "r_dot"``,
    rad/s^2) through the moment equations (:func:`aero_moments`, the rates' own errors left out):
    ``Cl: (Ixx^2 s_p^2 + Ixz^2 s_r^2) / (qbar S b)^2``, ``Cm: Iyy^2 s_q^2 / (qbar S c)^2``,
    ``Cn: (Izz^2 s_r^2 + Ixz^2 s_p^2) / (qbar S b)^2``. The thrust model's error (CX) is not stated.

    Args:
        states: smoothed states with ``sigma`` and ``qbar`` (Pa).
        airframe: mass (kg), inertia (kg m^2), S (m^2), b and c (m).

    Returns:
        ``(T, 6)`` in the coefficients' units squared (columns :data:`~gcs_sysid.aero.table.COEFFICIENTS`;
        NaN where a sigma is not stated or ``qbar <= 0``), or None when no sigma of these is stated.
    """
    sig = getattr(states, "sigma", None) or {}
    keys = ("ax", "ay", "az", "p_dot", "q_dot", "r_dot")
    if "qbar" not in states.data or not any(k in sig for k in keys):
        return None
    T = len(states)
    s2 = {k: np.asarray(sig[k], float) ** 2 if k in sig else np.full(T, np.nan) for k in keys}
    qbar = np.asarray(states.data["qbar"], float)
    with np.errstate(invalid="ignore", divide="ignore"):
        qS2 = np.where(qbar > 0, (qbar * airframe.S) ** 2, np.nan)
        m2 = airframe.mass**2
        Ixx2, Iyy2, Izz2, Ixz2 = airframe.Ixx**2, airframe.Iyy**2, airframe.Izz**2, airframe.Ixz**2
        cross = lambda k: 0.0 if Ixz2 == 0 else Ixz2 * s2[k]  # noqa: E731 (no NaN from an unstated cross term)
        out = np.stack([m2 * s2["ax"] / qS2, m2 * s2["ay"] / qS2, m2 * s2["az"] / qS2,
                        (Ixx2 * s2["p_dot"] + cross("r_dot")) / (qS2 * airframe.b**2),
                        Iyy2 * s2["q_dot"] / (qS2 * airframe.c**2),
                        (Izz2 * s2["r_dot"] + cross("p_dot")) / (qS2 * airframe.b**2)], axis=1)
    return out


def aero_moments(airframe: Airframe, p, q, r, p_dot, q_dot, r_dot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Aerodynamic (plus propulsive) moments L, M, N in N m from rates and accelerations.

    Args:
        airframe: inertia Ixx, Iyy, Izz, Ixz in kg m^2.
        p, q, r: body rates, rad/s, arrays of one shape.
        p_dot, q_dot, r_dot: angular accelerations, rad/s^2.

    Returns:
        ``(L, M, N)`` in N m, each of the inputs' shape.

    Source: Stevens, Lewis and Johnson (2016) ch. 1; ``M = I w_dot + w x (I w)`` expanded.
    """
    Ixx, Iyy, Izz, Ixz = airframe.Ixx, airframe.Iyy, airframe.Izz, airframe.Ixz
    L = Ixx * p_dot - Ixz * (r_dot + p * q) + (Izz - Iyy) * q * r
    M = Iyy * q_dot + (Ixx - Izz) * p * r + Ixz * (p**2 - r**2)
    N = Izz * r_dot - Ixz * (p_dot - q * r) + (Iyy - Ixx) * p * q
    return L, M, N


def _air_relative(states, airframe, frame, p, q, r, V, notes):
    """``(p, q, r)`` for the hats: inertial (``frame`` None) or minus the estimated gust rates."""
    if frame is None:
        return p, q, r
    from ..estimation.gustrates import states_gust_rates

    G = states_gust_rates(states, V, airframe.b, frame)
    if isinstance(G, str):
        notes.append(f"gust rates ({frame}) not removed from p_hat q_hat r_hat: {G}")
        return p, q, r
    notes.append("p_hat q_hat r_hat relative to the air: " + "; ".join(G.notes))
    return p - G.rates[:, 0], q - G.rates[:, 1], r - G.rates[:, 2]


def compute_coefficients(states: FlightStates, airframe: Airframe, gust_rates: str | None = None) -> CoefficientTable:
    """Measured coefficients CX CY CZ Cl Cm Cn and the regressors on the states' grid.

    Args:
        states: smoothed states (``ax ay az p q r p_dot q_dot r_dot V alpha beta
            qbar delta_*``); a missing key makes the columns that need it NaN.
        airframe: mass, inertia, S, b, c and the optional thrust model.
        gust_rates: None (default: ``p_hat q_hat r_hat`` from the inertial rates a gyro measures) or a
            frame of :data:`gcs_sysid.estimation.gustrates.FRAMES`: the hats from the rates relative
            to the air, ``p - p_g`` etc., with the gust rates estimated from the states' wind
            (:func:`gcs_sysid.estimation.gustrates.gust_rates`; needs ``phi theta psi wn we wd``).
            The moment equations keep the inertial rates.

    Returns:
        :class:`~gcs_sysid.aero.table.CoefficientTable` with ``X`` (T, 10) in the
        order of :data:`REGRESSORS`, ``Y`` (T, 6) in the order of
        :data:`COEFFICIENTS`; ``valid`` = ``states.valid`` and every entry finite
        and ``qbar > QBAR_MIN``; ``x_offset_cov`` from ``states.offsets`` (regressor units squared);
        ``x_var`` from :func:`stated_input_variance`, ``x_scale_var`` from :func:`stated_scale_variance`,
        ``x_map_cov`` from :func:`stated_map_covariance`.

    Source: Klein and Morelli (2006) ch. 3; Stevens, Lewis and Johnson (2016) ch. 1.
    """
    T = len(states)
    nan = np.full(T, np.nan)
    get = lambda k: np.asarray(states.data[k], float) if k in states.data else nan  # noqa: E731
    notes: list[str] = []
    V, qbar = get("V"), get("qbar")
    S, b, c, m = airframe.S, airframe.b, airframe.c, airframe.mass
    with np.errstate(invalid="ignore", divide="ignore"):
        qS = np.where(qbar > 0, qbar * S, np.nan)
        if airframe.thrust is not None and "delta_t" in states.data:
            thrust = airframe.thrust.thrust(get("delta_t"), V)
            notes.append("CX has the airframe's static-thrust model removed "
                         f"(T = {airframe.thrust.T_static:g} N * delta_t^{airframe.thrust.exponent:g} "
                         f"* (1 - V/{airframe.thrust.V_zero:g}))")
        else:
            thrust = np.zeros(T)
            why = "airframe has no thrust model" if airframe.thrust is None else "no throttle signal"
            notes.append(f"CX includes thrust: {why}")
        CX = (m * get("ax") - thrust) / qS
        CY = m * get("ay") / qS
        CZ = m * get("az") / qS
        p, q, r = get("p"), get("q"), get("r")
        L, M, N = aero_moments(airframe, p, q, r, get("p_dot"), get("q_dot"), get("r_dot"))
        Cl, Cm, Cn = L / (qS * b), M / (qS * c), N / (qS * b)
        pa, qa, ra = _air_relative(states, airframe, gust_rates, p, q, r, V, notes)
        hat = {"p_hat": pa * b / (2 * V), "q_hat": qa * c / (2 * V), "r_hat": ra * b / (2 * V)}
        # the unsteady pitch regressor (Etkin 1972 ch. 5): alpha_dot from the force equations, not a column of X
        alpha_dot_hat = get("alpha_dot") * c / (2 * V) if "alpha_dot" in states.data else None
    cols = {**hat, **{k: get(k) for k in REGRESSORS if k not in hat}}
    X = np.stack([cols[k] for k in REGRESSORS], axis=1)
    Y = np.stack([CX, CY, CZ, Cl, Cm, Cn], axis=1)
    valid = np.ones(T, bool) if states.valid is None else np.asarray(states.valid, bool).copy()
    # a row is valid when its regressors and force coefficients are finite; the moment columns may be NaN
    # where the rate derivatives could not be formed (the pipeline fits only identifiable columns)
    valid &= np.isfinite(X).all(axis=1) & np.isfinite(Y[:, :3]).all(axis=1) & (np.nan_to_num(qbar) > QBAR_MIN)
    for k in ("ax", "ay", "az", "p", "q", "r", "p_dot", "q_dot", "r_dot", "V", "qbar", "alpha", "beta",
              "delta_e", "delta_a", "delta_r", "delta_t"):
        if k not in states.data:
            notes.append(f"no {k} in the states: the columns that need it are NaN")
    for key, coeffs in (("moment_coefficients", "Cl Cm Cn"), ("force_coefficients", "CX CY CZ")):
        ok, why = states.identifiability.get(key, (True, ""))
        if not ok:
            notes.append(f"{coeffs} not identifiable: {why}")
    offsets = getattr(states, "offsets", None) or {}
    x_offset_cov = None
    if any(k in offsets for k in REGRESSORS):
        # errors common to the whole flight (alpha: the mean vertical wind over V): one draw, not per-row noise
        x_offset_cov = np.diag([float(offsets.get(k, 0.0)) ** 2 for k in REGRESSORS])
    return CoefficientTable(np.asarray(states.t, float), X, Y, valid, qbar.copy(), notes, x_offset_cov,
                            stated_input_variance(states), stated_scale_variance(states),
                            stated_map_covariance(states), alpha_dot_hat)
