"""Filter-error estimate of the rotational gusts ``p_g`` and ``r_g`` from the measured roll and yaw moments.

The aerodynamic roll and yaw moments read the body's rotation relative to the air, ``p - p_g`` and ``r - r_g``;
a gyro measures ``p`` and ``r``. ``p_g`` (the span-wise gradient ``dw_g/dy``) is not observable from one point's
air data (:mod:`gcs_sysid.estimation.gustrates`), but it is observable through the moment it causes. This module
treats it as Jategaonkar's filter-error method treats turbulence: as process noise of the state-space model whose
output is the measured coefficient, estimated by a Kalman filter and Rauch-Tung-Striebel smoother, alternated with
the model's parameters (Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., AIAA 2015, ch. 5 "filter
error method", ch. 7 "estimation in turbulence"; the alternation is the EM algorithm of Shumway and Stoffer,
"An approach to time series smoothing and forecasting using the EM algorithm", J. Time Series Anal. 3(4), 1982).

State (dimensionless, the hats' units): ``s = (p_g b/(2V), r_g b/(2V))``, each a first-order Gauss-Markov
process, MIL-F-8785C's Dryden form (sec. 3.7.2): ``p_g`` white noise through ``1/(1 + (4b/(pi V)) s)``, ``r_g``
the lateral gust's along-path derivative through ``1/(1 + (3b/(pi V)) s)`` (flat above the gust's break
frequency, so first-order there)::

    s_k+1 = diag(a_p, a_r) s_k + w_k,   a = exp(-dt / tau),   Q = diag(sig_hat^2 (1 - a^2))
    sig_hat = sigma_(p,r) b / (2V)   (gustrates.dryden_rate_sigma of gustrates.gust_intensity)

Measurement (the first-pass linear model ``C = theta . x`` on ``x = (1, alpha, beta, p_hat, r_hat, delta_a,
delta_r)`` with the gyro's hats; ``z`` is the measured coefficient less the model at the gyro's rates)::

    z_l = Cl_meas - theta_l . x = -Cl_p p_hat_g - Cl_r r_hat_g + e_l
    z_n = Cn_meas - theta_n . x = -Cn_p p_hat_g - Cn_r r_hat_g + e_n,   e ~ N(0, diag(R_l, R_n))

EM: the E-step smooths ``s`` (mean ``s_hat``, covariance ``P``); the M-step refits ``theta`` by least squares
on the air-relative hats ``p_hat - p_hat_g`` with the smoothed covariance added to the normal equations
(``E[x x^T] = x_hat x_hat^T + P``, the errors-in-variables correction that keeps ``Cl_p`` from attenuating) and
``R`` from the expected squared residual. The Dryden process-noise level stays fixed (known from the gust
intensity, not learned): a free level would let ``p_g`` take any unmodelled roll moment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..estimation.gustrates import dryden_rate_sigma, gust_intensity
from ..estimation.kalman import steady_state, steady_state_smoother
from .table import COEFFICIENTS, REGRESSORS

__all__ = ["GUST_FILTER", "GUST_FILTER_AXES", "GUST_FILTER_NOISE_SCALE", "LAT_TERMS", "stated_moment_variance", "GustFilterResult", "smooth_rotational_gusts", "filter_gust_table"]

#: The replay's default (:class:`gcs_sysid.pipeline.ReplayOptions` ``gust_filter``): train the GP on the hats
#: less the filter-error gust rates.
GUST_FILTER = False
#: The gust rates taken out of the training hats: ``p`` only. ``r_g`` is smoothed with it but left in: even with the
#: truth's own slopes the yaw moment gives it with correlation 0.4-0.6 and an error larger than its SD
#: (``docs/benchmarks.md``, "Sixteenth session, i8-fe").
GUST_FILTER_AXES = ("p",)
#: The measurement noise variance over the stated one (``p_dot r_dot`` sigma through the moment equations).
GUST_FILTER_NOISE_SCALE = 100.0
#: The first-pass linear model's regressors (an intercept first), the lateral-directional set.
LAT_TERMS = ("alpha", "beta", "p_hat", "r_hat", "delta_a", "delta_r")
_IP, _IR = LAT_TERMS.index("p_hat") + 1, LAT_TERMS.index("r_hat") + 1     # columns in the design (intercept 0)


@dataclass(frozen=True)
class GustFilterResult:
    """Smoothed rotational gusts and the model they were estimated with.

    Attributes:
        s: ``(T, 2)`` smoothed ``p_hat_g r_hat_g`` (dimensionless, the hats' units); 0 (the prior mean) outside
            the rows given.
        P: ``(T, 2, 2)`` their smoothed covariance; the prior's outside the rows given.
        prior_var: ``(T, 2)`` the prior (Dryden) variance of ``p_hat_g r_hat_g``.
        theta: ``(2, 7)`` the final linear model of Cl and Cn on ``(1,) + LAT_TERMS`` (air-relative hats).
        theta0: ``(2, 7)`` the first pass's (gyro hats).
        R: ``(2,)`` the measurement noise variances of Cl and Cn.
        n_iter: EM iterations run; converged: the relative change of ``theta`` fell under the tolerance.
        sigma_rates: ``(3,)`` ``sigma_p sigma_q sigma_r`` rad/s used.
        notes: one-line statements.
    """

    s: np.ndarray
    P: np.ndarray
    prior_var: np.ndarray
    theta: np.ndarray
    theta0: np.ndarray
    R: np.ndarray
    n_iter: int
    converged: bool
    sigma_rates: np.ndarray
    notes: tuple[str, ...]


def _unused_lstsq(A, y, P=None, w=None):
    """Least squares ``y ~ A theta`` with ``P`` ``(n, 2, 2)`` added to the normal equations' rate block."""
    G = A.T @ A
    if P is not None:
        G[np.ix_([_IP, _IR], [_IP, _IR])] += P.sum(0)
    G += 1e-9 * np.trace(G) / len(G) * np.eye(len(G))
    return np.linalg.solve(G, A.T @ y)


def _segments(use: np.ndarray, min_len: int) -> list[tuple[int, int]]:
    """``[start, stop)`` of the runs of True in ``use`` at least ``min_len`` long."""
    d = np.diff(np.r_[0, use.astype(int), 0])
    return [(a, b) for a, b in zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]) if b - a >= min_len]


