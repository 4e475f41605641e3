"""Air data: ISA atmosphere, density, EAS -> TAS, wind, alpha, beta, qbar.

Airspeed conventions: ArduPilot's VFR_HUD ``airspeed`` and its pitot-derived
SCALED_PRESSURE ``press_diff`` give *equivalent* airspeed
``EAS = sqrt(2 q_c / rho0)``; the true airspeed is ``V = EAS sqrt(rho0 / rho)``
and ``qbar = 0.5 rho V^2 = 0.5 rho0 EAS^2``. Density comes from static pressure
and temperature where they are logged (``rho = p / (R T)``), else from the ISA
at the altitude.

Wind and air-relative velocity (see ``docs/estimation.md``): a pitot gives the
airspeed magnitude only; GPS gives the ground velocity. With the heading
changing, ``|v_ground - w| = k * V_pitot`` over a window determines the
horizontal wind ``w`` (and a global pitot scale ``k``) by least squares; the
autopilot's own wind estimate (WIND / XKF2) enters only as a weak prior.
Then ``v_air = C' (v_ground - w)`` in body axes gives
``alpha = atan2(w_a, u_a)``, ``beta = asin(v_a / |v_air|)``.

References:
    ISO 2533:1975 / U.S. Standard Atmosphere 1976 (troposphere).
    Stevens, Lewis and Johnson (2016) ch. 2 (alpha, beta from body velocity).
    Klein and Morelli (2006) ch. 10 (wind and airspeed calibration from
    flight data); Cho, Kim, Lee and Kee, "Wind estimation and airspeed
    calibration using a UAV with a single-antenna GPS receiver and pitot tube",
    IEEE Trans. Aerospace and Electronic Systems 47(1), 2011.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

__all__ = ["RHO0", "P0", "T0", "R_AIR", "isa", "pressure_altitude", "density", "tas_from_eas",
           "WindEstimate", "estimate_wind", "air_angles"]

RHO0 = 1.225        #: sea-level ISA density, kg/m^3
P0 = 101325.0       #: sea-level ISA pressure, Pa
T0 = 288.15         #: sea-level ISA temperature, K
R_AIR = 287.05287   #: specific gas constant of dry air, J/(kg K)
_LAPSE = 0.0065     # K/m, troposphere
_G0 = 9.80665
_EXP = _G0 / (R_AIR * _LAPSE)  # 5.2559


def isa(alt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ISA troposphere (valid below 11 km).

    Args:
        alt: geopotential altitude, m, any shape.

    Returns:
        ``(p, T, rho)``: pressure Pa, temperature K, density kg/m^3, each like ``alt``.
    """
    h = np.minimum(np.asarray(alt, float), 11000.0)
    T = T0 - _LAPSE * h
    p = P0 * (T / T0) ** _EXP
    return p, T, p / (R_AIR * T)


def pressure_altitude(p: np.ndarray) -> np.ndarray:
    """ISA altitude (m) of static pressure ``p`` (Pa), any shape."""
    return T0 / _LAPSE * (1.0 - (np.asarray(p, float) / P0) ** (1.0 / _EXP))


def density(p: np.ndarray, T: np.ndarray | None = None) -> np.ndarray:
    """Air density ``rho = p / (R T)`` (kg/m^3) from static pressure (Pa) and temperature (K).

    A temperature missing, NaN or outside 180..340 K is replaced by the ISA
    temperature at the pressure altitude.
    """
    p = np.asarray(p, float)
    T_isa = isa(pressure_altitude(p))[1]
    if T is None:
        T = T_isa
    T = np.asarray(T, float)
    T = np.where(np.isfinite(T) & (T > 180.0) & (T < 340.0), T, T_isa)
    return p / (R_AIR * T)


