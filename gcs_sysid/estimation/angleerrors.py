"""What the air angles' reconstruction cannot see: the slope's errors in variables and the mean wind.

Two errors of the specific-force aided angle of attack (:mod:`gcs_sysid.estimation.airangles`),
measured against JSBSim's exact alpha (``docs/benchmarks.md``, "eval_jsbsim", 2026-11-22 subsection):

1. **Scale** (the force model's slope). The kinematic alpha is the *inertial* angle
   (``atan2`` of the ground velocity minus a slow wind, in body axes); the true, aerodynamic angle
   adds the vertical gust ``g``: ``alpha = alpha_kin + g``. The aircraft answers a gust (it heaves
   with it below the heave-mode corner, ``2 m / (rho S V CL_alpha)``, a fraction of a second), so
   ``alpha_kin`` and ``g`` are negatively correlated even above the band edge where the slopes are
   fitted, and the least-squares ``CZ_alpha`` on ``alpha_kin`` is attenuated (c172x, light: -8.9
   against -9.9 per rad, the aided alpha then 8 % too steep; moderate: half). The remedy of
   errors-in-variables regression is an instrument: a variable correlated with the true angle and
   not with the gust. The elevator is one: its maneuver part moves alpha and ignores the air
   (its feedback part answers the gust only through the attitude loop, slowly). Two-stage least
   squares with the elevator and its delayed copies as instruments (the angle's response to the
   elevator is spread over the short period) gives a consistent slope.
   Sources: Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016, sec. 5.4 (the
   equation-error bias with noisy regressors) and ch. 10 (data compatibility); Jategaonkar,
   *Flight Vehicle System Identification*, 2nd ed., AIAA 2015, ch. 10 (flight path
   reconstruction); Wooldridge, *Econometric Analysis of Cross Section and Panel Data*, 2nd ed.,
   MIT Press 2010, sec. 5.2 (two-stage least squares, first-stage strength).

2. **Mean** (the vertical wind over the flight). Body forces, rates and attitude do not see a
   constant vertical wind (a Galilean shift of the air mass changes nothing in the air-relative
   dynamics), and the force model's constant ``CZ0`` absorbs any constant in alpha; the pitot's
   energy channel gives the pitch attitude, not alpha. So the flight-mean of the vertical wind
   ``w_d`` stays out of reach, and with it an alpha offset ``mean(w_d) / V`` (measured: 0.07-0.17
   deg in light turbulence, 0.7-1.7 deg moderate, equal to ``mean(w_d) / V`` to 0.01 deg). What
   the log does give is the vertical wind's *fluctuation* (the aided gusts); with the turbulence's
   scale length ``L_w`` (MIL-F-8785C sec. 3.7.2: 1750 ft above 2000 ft, ``h`` below) the standard
   deviation of its mean over the record follows from the Dryden (first-order Gauss-Markov at zero
   frequency) model, ``tau = L_w / V``:

       var(mean over T) = 2 s^2 (tau / T) (1 - (tau / T) (1 - exp(-T / tau)))
       s^2 = s_rec^2 / (1 - var(mean) / s^2)    (the record's own std misses its mean's share)

   and the alpha offset's 1-sigma is ``sqrt(var(mean)) / V``. It is a *common* error of every
   sample of the flight, not independent per sample.
   Sources: MIL-F-8785C (1980) sec. 3.7; Papoulis, *Probability, Random Variables and Stochastic
   Processes*, 1991, sec. 9-5 (variance of the time average of a stationary process).
"""

from __future__ import annotations

import numpy as np

__all__ = ["GUST_SCALE_M", "INSTRUMENT_LAGS_S", "MIN_FIRST_STAGE_R2", "lagged_instruments", "iv_lstsq",
           "first_stage_f", "effective_n", "mean_wind_sigma"]

GUST_SCALE_M = 533.4          #: vertical turbulence scale L_w, m (MIL-F-8785C: 1750 ft above 2000 ft AGL)
INSTRUMENT_LAGS_S = (0.0, 0.1, 0.2, 0.4, 0.8, 1.6)   #: delays of the control instruments, s
MIN_FIRST_STAGE_R2 = 0.3      #: the instruments must explain this share of the angle's in-band variance


def lagged_instruments(dt: float, u: np.ndarray, lags_s: tuple[float, ...] = INSTRUMENT_LAGS_S) -> np.ndarray:
    """Delayed copies of the control inputs, the first value held before the start.

    Args:
        dt: grid step, s.
        u: (T, K) control inputs (e.g. the elevator, rad).
        lags_s: delays, s (rounded to whole samples).

    Returns:
        (T, K * L) array, the K inputs at each of the L delays.
    """
    u = np.asarray(u, float).reshape(len(u), -1)
    out = []
    for lag in lags_s:
        k = int(round(lag / dt))
        out.append(np.vstack([np.repeat(u[:1], k, axis=0), u[:len(u) - k]]) if k else u)
    return np.hstack(out)