def _innovations(F, Q, H, R, series, segs):
    """Innovations of each ``(T, 2)`` series under the steady-state filter, stacked over the segments."""
    gain = steady_state(F, Q, H, R)
    out = []
    for z in series:
        out.append(np.concatenate([steady_state_smoother(F, gain, H, z[a:b], np.zeros(2), smooth=False)[1]
                                   for a, b in segs]))
    return gain, out


def _profile(h, F, Q, R, A, y, segs, rate_cols):
    """For the rate slopes ``h`` ``(2, 2)``: the GLS estimate of the other slopes and the negative log-likelihood."""
    H = -h
    other = [j for j in range(A.shape[1]) if j not in rate_cols]
    z0 = y - A[:, rate_cols] @ h.T                                   # (T, 2): the measurement less the rate terms
    cols = []
    for j in other:
        for ch in range(2):
            c = np.zeros_like(y)
            c[:, ch] = A[:, j]
            cols.append(c)
    gain, inn = _innovations(F, Q, H, R, [z0] + cols, segs)
    W = np.linalg.cholesky(np.linalg.inv(gain.S))                  # whitening: nu' S^-1 nu = |W' nu|^2
    yv = (inn[0] @ W).ravel()
    M = np.stack([(c @ W).ravel() for c in inn[1:]], 1)
    beta = np.linalg.lstsq(M, yv, rcond=None)[0]
    r = yv - M @ beta
    n = len(inn[0])
    nll = 0.5 * float(r @ r) + 0.5 * n * float(np.log(np.linalg.det(gain.S)))
    theta = np.zeros((2, A.shape[1]))
    theta[:, rate_cols] = h
    for k, j in enumerate(other):
        theta[0, j], theta[1, j] = beta[2 * k], beta[2 * k + 1]
    return nll, theta, gain


