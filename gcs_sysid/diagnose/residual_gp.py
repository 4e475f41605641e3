"""Where structure remains: an exact GP with ARD length-scales on the residual, judged on held-out rows.

What no candidate cause explains is still worth knowing: a residual that is a function of the
flight condition is model structure the library lacks (hysteresis, a sin-shaped term, a
tabulated stall break), not noise. A Gaussian process on the residual (measured minus model,
after the accepted causes) over the envelope inputs alpha, beta, V, p_hat, q_hat, r_hat says

- **whether** there is structure: the GP is fitted on (thinned) training rows and predicts the
  held-out rows; the share of their residual it predicts (``1 - SSE_after / SSE_before``) is the
  structured share (no held-out row took part in the fit or in choosing the hyperparameters);
- **along what**: the ARD length-scales (in units of the training standard deviation of each
  input): an input with a short length-scale is one the residual changes along; a length-scale at
  its upper bound means the residual does not depend on it;
- **where and how large**: the region around the GP mean's largest magnitude (per relevant input,
  the 10-90 % range of the rows within one length-scale of the peak where the GP mean keeps at
  least half of it, with its sign) and the mean and peak of the GP mean there, in coefficient units.

The region is reported as *unexplained*: the GP names no cause (it cannot: any smooth function
fits). Kernel: ``k(x, x') = s_f^2 exp(-0.5 sum_d ((x_d - x'_d) / l_d)^2) + s_n^2 delta``;
hyperparameters by maximising the log marginal likelihood with its analytic gradient (Rasmussen
and Williams, *Gaussian Processes for Machine Learning*, 2006, eqs. 2.30, 5.9; L-BFGS-B).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_factor, cho_solve
from scipy.optimize import minimize

from ..aero.table import COEFFICIENTS, REGRESSORS

__all__ = ["GP_INPUTS", "ExactARDGP", "fit_exact_gp", "residual_structure"]

#: The envelope inputs of the residual GP (names in REGRESSORS).
GP_INPUTS = ("alpha", "beta", "V", "p_hat", "q_hat", "r_hat")
_LOG_L_BOUNDS = (np.log(0.05), np.log(10.0))   # standardised units; the upper bound means "irrelevant"


class ExactARDGP:
    """A fitted exact GP with an ARD squared-exponential kernel (numpy; standardised inputs).

    Attributes:
        Z: training inputs (N, D), standardised. y: training targets (N,), centred.
        lengthscale: (D,). signal_std, noise_std: s_f, s_n (target units). mean: the removed mean.
        log_marginal: log marginal likelihood at the optimum.
    """

    def __init__(self, Z, y, lengthscale, signal_std, noise_std, mean, log_marginal):
        self.Z, self.y = Z, y
        self.lengthscale, self.signal_std, self.noise_std = lengthscale, signal_std, noise_std
        self.mean, self.log_marginal = mean, log_marginal
        K = _kernel(Z, Z, lengthscale, signal_std) + noise_std**2 * np.eye(len(y))
        self._cho = cho_factor(K, lower=True)
        self._alpha = cho_solve(self._cho, y)

    def predict(self, Zq: np.ndarray) -> np.ndarray:
        """Latent predictive mean (Q,) at standardised inputs ``Zq (Q, D)`` (Rasmussen and Williams eq. 2.25)."""
        return self.mean + _kernel(Zq, self.Z, self.lengthscale, self.signal_std) @ self._alpha


def _kernel(A, B, ls, sf):
    a, b = A / ls, B / ls
    d2 = np.sum(a * a, 1)[:, None] + np.sum(b * b, 1)[None, :] - 2.0 * a @ b.T
    return sf**2 * np.exp(-0.5 * np.maximum(d2, 0.0))


def _neg_lml(theta, Z, y):
    """Negative log marginal likelihood and its gradient in (log l_1..l_D, log s_f, log s_n)."""
    D = Z.shape[1]
    ls, sf, sn = np.exp(theta[:D]), np.exp(theta[D]), np.exp(theta[D + 1])
    N = len(y)
    Kf = _kernel(Z, Z, ls, sf)
    K = Kf + (sn**2 + 1e-10) * np.eye(N)
    try:
        c = cho_factor(K, lower=True)
    except np.linalg.LinAlgError:
        return 1e25, np.zeros_like(theta)
    a = cho_solve(c, y)
    nll = 0.5 * y @ a + np.sum(np.log(np.diag(c[0]))) + 0.5 * N * np.log(2 * np.pi)
    W = np.outer(a, a) - cho_solve(c, np.eye(N))               # dL/dK = 0.5 W  (eq. 5.9)
    g = np.empty_like(theta)
    for d in range(D):
        diff2 = (Z[:, d][:, None] - Z[:, d][None, :]) ** 2 / ls[d] ** 2
        g[d] = -0.5 * np.sum(W * Kf * diff2)
    g[D] = -0.5 * np.sum(W * 2.0 * Kf)
    g[D + 1] = -0.5 * np.trace(W) * 2.0 * sn**2
    return float(nll), g


def fit_exact_gp(Z: np.ndarray, y: np.ndarray, restarts: int = 2, seed: int = 0) -> ExactARDGP:
    """Fit the hyperparameters by maximum marginal likelihood (L-BFGS-B, analytic gradient).

    Args:
        Z: (N, D) standardised inputs. y: (N,) targets (their mean is removed and kept).
        restarts: starts besides the default one (random length-scales); the best optimum is kept.
        seed: for the restarts.

    Returns:
        :class:`ExactARDGP`.

    Raises:
        ValueError: fewer than 10 points.
    """
    if len(y) < 10:
        raise ValueError(f"residual GP: need at least 10 points, got {len(y)}")
    mu = float(np.mean(y))
    yc = y - mu
    s = float(np.std(yc)) or 1.0
    D = Z.shape[1]
    rng = np.random.default_rng(seed)
    starts = [np.r_[np.zeros(D), np.log(s * 0.7), np.log(s * 0.7)]]
    starts += [np.r_[rng.uniform(-1.0, 1.5, D), np.log(s * 0.5), np.log(s * 0.8)] for _ in range(restarts)]
    bounds = [_LOG_L_BOUNDS] * D + [(np.log(s * 1e-3), np.log(s * 10))] + [(np.log(s * 1e-3), np.log(s * 2))]
    best = None
    for th0 in starts:
        r = minimize(_neg_lml, th0, args=(Z, yc), jac=True, method="L-BFGS-B", bounds=bounds,
                     options={"maxiter": 200})
        if best is None or r.fun < best.fun:
            best = r
    th = best.x
    return ExactARDGP(Z, yc, np.exp(th[:D]), float(np.exp(th[D])), float(np.exp(th[D + 1])), mu, -float(best.fun))


def _thin(mask: np.ndarray, n: int) -> np.ndarray:
    idx = np.nonzero(mask)[0]
    if len(idx) <= n:
        return idx
    return idx[np.linspace(0, len(idx) - 1, n).round().astype(int)]


def _phys(name: str, x: np.ndarray):
    """(values in report units, reported name): degrees for the angles."""
    if name in ("alpha", "beta"):
        return np.degrees(x), name + "_deg"
    if name == "V":
        return x, "V_mps"
    return x, name


def residual_structure(ctx, R: np.ndarray, threshold_pct: float = 20.0, min_size_pct: float = 2.0,
                       n_fit: int = 200, n_eval: int = 2000, relevant_l: float = 3.0) -> dict:
    """Per active coefficient: the residual GP's held-out structured share, relevant inputs and region.

    Args:
        ctx: :class:`~gcs_sysid.diagnose.context.DiagContext` (regressors ``X``, ``train``, ``test``,
            ``valid``, ``active``, ``Y``).
        R: residual (T, 6) after the accepted causes (projected like the diagnosis' scoring).
        threshold_pct: structured share (percent of the held-out residual variance) to report it.
        min_size_pct: and the GP mean's held-out RMS must be at least this percent of the measured
            coefficient's RMS (smaller is below what a model is expected to reach).
        n_fit: training rows the GP is fitted on (evenly thinned in time). n_eval: held-out rows predicted.
        relevant_l: an input whose length-scale (standardised units) is below this is called relevant.

    Returns:
        ``{coef: {"structured_percent", "rms_gp_mean", "percent_of_measured", "structured" (bool),
        "lengthscales" {input: l}, "relevant" [inputs, shortest length-scale first], "region" {name: [lo, hi]},
        "region_mean", "region_peak", "region_share_of_rows", "n_fit", "n_eval"}}`` for the active
        coefficients (alpha, beta in degrees, V in m/s, rates normalised); ``{}`` entries are left out
        when there are too few rows.
    """
    from threadpoolctl import threadpool_limits

    # many small factorisations: BLAS threads cost more than they give (docs/gp.md); restored on return
    with threadpool_limits(limits=1, user_api="blas"):
        return _residual_structure(ctx, R, threshold_pct, min_size_pct, n_fit, n_eval, relevant_l)


def _residual_structure(ctx, R, threshold_pct, min_size_pct, n_fit, n_eval, relevant_l) -> dict:
    cols = [REGRESSORS.index(n) for n in GP_INPUTS]
    X = np.nan_to_num(ctx.X[:, cols])
    tr_idx = _thin(ctx.train & ctx.valid, n_fit)
    te_idx = _thin(ctx.test & ctx.valid, n_eval)
    out: dict = {}
    if len(tr_idx) < 50 or len(te_idx) < 20:
        return out
    mu, sd = X[tr_idx].mean(0), X[tr_idx].std(0)
    use = sd > 0
    names = [n for n, u in zip(GP_INPUTS, use) if u]
    Z = (X[:, use] - mu[use]) / sd[use]
    allv = _thin(ctx.valid, 4 * n_eval)
    for j, coef in enumerate(COEFFICIENTS):
        if not ctx.active[j]:
            continue
        r = np.nan_to_num(R[:, j])
        gp = fit_exact_gp(Z[tr_idx], r[tr_idx], restarts=0)
        pred = gp.predict(Z[te_idx])
        e0 = float(np.sum(r[te_idx] ** 2))
        e1 = float(np.sum((r[te_idx] - pred) ** 2))
        share = max(0.0, 1.0 - e1 / e0) if e0 > 0 else 0.0
        rms_m = float(np.sqrt(np.mean(pred**2)))
        rms_y = float(np.sqrt(np.mean(ctx.Y[te_idx, j] ** 2)))
        ls = {n: float(v) for n, v in zip(names, gp.lengthscale)}
        relevant = sorted([n for n in names if ls[n] < relevant_l], key=lambda n: ls[n])
        m_all = gp.predict(Z[allv])
        sign = 1.0 if np.max(m_all) >= -np.min(m_all) else -1.0
        peak = float(np.max(sign * m_all))
        # the region: rows around the peak (within one length-scale along the relevant inputs) where the
        # GP mean keeps at least half the peak, with its sign
        dims = [names.index(n) for n in (relevant or names[:1])]
        c = Z[allv][int(np.argmax(sign * m_all))]
        near = np.sum(((Z[allv][:, dims] - c[dims]) / gp.lengthscale[dims]) ** 2, axis=1) <= 1.0
        sel = near & (sign * m_all >= 0.5 * peak)
        region = {}
        for n in relevant or names[:1]:
            x, label = _phys(n, ctx.X[allv[sel], REGRESSORS.index(n)])
            region[label] = [float(np.percentile(x, 10)), float(np.percentile(x, 90))]
        structured = bool(100 * share >= threshold_pct and rms_m >= min_size_pct / 100 * rms_y)
        out[coef] = {"structured_percent": float(100 * share), "rms_gp_mean": rms_m,
                     "percent_of_measured": float(100 * rms_m / rms_y) if rms_y > 0 else None,
                     "structured": structured, "lengthscales": ls, "relevant": relevant, "region": region,
                     "region_mean": float(np.mean(m_all[sel])), "region_peak": float(sign * peak),
                     "region_share_of_rows": float(np.mean(sel)), "n_fit": int(len(tr_idx)),
                     "n_eval": int(len(te_idx)), "noise_std": gp.noise_std, "signal_std": gp.signal_std}
    return out