def tas_from_eas(eas: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """True airspeed ``V = EAS * sqrt(rho0 / rho)`` (m/s) from equivalent airspeed (m/s) and density."""
    return np.asarray(eas, float) * np.sqrt(RHO0 / np.asarray(rho, float))


@dataclass
class WindEstimate:
    """Wind from GPS velocity and airspeed.

    Attributes:
        wind: (T, 3) wn, we, wd m/s (air velocity over ground, NED; wd = 0).
        sigma: (T, 3) 1-sigma, m/s.
        scale: estimated pitot scale ``k`` (true airspeed = k * measured); 1 when not estimated.
        scale_sigma: its 1-sigma (NaN when not estimated: the track did not turn enough).
        window_s: window length used, s.
        sigma_airspeed: the standard deviation (m/s) the airspeed residuals were weighted with: ``sigma_tas``, or
            with ``residual_scale`` the residuals' own RMS where that is larger.
        fits: how many times the least-squares problem was solved (1 unless ``residual_scale`` refitted).
    """

    wind: np.ndarray
    sigma: np.ndarray
    scale: float
    scale_sigma: float
    window_s: float
    sigma_airspeed: float = 0.5
    fits: int = 1


def estimate_wind(t: np.ndarray, v_ned: np.ndarray, tas: np.ndarray, use: np.ndarray,
                  prior: np.ndarray | None = None, C: np.ndarray | None = None, window_s: float = 30.0,
                  sigma_tas: float = 0.5, sigma_prior: float = 3.0, sigma_beta: float = 0.08,
                  min_turn: float = 0.5, max_points: int = 300, residual_scale: bool = False,
                  max_fits: int = 4) -> WindEstimate:
    """Piecewise-constant horizontal wind and a pitot scale by regularised least squares.

    Unknowns: ``(wn, we)`` per window of ``window_s`` seconds and one scale
    ``k`` for the flight. Residuals: ``(|v_ground - w| - k V) / sigma_tas`` at
    (sub-sampled) points; with the attitude ``C``, the lateral body component of
    the air velocity ``v_a / (sigma_beta V)`` (coordinated flight: beta is zero
    on average; this is what makes the cross-track wind observable on straight
    legs, through the crab angle between heading and track);
    ``(w - w_prior) / sigma_prior`` per window (prior: the autopilot's wind
    where given, else 0 with 15 m/s) and ``(k - 1) / 0.1``. The pitot scale is
    only estimated when the track turns enough (mean resultant length of the
    track directions below ``min_turn``): on straight legs it is confounded with
    the along-track wind, so ``k = 1`` is kept. The window values are linearly
    interpolated between window centres; the 1-sigma comes from the
    Gauss-Newton covariance ``(J'J)^-1``.

    With ``residual_scale`` the airspeed residuals are weighted with their own
    standard deviation, not with the pitot's noise alone: after each solve the
    RMS of ``|v_ground - w| - k V`` over the fitted points becomes the weight's
    sigma (never below ``sigma_tas``), and the problem is solved again until that
    sigma moves by less than 5 % (at most ``max_fits`` solves). In turbulence the
    residual holds what the model leaves out (the vertical wind along the flight
    path, the gust within a window): 0.75-2.4 m/s RMS on JSBSim's light turbulence
    against the pitot's 0.5 m/s. Weighted as pitot noise, it outweighs the
    sideslip residuals, and the fit buys it down with a crosswind of tens of m/s
    (``|v_ground - w|`` grows with the square of a cross-track wind error: the
    JSBSim Navion's dive, ``docs/estimation.md``). This is the two-group
    variance-component estimate of weighted least squares (iteratively
    reweighted; Koch, *Parameter Estimation and Hypothesis Testing in Linear
    Models*, 2nd ed., Springer 1999, sec. 3.6), for the airspeed group; the
    sideslip's spread ``sigma_beta`` stays a stated prior.

    Args:
        t: grid times (T,), s.
        v_ned: (T, 3) smoothed ground velocity, m/s.
        tas: (T,) true airspeed from the pitot, m/s (NaN where missing).
        use: (T,) bool, points to fit (airborne, all finite).
        prior: optional (T, 3) autopilot wind estimate (NaN where missing).
        C: optional (T, 3, 3) body-to-NED direction cosines (adds the beta ~ 0 residuals).
        window_s: window length, s.
        sigma_tas: airspeed noise, m/s.
        sigma_prior: 1-sigma of the autopilot prior, m/s.
        sigma_beta: spread of the sideslip angle about zero, rad.
        min_turn: largest mean resultant length of the track directions at which ``k`` is estimated.
        max_points: largest number of points per window used in the fit.
        residual_scale: weight the airspeed residuals with their own RMS (above).
        max_fits: largest number of solves with ``residual_scale``.

    Returns:
        :class:`WindEstimate`.

    Raises:
        ValueError: fewer than 10 usable points.

    Source: Cho et al. (2011); Klein and Morelli (2006) ch. 10.
    """
    use = use & np.isfinite(tas) & np.isfinite(v_ned).all(axis=1)
    idx = np.nonzero(use)[0]
    if len(idx) < 10:
        raise ValueError("fewer than 10 points with airspeed and GPS velocity to estimate the wind")
    t_used = t[idx]
    nw = max(1, int(np.ceil((t_used[-1] - t_used[0]) / window_s)))
    edges = np.linspace(t_used[0], t_used[-1] + 1e-9, nw + 1)
    win = np.clip(np.searchsorted(edges, t_used, side="right") - 1, 0, nw - 1)
    pts = []
    for j in range(nw):  # sub-sample each window evenly
        m = idx[win == j]
        if len(m) > max_points:
            m = m[np.linspace(0, len(m) - 1, max_points).astype(int)]
        pts.append(m)
    sel = np.concatenate(pts)
    wsel = np.concatenate([np.full(len(m), j) for j, m in enumerate(pts)])
    vg, Vm = v_ned[sel], tas[sel]
    yb = C[sel, :, 1] if C is not None else None          # body y axis in NED
    trk = np.arctan2(v_ned[idx, 1], v_ned[idx, 0])
    turning = float(np.hypot(np.cos(trk).mean(), np.sin(trk).mean())) < min_turn
    centres = np.array([t_used[win == j].mean() if (win == j).any() else 0.5 * (edges[j] + edges[j + 1])
                        for j in range(nw)])
    w_prior = np.zeros((nw, 2))
    s_prior = np.full(nw, 15.0)
    if prior is not None:
        for j in range(nw):
            pw = prior[idx[win == j], :2]
            pw = pw[np.isfinite(pw).all(axis=1)]
            if len(pw):
                w_prior[j] = pw.mean(axis=0)
                s_prior[j] = sigma_prior

    sig_v = sigma_tas   # the airspeed residuals' weight (residual_scale: their own RMS, at least sigma_tas)

    def resid(x):
        w = x[:2 * nw].reshape(nw, 2)
        k = x[-1] if turning else 1.0
        d = vg.copy()
        d[:, :2] -= w[wsel]
        r = [(np.linalg.norm(d, axis=1) - k * Vm) / sig_v]
        if yb is not None:                                  # beta ~ 0: lateral air velocity ~ 0
            r.append((d * yb).sum(axis=1) / (sigma_beta * np.maximum(Vm, 1.0)))
        r.append(((w - w_prior) / s_prior[:, None]).ravel())
        if turning:
            r.append([(k - 1.0) / 0.1])
        return np.concatenate(r)

    def jac(x):
        w = x[:2 * nw].reshape(nw, 2)
        d = vg.copy()
        d[:, :2] -= w[wsel]
        npt, nx = len(sel), len(x)
        rows = [np.zeros((npt, nx))]
        cols = 2 * wsel
        nd = np.linalg.norm(d, axis=1)[:, None]
        rows[0][np.arange(npt), cols] = -d[:, 0] / nd[:, 0] / sig_v      # d|d|/dwn = -d_n/|d|
        rows[0][np.arange(npt), cols + 1] = -d[:, 1] / nd[:, 0] / sig_v
        if turning:
            rows[0][:, -1] = -Vm / sig_v
        if yb is not None:
            jb = np.zeros((npt, nx))
            sb = sigma_beta * np.maximum(Vm, 1.0)
            jb[np.arange(npt), cols] = -yb[:, 0] / sb
            jb[np.arange(npt), cols + 1] = -yb[:, 1] / sb
            rows.append(jb)
        jp = np.zeros((2 * nw, nx))
        jp[np.arange(2 * nw), np.arange(2 * nw)] = 1.0 / np.repeat(s_prior, 2)
        rows.append(jp)
        if turning:
            jk = np.zeros((1, nx))
            jk[0, -1] = 1.0 / 0.1
            rows.append(jk)
        return np.vstack(rows)

    x0 = np.concatenate([w_prior.ravel(), [1.0]] if turning else [w_prior.ravel()])
    fits = 0
    while True:
        sol = least_squares(resid, x0, jac=jac, method="lm" if len(x0) <= len(sel) else "trf")
        fits += 1
        if not residual_scale or fits >= max_fits:
            break
        rms = float(np.sqrt(np.mean((sol.fun[:len(sel)] * sig_v) ** 2)))   # airspeed residuals, m/s
        new = max(sigma_tas, rms)
        if abs(np.log(new / sig_v)) < 0.05:
            break
        sig_v = new
    Jm = sol.jac
    try:
        cov = np.linalg.inv(Jm.T @ Jm)
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(Jm.T @ Jm)
    chi2 = float(np.mean(sol.fun[:len(sel)] ** 2))   # about 1 once residual_scale has settled
    cov = cov * max(chi2, 1.0)
    w = sol.x[:2 * nw].reshape(nw, 2)
    ws = np.sqrt(np.maximum(np.diag(cov)[:2 * nw], 0)).reshape(nw, 2)
    k_hat, k_sig = (float(sol.x[-1]), float(np.sqrt(max(cov[-1, -1], 0.0)))) if turning else (1.0, float("nan"))
    wind = np.zeros((len(t), 3))
    sig = np.zeros((len(t), 3))
    for i in range(2):
        wind[:, i] = np.interp(t, centres, w[:, i])
        sig[:, i] = np.interp(t, centres, ws[:, i])
    return WindEstimate(wind, sig, k_hat, k_sig, window_s, sig_v, fits)


def air_angles(C: np.ndarray, v_ned: np.ndarray, wind: np.ndarray) -> tuple[np.ndarray, ...]:
    """Air-relative body velocity, airspeed, alpha and beta.

    Args:
        C: (T, 3, 3) body-to-NED direction cosines.
        v_ned: (T, 3) ground velocity, m/s.
        wind: (T, 3) wind (air velocity over ground), m/s.

    Returns:
        ``(v_air_body (T, 3) m/s, V (T,) m/s, alpha (T,) rad, beta (T,) rad)`` with
        ``alpha = atan2(w_a, u_a)`` and ``beta = asin(v_a / V)``.

    Source: Stevens, Lewis and Johnson (2016) ch. 2.
    """
    vb = np.einsum("tji,tj->ti", C, v_ned - wind)     # C' (v_ground - w)
    V = np.linalg.norm(vb, axis=1)
    alpha = np.arctan2(vb[:, 2], vb[:, 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        beta = np.arcsin(np.clip(vb[:, 1] / V, -1.0, 1.0))
    return vb, V, alpha, beta