def smooth_rotational_gusts(dt: float, X: np.ndarray, Y: np.ndarray, rows: np.ndarray, V: np.ndarray, b: float,
                            sigma_rates: np.ndarray, R: np.ndarray, fit_noise: bool = False, fit_tau: bool = False, max_iter: int = 400,
                            tol: float = 1e-4) -> GustFilterResult:
    """Filter-error estimate of ``p_hat_g r_hat_g`` from the measured Cl and Cn (module docstring).

    The model is time-invariant at the training rows' median airspeed, so the steady-state Kalman filter and RTS
    smoother are exact after their start (:func:`~gcs_sysid.estimation.kalman.steady_state_smoother`); the
    likelihood of the innovations is maximised over the four rate slopes (Nelder-Mead) with the other slopes
    profiled out by generalised least squares on the whitened innovations (Jategaonkar 2015, ch. 5: the
    filter-error method with steady-state gain).

    Args:
        dt: grid interval, s.
        X: ``(T, 10)`` regressors in the order of :data:`~gcs_sysid.aero.table.REGRESSORS` (gyro hats).
        Y: ``(T, 6)`` measured coefficients in the order of :data:`~gcs_sysid.aero.table.COEFFICIENTS`.
        rows: ``(T,)`` bool, the rows whose moments may be used (training rows: never the held-out segment);
            the others get the prior (``s = 0``, the prior variance).
        V: ``(T,)`` true airspeed, m/s (the Dryden time constants and the hats' scale).
        b: wing span, m.
        sigma_rates: ``(3,)`` ``sigma_p sigma_q sigma_r`` rad/s (:func:`~gcs_sysid.estimation.gustrates.dryden_rate_sigma`).
        R: ``(2,)`` the measured Cl's and Cn's white-noise variances (the estimator's stated ones).
        max_iter, tol: Nelder-Mead's evaluations and tolerance.

    Returns:
        :class:`GustFilterResult`.

    Raises:
        ValueError: shapes that disagree, ``b`` or ``dt`` not positive, fewer than 200 usable rows in runs of
            at least 50, or a non-finite or non-positive ``sigma_rates`` or ``R``.

    Source: Jategaonkar (2015) ch. 5 and 7; Rauch, Tung and Striebel (1965); MIL-F-8785C sec. 3.7.2.
    """
    from scipy.optimize import minimize

    X, Y, V = np.asarray(X, float), np.asarray(Y, float), np.asarray(V, float)
    T = len(X)
    if X.shape != (T, len(REGRESSORS)) or Y.shape != (T, len(COEFFICIENTS)) or V.shape != (T,) or len(rows) != T:
        raise ValueError(f"smooth_rotational_gusts: X (T, 10), Y (T, 6), V and rows (T,) expected, got {X.shape}, "
                         f"{Y.shape}, {V.shape}, {np.shape(rows)}")
    if not (b > 0 and dt > 0):
        raise ValueError(f"smooth_rotational_gusts: span and dt must be positive, got b={b}, dt={dt}")
    sig = np.asarray(sigma_rates, float)
    Rv = np.asarray(R, float)
    if sig.shape != (3,) or not (np.isfinite(sig).all() and (sig > 0).all()):
        raise ValueError(f"smooth_rotational_gusts: sigma_rates must be 3 positive rad/s values, got {sig}")
    if Rv.shape != (2,) or not (np.isfinite(Rv).all() and (Rv > 0).all()):
        raise ValueError(f"smooth_rotational_gusts: R must be 2 positive variances, got {Rv}")
    cols = [REGRESSORS.index(k) for k in LAT_TERMS]
    il, in_ = COEFFICIENTS.index("Cl"), COEFFICIENTS.index("Cn")
    A = np.c_[np.ones(T), X[:, cols]]
    y = Y[:, [il, in_]]
    use = np.asarray(rows, bool) & np.isfinite(A).all(1) & np.isfinite(y).all(1) & np.isfinite(V) & (V > 1.0)
    segs = _segments(use, 50)
    if sum(b_ - a_ for a_, b_ in segs) < 200:
        raise ValueError(f"smooth_rotational_gusts: {int(use.sum())} usable rows, at least 200 in runs of 50 needed")
    seg_rows = np.zeros(T, bool)
    for a_, b_ in segs:
        seg_rows[a_:b_] = True
    Vm = float(np.median(V[seg_rows]))
    tau0 = np.array([4.0 * b / (np.pi * Vm), 3.0 * b / (np.pi * Vm)])
    sh2 = (np.array([sig[0], sig[2]]) * b / (2.0 * Vm)) ** 2             # prior variance, hats

    def model(log_k):
        a = np.exp(-dt / (tau0 * np.exp(log_k)))
        return np.diag(a), np.diag(sh2 * (1 - a**2))

    F, Q = model(0.0)
    Rm = np.diag(Rv)
    Au, yu = A[seg_rows], y[seg_rows]
    theta0 = np.stack([np.linalg.lstsq(Au, yu[:, j], rcond=None)[0] for j in range(2)])
    rc = [_IP, _IR]
    scale = np.maximum(np.abs(theta0[:, rc]), 0.02)
    Ac, yc = A.copy(), y.copy()
    Ac[~seg_rows], yc[~seg_rows] = 0.0, 0.0

    def unpack(v):
        Rk = Rm * (np.exp(v[4]) if fit_noise else 1.0)
        return (v[:4].reshape(2, 2) * scale, Rk) + (model(v[-1]) if fit_tau else (F, Q))

    def nll(v):
        h, Rk, Fk, Qk = unpack(v)
        return _profile(h, Fk, Qk, Rk, Ac, yc, segs, rc)[0]

    v0 = np.r_[(theta0[:, rc] / scale).ravel(), [0.0] * (int(fit_noise) + int(fit_tau))]
    opt = minimize(nll, v0, method="Nelder-Mead", options={"maxfev": max_iter, "xatol": tol, "fatol": 1e-3})
    h_opt, Rm, F, Q = unpack(opt.x)
    Rv = np.diag(Rm).copy()
    tau_k = float(np.exp(opt.x[-1])) if fit_tau else 1.0
    _, theta, gain = _profile(h_opt, F, Q, Rm, Ac, yc, segs, rc)
    H = -theta[:, rc]
    s = np.zeros((T, 2))
    z = y - A @ theta.T
    for a_, b_ in segs:
        s[a_:b_] = steady_state_smoother(F, gain, H, z[a_:b_], np.zeros(2))[0]
    P = np.where(seg_rows[:, None, None], gain.Ps[None], np.diag(sh2)[None])
    prior_var = np.broadcast_to(sh2, (T, 2)).copy()
    notes = (f"rotational gusts p_g, r_g smoothed from the measured Cl and Cn (filter-error method, steady-state "
             f"gain, {opt.nfev} evaluations{'' if opt.success else ', not converged'}; Dryden sigma_p {sig[0]:.3f}, "
             f"sigma_r {sig[2]:.3f} rad/s); Cl_p {theta0[0, _IP]:.3f} -> {theta[0, _IP]:.3f}, "
             f"Cn_r {theta0[1, _IR]:.3f} -> {theta[1, _IR]:.3f}",)
    return GustFilterResult(s, P, prior_var, theta, theta0, Rv, int(opt.nfev), bool(opt.success), sig, notes)


