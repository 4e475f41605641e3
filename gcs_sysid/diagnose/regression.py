"""Equation-error least squares and stepwise regression (Morelli and Klein, ch. 5).

Ordinary least squares on normalised regressors, the parameter covariance
``s^2 (X'X)^-1`` and its correction for coloured residuals, the fit statistics
R^2, F0 and PSE, and stepwise regression to pick the model structure.

References:
    E. A. Morelli and V. Klein, *Aircraft System Identification: Theory and
    Practice*, 2nd ed., Sunflyte, 2016 (1st ed. AIAA 2006):
    sec. 5.2 (ordinary least squares, eqs. 5.8-5.24), sec. 5.3 (coloured
    residuals: ``Cov = (X'X)^-1 [sum_i sum_j x(i) R_vv(i-j) x(j)'] (X'X)^-1``),
    sec. 5.4 (model structure determination: R^2, F0, partial F, partial
    correlation, predicted squared error ``PSE = v'v/N + sigma_max^2 p/N``,
    stepwise regression). The lag window on ``R_vv`` (Bartlett weights) follows
    Newey and West, Econometrica 55 (1987) 703-708, to keep the estimate stable.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import fftconvolve

from ..errors import DataError
from .terms import canonical_term, term_factors, term_matrix

__all__ = ["OLSResult", "ols", "colored_covariance", "stepwise", "StepwiseResult", "effective_samples"]


@dataclass(frozen=True)
class OLSResult:
    """One least-squares fit ``z = X theta + v``.

    Attributes:
        terms: names of the K columns (``"1"`` for the intercept).
        theta: estimates, shape (K,), in the units of the raw columns.
        std_error: standard errors corrected for coloured residuals, shape (K,).
        std_error_white: standard errors ``sqrt(diag(s^2 (X'X)^-1))``, shape (K,).
        cov: corrected covariance, shape (K, K).
        s2: residual variance ``v'v / (N - K)``.
        r2: coefficient of determination (eq. 5.62); 0 when z is constant.
        f0: overall F statistic for regression (eq. 5.64), NaN with intercept only.
        pse: predicted squared error (eq. 5.98).
        n: number of samples N.
        residual: ``z - X theta``, shape (N,).
        condition: condition number of the normalised design.
    """

    terms: tuple[str, ...]
    theta: np.ndarray
    std_error: np.ndarray
    std_error_white: np.ndarray
    cov: np.ndarray
    s2: float
    r2: float
    f0: float
    pse: float
    n: int
    residual: np.ndarray = field(repr=False)
    condition: float = 1.0

    def as_dict(self) -> dict:
        """JSON-able summary (no residual)."""
        return {
            "terms": {t: {"value": float(v), "std_error": float(s), "std_error_white": float(w)}
                      for t, v, s, w in zip(self.terms, self.theta, self.std_error, self.std_error_white)},
            "s2": float(self.s2), "r2": float(self.r2), "f0": float(self.f0), "pse": float(self.pse),
            "n": int(self.n), "condition": float(self.condition),
        }


def _autocov(v: np.ndarray, max_lag: int) -> np.ndarray:
    """Biased autocovariance ``R(k) = (1/N) sum_i v(i) v(i+k)``, k = 0..max_lag (via FFT)."""
    n = v.shape[0]
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    f = np.fft.rfft(v, nfft)
    r = np.fft.irfft(f * np.conj(f), nfft)[: max_lag + 1] / n
    return r


def colored_covariance(X: np.ndarray, v: np.ndarray, max_lag: int | None = None,
                       method: str = "bartlett") -> np.ndarray:
    """Parameter covariance of OLS for coloured residuals (Morelli and Klein sec. 5.3).

    ``Cov = (X'X)^-1 X' R X (X'X)^-1`` with ``R`` the Toeplitz matrix of the biased residual
    autocovariance ``R_vv(k) = (1/N) sum_i v(i) v(i+k)``.

    Two forms:

    * ``"bartlett"`` (default): lags beyond ``max_lag`` set to zero and the rest weighted by
      Bartlett's window (Newey and West 1987), which keeps the middle factor positive
      semi-definite; short lag windows under-state the variance when the residual is correlated
      over seconds.
    * ``"morelli"``: Morelli and Klein's own form (sec. 5.3; their SIDPAC ``r_colores``): every
      lag ``|k| <= N - 1`` of the biased autocovariance, unweighted
      (``sum_i sum_j x(i) R_vv(i - j) x(j)'``). It follows correlation over the whole record,
      which is what 2-sigma intervals of equation-error estimates on turbulent flights need;
      ``max_lag`` is ignored. The middle factor is symmetrised; it may be indefinite for
      parameter combinations the data hardly excite, so take square roots of ``max(diag, 0)``.

    Args:
        X: design, shape (N, K).
        v: residuals, shape (N,).
        max_lag: largest lag of ``"bartlett"``; default ``min(N - 1, max(10, 4 * N**(1/3)), 250)``.
        method: ``"bartlett"`` or ``"morelli"``.

    Returns:
        covariance of shape (K, K). White residuals give ``~ s^2 (X'X)^-1`` with either form.

    Raises:
        ValueError: unknown ``method``.
    """
    X = np.asarray(X, float)
    v = np.asarray(v, float)
    n = X.shape[0]
    if method == "morelli":
        r = _autocov(v, n - 1)
        kern = np.concatenate([r[:0:-1], r])                     # lags -(N-1)..N-1, unweighted
        RX = fftconvolve(X, kern[:, None], mode="same", axes=0) if n > 1 else X * r[0]
    elif method == "bartlett":
        if max_lag is None:
            max_lag = int(min(n - 1, 250, max(10, 4 * n ** (1 / 3))))
        max_lag = max(0, min(int(max_lag), n - 1))
        r = _autocov(v, max_lag)
        w = 1.0 - np.arange(max_lag + 1) / (max_lag + 1.0)
        kern = np.concatenate([(r * w)[:0:-1], r * w])          # lags -L..L
        RX = fftconvolve(X, kern[:, None], mode="same", axes=0) if max_lag > 0 else X * r[0]
    else:
        raise ValueError(f"colored_covariance: method must be 'bartlett' or 'morelli', got '{method}'")
    mid = X.T @ RX
    mid = 0.5 * (mid + mid.T)
    xtx_inv = np.linalg.pinv(X.T @ X)
    return xtx_inv @ mid @ xtx_inv


def effective_samples(v: np.ndarray, max_lag: int = 250) -> float:
    """Effective number of independent samples of a coloured series.

    ``N_eff = N / (1 + 2 sum_k w_k rho(k))`` with the Bartlett-weighted autocorrelation
    ``rho`` (the variance-inflation factor of a sample mean); clipped to ``[1, N]``.
    """
    v = np.asarray(v, float) - np.mean(v)
    n = v.shape[0]
    if n < 3 or not np.any(v):
        return float(max(n, 1))
    L = int(min(n - 1, max_lag))
    r = _autocov(v, L)
    rho = r / r[0]
    w = 1.0 - np.arange(L + 1) / (L + 1.0)
    infl = 1.0 + 2.0 * np.sum(w[1:] * rho[1:])
    return float(np.clip(n / max(infl, 1e-9), 1.0, n))


def ols(X: np.ndarray, z: np.ndarray, terms=None, colored: bool = True, max_lag: int | None = None,
        cov_method: str = "bartlett") -> OLSResult:
    """Ordinary least squares with normalised regressors (Morelli and Klein sec. 5.2-5.4).

    Columns are centred (when an intercept column ``"1"`` is present) and scaled to
    unit length before solving, which keeps ``X'X`` well conditioned (sec. 5.2.3);
    estimates and covariances are transformed back to the raw columns.

    Args:
        X: design, shape (N, K); a column of ones is the intercept.
        z: measured output, shape (N,).
        terms: K column names (default ``x0, x1, ...``; ``"1"`` for a constant column).
        colored: correct standard errors for coloured residuals (sec. 5.3).
        max_lag: lag limit of the residual autocovariance (see :func:`colored_covariance`).
        cov_method: ``"bartlett"`` or ``"morelli"``, the form of :func:`colored_covariance`.

    Returns:
        :class:`OLSResult`.

    Raises:
        DataError: fewer samples than parameters + 1, or non-finite data.
    """
    X = np.asarray(X, float)
    z = np.asarray(z, float)
    n, k = X.shape
    if terms is None:
        terms = tuple("1" if np.all(X[:, j] == 1.0) else f"x{j}" for j in range(k))
    terms = tuple(terms)
    if n <= k:
        raise DataError(f"least squares: {n} samples cannot determine {k} parameters")
    if not (np.all(np.isfinite(X)) and np.all(np.isfinite(z))):
        raise DataError("least squares: regressors or output contain NaN or inf")
    icpt = [j for j in range(k) if terms[j] == "1"]
    has_icpt = bool(icpt)
    mean = X.mean(axis=0) if has_icpt else np.zeros(k)
    for j in icpt:
        mean[j] = 0.0
    Xc = X - mean
    scale = np.sqrt(np.sum(Xc**2, axis=0))
    scale[scale == 0] = 1.0
    Xn = Xc / scale
    # z = Xn b ; theta_j = b_j / scale_j (j not intercept); theta_0 = b_0/scale_0 - sum_j theta_j mean_j
    b, *_ = np.linalg.lstsq(Xn, z, rcond=None)
    T = np.diag(1.0 / scale)
    for j0 in icpt:
        T[j0, :] -= mean / scale
        T[j0, j0] = 1.0 / scale[j0]
    theta = T @ b
    v = z - X @ theta
    dof = n - k
    s2 = float(v @ v / dof)
    sv = np.linalg.svd(Xn, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    cov_b_white = s2 * np.linalg.pinv(Xn.T @ Xn)
    cov_white = T @ cov_b_white @ T.T
    cov = T @ colored_covariance(Xn, v, max_lag, cov_method) @ T.T if colored else cov_white
    se_w = np.sqrt(np.maximum(np.diag(cov_white), 0.0))
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    zbar = float(np.mean(z))
    sst = float(np.sum((z - zbar) ** 2))
    sse = float(v @ v)
    r2 = 1.0 - sse / sst if sst > 0 else 0.0
    p_reg = k - (1 if has_icpt else 0)
    f0 = ((sst - sse) / p_reg) / s2 if p_reg > 0 and s2 > 0 else float("nan")
    sigma_max2 = sst / n
    pse = sse / n + sigma_max2 * k / n
    return OLSResult(terms, theta, se, se_w, cov, s2, r2, f0, pse, n, v, cond)


@dataclass
class StepwiseResult:
    """Outcome of :func:`stepwise`.

    Attributes:
        fit: the final :class:`OLSResult`.
        history: one dict per step (``action`` add/drop/stop, ``term``, ``partial_f``,
            ``partial_corr``, ``r2``, ``pse``).
    """

    fit: OLSResult
    history: list[dict]


def stepwise(X: np.ndarray, z: np.ndarray, candidates, forced=("1",), f_in: float = 4.0, f_out: float = 4.0,
             colored: bool = True, max_terms: int = 12, min_r2_gain: float = 0.0025) -> StepwiseResult:
    """Stepwise regression (Morelli and Klein sec. 5.4.3; Draper and Smith ch. 15).

    Starting from the forced terms, repeat: add the candidate with the largest
    partial correlation with the current residual if its partial F (computed with
    the coloured-residual standard error when ``colored``) exceeds ``f_in``, the PSE
    decreases and R^2 rises by at least ``min_r2_gain``; then drop any non-forced
    term whose partial F has fallen below ``f_out``. Stop when nothing enters.

    Args:
        X: regressors, shape (N, 10), columns ``REGRESSORS``.
        z: measured coefficient, shape (N,).
        candidates: pool of term strings.
        forced: terms always kept (the intercept by default).
        f_in, f_out: partial-F thresholds to enter and to stay (f_out <= f_in).
        colored: use coloured-residual standard errors for partial F.
        max_terms: largest model size.
        min_r2_gain: smallest increase of R^2 for a term to enter (Morelli: 0.5 %).

    Returns:
        :class:`StepwiseResult`.
    """
    forced = [canonical_term(t) for t in forced]
    pool = [canonical_term(t) for t in candidates if canonical_term(t) not in forced]
    pool = list(dict.fromkeys(pool))
    Xall = term_matrix(X, forced + pool)
    col = {t: Xall[:, i] for i, t in enumerate(forced + pool)}
    # drop candidates that are constant (indistinguishable from the intercept) or all zero
    pool = [t for t in pool if np.ptp(col[t]) > 0]
    current = list(forced)
    history: list[dict] = []

    def fit(ts):
        return ols(np.column_stack([col[t] for t in ts]), z, ts, colored=colored)

    res = fit(current)
    for _ in range(4 * max(len(pool), 1)):
        remaining = [t for t in pool if t not in current]
        if not remaining or len(current) >= max_terms:
            break
        A = np.column_stack([col[t] for t in current])
        Q, _ = np.linalg.qr(A)
        C = np.column_stack([col[t] for t in remaining])
        Cp = C - Q @ (Q.T @ C)
        norms = np.sqrt(np.sum(Cp**2, axis=0))
        vn = np.sqrt(res.residual @ res.residual)
        with np.errstate(invalid="ignore", divide="ignore"):
            pc = np.abs(Cp.T @ res.residual) / (norms * vn)
        pc[~np.isfinite(pc) | (norms < 1e-9 * np.sqrt(np.sum(C**2, axis=0)) + 1e-300)] = -1.0
        # tie-break towards simpler terms: a quadratic term must beat a linear one by 3 %
        deg = np.array([len(term_factors(t)) for t in remaining])
        j = int(np.argmax(pc * np.where(deg > 1, 0.97, 1.0)))
        if pc[j] <= 0:
            break
        cand = remaining[j]
        trial = fit(current + [cand])
        se = trial.std_error[-1]
        pf = float((trial.theta[-1] / se) ** 2) if se > 0 else float("inf")
        if pf < f_in or trial.pse >= res.pse or trial.r2 - res.r2 < min_r2_gain:
            history.append({"action": "stop", "term": cand, "partial_f": pf, "partial_corr": float(pc[j]),
                            "r2": trial.r2, "pse": trial.pse})
            break
        current.append(cand)
        res = trial
        history.append({"action": "add", "term": cand, "partial_f": pf, "partial_corr": float(pc[j]),
                        "r2": res.r2, "pse": res.pse})
        # backward check
        while True:
            pfs = [(float((res.theta[i] / res.std_error[i]) ** 2) if res.std_error[i] > 0 else float("inf"), t)
                   for i, t in enumerate(current) if t not in forced]
            if not pfs:
                break
            worst = min(pfs)
            if worst[0] >= f_out:
                break
            current.remove(worst[1])
            res = fit(current)
            history.append({"action": "drop", "term": worst[1], "partial_f": worst[0], "partial_corr": float("nan"),
                            "r2": res.r2, "pse": res.pse})
    return StepwiseResult(res, history)
