"""Control commands as known inputs of the rate and force smoothers: response columns and delays.

Also the measured signals that enter the rate smoother beside the controls (:func:`aux_columns`,
:func:`normal_force_input`). The columns are the deterministic responses (acceleration and its exact
integral) to unit coefficients of each control's step and decaying transients;
see :mod:`gcs_sysid.estimation.rates` for the model and the references.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import butter, filtfilt, lfilter

__all__ = ["control_columns", "aux_columns", "normal_force_input", "prepare_inputs", "shift", "lagged"]


def control_columns(dt: float, controls: np.ndarray, scale: np.ndarray, lags: tuple[int, ...] = (0, 1),
                    decays: tuple[float, ...] = (0.0, 10.0), hold: str = "zoh") -> tuple[np.ndarray, np.ndarray]:
    """Acceleration and rate responses to unit coefficients of each scaled, lagged control.

    Column ``j = (c * len(lags) + l) * len(decays) + d``, with ``lambda = decays[d]``
    (1/s) and ``delta = delta_c(k - lag)`` (held at its first value before the
    lagged record starts):

    - ``lambda = 0`` (a step): acceleration ``A_k = s_k (delta_k - delta_0)``, the
      control moment itself, jumping where the control steps;
    - ``lambda > 0`` (a decaying transient): each change ``s_k (delta_k - delta_{k-1})``
      starts an acceleration ``exp(-lambda (t - t_k))``:
      ``A_k = exp(-lambda dt) A_{k-1} + s_k (delta_k - delta_{k-1})``. Together
      with the step this lets the *jerk* jump too (``-lambda`` times the
      transient's share), as after a step the damping moment builds up at
      once (roll rate: ``p_dot = L_da da exp(L_p t)``).

    Acceleration ``A_k`` is the value at ``t_k``, held (step) or decaying over
    ``[t_k, t_k + dt)``; the rate ``W`` is its exact integral:
    ``W_{k+1} = W_k + A_k (1 - exp(-lambda dt)) / lambda`` (``dt A_k`` for a step).

    With ``hold="foh"`` the control moves linearly between its samples instead
    (a servo's smooth motion): the step column is ``s_k (delta_k - delta_0)`` at
    the grid points, linear between them, and the transients are the exact
    responses of ``a_dot = -lambda a + d/dt (s delta)`` to that ramp
    (:func:`_foh_column`); ``W`` is again the exact integral (Franklin, Powell
    and Workman 1998, sec. 6.3, first-order hold).

    Args:
        dt: grid step, s.
        controls: (n, m) control deflections (any unit), finite.
        scale: (n,) effectiveness scale (dynamic pressure), finite.
        lags: input lags in grid steps.
        decays: decay rates of the transients, 1/s (0: a step).
        hold: ``"zoh"`` (held over each step) or ``"foh"`` (linear between samples).

    Returns:
        ``(A, W)``, each (n, m * len(lags) * len(decays)).
    """
    n, m = controls.shape
    ncol = m * len(lags) * len(decays)
    A = np.zeros((n, ncol))
    W = np.zeros((n, ncol))
    for c in range(m):
        for li, lag in enumerate(lags):
            dl = np.concatenate([np.full(min(lag, n), controls[0, c]), controls[:n - lag, c]])
            for di, lam in enumerate(decays):
                j = (c * len(lags) + li) * len(decays) + di
                if hold == "foh":
                    x = scale * (dl - dl[0]) if lam == 0.0 else scale * np.diff(dl, prepend=dl[0])
                    A[:, j], W[:, j] = _foh_column(dt, x, lam)
                    continue
                if lam == 0.0:
                    A[:, j] = scale * (dl - dl[0])
                    inc = dt
                else:
                    ch = scale * np.diff(dl, prepend=dl[0])
                    rho = math.exp(-lam * dt)
                    A[:, j] = lfilter([1.0], [1.0, -rho], ch)
                    inc = (1.0 - rho) / lam
                W[1:, j] = inc * np.cumsum(A[:-1, j])
    return A, W


def _foh_column(dt: float, x: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray]:
    """Acceleration at the grid points and its exact integral for a control moving linearly between
    its samples (first-order hold). ``lam = 0``: ``x`` (n,) is the step column itself,
    ``s_k (delta_k - delta_0)``; ``lam > 0``: ``x`` (n,) holds the scaled changes ``s_k (delta_k -
    delta_{k-1})``, each spread evenly over the interval before sample ``k``, and the column is the
    exact response of ``a_dot = -lam a + (the control's rate)`` to them (a decaying transient)."""
    n = len(x)
    W = np.zeros(n)
    if lam == 0.0:
        W[1:] = np.cumsum(0.5 * dt * (x[:-1] + x[1:]))
        return x, W
    rho = math.exp(-lam * dt)
    g = (1.0 - rho) / (lam * dt)                     # a ramp's contribution over one interval
    A = lfilter([g], [1.0, -rho], x)
    # integral over [t_k, t_k+1]: A_k (1 - rho) / lam + r (dt - (1 - rho) / lam) / lam, r = x_{k+1} / dt
    inc = A[:-1] * (1.0 - rho) / lam + x[1:] / dt * (dt - (1.0 - rho) / lam) / lam
    W[1:] = np.cumsum(inc)
    return A, W


def aux_columns(dt: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Acceleration columns ``x - x_0`` of measured signals (n, k), linear between samples, and their
    exact (trapezoid) integrals."""
    A = x - x[0]
    W = np.zeros_like(A)
    W[1:] = np.cumsum(0.5 * dt * (A[:-1] + A[1:]), axis=0)
    return A, W


def normal_force_input(dt: float, az: np.ndarray, cutoff_hz: float | None = None) -> np.ndarray | None:
    """The measured normal specific force as a known input of the rate smoother.

    ``az`` carries what the gyros cannot: the angle-of-attack changes that gusts make (``CZ_alpha
    alpha``), which drive the pitching moment through ``Cm_alpha alpha`` at the same instant. Passed
    as ``aux`` to :func:`smooth_rates` for the pitch axis (``aux_axes=(1,)``: on roll and yaw it would
    stand in for turn dynamics it does not cause), the smoother fits one coefficient (a ratio like
    ``M_alpha / Z_alpha``) by the same likelihood as the controls' and the angular acceleration gets
    that part at the accelerometer's bandwidth, not the smoother's.

    By default the samples go in as they are (gaps filled linearly for the column, NaN again after):
    the gust-driven part of ``Cm`` reaches the Nyquist frequency in turbulence, and any low-pass cuts
    it off, while the accelerometer's white noise enters ``q_dot`` only times the fitted ratio and is
    then smoothed with the rest. On JSBSim (c172x, seeds 4 and 6, issue 8, 2026-11-22) the held-out
    Cm went 6.2-6.6 -> 5.2-5.7 % in light and 19-20 -> 11-12 % in moderate turbulence against the
    earlier 6 Hz second-order zero-phase Butterworth (5.6-6.1 and 15-16 % at 12 Hz); the sgs stays
    within 0.1 point light and gains 0.7 moderate. ``cutoff_hz`` keeps that low-pass (``filtfilt``
    at ``min(cutoff_hz, 0.25 / dt)``) for data whose accelerometer carries vibration lines.

    Args:
        dt: grid step, s.
        az: (T,) body-z specific force, m/s^2, NaN where missing.
        cutoff_hz: optional low-pass cut-off, Hz (None: unfiltered).

    Returns:
        (T, 1) ``az`` in m/s^2 (filtered if asked), or None when fewer than 30 samples are finite.

    Source: Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016, ch. 5 and 11
    (measured accelerations as regressors; zero-phase smoothing before differentiation).
    """
    az = np.asarray(az, float)
    ok = np.isfinite(az)
    if ok.sum() < 30:
        return None
    y = np.interp(np.arange(len(az)), np.nonzero(ok)[0], az[ok])
    if cutoff_hz is not None:
        b, a = butter(2, min(cutoff_hz, 0.25 / dt) * 2.0 * dt)
        y = filtfilt(b, a, y)
    y[~ok] = np.nan
    return y[:, None]


def prepare_inputs(T: int, controls, scale) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Controls that move (T, nc), the mask of those among the given ones, and the filled scale (T,)."""
    if controls is None:
        return np.zeros((T, 0)), np.zeros(0, bool), np.ones(T)
    U = np.asarray(controls, float).reshape(len(controls), -1)
    if len(U) != T:
        raise ValueError(f"controls have {len(U)} rows, the signal {T}")
    moving = np.array([np.isfinite(U[:, c]).any() and np.nanmax(U[:, c]) > np.nanmin(U[:, c])
                       for c in range(U.shape[1])], bool)
    U = U[:, moving]
    s = np.ones(T)
    if scale is not None and U.shape[1]:
        s = np.asarray(scale, float)
        if len(s) != T:
            raise ValueError(f"scale has {len(s)} rows, the signal {T}")
        f = np.isfinite(s)
        s = np.interp(np.arange(T), np.nonzero(f)[0], s[f]) if f.any() else np.ones(T)
    return U, moving, s


def shift(X: np.ndarray, lag: int) -> np.ndarray:
    """Rows of ``X`` moved ``lag`` steps later, zeros in front (a delayed zero-state response)."""
    if lag == 0:
        return X
    Y = np.zeros_like(X)
    Y[lag:] = X[:len(X) - lag]
    return Y


def lagged(X: np.ndarray, nd: int, lag: np.ndarray) -> np.ndarray:
    """Columns of each control (blocks of ``nd``) delayed by that control's lag."""
    if not np.any(lag):
        return X
    # columns after the controls' blocks (measured signals) are not delayed
    return np.concatenate([shift(X[:, k * nd:(k + 1) * nd], int(lag[k])) for k in range(len(lag))]
                          + [X[:, len(lag) * nd:]], axis=1)