def stated_moment_variance(states, airframe, qbar: np.ndarray, rows: np.ndarray) -> np.ndarray | None:
    """Mean over ``rows`` of the measured Cl's and Cn's white-noise variance the rate smoother states, ``(2,)``.

    ``Cl = (Ixx p_dot - Ixz r_dot + ...) / (qbar S b)`` (:func:`gcs_sysid.aero.coefficients.aero_moments`), so
    ``var Cl = (Ixx s_p)^2 + (Ixz s_r)^2`` over ``(qbar S b)^2`` with ``s_p s_r`` the stated 1-sigma of
    ``p_dot r_dot`` (``states.sigma``), and likewise Cn with ``Izz`` and ``Ixz``. None when not stated.
    """
    sig = getattr(states, "sigma", None) or {}
    if "p_dot" not in sig or "r_dot" not in sig:
        return None
    sp, sr = np.asarray(sig["p_dot"], float), np.asarray(sig["r_dot"], float)
    qsb = np.asarray(qbar, float) * airframe.S * airframe.b
    with np.errstate(invalid="ignore", divide="ignore"):
        vl = ((airframe.Ixx * sp) ** 2 + (airframe.Ixz * sr) ** 2) / qsb**2
        vn = ((airframe.Izz * sr) ** 2 + (airframe.Ixz * sp) ** 2) / qsb**2
    out = np.array([np.nanmean(vl[rows]), np.nanmean(vn[rows])]) if np.any(rows) else np.full(2, np.nan)
    return out if np.isfinite(out).all() and (out > 0).all() else None


