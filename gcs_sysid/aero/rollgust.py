"""The rolling gust as a state of the roll dynamics: filter-error estimate of ``Cl``'s slopes and ``p_g`` together.

JSBSim's aerodynamics (and the air's) read the body's roll rate relative to the air, ``p - p_g``
(``FGAuxiliary``: ``vAeroPQR = vPQR - TurbPQR``); a gyro measures ``p``. The gust drives the roll response, so the
gyro's ``p`` is correlated with the ``Cl_p p_g`` term a regression of the measured ``Cl`` leaves in its residual:
least squares attenuates ``Cl_p``, ``Cl_delta_a`` and ``Cl_beta`` (c172p ``Cl_p`` -0.22 against JSBSim's -0.49,
``docs/benchmarks.md``, "Twentieth session, i8-roll").

Roll equation (Stevens, Lewis and Johnson, *Aircraft Control and Simulation*, 3rd ed., 2016, eq. 1.7-18), with
the gust as a state (the filter-error method: Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., AIAA
2015, ch. 5, process noise entering the state equation; Morelli and Klein, *Aircraft System Identification*, 2nd
ed., 2016, ch. 6-7)::

    Ixx p_dot - Ixz (r_dot + p q) + (Izz - Iyy) q r = qbar S b Cl(beta, (p - p_g) b/(2V), r_hat, delta_a, delta_r)
    d p_g/dt = -p_g / tau + white,   tau = 4 b / (pi V)        (MIL-F-8785C sec. 3.7.2; MIL-HDBK-1797)

``p`` is a state that the gyro measures, not a regressor: the model pairs the moment over one grid step
``[k, k+1]`` with the rate ``p_k`` the step starts from, which the gust's innovations inside the step have not
reached yet. The pipeline's ``Cl`` takes ``p_dot`` from a smoother consistent with its rate (a central, non-causal
derivative); advanced by half a step (``+ Ixx dt/2 p_ddot / (qbar S b)``, :func:`causal_roll_moment`) it is the
step's moment. Paired at the same instant, the gyro's ``p`` answers the gust's innovation within the step and the
innovations' likelihood attenuates ``Cl_p`` (the seventeenth session's finding for :mod:`gcs_sysid.aero.gustfilter`,
``docs/benchmarks.md``, "Seventeenth session, i8-fe2"; c172p light s1 here: -0.31 paired at the instant, -0.38
with the step's moment, JSBSim -0.49).

The gust term enters the output as a first-order Gauss-Markov process ``s = -Cl_p p_hat_g`` (Cl units), so the
model of the step's roll moment is linear in the slopes::

    Cl_k+1/2 = theta . x_k + s_k + e_k,   s_k+1 = a s_k + w_k,   a = exp(-dt/tau),  var w = sigma^2 (1 - a^2)

with ``x = (1, alpha, beta, p_hat, r_hat, delta_a, delta_r)`` at ``k``. For given ``(sigma, R)`` the slopes are
generalised least squares through the steady-state Kalman filter's innovations of the moment and of each column of
``x`` (the concentrated likelihood; Harvey, *Forecasting, Structural Time Series Models and the Kalman Filter*, 1989,
sec. 3.4); ``sigma`` and ``R`` maximise it (Nelder-Mead; ``R`` goes to its lower bound on JSBSim's flights, as in
:mod:`~gcs_sysid.aero.gustfilter`: the smoothed moment has no white floor, and ``sigma`` comes out at about half
the truth's). The step integrates the rate's own damping, ``(e^{L_p dt} - 1)/(L_p dt)`` (``L_p = qbar S b Cl_p
b/(2 V Ixx)``), which is divided out of the slopes afterwards. ``p_g`` is the Rauch-Tung-Striebel smoothed ``s``
over ``-Cl_p``.

On the pipeline's own data of JSBSim flights, light turbulence, seed 1 (``docs/benchmarks.md``, "Twenty-first
session, i8-rollfe"): ``Cl_p`` c172p -0.22 (least squares) -> -0.38 (JSBSim -0.49), c172x -0.30 -> -0.46 (-0.47),
j3cub -0.15 -> -0.49 (-0.52); ``Cl_delta_a`` -0.14 -> -0.21 (-0.23), -0.17 -> -0.23 (-0.23), -0.13 -> -0.33 (-0.35);
``corr(p_g_hat, p_g)`` 0.92-0.96. Not better everywhere: on the b737 (gust term 29 % of Cl, large sideslip) ``Cl_p``
and ``Cl_beta`` move away from JSBSim's; where the moment does not read the gust (JSBSim's pa28) the state takes up
coloured error and ``Cl_p`` overshoots by 27 %, which is why :func:`gcs_sysid.aero.gustfilter.filter_gust_table`
applies the fit only when its SD is near the Dryden one expected from the wind.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .gustfilter import LAT_TERMS, RollGustFit, _gains, _innovations, _segments, _smooth
from .table import COEFFICIENTS, REGRESSORS

__all__ = ["ROLL_TAU", "ROW_GUST_MODES", "RollDynamicsFit", "dryden_roll_tau", "causal_roll_moment",
           "fit_roll_dynamics", "roll_gust_on_rows", "PRED_VAR_METHODS", "predicted_gust_variance",
           "gust_cutoff_variance"]

_IP = LAT_TERMS.index("p_hat") + 1       # the roll-rate column in the design (intercept at 0)
_MIN_ROWS, _MIN_RUN = 200, 50
#: The gust's correlation time: ``"dryden"`` (``4 b/(pi V)``, MIL-F-8785C) or ``"fit"`` (a third likelihood
#: parameter; on JSBSim's flights it runs to 1-13 s where the slopes leave slow residue and the proxy true-air Cl
#: gets worse, c172x s1 15 -> 72 %).
ROLL_TAU = "dryden"


@dataclass(frozen=True)
class RollDynamicsFit(RollGustFit):
    """:class:`~gcs_sysid.aero.gustfilter.RollGustFit` (``theta`` the filter-error slopes, ``theta0`` least squares
    of the pipeline's ``Cl`` on the gyro's hats) plus the roll damping ``L_p`` (1/s) the step correction used."""

    L_p: float = float("nan")


def dryden_roll_tau(b: float, V: float) -> float:
    """The Dryden rolling gust's time constant ``4 b/(pi V)``, s (MIL-F-8785C sec. 3.7.2, the ``p_g`` filter's
    break frequency ``pi V/(4 b)``).

    Raises:
        ValueError: ``b`` or ``V`` not positive.
    """
    if not (b > 0 and V > 0):
        raise ValueError(f"dryden_roll_tau: span and airspeed must be positive, got b={b}, V={V}")
    return 4.0 * b / (np.pi * V)


def causal_roll_moment(dt: float, Cl: np.ndarray, p: np.ndarray, qbar: np.ndarray, Ixx: float, S: float,
                       b: float) -> np.ndarray:
    """``(T,)`` the rolling-moment coefficient over each step ``[k, k+1]``: the measured ``Cl`` with its ``Ixx p_dot``
    term advanced half a step, ``+ Ixx ((p_k+1 - p_k)/dt - (p_k+1 - p_k-1)/(2 dt)) / (qbar S b)`` (the forward
    difference less the central one, ``dt/2 p_ddot``); NaN in the first and last rows.

    Args:
        dt: grid interval, s. Cl: ``(T,)`` the pipeline's measured Cl. p: ``(T,)`` the smoothed roll rate, rad/s.
        qbar: ``(T,)`` Pa. Ixx: kg m^2. S: m^2. b: m.
    """
    p = np.asarray(p, float)
    adv = np.full(len(p), np.nan)
    adv[1:-1] = (p[2:] - 2 * p[1:-1] + p[:-2]) / (2 * dt)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(Cl, float) + Ixx * adv / (np.asarray(qbar, float) * S * b)


def fit_roll_dynamics(dt: float, X: np.ndarray, Y: np.ndarray, p: np.ndarray, qbar: np.ndarray,
                      rows: np.ndarray, Ixx: float, S: float, b: float, tau: str = ROLL_TAU,
                      max_fev: int = 400, R: float | None = None,
                      extra: np.ndarray | None = None) -> RollDynamicsFit:
    """Filter-error slopes of the lateral ``Cl`` and the smoothed rolling gust (module docstring).

    Args:
        dt: grid interval, s.
        X: ``(T, 10)`` regressors (:data:`~gcs_sysid.aero.table.REGRESSORS`, gyro hats).
        Y: ``(T, 6)`` measured coefficients (:data:`~gcs_sysid.aero.table.COEFFICIENTS`; Cl used).
        p: ``(T,)`` the smoothed roll rate, rad/s.
        qbar: ``(T,)`` dynamic pressure, Pa.
        rows: ``(T,)`` bool, the rows whose roll moment may be used (never a held-out segment).
        Ixx, S, b: kg m^2, m^2, m.
        tau: ``"dryden"`` (``4 b/(pi V)`` at the rows' mean airspeed) or ``"fit"``.
        max_fev: Nelder-Mead's likelihood evaluations at most.
        R: the moment's white-noise variance held fixed (None: a likelihood parameter).
        extra: ``(T, k)`` further columns of the design beside ``(1,) + LAT_TERMS`` (None: none), their slopes
            estimated with the others by the same GLS, so that a moment they carry is not taken up by the gust
            state: the diagnosis's candidate terms (:func:`gcs_sysid.diagnose.air_roll.air_roll_table`). Their
            slopes follow ``theta[7:]`` (the step's damping factor divided out as for the others).

    Returns:
        :class:`RollDynamicsFit`; ``g`` (``p_hat_g``) is 0 with the prior variance outside the rows used.

    Raises:
        ValueError: shapes that disagree (``extra`` included), ``dt`` not positive, fewer than 200 usable rows in runs
            of at least 50, an unknown ``tau``, or a roll damping ``Cl_p`` that is not negative.
    """
    from scipy.optimize import minimize

    X, Y = np.asarray(X, float), np.asarray(Y, float)
    T = len(X)
    shapes = [np.shape(v) for v in (p, qbar, rows)]
    extra = np.zeros((T, 0)) if extra is None else np.asarray(extra, float)
    if extra.ndim == 1:
        extra = extra[:, None]
    if extra.ndim != 2 or len(extra) != T:
        raise ValueError(f"fit_roll_dynamics: extra columns (T, k) with T = {T} expected, got {extra.shape}")
    if X.shape != (T, len(REGRESSORS)) or Y.shape != (T, len(COEFFICIENTS)) or any(s != (T,) for s in shapes):
        raise ValueError(f"fit_roll_dynamics: X (T, {len(REGRESSORS)}), Y (T, {len(COEFFICIENTS)}) and p, p_dot, "
                         f"qbar, rows (T,) expected, got {X.shape}, {Y.shape}, {shapes}")
    if not dt > 0:
        raise ValueError(f"fit_roll_dynamics: dt must be positive, got {dt}")
    if tau not in ("dryden", "fit"):
        raise ValueError(f"fit_roll_dynamics: tau must be 'dryden' or 'fit', got {tau!r}")
    cols = [REGRESSORS.index(k) for k in LAT_TERMS]
    A0 = np.c_[np.ones(T), X[:, cols], extra]
    A = A0.copy()                                    # at k: the state the step starts from, the inputs it holds
    A[-1] = np.nan
    y = causal_roll_moment(dt, Y[:, COEFFICIENTS.index("Cl")], p, qbar, Ixx, S, b)
    r = np.asarray(rows, bool)
    use = r & np.r_[r[1:], False] & np.r_[False, r[:-1]] & np.isfinite(A).all(1) & np.isfinite(y)
    segs = _segments(use, _MIN_RUN)
    used = np.zeros(T, bool)
    for s0, s1 in segs:
        used[s0:s1] = True
    if used.sum() < _MIN_ROWS:
        raise ValueError(f"fit_roll_dynamics: {int(use.sum())} usable rows, at least {_MIN_ROWS} in runs of "
                         f"{_MIN_RUN} needed")
    Cl = Y[:, COEFFICIENTS.index("Cl")]
    ok0 = used & np.isfinite(Cl)
    theta0 = np.linalg.lstsq(A0[ok0], Cl[ok0], rcond=None)[0]
    Vbar = float(np.mean(X[used, REGRESSORS.index("V")]))
    tau_d = dryden_roll_tau(b, Vbar)
    M = np.where(used[:, None], np.c_[y, A], 0.0)
    th_ls = np.linalg.lstsq(M[used, 1:], M[used, 0], rcond=None)[0]
    zv = float(np.var(M[used, 0] - M[used, 1:] @ th_ls))
    n_used = int(used.sum())

    R_fixed = R

    def full(v):                                     # the free parameters -> (log sigma, log R[, log tau])
        return v if R_fixed is None else np.r_[v[0], np.log(R_fixed), v[1:]]

    def nll(v):
        v = full(v)
        sig, R = np.exp(v[0]), np.exp(v[1])
        tau_ = float(np.exp(v[2])) if tau == "fit" else tau_d
        a = float(np.exp(-dt / tau_))
        ss = _gains(a, sig * sig, 1.0, R)
        if not (np.isfinite(ss.S) and ss.S > 0):
            return np.inf, None, a, ss
        E = _innovations(M, a, ss, 1.0, segs)         # GLS: every column through the same steady-state filter
        th = np.linalg.lstsq(E[:, 1:], E[:, 0], rcond=None)[0]
        nu = E[:, 0] - E[:, 1:] @ th
        return 0.5 * float(nu @ nu) / ss.S + 0.5 * len(nu) * np.log(2 * np.pi * ss.S), th, a, ss

    v0 = [0.5 * np.log(0.5 * zv), np.log(0.5 * zv)] + ([np.log(tau_d)] if tau == "fit" else [])
    span = max(s1 - s0 for s0, s1 in segs) * dt
    bounds = [(v0[0] + 0.5 * np.log(1e-8), v0[0] + 0.5 * np.log(1e4)), (np.log(1e-10 * zv), np.log(zv))]
    if tau == "fit":
        bounds.append((np.log(dt), np.log(span)))
    if R_fixed is not None:
        if not R_fixed > 0:
            raise ValueError(f"fit_roll_dynamics: a fixed R must be positive, got {R_fixed}")
        del v0[1], bounds[1]
    opt = minimize(lambda v: nll(v)[0], v0, method="Nelder-Mead" if len(v0) > 1 else "Powell", bounds=bounds,
                   options={"maxfev": max_fev, "xatol": 1e-3, "fatol": 1e-2} if len(v0) > 1 else {"maxfev": max_fev})
    f, th, a, ss = nll(opt.x)
    xf = full(opt.x)
    if th is None or not th[_IP] < 0:
        raise ValueError("fit_roll_dynamics: no likelihood optimum with a negative roll damping Cl_p")
    sig, R = float(np.exp(xf[0])), float(np.exp(xf[1]))
    tau_ = float(np.exp(xf[2])) if tau == "fit" else tau_d
    # divide the step's integration of the damping out: y = (e^{Lp dt} - 1)/(Lp dt) (Lp p + forcing)
    k_h = float(np.mean(np.asarray(qbar, float)[used] * S * b / Ixx * b / (2 * X[used, REGRESSORS.index("V")])))
    Lf = k_h * th[_IP]
    if not 1 + Lf * dt > 0:
        raise ValueError(f"fit_roll_dynamics: roll damping {Lf:.1f} 1/s too fast for the step {dt} s")
    Lp = float(np.log1p(Lf * dt) / dt)
    theta = th * (Lp * dt) / np.expm1(Lp * dt)
    s = np.zeros(T)
    for s0, s1 in segs:
        s[s0:s1] = _smooth(M[s0:s1, 0] - M[s0:s1, 1:] @ th, a, ss, 1.0)
    g = np.where(used, -s / th[_IP], 0.0)
    sg2 = sig * sig / th[_IP] ** 2
    g_var = np.where(used, ss.Ps / th[_IP] ** 2, sg2)
    nll_white = 0.5 * n_used * (1 + np.log(2 * np.pi * zv))
    notes = (f"rolling gust p_g as a state of the roll dynamics (filter-error method, causal step moment; "
             f"{'Dryden' if tau == 'dryden' else 'fitted'} tau {tau_:.2f} s, sigma(p_hat_g) {np.sqrt(sg2):.4f}, "
             f"R {R:.2e}; {opt.nfev} evaluations{'' if opt.success else ', not converged'}): Cl_p "
             f"{theta0[_IP]:.3f} (least squares) -> {theta[_IP]:.3f}, Cl_beta {theta0[2]:.3f} -> {theta[2]:.3f}, "
             f"Cl_delta_a {theta0[5]:.3f} -> {theta[5]:.3f}; -log L {f:.0f} against {nll_white:.0f} without the gust",)
    return RollDynamicsFit(g, g_var, used, theta, theta0, float(theta[_IP]), tau_, float(np.sqrt(sg2)), R, float(f),
                           float(nll_white), int(opt.nfev), bool(opt.success), notes, L_p=Lp)


#: The estimates of the rolling gust on rows the fit did not use (:func:`roll_gust_on_rows`).
ROW_GUST_MODES = ("smoothed", "filtered", "predicted")


def roll_gust_on_rows(G: RollDynamicsFit, dt: float, X: np.ndarray, Y: np.ndarray, p: np.ndarray, qbar: np.ndarray,
                      rows: np.ndarray, Ixx: float, S: float, b: float, mode: str = "smoothed",
                      min_run: int = 10, gust_var: float | None = None,
                      pred_var: float | None = None, center: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The rolling gust ``p_hat_g`` on ``rows`` (a held-out segment) from their own measured roll moment, with the
    slopes, gust process and noise of a fit made on other rows (:func:`fit_roll_dynamics`, nothing refitted).

    The step moment's residual on the fit's step slopes, ``z_k = Cl_k+1/2 - theta_step . x_k`` (module docstring),
    goes through the fit's steady-state Kalman filter (``a = exp(-dt/tau)``, process SD ``sigma |Cl_p_step|``, noise
    ``R``; Jategaonkar 2015, ch. 5; Simon, *Optimal State Estimation*, 2006, ch. 5 and 9) on each run of usable rows:

    - ``"smoothed"``: the Rauch-Tung-Striebel smoothed state (every moment of the run; offline reconstruction);
    - ``"filtered"``: the filtered state (the moments up to the step ``[k, k+1]``);
    - ``"predicted"``: the one-step prediction (the moments before ``k`` only: row ``k``'s own measured moment
      is not used, so a model asked at ``p_hat - p_hat_g`` there is not given the moment it is scored on).

    ``p_hat_g = -s / Cl_p_step``. The fit's ``theta`` had the step's damping factor divided out; it is put back
    (``theta (e^{L_p dt} - 1)/(L_p dt)``) so that the residual is the one the fit's filter saw.

    Args:
        G: the fit (:class:`RollDynamicsFit`, with ``L_p``).
        dt: grid interval, s. X: ``(T, 10)`` regressors (gyro hats). Y: ``(T, 6)`` measured coefficients.
        p: ``(T,)`` the smoothed roll rate, rad/s. qbar: ``(T,)`` Pa. rows: ``(T,)`` bool, where to estimate.
        Ixx, S, b: kg m^2, m^2, m. mode: one of :data:`ROW_GUST_MODES`. min_run: shortest run of usable rows.
        gust_var: the variance of ``p_hat_g`` (dimensionless) under which the ``"predicted"`` and ``"filtered"``
            estimates' error variance is stated (None: the fit's ``sigma**2``). The filter keeps the fit's gain;
            with a larger process variance ``q`` its error variance is that of a suboptimal filter, the stationary
            solution of ``P = a^2 (1 - K)^2 P + a^2 K^2 R + q`` (predicted; filtered ``(1 - K)^2 P + K^2 R``;
            Gelb, *Applied Optimal Estimation*, 1974, sec. 7.2). ``"smoothed"`` states the fit's ``Ps``.
        pred_var: the ``"predicted"`` estimate's error variance of ``p_hat_g`` (dimensionless) measured elsewhere
            (:func:`predicted_gust_variance` on the training rows; None: not given). Used in place of the fit's
            (and of ``gust_var``'s) when larger; the ``"filtered"`` one follows as ``(1 - K)^2 P + K^2 R`` (the fit's
            gain ``K``; Gelb 1974, sec. 7.2).
        center: take each run's mean step-moment residual out before filtering: the run's level goes to an intercept,
            not to the zero-mean gust (rows estimated at another level than the fit's, e.g. a later live window;
            :data:`gcs_sysid.aero.gustfilter.AIR_ROLL_ROWS_CENTER`). The run's mean of the gust itself is given up.

    Returns:
        ``(g, g_var)``, each ``(T,)``: ``p_hat_g`` and its variance on the usable runs of ``rows``; 0 and the fit's
        stationary variance ``sigma**2`` elsewhere (the prior).

    Raises:
        ValueError: an unknown ``mode``, shapes that disagree, or a fit without a finite ``L_p``.
    """
    from scipy.signal import lfilter

    if mode not in ROW_GUST_MODES:
        raise ValueError(f"roll_gust_on_rows: mode must be one of {ROW_GUST_MODES}, got {mode!r}")
    X, Y = np.asarray(X, float), np.asarray(Y, float)
    T = len(X)
    if X.shape != (T, len(REGRESSORS)) or Y.shape != (T, len(COEFFICIENTS)) or any(
            np.shape(v) != (T,) for v in (p, qbar, rows)):
        raise ValueError(f"roll_gust_on_rows: X (T, {len(REGRESSORS)}), Y (T, {len(COEFFICIENTS)}), p, qbar, rows "
                         f"(T,) expected, got {X.shape}, {Y.shape}, {[np.shape(v) for v in (p, qbar, rows)]}")
    z, cl_p, a, ss = _step_residual(G, dt, X, Y, p, qbar, Ixx, S, b, "roll_gust_on_rows")
    use = np.asarray(rows, bool) & np.isfinite(z)
    s = np.zeros(T)
    var = np.full(T, (G.sigma * cl_p) ** 2)
    Pf = ss.P * G.R / ss.S
    Pp = ss.P
    if pred_var is not None and pred_var * cl_p**2 > Pp:  # a stated prediction error (predicted_gust_variance)
        Pp = pred_var * cl_p**2
        Pf = (1 - ss.K) ** 2 * Pp + ss.K**2 * G.R
    elif gust_var is not None and gust_var > G.sigma**2:   # the fit's gain under a larger gust (a suboptimal filter)
        q = gust_var * cl_p**2 * (1 - a * a)
        Pp = (q + (a * ss.K) ** 2 * G.R) / (1 - (a * (1 - ss.K)) ** 2)
        Pf = (1 - ss.K) ** 2 * Pp + ss.K**2 * G.R
    for s0, s1 in _segments(use, min_run):
        zz = z[s0:s1]
        if center:                  # the run's rows are finite (use)
            zz = zz - zz.mean()
        if mode == "smoothed":
            s[s0:s1], var[s0:s1] = _smooth(zz, a, ss, 1.0), ss.Ps
        else:
            xp = lfilter([0.0, a * ss.K], [1.0, -a * (1 - ss.K)], zz)     # one-step prediction, prior 0 at the start
            if mode == "predicted":
                s[s0:s1], var[s0:s1] = xp, Pp
            else:
                s[s0:s1], var[s0:s1] = xp + ss.K * (zz - xp), Pf
    return -s / cl_p, var / cl_p**2


def _step_slopes(G: RollDynamicsFit, dt: float, who: str) -> np.ndarray:
    """``(7,)`` the step slopes the fit's filter used: ``theta`` times the step's damping factor
    ``(e^{L_p dt} - 1)/(L_p dt)``. Raises ValueError (the message starts with ``who``) without a finite ``L_p``."""
    if not np.isfinite(G.L_p):
        raise ValueError(f"{who}: the fit has no roll damping L_p")
    x = G.L_p * dt
    return np.asarray(G.theta, float) * (np.expm1(x) / x if x != 0 else 1.0)


def gust_cutoff_variance(G: RollDynamicsFit, dt: float, bandwidth_hz: float) -> float:
    """The part of the rolling gust's moment that the rate smoother cuts off the measured Cl, as a variance (Cl units).

    The measured Cl takes ``Ixx p_dot`` from the rate smoother (:mod:`gcs_sysid.estimation.rates`), which follows
    the roll acceleration only up to its bandwidth; above it the gust's moment is missing from the measurement and no
    statistic of the gyro shows it (:mod:`gcs_sysid.estimation.smootherror`: the smoother's stated error takes its
    white-snap prior there; on JSBSim's light flights the stated ``p_dot`` error variance is 0.1-0.6 of the true one,
    docs/benchmarks.md, "Seventy-third session"). The fit's own gust model says what is there: the step moment's
    gust term ``s`` (Cl units) is first-order Gauss-Markov, ``sigma_s = sigma |Cl_p,step|``, ``a = exp(-dt/tau)``,
    and the roll rate answers it through the roll mode, ``(j w - L_p) p = s / k`` (``k = Ixx/(qbar S b)``). The
    smoothed acceleration then misses ``k (D - j w) p`` of the moment, so in Cl units

        var = mean over w in (0, pi) of  |D(w) - j w/dt|^2 / (w^2/dt^2 + L_p^2) * S_s(w),
        S_s(w) = sigma_s^2 (1 - a^2) / (1 - 2 a cos w + a^2)           (the sampled first-order process)

    with ``|D - j w/dt|^2`` :func:`gcs_sysid.estimation.smootherror.cutoff_gain` at the roll axis' bandwidth. The
    Wiener correction of the smoother's residual (which recovers some signal just above the bandwidth) is left out,
    so the figure leans high; the gust's sigma from the likelihood (about half JSBSim's, module docstring) leans low.

    Args:
        G: the roll fit (with a finite ``L_p``). dt: grid interval, s. bandwidth_hz: the rate smoother's roll-axis
            bandwidth, Hz (:attr:`gcs_sysid.estimation.states.FlightStates.rate_bandwidth_hz`).

    Returns:
        the variance, Cl^2 (0 for a fit without a gust).

    Raises:
        ValueError: a fit without a finite ``L_p``, or ``dt``/``bandwidth_hz`` not positive.

    Source: Bendat and Piersol, *Random Data*, 4th ed., 2010, sec. 6.1 (the linear estimate's error spectrum);
    MIL-F-8785C sec. 3.7.2 (the rolling gust as a first-order process); Stevens, Lewis and Johnson (2016), eq. 1.7-18.
    """
    from ..estimation.smootherror import N_FREQ, cutoff_gain

    cl_p = float(_step_slopes(G, dt, "gust_cutoff_variance")[_IP])
    var_s = float(G.sigma * cl_p) ** 2
    if not (np.isfinite(var_s) and var_s > 0):
        return 0.0
    w = np.pi * (np.arange(N_FREQ) + 0.5) / N_FREQ
    a = float(np.exp(-dt / G.tau))
    S = var_s * (1 - a * a) / (1 - 2 * a * np.cos(w) + a * a)
    return float(np.mean(cutoff_gain(dt, bandwidth_hz, w) / ((w / dt) ** 2 + G.L_p**2) * S))


def _step_residual(G: RollDynamicsFit, dt: float, X, Y, p, qbar, Ixx: float, S: float, b: float, who: str):
    """The step moment's residual on the fit's step slopes and the fit's steady-state filter: ``(z, cl_p, a, ss)``,
    ``z`` ``(T,)`` (NaN where the step moment is not defined), ``cl_p`` the step's ``Cl_p``, ``a = exp(-dt/tau)``,
    ``ss`` the :func:`~gcs_sysid.aero.gustfilter._gains` for the gust term ``s = -cl_p p_hat_g`` (Cl units).

    Raises:
        ValueError: shapes that disagree, or a fit without a finite ``L_p`` (the message starts with ``who``).
    """
    X, Y = np.asarray(X, float), np.asarray(Y, float)
    T = len(X)
    if X.shape != (T, len(REGRESSORS)) or Y.shape != (T, len(COEFFICIENTS)) or any(
            np.shape(v) != (T,) for v in (p, qbar)):
        raise ValueError(f"{who}: X (T, {len(REGRESSORS)}), Y (T, {len(COEFFICIENTS)}), p, qbar (T,) expected, got "
                         f"{X.shape}, {Y.shape}, {[np.shape(v) for v in (p, qbar)]}")
    th = _step_slopes(G, dt, who)
    cl_p = float(th[_IP])
    cols = [REGRESSORS.index(k) for k in LAT_TERMS]
    A = np.c_[np.ones(T), X[:, cols]]
    y = causal_roll_moment(dt, Y[:, COEFFICIENTS.index("Cl")], p, qbar, Ixx, S, b)
    a = float(np.exp(-dt / G.tau))
    return y - A @ th, cl_p, a, _gains(a, (G.sigma * cl_p) ** 2, 1.0, G.R)


#: How :func:`predicted_gust_variance` reads the training rows: ``"rts"`` (the one-step prediction against the
#: smoothed gust), ``"nis"`` (the innovations' mean square less the moment's noise) or ``"innov"`` (the
#: innovations' mean square plus the moment's noise: the prediction carries the measured moment's slow error).
PRED_VAR_METHODS = ("rts", "nis", "innov")


def predicted_gust_variance(G: RollDynamicsFit, dt: float, X: np.ndarray, Y: np.ndarray, p: np.ndarray,
                            qbar: np.ndarray, rows: np.ndarray, Ixx: float, S: float, b: float, method: str = "rts",
                            min_run: int = 10, cutoff_var: float = 0.0) -> float:
    """The one-step-ahead estimate's error variance of ``p_hat_g`` (dimensionless), measured on rows where the
    gust's moment is known to the fit (its training rows), not stated by the fit's likelihood: what
    :func:`roll_gust_on_rows` ``"predicted"`` should state on a held-out segment (its ``pred_var``). Nothing but
    the log's own moment enters (no true gust).

    On each run of usable ``rows`` the step moment's residual ``z`` goes through the fit's steady-state filter
    (prediction ``xp``, the innovations ``nu = z - xp``) and its Rauch-Tung-Striebel smoother (``xs``), the same
    filter as :func:`roll_gust_on_rows` on the held-out rows (``s = -Cl_p,step p_hat_g``, Cl units):

    - ``"rts"``: ``mean((xp - xs)^2) + Ps``. For a linear-Gaussian model the smoothed error is orthogonal to the
      smoother's correction, so the prediction's error variance is the correction's variance plus the smoothed one
      (Rauch, Tung and Striebel, AIAA J. 3(8), 1965; Gelb, *Applied Optimal Estimation*, 1974, sec. 5.2). The
      correction is measured; ``Ps`` is the fit's.
    - ``"nis"``: ``mean(nu^2) - R``. The innovation is the prediction's error plus the moment's white noise, which
      the prediction has not seen (Bar-Shalom, Li and Kirubarajan, *Estimation with Applications to Tracking and
      Navigation*, 2001, sec. 5.4: the normalised innovation squared; its mean ``mean(nu^2)/S`` is 1 for a
      consistent filter). Holds whatever the process variance, given the noise ``R``, if that noise is white.
    - ``"innov"``: ``mean(nu^2) + R``. The prediction is made from the *measured* moments before ``k``, so against
      the true moment its error is ``e - nu`` (``e`` the measured moment's error): variance
      ``mean(nu^2) + var e - 2 cov(nu, e)``. With white ``e`` the covariance is ``var e`` (``"nis"``); where ``e``
      is slow (the rate smoother's ``p_dot`` error, correlated over many grid steps) the prediction has followed
      it and ``nu`` holds little of it, the covariance goes to 0, and the error to ``mean(nu^2) + var e``, ``var e``
      the stated ``R``: the upper end of the bracket ``"nis"`` .. ``"innov"``
      (tests/aero/test_rollgust.py: a slow ``e`` lies inside it, 1.4-1.7 times short of ``"innov"``).

    On JSBSim's flights (72 light flights, thirty-second session, i8-clband, docs/benchmarks.md) the filter is
    consistent by its own innovations: ``"rts"`` gives the fit's ``P`` (ratio 1.00) and ``mean(nu^2)/S`` is
    0.36-0.94, so ``"rts"`` and ``"nis"`` state the fit's ``P``; the measured Cl's error against JSBSim's is
    2.0-6.0 times ``R`` and slow, and the GP's held-out Cl error against the truth is close to ``mean(nu^2)`` plus
    it, which only ``"innov"`` reads (with ``R``, still short of it).

    Each is floored at the fit's own ``P`` (the variance :func:`roll_gust_on_rows` states without it). ``cutoff_var``
    (Cl units, e.g. :func:`gust_cutoff_variance`) is added to any of them: the gust's moment the measured Cl never
    held, which the prediction, made from measured moments, misses against the true moment whatever the method.

    Args:
        G: the fit (:class:`RollDynamicsFit`, with ``L_p``). dt: grid interval, s.
        X: ``(T, 10)`` regressors (gyro hats). Y: ``(T, 6)`` measured coefficients. p: ``(T,)`` the smoothed roll
            rate, rad/s. qbar: ``(T,)`` Pa. rows: ``(T,)`` bool, where to measure (the fit's rows, ``G.used``).
        Ixx, S, b: kg m^2, m^2, m. method: one of :data:`PRED_VAR_METHODS`. min_run: shortest run of usable rows.
        cutoff_var: Cl^2, added before the division by ``Cl_p,step^2`` (0: none).

    Returns:
        the variance of ``p_hat_g``'s one-step prediction error (dimensionless); the fit's ``P / Cl_p,step^2``
        when no run is usable (with ``cutoff_var`` added in both cases).

    Raises:
        ValueError: an unknown ``method``, ``cutoff_var`` negative or not finite, shapes that disagree, or a fit
            without a finite ``L_p``.
    """
    from scipy.signal import lfilter

    if method not in PRED_VAR_METHODS:
        raise ValueError(f"predicted_gust_variance: method must be one of {PRED_VAR_METHODS}, got {method!r}")
    if not (np.isfinite(cutoff_var) and cutoff_var >= 0):
        raise ValueError(f"predicted_gust_variance: cutoff_var must be finite and >= 0, got {cutoff_var}")
    z, cl_p, a, ss = _step_residual(G, dt, X, Y, p, qbar, Ixx, S, b, "predicted_gust_variance")
    if np.shape(rows) != z.shape:
        raise ValueError(f"predicted_gust_variance: rows must be {z.shape}, got {np.shape(rows)}")
    use = np.asarray(rows, bool) & np.isfinite(z)
    sq, n = 0.0, 0
    for s0, s1 in _segments(use, min_run):
        zz = z[s0:s1]
        xp = lfilter([0.0, a * ss.K], [1.0, -a * (1 - ss.K)], zz)
        d = xp - _smooth(zz, a, ss, 1.0) if method == "rts" else zz - xp
        sq, n = sq + float(d @ d), n + len(d)
    if n == 0:
        return float((ss.P + cutoff_var) / cl_p**2)
    P = sq / n + {"rts": ss.Ps, "nis": -G.R, "innov": G.R}[method]
    return float((max(P, ss.P) + cutoff_var) / cl_p**2)
