"""Batched linear Kalman filter and Rauch-Tung-Striebel smoother (offline, numpy).

The per-axis and per-candidate filters of :mod:`gcs_sysid.estimation.ekf` are many
small, independent linear filters over the same time grid. filterpy's
``KalmanFilter.batch_filter`` + ``rts_smoother`` run one filter at a time with
several Python-level calls per step (measured about 40 us per step and filter
for a 3-state model, i.e. 3.6 s for three axes of a 10-minute 50 Hz flight);
here ``B`` filters advance together in one vectorised step (about 12 us per
step for B = 3), which is what makes smoothing a 30000-step flight take a few
seconds. The equations are filterpy's (and the tests check this module against
filterpy's ``batch_filter`` and ``rts_smoother``):

    predict:  x- = F x + u,            P- = F P F' + Q
    update:   S = H P- H' + R,         K = P- H' S^-1
              x = x- + K (z - H x-),   P = (I - K H) P- (I - K H)' + K R K'   (Joseph form)
    RTS:      C_k = P_k F_{k+1}' (P-_{k+1})^-1
              xs_k = x_k + C_k (xs_{k+1} - x-_{k+1}),  Ps_k = P_k + C_k (Ps_{k+1} - P-_{k+1}) C_k'

References:
    Rauch, Tung and Striebel, "Maximum likelihood estimates of linear dynamic
    systems", AIAA Journal 3(8), 1965, doi:10.2514/3.3166.
    Simon, *Optimal State Estimation*, Wiley 2006, ch. 5 (filter), ch. 7 (steady state), ch. 9 (RTS).
    Labbe, *Kalman and Bayesian Filters in Python* (filterpy), ch. 13 (smoothing).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_discrete_are, solve_discrete_lyapunov
from scipy.signal import lfilter, ss2tf

__all__ = ["FilterResult", "kalman_filter", "rts_smoother", "SteadyState", "steady_state", "steady_state_smoother",
           "lti_response",            "noise_std"]


@dataclass
class FilterResult:
    """Forward-pass output, kept for the smoother.

    Attributes:
        x: filtered means, shape (T, B, Nx).
        P: filtered covariances, shape (T, B, Nx, Nx).
        xp: predicted (prior) means, shape (T, B, Nx).
        Pp: predicted covariances, shape (T, B, Nx, Nx).
        loglik: innovation log-likelihood per filter, shape (B,).
    """

    x: np.ndarray
    P: np.ndarray
    xp: np.ndarray
    Pp: np.ndarray
    loglik: np.ndarray


def _per_step(a: np.ndarray, T: int, nd: int) -> bool:
    """True if ``a`` carries a leading time axis (ndim > nd)."""
    return a.ndim > nd and a.shape[0] == T


def kalman_filter(x0: np.ndarray, P0: np.ndarray, F: np.ndarray, Q: np.ndarray, H: np.ndarray,
                  R: np.ndarray, z: np.ndarray, u: np.ndarray | None = None) -> FilterResult:
    """Run ``B`` independent linear Kalman filters over ``T`` steps.

    Each step predicts with ``F[k]`` (from step k-1 to k; at k = 0 from the
    prior ``x0, P0``) and then updates with ``z[k]``, as filterpy's
    ``batch_filter`` does. A measurement row holding any NaN is skipped
    (predict only).

    Args:
        x0: prior means (B, Nx).
        P0: prior covariances (B, Nx, Nx) or (Nx, Nx).
        F: transition (Nx, Nx), or per step (T, Nx, Nx), shared by the batch.
        Q: process noise (Nx, Nx), per filter (B, Nx, Nx) or per step (T, B, Nx, Nx).
        H: measurement matrix (Nz, Nx).
        R: measurement noise (Nz, Nz) or per filter (B, Nz, Nz).
        z: measurements (T, B, Nz), NaN = missing.
        u: optional additive input (T, B, Nx) (i.e. ``B_u @ u`` already applied).

    Returns:
        :class:`FilterResult`.

    Raises:
        ValueError: inconsistent shapes.
    """
    x0 = np.asarray(x0, float)
    B, nx = x0.shape
    T, Bz, nz = z.shape
    if Bz != B or H.shape != (nz, nx):
        raise ValueError(f"shape mismatch: x0 {x0.shape}, z {z.shape}, H {H.shape}")
    F_t = _per_step(F, T, 2)
    Q_t = Q.ndim == 4
    P = np.broadcast_to(P0, (B, nx, nx)).copy()
    R = np.broadcast_to(R, (B, nz, nz))
    if B == 1:
        return _filter_one(x0[0], P[0], F, F_t, Q, Q_t, H, R[0], z[:, 0], None if u is None else u[:, 0])
    x = x0.copy()
    xs = np.empty((T, B, nx))
    Ps = np.empty((T, B, nx, nx))
    xps = np.empty((T, B, nx))
    Pps = np.empty((T, B, nx, nx))
    ll = np.zeros(B)
    eye = np.eye(nx)
    ok_all = np.isfinite(z).all(axis=2)
    scalar = nz == 1
    h_row = H[0]
    for k in range(T):
        Fk = F[k] if F_t else F
        Qk = Q[k] if Q_t else Q
        x = x @ Fk.T                                       # x- = F x (+ u)
        if u is not None:
            x = x + u[k]
        P = Fk @ P @ Fk.T + Qk                             # P- = F P F' + Q
        xps[k] = x
        Pps[k] = P
        ok = ok_all[k]
        if ok.any():
            if scalar:                                     # one measurement: scalar S, no solve
                PHt = P @ h_row                            # (B, nx)
                S = PHt @ h_row + R[:, 0, 0]               # S = H P- H' + R
                K = PHt / S[:, None]                       # K = P- H' S^-1
                y = z[k, :, 0] - x @ h_row                 # innovation
                y = np.where(ok, y, 0.0)
                K = np.where(ok[:, None], K, 0.0)
                x = x + K * y[:, None]
                IKH = eye - K[:, :, None] * h_row[None, None, :]
                KRK = (K[:, :, None] * K[:, None, :]) * R[:, 0, 0][:, None, None]
                ll += np.where(ok, -0.5 * (y * y / S + np.log(2 * np.pi * S)), 0.0)
            else:
                PHt = P @ H.T                              # (B, nx, nz)
                S = H @ PHt + R                            # (B, nz, nz)
                Kt = np.linalg.solve(S, np.swapaxes(PHt, 1, 2))  # S^-1 H P-  (solve, not invert)
                K = np.swapaxes(Kt, 1, 2)
                K = np.where(ok[:, None, None], K, 0.0)
                y = np.where(ok[:, None], np.nan_to_num(z[k]) - x @ H.T, 0.0)
                x = x + np.einsum("bij,bj->bi", K, y)
                IKH = eye - K @ H
                KRK = K @ R @ np.swapaxes(K, 1, 2)
                Sy = np.linalg.solve(S, y[:, :, None])[:, :, 0]
                _, logdet = np.linalg.slogdet(S)
                ll += np.where(ok, -0.5 * ((y * Sy).sum(1) + logdet + nz * np.log(2 * np.pi)), 0.0)
            P = IKH @ P @ np.swapaxes(IKH, 1, 2) + KRK     # Joseph form
        xs[k] = x
        Ps[k] = P
    return FilterResult(xs, Ps, xps, Pps, ll)


def _filter_one(x, P, F, F_t, Q, Q_t, H, R, z, u) -> FilterResult:
    """:func:`kalman_filter` for one filter (``B = 1``) on plain vectors and matrices.

    The same equations; at these sizes numpy's per-call overhead is the cost, and the
    batched step's masks and stacked solves cost about twice the arithmetic of one filter.
    """
    T, nz = z.shape
    nx = len(x)
    xs, Ps = np.empty((T, 1, nx)), np.empty((T, 1, nx, nx))
    xps, Pps = np.empty((T, 1, nx)), np.empty((T, 1, nx, nx))
    ll = 0.0
    eye = np.eye(nx)
    ok_all = np.isfinite(z).all(axis=1)
    Qc = Q if Q_t or Q.ndim == 2 else Q[0]
    Ht = H.T
    for k in range(T):
        Fk = F[k] if F_t else F
        x = Fk @ x                                         # x- = F x (+ u)
        if u is not None:
            x = x + u[k]
        P = Fk @ P @ Fk.T + (Qc[k, 0] if Q_t else Qc)      # P- = F P F' + Q
        xps[k, 0] = x
        Pps[k, 0] = P
        if ok_all[k]:
            PHt = P @ Ht                                   # (nx, nz)
            S = H @ PHt + R                                # S = H P- H' + R
            y = z[k] - H @ x                               # innovation
            sol = np.linalg.solve(S, np.column_stack([PHt.T, y]))   # [S^-1 H P-, S^-1 y]
            K = sol[:, :nx].T                              # K = P- H' S^-1
            x = x + K @ y
            IKH = eye - K @ H
            P = IKH @ P @ IKH.T + K @ R @ K.T              # Joseph form
            ll += -0.5 * (float(y @ sol[:, nx]) + np.linalg.slogdet(S)[1] + nz * np.log(2 * np.pi))
        xs[k, 0] = x
        Ps[k, 0] = P
    return FilterResult(xs, Ps, xps, Pps, np.array([ll]))


def rts_smoother(res: FilterResult, F: np.ndarray, wrap: tuple[int, ...] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Rauch-Tung-Striebel fixed-interval smoother over a :class:`FilterResult`.

    Works for the extended filter too: pass the per-step Jacobians as ``F`` and
    the stored predicted means (the extended RTS of Sarkka, *Bayesian Filtering
    and Smoothing*, 2013, alg. 9.3).

    Args:
        res: forward pass (means and covariances, filtered and predicted).
        F: transition (Nx, Nx) or per step (T, Nx, Nx), as given to the filter
            (``F[k+1]`` maps step k to k+1).
        wrap: state indices that are angles; their smoother corrections are
            wrapped to (-pi, pi].

    Returns:
        ``(xs, Ps)``: smoothed means (T, B, Nx) and covariances (T, B, Nx, Nx).
    """
    T = res.x.shape[0]
    F_t = _per_step(F, T, 2)
    xs = res.x.copy()
    Ps = res.P.copy()
    widx = list(wrap)
    if xs.shape[1] == 1:                                   # one filter: plain vectors and matrices
        x1, P1, xp1, Pp1 = res.x[:, 0], res.P[:, 0], res.xp[:, 0], res.Pp[:, 0]
        xn, Pn = xs[T - 1, 0], Ps[T - 1, 0]
        # the gains do not depend on the smoothed values: all T-1 solves in one stacked call (the same
        # LAPACK solve on the same matrices as one call per step, so the same numbers; 25 % of the time)
        Cts = np.linalg.solve(Pp1[1:], (F[1:] if F_t else F) @ P1[:-1]) if T > 1 else None
        for k in range(T - 2, -1, -1):
            Ct = Cts[k]
            d = xn - xp1[k + 1]
            if widx:
                d[widx] = np.mod(d[widx] + np.pi, 2 * np.pi) - np.pi
            xn = x1[k] + Ct.T @ d
            Pn = P1[k] + Ct.T @ (Pn - Pp1[k + 1]) @ Ct
            xs[k, 0], Ps[k, 0] = xn, Pn
        return xs, Ps
    for k in range(T - 2, -1, -1):
        Fk1 = F[k + 1] if F_t else F
        Pp = res.Pp[k + 1]
        # C = P F' Pp^-1  ->  C' = Pp^-1 F P  (Pp symmetric): solve, don't invert
        Ct = np.linalg.solve(Pp, Fk1 @ res.P[k])
        C = np.swapaxes(Ct, 1, 2)
        d = xs[k + 1] - res.xp[k + 1]
        if widx:
            d[:, widx] = np.mod(d[:, widx] + np.pi, 2 * np.pi) - np.pi
        xs[k] = res.x[k] + np.einsum("bij,bj->bi", C, d)
        Ps[k] = res.P[k] + C @ (Ps[k + 1] - Pp) @ Ct
    return xs, Ps


