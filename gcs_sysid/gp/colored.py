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

__all__ = ["variance_inflation", "decorrelation_lag", "linear_residual", "ols_coloured_t", "significant_inputs",
           "T_KEEP", "lagged_products", "default_lag"]


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


def decorrelation_lag(resid: np.ndarray, level: float = float(np.exp(-1.0)), max_share: float = 0.25) -> np.ndarray:
    """The decorrelation time of each column of time-ordered residuals, in rows: the first lag ``k >= 1``
    where the sample autocorrelation ``rho(k)`` falls below ``level`` (1/e: the time constant of an
    exponential autocorrelation, ``rho(k) = exp(-k dt / T)``).

    Rows ``k`` apart then correlate by at most ~1/e: for a first-order autoregressive error the effective
    number of independent rows among ``n`` correlated by ``rho`` is ``n (1 - rho) / (1 + rho)`` (Bayley and
    Hammersley 1946, "The 'effective' number of independent observations in an autocorrelated time series",
    J. R. Stat. Soc. Suppl. 8(2):184-197; Bartlett 1946), so rows a decorrelation time apart are worth
    ``(1 - 1/e) / (1 + 1/e) ~ 0.46`` of independent ones each, and rows closer together much less (50 Hz rows
    with ``rho = 0.95``: 0.026). Morelli and Klein (*Aircraft System Identification*, 2nd ed., 2016, ch. 5)
    and Jategaonkar (*Flight Vehicle System Identification*, 2nd ed., 2015, ch. 6) correct the equation-error
    covariance for the same colouring.

    Args:
        resid: ``(N, P)`` residuals in time order (NaN rows of a column are dropped for that column).
        level: the autocorrelation the lag must fall below, in (0, 1).
        max_share: most lags searched, as a share of the column's rows.

    Returns:
        ``(P,)`` lags in rows, at least 1 (1 for a column with fewer than 8 rows or zero variance; the
        largest lag searched when ``rho`` never falls below ``level``).

    Raises:
        ValueError: ``level`` outside (0, 1).
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"decorrelation_lag: level must be in (0, 1), got {level!r}")
    r = np.asarray(resid, float)
    r = r[:, None] if r.ndim == 1 else r
    out = np.ones(r.shape[1], int)
    for p in range(r.shape[1]):
        v = r[np.isfinite(r[:, p]), p]
        if len(v) < 8:
            continue
        v = v - v.mean()
        max_lag = max(1, int(max_share * len(v)))
        ac = _autocov(v, max_lag)
        if ac[0] <= 0:
            continue
        below = np.flatnonzero(ac[1:] / ac[0] < level)
        out[p] = int(below[0]) + 1 if len(below) else max_lag
    return out


def linear_residual(Xs: np.ndarray, Ys: np.ndarray, ridge: float = 1e-3) -> np.ndarray:
    """The residual ``(N, P)`` of a ridge least-squares fit ``Ys ~ [1, Xs] W`` (each output on its finite rows;
    NaN where an output is missing): the equation-error residual whose colour :func:`decorrelation_lag` reads.

    Args:
        Xs: ``(N, D)`` regressors, Ys: ``(N, P)`` outputs (standardised; NaN: missing), rows in time order.
        ridge: added to the normal matrix's diagonal.
    """
    Xa = np.concatenate([np.ones((len(Xs), 1)), np.asarray(Xs, float)], axis=1)
    Ys = np.asarray(Ys, float)
    R = np.full_like(Ys, np.nan)
    for p in range(Ys.shape[1]):
        ok = np.isfinite(Ys[:, p])
        if ok.sum() < 2:
            continue
        A = Xa[ok]
        w = np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]), A.T @ Ys[ok, p])
        R[ok, p] = Ys[ok, p] - A @ w
    return R


def default_lag(n: int) -> int:
    """The Bartlett window's largest lag for ``n`` rows: ``min(n - 1, 250, max(10, 4 n^(1/3)))`` (as
    ``gcs_sysid.diagnose.regression.colored_covariance``)."""
    return max(0, int(min(n - 1, 250, max(10, 4 * n ** (1 / 3)))))


def _autocov(v: np.ndarray, max_lag: int) -> np.ndarray:
    """Biased autocovariance ``(max_lag + 1,)``: ``r_k = (1/N) sum_i v_i v_(i+k)`` (by FFT)."""
    n = len(v)
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    f = np.fft.rfft(v, nfft)
    return np.fft.irfft(f * np.conj(f), nfft)[: max_lag + 1] / n


def lagged_products(X: np.ndarray, max_lag: int) -> np.ndarray:
    """``G_k = sum_i x_i x_(i+k)^T`` for ``k = 0..max_lag``, ``(max_lag + 1, K, K)``, of the columns of
    ``X (N, K)`` (by FFT: one cross-spectrum per pair of columns)."""
    X = np.asarray(X, float)
    n = len(X)
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    F = np.fft.rfft(X, nfft, axis=0)                                   # (nfft/2+1, K)
    cross = np.fft.irfft(np.conj(F)[:, :, None] * F[:, None, :], nfft, axis=0)   # [k, a, b] = sum_i x_ia x_(i+k)b
    return cross[: max_lag + 1]


def ols_coloured_t(X: np.ndarray, y: np.ndarray, max_lag: int | None = None, lagged: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Least squares ``y ~ theta_0 + X theta`` and the ``|t|`` of each slope with coloured residuals.

    The slopes' covariance is the sandwich ``(X^T X)^{-1} X^T R X (X^T X)^{-1}`` with ``R`` the
    Toeplitz matrix of the residuals' biased autocovariance ``r_k``, weighted by Bartlett's window
    ``w_k = 1 - k / (L + 1)`` up to ``L = max_lag`` (Morelli and Klein 2016, sec. 5.3; Newey and West
    1987), so ``X^T R X = w_0 r_0 G_0 + sum_(k=1..L) w_k r_k (G_k + G_k^T)`` with the lagged products
    ``G_k`` of the centred columns (:func:`lagged_products`). It is the form and default lag of
    ``gcs_sysid.diagnose.regression.colored_covariance`` (``"bartlett"``), which the project's
    stepwise regression uses for its partial F (``tests/gp/test_linear_terms.py`` checks that the two
    agree). The intercept is estimated (columns centred), not tested.

    Args:
        X: ``(N, K)`` regressors in time order (K >= 1), finite.
        y: ``(N,)`` output, finite.
        max_lag: ``L``; default :func:`default_lag`.
        lagged: ``lagged_products(X - X.mean(0), L)`` when the caller has it (a backward elimination
            reuses the products of all columns: pass the rows and columns of the kept ones).

    Returns:
        ``(theta (K,), t (K,))``: the slopes and ``|theta| / se`` (``inf`` where the standard error is 0).
    """
    X = np.asarray(X, float)
    y = np.asarray(y, float)
    n = len(y)
    L = default_lag(n) if max_lag is None else max(0, min(int(max_lag), n - 1))
    Xc = X - X.mean(0)
    G = lagged_products(Xc, L) if lagged is None else np.asarray(lagged)[: L + 1]
    xtx = G[0]
    yc = y - y.mean()
    theta = np.linalg.lstsq(xtx, Xc.T @ yc, rcond=None)[0]          # normal equations (K x K): columns centred
    r = _autocov(yc - Xc @ theta, L)
    w = 1.0 - np.arange(L + 1) / (L + 1.0)
    S = np.einsum("k,kab->ab", w[1:] * r[1:], G[1:]) if L > 0 else np.zeros_like(xtx)
    mid = r[0] * xtx + S + S.T
    xtx_inv = np.linalg.pinv(xtx)
    se = np.sqrt(np.maximum(np.diag(xtx_inv @ mid @ xtx_inv), 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(se > 0, np.abs(theta) / se, np.inf)
    return theta, t


#: A regressor stays in an output's linear mean while its slope's ``|t|`` with coloured residuals is at
#: least this: partial F >= 4, the stepwise regression's rule to keep a term (``f_out``; Morelli and
#: Klein 2016, sec. 5.4.3).
T_KEEP = 2.0


def significant_inputs(Xs: np.ndarray, Ys: np.ndarray, active: np.ndarray, t_keep: float = T_KEEP) -> np.ndarray:
    """Per output, the regressors whose linear term the data support with coloured residuals.

    Backward elimination (Morelli and Klein 2016, sec. 5.4.3; Draper and Smith, *Applied Regression
    Analysis*, 3rd ed., ch. 15): start from every active regressor, fit least squares, drop the
    regressor with the smallest ``|t|`` (:func:`ols_coloured_t`) while it is below ``t_keep``.

    Why (``docs/gp.md``, "Linear terms that earn their place"): the measured moment coefficients carry
    the angular-acceleration estimate's error, which grows with the control rate and so is correlated with
    the controls over a whole flight. A linear mean with every regressor turns it into small apparent
    derivatives (on the JSBSim T-6, ``Cn_delta_a`` and ``Cn_q_hat``, which its aerodynamics does not
    have) that do not hold on a differently excited segment. With white-noise standard errors those
    terms look significant; with the residuals' autocorrelation most of them do not.

    The test treats the linear fit's residual as noise. For an output with a large smooth nonlinear
    part that residual is signal, and a true linear term can be dropped. That is why the default
    ``GPConfig.linear_terms = "validated"`` applies it only to the outputs whose latent GP the blocked
    validation shrank (``gcs_sysid.gp.fit._validated_terms``; ``docs/gp.md``).

    Args:
        Xs: ``(N, D)`` regressors in time order (standardised or not: ``t`` does not depend on scale).
        Ys: ``(N, P)`` outputs; NaN marks a missing entry (each output uses its own finite rows).
        active: ``(D,)`` bool, the regressors that vary (the others are never kept).
        t_keep: the least ``|t|`` a kept term has.

    Returns:
        ``(P, D)`` bool: True where output ``p``'s linear mean keeps regressor ``d``. An output with
        fewer rows than ``2 (D + 2)`` keeps every active regressor.
    """
    Xs = np.asarray(Xs, float)
    Ys = np.asarray(Ys, float)
    active = np.asarray(active, bool)
    P, D = Ys.shape[1], Xs.shape[1]
    keep = np.tile(active, (P, 1))
    G = None
    for p in range(P):
        rows = np.isfinite(Ys[:, p]) & np.all(np.isfinite(Xs), 1)
        if rows.sum() < 2 * (D + 2):
            continue
        X, y = Xs[rows], Ys[rows, p]
        cols = [d for d in range(D) if active[d]]
        L = default_lag(len(y))
        if G is None or G[0] != rows.tobytes():         # the lagged products of these rows, once
            G = (rows.tobytes(), lagged_products(X - X.mean(0), L))
        while cols:
            _, t = ols_coloured_t(X[:, cols], y, L, G[1][:, cols][:, :, cols])
            j = int(np.argmin(t))
            if t[j] >= t_keep:
                break
            cols.pop(j)
        keep[p] = False
        keep[p, cols] = True
    return keep