def filter_gust_table(table, states, airframe, train: np.ndarray, axes: tuple[str, ...] = GUST_FILTER_AXES,
                      noise_scale: float = GUST_FILTER_NOISE_SCALE):
    """The table with the training rows' hats less the smoothed gust rates (module docstring).

    Only the rows in ``train`` are changed and only their moments are used; every other row keeps the gyro's hats
    (``p_g = 0``, the prior mean) and states the prior variance of ``p_hat_g`` (``r_hat_g``) in ``x_var`` (the
    training rows state the smoothed variance), so the GP's band carries the gust the regressors leave out.

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable`.
        states: the smoothed states (``wn we wd V`` for the gust intensity; ``sigma`` of ``p_dot r_dot``).
        airframe: span and inertia.
        train: ``(T,)`` bool training rows.
        axes: the gust rates taken out of the hats, among ``"p"`` and ``"r"`` (:data:`GUST_FILTER_AXES`).
        noise_scale: the measurement noise variance over the stated one (:data:`GUST_FILTER_NOISE_SCALE`).

    Returns:
        ``(table, GustFilterResult | None)``: a new table (the input is not changed), or the input with a note
        and None when the gust intensity, the stated moment noise or the rows cannot be had.
    """
    from dataclasses import replace

    d = states.data
    T = len(table.t)
    train = np.asarray(train, bool)
    need = [k for k in ("wn", "we", "wd", "V") if k not in d]
    if need or T < 3:
        return replace(table, notes=list(table.notes) + [f"gust filter not run: no {' '.join(need) or 'grid'} in the states"]), None
    dt = float(np.median(np.diff(table.t)))
    V = np.asarray(d["V"], float)
    wind = np.stack([d["wn"], d["we"], d["wd"]], 1)
    sigma = gust_intensity(dt, wind[train], V[train]) if train.sum() > 20 else float("nan")
    R = stated_moment_variance(states, airframe, table.qbar, train & table.valid)
    if not (np.isfinite(sigma) and sigma > 0) or R is None:
        why = "no gust intensity from the wind" if R is not None else "no stated p_dot r_dot noise"
        return replace(table, notes=list(table.notes) + [f"gust filter not run: {why}"]), None
    try:
        G = smooth_rotational_gusts(dt, table.X, table.Y, train & table.valid, V, airframe.b,
                                    dryden_rate_sigma(sigma, airframe.b), R * noise_scale)
    except ValueError as e:
        return replace(table, notes=list(table.notes) + [f"gust filter not run: {e}"]), None
    X = table.X.copy()
    xv = np.full((T, len(REGRESSORS)), np.nan) if table.x_var is None else table.x_var.copy()
    for k, ax in enumerate(("p", "r")):
        if ax in axes:
            j = REGRESSORS.index(f"{ax}_hat")
            X[:, j] -= G.s[:, k]
            xv[:, j] = G.P[:, k, k]
    note = G.notes[0] + f" (gust intensity {sigma:.2f} m/s; taken out of {', '.join(a + '_hat' for a in axes)} on the training rows)"
    return replace(table, X=X, x_var=xv, notes=list(table.notes) + [note]), G