@dataclass
class SteadyState:
    """Steady-state quantities of a time-invariant filter and smoother.

    Attributes:
        K: Kalman gain (Nx, Nz).
        Pp: predicted covariance (Nx, Nx) (the Riccati fixed point).
        Pf: filtered covariance (Nx, Nx).
        C: RTS smoother gain (Nx, Nx).
        Ps: smoothed covariance (Nx, Nx) far from the ends of the record.
        S: innovation covariance (Nz, Nz).
    """

    K: np.ndarray
    Pp: np.ndarray
    Pf: np.ndarray
    C: np.ndarray
    Ps: np.ndarray
    S: np.ndarray


def _dare(a: np.ndarray, b: np.ndarray, q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """X solving ``a' X a - X - a' X b (r + b' X b)^-1 b' X a + q = 0`` by doubling (Anderson 1978)."""
    n = a.shape[0]
    A = a.copy()
    G = b @ np.linalg.solve(r, b.T)
    X = q.copy()
    eye = np.eye(n)
    for _ in range(100):
        W = np.linalg.solve(eye + G @ X, np.hstack([A, G]))   # (I + G X)^-1 [A, G]
        WA, WG = W[:, :n], W[:, n:]
        X_new = X + A.T @ X @ WA
        G = G + A @ WG @ A.T
        A = A @ WA
        if np.abs(X_new - X).max() <= 1e-13 * max(np.abs(X_new).max(), 1e-300):
            return 0.5 * (X_new + X_new.T)
        X = X_new
    return solve_discrete_are(a, b, q, r)


def steady_state(F: np.ndarray, Q: np.ndarray, H: np.ndarray, R: np.ndarray) -> SteadyState:
    """Steady-state gains of the filter and the RTS smoother for a time-invariant model.

    The predicted covariance solves the discrete algebraic Riccati equation
    ``P = F P F' - F P H' (H P H' + R)^-1 H P F' + Q`` (``scipy.linalg.
    solve_discrete_are``); the smoothed covariance solves the Lyapunov equation
    ``Ps = C Ps C' + Pf - C Pp C'`` that the RTS recursion converges to. The
    Riccati equation is solved by the doubling algorithm (B. D. O. Anderson,
    Int. J. Control 28(2), 1978),
    microseconds for these small models where ``scipy.linalg.solve_discrete_are``
    takes tens of milliseconds; scipy's solver is the fallback.

    Args:
        F: (Nx, Nx). Q: (Nx, Nx). H: (Nz, Nx). R: (Nz, Nz).

    Returns:
        :class:`SteadyState`.

    Source: Simon (2006) ch. 7 (steady-state filtering) and ch. 9 (smoothing).
    """
    Pp = _dare(F.T, H.T, Q, R)
    Pp = 0.5 * (Pp + Pp.T)
    S = H @ Pp @ H.T + R
    K = np.linalg.solve(S, H @ Pp).T                    # K = Pp H' S^-1
    IKH = np.eye(len(F)) - K @ H
    Pf = IKH @ Pp @ IKH.T + K @ R @ K.T
    C = np.linalg.solve(Pp, F @ Pf).T                   # C = Pf F' Pp^-1
    Ps = solve_discrete_lyapunov(C, Pf - C @ Pp @ C.T)
    return SteadyState(K, Pp, Pf, C, 0.5 * (Ps + Ps.T), S)


#: Steps of the zero-input response of :func:`lti_response` taken one by one before the rest is filtered.
_ZERO_INPUT_STEPS = 200


def lti_response(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, u: np.ndarray,
                 x0: np.ndarray) -> np.ndarray:
    """Output of ``x_{k+1} = A x_k + B u_k, y_k = C x_k + D u_k`` from state ``x0``, in compiled code.

    The zero-state part runs through ``scipy.signal.lfilter`` (one transfer
    function per input, ``scipy.signal.ss2tf``); the zero-input part
    ``C A^k x0`` is added until it has decayed (``A`` must be stable).

    Args:
        A: (n, n). B: (n, m). C: (p, n). D: (p, m). u: inputs (T, m). x0: (n,).

    Returns:
        Outputs (T, p).
    """
    T, m = u.shape
    y = np.zeros((T, C.shape[0]))
    for i in range(m):
        num, den = ss2tf(A, B, C, D, input=i)
        for j in range(C.shape[0]):
            y[:, j] += lfilter(num[j], den, u[:, i])
    v = np.asarray(x0, float).copy()
    scale = max(float(np.abs(v).max()), 1e-300)
    for k in range(T):
        if not np.abs(v).max() > 1e-15 * scale:
            break
        if k == _ZERO_INPUT_STEPS:
            # a slowly decaying mode (a Gauss-Markov state near 1): the rest of C A^j v at once, as the
            # impulse response of (A, A v, C, C v) through lfilter, instead of one Python step per sample
            imp = np.zeros(T - k)
            imp[0] = 1.0
            for j in range(C.shape[0]):
                num, den = ss2tf(A, (A @ v)[:, None], C[j:j + 1], np.array([[C[j] @ v]]))
                y[k:, j] += lfilter(num[0], den, imp)
            break
        y[k] += C @ v
        v = A @ v
    return y


def steady_state_smoother(F: np.ndarray, gain: SteadyState, H: np.ndarray, z: np.ndarray,
                          x0: np.ndarray, smooth: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Filter (and smooth) a time-invariant model with its constant gains.

    Started from the prior ``x0`` with covariance ``gain.Pf``, the Riccati
    recursion sits at its fixed point from the first step, so the constant gains
    give *exactly* the means of :func:`kalman_filter` and :func:`rts_smoother`
    (the tests check this). Both passes are linear time-invariant systems and
    run in compiled code (:func:`lti_response`):

        forward   x_k = A x_{k-1} + K z_k,  A = (I - K H) F,  innovation y_k = z_k - H F x_{k-1}
        backward  xs_k = C xs_{k+1} + (I - C F) x_k,  started from xs_T := F x_{T-1}

    Args:
        F: transition (Nx, Nx).
        gain: :func:`steady_state` of the model.
        H: measurement matrix (Nz, Nx).
        z: measurements (T, Nz), all finite (split records at gaps).
        x0: prior mean (Nx,).
        smooth: also run the backward (RTS) pass.

    Returns:
        ``(x, innov)``: smoothed (or filtered) means (T, Nx) and innovations (T, Nz).
    """
    nx = F.shape[0]
    nz = H.shape[0]
    K = gain.K
    A = (np.eye(nx) - K @ H) @ F
    Cout = np.vstack([A, -H @ F])
    Dout = np.vstack([K, np.eye(nz)])
    y = lti_response(A, K, Cout, Dout, z, x0)
    x, innov = y[:, :nx], y[:, nx:]
    if not smooth:
        return x, innov
    Cg = gain.C
    M = np.eye(nx) - Cg @ F
    xs = lti_response(Cg, M, Cg, M, x[::-1], F @ x[-1])[::-1]
    return xs, innov


def noise_std(y: np.ndarray, floor: float = 0.0) -> float:
    """Robust white-noise standard deviation of a sampled signal.

    Uses the median absolute deviation of the second difference, which for
    white noise of variance s^2 has variance 6 s^2 while a smooth signal
    contributes little, and the median ignores the few large steps of
    maneuvers (Donoho's MAD estimator applied to differences).

    Args:
        y: samples (N,), NaN ignored.
        floor: lower bound returned (e.g. the sensor quantisation step / sqrt(12)).

    Returns:
        Estimated standard deviation (same units as ``y``), at least ``floor``.
    """
    d2 = np.diff(np.asarray(y, float), 2)
    d2 = d2[np.isfinite(d2)]
    if len(d2) < 10:
        return float(floor)
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return max(1.4826 * mad / np.sqrt(6.0), float(floor))