def iv_lstsq(A: np.ndarray, y: np.ndarray, endog: list[int], Z: np.ndarray, fuller_n: float | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """Two-stage least squares ``y ~ A c`` with the columns ``endog`` of ``A`` instrumented by ``Z``.

    The exogenous columns of ``A`` are their own instruments. First stage: each endogenous column on
    ``[Z, A_exog]``; second stage: ``y`` on ``A`` with the endogenous columns replaced by their fitted
    values. Residuals are ``y - A c`` (with the actual columns); covariance ``s^2 (Ah' Ah)^-1``.

    With ``fuller_n`` the slopes are Fuller's k-class estimator instead (``alpha = 1``; Fuller, Econometrica 45,
    1977): ``c = (A' (I - k M) A)^-1 A' (I - k M) y`` with ``M`` the residual maker of ``W = [Z, A_exog]``,
    ``k = lambda - 1 / (fuller_n - cols(W))`` and ``lambda`` LIML's least eigenvalue of ``(Y' M Y)^-1 Y' M_X Y``,
    ``Y = [y, A_endog]``, ``M_X`` the residual maker of ``A_exog`` (``k = 1`` is 2SLS). Less biased than 2SLS with
    weak instruments and, unlike LIML, with finite moments (Hahn, Hausman and Kuersteiner, Econometrics J. 7, 2004).
    ``fuller_n`` is the sample size in the correction (the effective one for serially correlated data).

    Args:
        A: (N, P) regressors. y: (N,) regressand. endog: indices of the noisy columns of ``A``.
        Z: (N, Q) instruments, ``Q >= len(endog)``. fuller_n: None: 2SLS; else Fuller's k-class with this ``N``.

    Returns:
        ``(c (P,), standard errors (P,), residuals (N,), covariance (P, P), first-stage partial R^2)``:
        the share of the endogenous columns' variance left by the exogenous columns that the
        instruments explain (the smallest over ``endog``; weak instruments: near 0).

    Source: Wooldridge (2010) sec. 5.2 (module docstring).
    """
    exog = [j for j in range(A.shape[1]) if j not in endog]
    W = np.hstack([Z, A[:, exog]])
    Ah = A.copy()
    r2 = 1.0
    for j in endog:
        pi, *_ = np.linalg.lstsq(W, A[:, j], rcond=None)
        Ah[:, j] = W @ pi
        if exog:
            pe, *_ = np.linalg.lstsq(A[:, exog], A[:, j], rcond=None)
            left = A[:, j] - A[:, exog] @ pe
        else:
            left = A[:, j] - A[:, j].mean()
        explained = Ah[:, j] - (A[:, exog] @ pe if exog else A[:, j].mean())
        r2 = min(r2, float(explained @ explained) / max(float(left @ left), 1e-300))
    if fuller_n is None:
        c, *_ = np.linalg.lstsq(Ah, y, rcond=None)
        G = Ah.T @ Ah
    else:
        res_w = lambda X: X - W @ np.linalg.lstsq(W, X, rcond=None)[0]  # noqa: E731
        Y = np.column_stack([y, A[:, endog]])
        RY = res_w(Y)
        RX = Y - A[:, exog] @ np.linalg.lstsq(A[:, exog], Y, rcond=None)[0] if exog else Y - Y.mean(0)
        lam = float(np.min(np.real(np.linalg.eigvals(np.linalg.solve(RY.T @ RY, RX.T @ RX)))))
        k = lam - 1.0 / max(fuller_n - W.shape[1], 1.0)
        RA, ry = res_w(A), RY[:, 0]
        G = A.T @ A - k * (RA.T @ RA)
        c = np.linalg.solve(G, A.T @ y - k * (RA.T @ ry))
    e = y - A @ c
    s2 = float(e @ e) / max(len(y) - A.shape[1], 1)
    try:
        cov = np.linalg.inv(G) * s2
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(G) * s2
    return c, np.sqrt(np.maximum(np.diag(cov), 0.0)), e, cov, r2


def effective_n(a: np.ndarray, b: np.ndarray, max_lag: int) -> float:
    """Effective sample size of the correlation of two serially correlated series.

    ``N / (1 + 2 sum_{k=1}^{L} rho_a(k) rho_b(k))``: the variance of the sample correlation of two
    independent stationary series (Bartlett 1946; Bayley and Hammersley, J. R. Stat. Soc. Suppl. 8, 1946;
    Pyper and Peterman, Can. J. Fish. Aquat. Sci. 55, 1998, eq. 1), clipped to ``[1, N]``.

    Args:
        a, b: (N,) series (their means are removed). max_lag: ``L``, samples.

    Returns:
        the effective number of independent samples.
    """
    a, b = np.asarray(a, float) - np.mean(a), np.asarray(b, float) - np.mean(b)
    n = len(a)
    va, vb = float(a @ a), float(b @ b)
    if n < 3 or va <= 0 or vb <= 0:
        return float(max(n, 1))
    tau = 1.0
    for k in range(1, min(max_lag, n - 2) + 1):
        tau += 2.0 * (float(a[k:] @ a[:-k]) / va) * (float(b[k:] @ b[:-k]) / vb)
    return float(min(max(n / max(tau, 1e-9), 1.0), n))


def first_stage_f(A: np.ndarray, endog: list[int], Z: np.ndarray, max_lag: int) -> tuple[float, float, float]:
    """The least first-stage F statistic of the instruments ``Z`` over the endogenous columns, on the
    effective sample size.

    For each column ``j`` in ``endog``: ``x_j`` on ``[Z, A_exog]`` against ``x_j`` on ``A_exog``; the partial
    ``R^2`` gives ``F = (R^2 / Q) / ((1 - R^2) / (N_eff - Q - K))`` with ``Q`` instruments and ``K`` exogenous
    columns, where ``N_eff`` (:func:`effective_n` of the first stage's fitted part and residual) replaces ``N``:
    flight data at 50 Hz are strongly serially correlated and the iid ``F`` would count every sample. The weak-
    instrument rule: 2SLS only where ``F > 10`` (Staiger and Stock, Econometrica 65, 1997; Stock and Yogo, "Testing
    for weak instruments in linear IV regression", 2005: critical values near 10 for 10 % maximal bias of 2SLS
    relative to least squares at these sizes).

    Args:
        A: (N, P) regressors. endog: indices of the instrumented columns. Z: (N, Q) instruments.
        max_lag: the autocorrelation lags summed in :func:`effective_n`, samples.

    Returns:
        ``(F, partial R^2, N_eff)`` of the weakest column (the one with the least ``F``).
    """
    exog = [j for j in range(A.shape[1]) if j not in endog]
    W = np.hstack([Z, A[:, exog]])
    q, k = Z.shape[1], len(exog)
    best = (np.inf, 1.0, float(len(A)))
    for j in endog:
        pi, *_ = np.linalg.lstsq(W, A[:, j], rcond=None)
        fit = W @ pi
        if exog:
            pe, *_ = np.linalg.lstsq(A[:, exog], A[:, j], rcond=None)
            base = A[:, exog] @ pe
        else:
            base = np.full(len(A), A[:, j].mean())
        left, expl, res = A[:, j] - base, fit - base, A[:, j] - fit
        r2 = float(expl @ expl) / max(float(left @ left), 1e-300)
        n_eff = effective_n(expl, res, max_lag)
        dof = n_eff - q - k
        f = (r2 / q) / max((1.0 - r2) / dof, 1e-300) if dof > 0 else 0.0
        if f < best[0]:
            best = (float(f), r2, n_eff)
    return best


def mean_wind_sigma(w_gust: np.ndarray, V: np.ndarray, duration_s: float, scale_m: float = GUST_SCALE_M) -> float:
    """1-sigma of the flight-mean of the vertical wind, as an angle-of-attack offset, rad.

    Args:
        w_gust: (N,) the vertical wind's fluctuation over the record, m/s (e.g. airspeed times the
            aided minus the kinematic alpha), finite samples only.
        V: (N,) true airspeed, m/s.
        duration_s: record length T, s (the sum of the aided segments).
        scale_m: turbulence scale length ``L_w``, m.

    Returns:
        ``sqrt(var(mean w_d over T)) / mean(V)`` (module docstring), rad; NaN without data.

    Source: MIL-F-8785C sec. 3.7; Papoulis (1991) sec. 9-5 (module docstring).
    """
    w = np.asarray(w_gust, float)
    if len(w) < 10 or not duration_s > 0:
        return float("nan")
    Vm = float(np.mean(V))
    x = duration_s / (scale_m / max(Vm, 1.0))                      # T / tau
    r = 2.0 / x * (1.0 - (1.0 - np.exp(-x)) / x)                  # var(mean) / s^2 of a Gauss-Markov process
    s2 = float(np.var(w)) / max(1.0 - r, 1e-3)                     # the record's variance lacks its mean's share
    return float(np.sqrt(r * s2) / max(Vm, 1.0))
