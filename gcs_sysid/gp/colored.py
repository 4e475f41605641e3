"""Coloured residuals: how much less the rows are worth than their number says.

The global layer's likelihood treats the rows' noise as independent from row to row. In flight
data it is not: a gust, a lagging air-angle estimate or the angular-acceleration smoother's error
moves tens to hundreds of consecutive 50 Hz rows the same way, so the posterior variance of the
model, which falls as ``1 / n``, is too small by about the number of rows one error lasts. In
equation-error regression the same effect is corrected with the residuals' autocorrelation
(Morelli and Klein, *Aircraft System Identification: Theory and Practice*, 2nd ed., 2016, ch. 5,
the parameter covariance for coloured residuals,
``(X^T X)^{-1} X^T R_vv X (X^T X)^{-1}``); for regressors that vary slowly against the
residuals' correlation time that sandwich is the white-noise covariance times the long-run
variance ratio

    c = 1 + 2 sum_{k >= 1} w_k rho(k),     w_k = 1 - k / (K + 1)   (Bartlett weights)

of the residuals' autocorrelation ``rho`` (Newey and West 1987, "A simple, positive
semi-definite, heteroskedasticity and autocorrelation consistent covariance matrix",
Econometrica 55(3):703-708). ``K`` is the first lag where ``rho`` falls below 0.05 (at most a
quarter of the rows). The GP's explained (data-driven) predictive variance ``u^T H_p u`` is then
multiplied by ``c_p`` per output (``GPConfig.residual_correlation``); the prior part is not.

This needs the training rows in time order (as a flight's table gives them); shuffled rows give
``c ~ 1`` and change nothing.
"""

from __future__ import annotations

import numpy as np

__all__ = ["variance_inflation"]


def variance_inflation(resid: np.ndarray, floor: float = 0.05, max_share: float = 0.25) -> np.ndarray:
    """Long-run variance ratio ``c_p >= 1`` of each column of time-ordered residuals.

    Args:
        resid: ``(N, P)`` residuals of the model on its training rows, in time order.
        floor: the sum stops at the first lag whose autocorrelation is below this.
        max_share: most lags, as a share of ``N``.

    Returns:
        ``(P,)`` factors, at least 1 (a negative sum, anti-correlated residuals, is not used to
        shrink the variance). Ones when ``N < 8``.
    """
    r = np.asarray(resid, float)
    N, P = r.shape
    out = np.ones(P)
    if N < 8:
        return out
    r = r - r.mean(0)
    n_fft = 1 << int(np.ceil(np.log2(2 * N)))
    spec = np.fft.rfft(r, n_fft, axis=0)
    acov = np.fft.irfft(spec * np.conj(spec), n_fft, axis=0)[:N]        # sum_t r_t r_{t+k}, k = 0..N-1
    max_lag = max(1, int(max_share * N))
    for p in range(P):
        if acov[0, p] <= 0:
            continue
        rho = acov[1:max_lag + 1, p] / acov[0, p]
        below = np.flatnonzero(rho < floor)
        K = int(below[0]) if len(below) else len(rho)
        w = 1.0 - np.arange(1, K + 1) / (K + 1.0)
        out[p] = max(1.0, 1.0 + 2.0 * float(np.sum(w * rho[:K])))
    return out
