"""Fit every candidate cause on the training rows and score it on the held-out rows.

A candidate is fitted by weighted least squares on the training rows (weights
``1 / sigma_c^2`` per coefficient), its standard errors corrected for coloured
residuals (Morelli and Klein sec. 5.3) and it is scored on the held-out rows by
a held-out likelihood ratio with a BIC penalty::

    score = sum_c N_eff,c / 2 * log(SSE_c,before / SSE_c,after) - k / 2 * log(N_eff)

(Schwarz, Ann. Statist. 6 (1978) 461; N_eff the effective number of independent
samples of each coefficient's residual). Candidates: every ``<coef>:<term>`` of
the vocabulary, actuator delays (scanned over the delay), stuck surfaces
(scanned over the onset), and the sensor / wind / mass-property causes of
:mod:`gcs_sysid.diagnose.causes`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..aero.table import COEFFICIENTS, REGRESSORS
from .causes import transforms
from .evidence import noise_residual
from .context import DiagContext
from .regression import colored_covariance, effective_samples
from .terms import VOCABULARY, term_factors, term_matrix

__all__ = ["Fitted", "Scorer", "fit_aero_terms", "fit_delays", "fit_stuck", "fit_sensor_causes", "CONTROLS4"]

CONTROLS4 = ("delta_e", "delta_a", "delta_r", "delta_t")


@dataclass
class Fitted:
    """A fitted candidate cause.

    Attributes:
        cause: catalogue name (``"Cm:alpha^2"``, ``"delay:delta_e"``, ``"wind"`` ...).
        kind: ``"aero"``, ``"delay"``, ``"stuck"`` or ``"sensor"``.
        params, cov, labels: parameters, their (coloured) covariance, names.
        delta: (T, 6) change of the residual on every row.
        score: held-out penalised likelihood ratio (see module doc).
        gains: coef -> {"rms_before", "rms_after", "percent"} on the held-out rows.
        estimate, std_error: the headline number and its standard error.
        evidence: extra facts (JSON-able).
        onset_s: vehicle time at which the cause begins (mid-flight causes).
        model_update: for aero terms, ``{coef: {term: delta_value}}``.
    """

    cause: str
    kind: str
    params: np.ndarray
    cov: np.ndarray
    labels: list[str]
    delta: np.ndarray = field(repr=False)
    score: float = -np.inf
    gains: dict = field(default_factory=dict)
    estimate: float = float("nan")
    std_error: float = float("nan")
    evidence: dict = field(default_factory=dict)
    onset_s: float | None = None
    model_update: dict | None = None

    @property
    def coefficient(self) -> str:
        """The coefficient with the largest held-out gain."""
        if not self.gains:
            return ""
        return max(self.gains, key=lambda c: self.gains[c]["percent"])

    @property
    def gain_percent(self) -> float:
        return self.gains[self.coefficient]["percent"] if self.gains else 0.0


class Scorer:
    """Held-out scoring against the current residual ``R`` (T, 6).

    With a :class:`~gcs_sysid.diagnose.turbulence.GustProjector` ``proj``, residual and
    corrections are compared after projecting out the angle errors the reconstruction
    cannot see (turbulence); ``proj=None`` compares them as they are.
    """

    def __init__(self, ctx: DiagContext, R: np.ndarray, proj=None):
        self.ctx, self.R = ctx, R
        self.proj = proj if proj is not None else (lambda D: D)
        self.Rp = self.proj(R)
        te = ctx.test
        self.active = ctx.active
        self.sse0 = np.sum(self.Rp[te] ** 2, axis=0)
        # effective samples of the noise: what a quadratic in all regressors (ridge, fitted on the
        # training rows) leaves on the held-out rows; one value per coefficient for every candidate,
        # so candidates are ranked by their held-out sum of squares
        noise = noise_residual(ctx, self.Rp)
        self.neff = np.array([effective_samples(noise[:, j]) for j in range(6)])
        self.n_pen = float(np.mean(self.neff))

    def rows(self, D: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Projection of ``D`` (N, 6) given on the rows ``mask`` (per row, for fitting)."""
        return self.proj.rows(D, mask) if hasattr(self.proj, "rows") else D

    def score(self, delta: np.ndarray, k: int) -> tuple[float, dict]:
        te = self.ctx.test
        delta = self.proj(np.where(self.active[None, :], delta, 0.0))
        delta = np.where(self.active[None, :], delta, 0.0)
        sse1 = np.sum((self.Rp[te] + delta[te]) ** 2, axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(self.sse0 > 0, self.sse0 / np.maximum(sse1, 1e-300), 1.0)
        ll = float(np.sum(self.neff * self.active / 2 * np.log(ratio)))
        s = ll - k / 2 * np.log(max(self.n_pen, 2.0))
        gains = {}
        for j, c in enumerate(COEFFICIENTS):
            if np.any(np.abs(delta[te, j]) > 1e-12 * (np.sqrt(self.sse0[j] / te.sum()) + 1e-300)):
                b, a = np.sqrt(self.sse0[j] / te.sum()), np.sqrt(sse1[j] / te.sum())
                gains[c] = {"rms_before": float(b), "rms_after": float(a),
                            "percent": float(100 * (1 - a / b)) if b > 0 else 0.0}
        return s, gains


def _weighted(ctx: DiagContext, A: np.ndarray) -> np.ndarray:
    """(N, 6, ...) -> channel-major stacked (6N, ...) with sqrt weights."""
    sw = np.sqrt(ctx.weight)
    A = A * sw.reshape((1, 6) + (1,) * (A.ndim - 2))
    return np.moveaxis(A, 1, 0).reshape((-1,) + A.shape[2:])


def _finish(ctx, scorer, f: Fitted, J: np.ndarray, v: np.ndarray) -> Fitted:
    k = len(f.params)
    if not (J.size and np.all(np.isfinite(J)) and np.all(np.isfinite(v))):
        f.cov = np.full((k, k), np.nan)
        f.score, f.gains = -np.inf, {}
        return f
    f.cov = colored_covariance(J, v)
    f.score, f.gains = scorer.score(f.delta, len(f.params))
    return f


# --------------------------------------------------------------------------- aero terms


def fit_aero_terms(ctx: DiagContext, R: np.ndarray, scorer: Scorer, top: int = 4) -> list[Fitted]:
    """Screen every ``<coef>:<term>`` as a one-parameter correction; return the best ``top`` fitted.

    Screening is vectorised (closed-form one-parameter least squares per term);
    the best are refitted with coloured-residual standard errors.
    """
    tr, te = ctx.train, ctx.test
    Phi = term_matrix(ctx.X, VOCABULARY)
    proj = scorer.proj
    Rp = scorer.Rp
    w = ctx.weight
    rank = []
    for j, coef in enumerate(COEFFICIENTS):
        if not ctx.active[j]:
            continue
        # projected columns of the correction "term k in coefficient j": B (T, 6, K)
        if getattr(proj, "active", False):
            a = proj.H[:, :, j, None] * Phi[:, None, :]                       # (T, k, K)
            a = a - a[proj.mean_rows].mean(axis=0) if proj.keep_mean else a
            B = -np.einsum("tcm,tmK->tcK", proj.G, a)
            B[:, j, :] += Phi
            B *= ctx.active[None, :, None]
        else:
            B = np.zeros((len(ctx.t), 6, Phi.shape[1]))
            B[:, j, :] = Phi
        Bw = B * np.sqrt(w)[None, :, None]
        Rw = Rp * np.sqrt(w)[None, :]
        den = np.einsum("tcK,tcK->K", Bw[tr], Bw[tr])
        num = np.einsum("tcK,tc->K", Bw[tr], Rw[tr])
        ok = (den > 1e-300) & (np.std(Phi[te], axis=0) + np.abs(np.mean(Phi[te], axis=0)) > 0)
        # correction delta = -th * B: fitted on the training rows
        th = np.where(ok, num / np.where(ok, den, 1.0), 0.0)
        # held-out weighted sse after, per coefficient j only for the ranking
        Bt = B[te]
        sse_after = np.sum((Rp[te, :, None] - th[None, None, :] * Bt) ** 2, axis=0)   # (6, K)
        with np.errstate(divide="ignore", invalid="ignore"):
            ll = np.sum(scorer.neff[:, None] / 2 * np.log(np.where(scorer.sse0[:, None] > 0, scorer.sse0[:, None]
                        / np.maximum(sse_after, 1e-300), 1.0)) * ctx.active[:, None], axis=0)
        for k in np.nonzero(ok)[0]:
            rank.append((float(ll[k]), coef, VOCABULARY[k], float(th[k]), j, k))
    rank.sort(reverse=True)
    out = []
    for ll, coef, term, th, j, k in rank[:top]:
        phi = Phi[:, k]
        delta = np.zeros_like(R)
        delta[:, j] = -th * phi
        # coloured covariance of the (projected, weighted) fit
        Dp = scorer.rows(delta[tr], tr)
        v = _weighted(ctx, Rp[tr] + Dp)
        Jw = _weighted(ctx, (-Dp / th if th != 0 else Dp)[:, :, None])
        cov = colored_covariance(Jw, v)
        f = Fitted(f"{coef}:{term}", "aero", np.array([th]), cov, [term], delta,
                   model_update={coef: {term: th}})
        f.score, f.gains = scorer.score(delta, 1)
        old = ctx.model.get(coef, {}).get(term, 0.0)
        f.estimate, f.std_error = old + th, float(np.sqrt(cov[0, 0]))
        f.evidence = {"model_value": old, "correction": th, "kind": "missing term" if old == 0 else "wrong value"}
        out.append(f)
    return out


# --------------------------------------------------------------------------- delays


def _control_used(ctx: DiagContext, u: str) -> bool:
    i = REGRESSORS.index(u)
    used = any(i in term_factors(t) for terms in ctx.model.values() for t in terms)
    return used or (u == "delta_t" and ctx.airframe.thrust is not None)


def _delay_delta(ctx: DiagContext, u: str, tau: float) -> np.ndarray:
    i = REGRESSORS.index(u)
    X = ctx.X.copy()
    X[:, i] = np.interp(ctx.t - tau, ctx.t, ctx.X[:, i])
    d = -(ctx.model_values(X) - ctx.model_values())
    if u == "delta_t" and ctx.airframe.thrust is not None:
        d[:, 0] += (ctx.thrust() - ctx.thrust(delta_t=X[:, i])) / (ctx.qbar * ctx.airframe.S)
    return d


def fit_delays(ctx: DiagContext, R: np.ndarray, scorer: Scorer, max_delay_s: float = 0.5) -> list[Fitted]:
    """Actuator delay per control: scan the delay, refine by a parabola, score held out.

    The measured coefficient follows the surface, the logged command leads it:
    ``Y(t) = model(delta(t - tau))``. A first-order lag of time constant T looks
    like a delay of about T at the frequencies of the maneuvers.
    """
    tr = ctx.train
    dt = float(np.median(np.diff(ctx.t)))
    taus = np.arange(1, int(max_delay_s / dt) + 1) * dt
    out = []
    for u in CONTROLS4:
        if not _control_used(ctx, u) or np.ptp(ctx.x(u)[ctx.valid]) <= 0:
            continue

        def sse(tau):
            d = scorer.rows(_delay_delta(ctx, u, tau)[tr], tr)
            return float(np.sum(ctx.weight * (scorer.Rp[tr] + d) ** 2))

        vals = np.array([sse(tau) for tau in taus])
        k = int(np.argmin(vals))
        tau = taus[k]
        if 0 < k < len(taus) - 1:
            y0, y1, y2 = vals[k - 1], vals[k], vals[k + 1]
            den = y0 - 2 * y1 + y2
            if den > 0:
                tau = taus[k] + 0.5 * dt * (y0 - y2) / den
        delta = _delay_delta(ctx, u, tau)
        h = 0.25 * dt
        J = scorer.rows((_delay_delta(ctx, u, tau + h) - _delay_delta(ctx, u, tau - h))[tr] / (2 * h), tr)
        v = _weighted(ctx, scorer.Rp[tr] + scorer.rows(delta[tr], tr))
        f = Fitted(f"delay:{u}", "delay", np.array([tau]), np.zeros((1, 1)), ["tau_s"], delta)
        _finish(ctx, scorer, f, _weighted(ctx, J[:, :, None]), v)
        f.estimate, f.std_error = float(tau), float(np.sqrt(f.cov[0, 0]))
        f.evidence = {"tau_s": float(tau), "scan_s": [float(x) for x in taus[:: max(1, len(taus) // 25)]],
                      "scan_wsse": [float(x) for x in vals[:: max(1, len(taus) // 25)]]}
        out.append(f)
    return out


# --------------------------------------------------------------------------- stuck surfaces


def fit_stuck(ctx: DiagContext, R: np.ndarray, scorer: Scorer, min_after_s: float = 3.0) -> list[Fitted]:
    """A control surface that stops following its command from an onset time.

    The model is linearised in the control, ``g = d model / d delta``; after the
    onset the true deflection is a constant ``delta_s``, so the residual is
    ``g (delta_s - delta(t))``. For each onset on the grid, ``delta_s`` has a
    closed form; the onset minimising the weighted SSE over all valid rows is kept
    (one scalar looked up on all rows), ``delta_s`` is fitted on the training rows.
    """
    out = []
    v_rows = np.nonzero(ctx.valid)[0]
    if v_rows.size < 10:
        return out
    t_v = ctx.t[v_rows]
    for u in CONTROLS4[:3]:
        if not _control_used(ctx, u):
            continue
        i = REGRESSORS.index(u)
        uu = ctx.x(u)
        h = 0.01
        Xp, Xm = ctx.X.copy(), ctx.X.copy()
        Xp[:, i] += h
        Xm[:, i] -= h
        g = (ctx.model_values(Xp) - ctx.model_values(Xm)) / (2 * h)
        if not np.any(g[ctx.valid]):
            continue
        w = ctx.weight
        allrows = np.ones(len(ctx.t), bool)
        g = scorer.rows(g, allrows)
        Rs = scorer.rows(R, allrows)
        y = Rs + g * uu[:, None]                          # residual after = y - g * delta_s
        a = np.sum(w * g**2, axis=1)[v_rows]
        b = np.sum(w * g * y, axis=1)[v_rows]
        c = np.sum(w * y**2, axis=1)[v_rows]
        r0 = np.sum(w * Rs**2, axis=1)[v_rows]
        A, B, C = (np.cumsum(x[::-1])[::-1] for x in (a, b, c))
        P = np.concatenate([[0.0], np.cumsum(r0)])[:-1]
        total = P + C - B**2 / np.maximum(A, 1e-300)
        ok = (t_v >= t_v[0] + 1.0) & (t_v <= t_v[-1] - min_after_s)
        # the command must keep moving after the onset for the failure to be visible
        uv = uu[v_rows]
        n_after = np.arange(len(v_rows), 0, -1)
        s1, s2 = np.cumsum(uv[::-1])[::-1], np.cumsum(uv[::-1] ** 2)[::-1]
        moving = np.sqrt(np.maximum(s2 / n_after - (s1 / n_after) ** 2, 0.0))
        ok &= moving > 0.1 * max(np.std(uu[v_rows]), 1e-9)
        if not ok.any():
            continue
        k = int(np.argmin(np.where(ok, total, np.inf)))
        onset = float(t_v[k])
        after = ctx.t >= onset
        m = ctx.train & after
        if m.sum() < 10:                                  # no training rows after the onset to fit it on
            continue
        gw = (np.sqrt(w) * g)[m].T.ravel()
        yw = (np.sqrt(w) * y)[m].T.ravel()
        us = float(gw @ yw / max(gw @ gw, 1e-300))
        g_raw = (ctx.model_values(Xp) - ctx.model_values(Xm)) / (2 * h)
        delta = np.where(after[:, None], -g_raw * (us - uu[:, None]), 0.0)
        f = Fitted(f"stuck:{u}", "stuck", np.array([us, onset]), np.zeros((2, 2)), ["delta_stuck", "onset_s"],
                   delta, onset_s=onset)
        cov1 = colored_covariance(gw[:, None], yw - gw * us)
        f.score, f.gains = scorer.score(delta, 2)
        f.cov = np.diag([cov1[0, 0], float(np.median(np.diff(ctx.t))) ** 2])
        f.estimate, f.std_error = us, float(np.sqrt(cov1[0, 0]))
        f.evidence = {"delta_stuck_rad": us, "onset_s": onset,
                      "command_std_after_rad": float(np.std(uu[after & ctx.valid]))}
        out.append(f)
    return out


# --------------------------------------------------------------------------- sensors, wind, mass properties


def fit_sensor_causes(ctx: DiagContext, R: np.ndarray, scorer: Scorer, exclude=()) -> list[Fitted]:
    """Fit each sensor / wind / mass-property cause by nonlinear least squares on the training rows.

    ``exclude``: causes left out (sensor causes judged by data compatibility instead).
    """
    tr = ctx.train
    sub = ctx.rows(tr)
    Rt = scorer.Rp[tr]
    out = []
    for cause in [c for c in transforms(ctx) if c.cause not in exclude]:
        def fun(p, cause=cause):
            return _weighted(sub, Rt + scorer.rows(cause.delta(sub, p), tr))

        try:
            sol = least_squares(fun, cause.p0, x_scale=cause.scale, method="lm" if len(Rt) * 6 > cause.n_params
                                else "trf", max_nfev=60 * (cause.n_params + 1))
        except (ValueError, FloatingPointError, np.linalg.LinAlgError):
            continue
        if not (np.all(np.isfinite(sol.x)) and np.all(np.isfinite(sol.jac)) and np.all(np.isfinite(sol.fun))):
            continue
        delta = cause.delta(ctx, sol.x)
        if not np.all(np.isfinite(delta[ctx.valid])):
            continue
        f = Fitted(cause.cause, "sensor", sol.x, np.zeros((cause.n_params,) * 2), list(cause.labels), delta)
        _finish(ctx, scorer, f, sol.jac, sol.fun)
        se = np.sqrt(np.maximum(np.diag(f.cov), 0))
        if cause.cause == "wind":
            wn, we = sol.x
            spd = float(np.hypot(wn, we))
            g = np.array([wn, we]) / max(spd, 1e-9)
            f.estimate, f.std_error = spd, float(np.sqrt(max(g @ f.cov @ g, 0)))
            f.evidence = {"wn_mps": float(wn), "we_mps": float(we), "speed_mps": spd,
                          "from_deg": float(np.degrees(np.arctan2(-we, -wn)) % 360)}
        elif cause.cause == "cg_offset":
            d = sol.x
            mag = float(np.linalg.norm(d))
            g = d / max(mag, 1e-12)
            f.estimate, f.std_error = mag, float(np.sqrt(max(g @ f.cov @ g, 0)))
            f.evidence = {"dx_m": float(d[0]), "dy_m": float(d[1]), "dz_m": float(d[2]),
                          "std_error_m": [float(x) for x in se]}
        else:
            f.estimate, f.std_error = float(sol.x[0]), float(se[0])
            if cause.cause == "mass" or cause.cause.startswith("inertia:"):
                nom = ctx.airframe.mass if cause.cause == "mass" else getattr(ctx.airframe, cause.cause[8:])
                f.evidence = {"airframe_value": nom, "ratio": float(sol.x[0] / nom) if nom else None}
        out.append(f)
    return out
