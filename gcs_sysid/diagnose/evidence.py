"""What is left: the unexplained residual, where it lives, and which maneuver would separate causes."""

from __future__ import annotations

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from .context import DiagContext
from .terms import VOCABULARY, term_factors, term_matrix

__all__ = ["unexplained_report", "maneuver_for", "noise_residual", "binned_structure"]

_AXIS_MANEUVER = {
    "alpha": "elevator 3-2-1-1 or doublets at several airspeeds (vary alpha)",
    "q_hat": "elevator doublets (pitch rate)",
    "delta_e": "elevator 3-2-1-1 (pitch)",
    "beta": "rudder doublets (sideslip)",
    "r_hat": "rudder doublets (yaw rate)",
    "delta_r": "rudder 3-2-1-1 (yaw)",
    "p_hat": "aileron doublets (roll rate)",
    "delta_a": "aileron 3-2-1-1 (roll)",
    "delta_t": "throttle steps",
    "V": "steady segments at several airspeeds (throttle steps)",
}

_CAUSE_MANEUVER = {
    "bias:airspeed": "steady segments at several airspeeds (a bias shrinks in relative size as V grows)",
    "scale:airspeed": "steady segments at several airspeeds (a scale error keeps its relative size)",
    "bias:alpha": "elevator doublets at several airspeeds (alpha bias shifts every alpha-dependent coefficient)",
    "bias:beta": "rudder doublets and steady sideslips in both directions",
    "wind": "a full 360 degree turn (wind errors change sign with heading)",
    "mass": "pull-ups and push-overs (vary the load factor)",
    "cg_offset": "elevator doublets at several airspeeds (vary CZ so the CG moment arm shows)",
}


def maneuver_for(cause: str) -> str:
    """A maneuver that excites what tells ``cause`` apart from its rivals (one line)."""
    if cause in _CAUSE_MANEUVER:
        return _CAUSE_MANEUVER[cause]
    kind, _, rest = cause.partition(":")
    if kind == "delay":
        return f"sharp doublets on {rest} (a delay shows in the fast part of the response)"
    if kind == "stuck":
        return f"keep exciting {rest} after the suspected onset"
    if kind == "bias" and rest.startswith("gyro"):
        axis = {"gyro_x": "p_hat", "gyro_y": "q_hat", "gyro_z": "r_hat"}[rest]
        return _AXIS_MANEUVER[axis] + " at several airspeeds"
    if kind == "bias" and rest.startswith("accel"):
        return "steady segments at several airspeeds (an accelerometer bias scales as 1/qbar)"
    if kind == "inertia":
        return {"Ixx": "sharp aileron doublets", "Iyy": "sharp elevator doublets", "Izz": "sharp rudder doublets",
                "Ixz": "sharp aileron and rudder doublets"}[rest]
    if kind in COEFFICIENTS:
        try:
            names = [REGRESSORS[i] for i in term_factors(rest)]
        except Exception:                                     # noqa: BLE001 - advice only
            names = []
        return "; ".join(dict.fromkeys(_AXIS_MANEUVER[n] for n in names)) or "a longer flight with all axes excited"
    return "a longer flight with all axes excited"


def _ridge_design(ctx: DiagContext):
    """Standardised quadratic design (T, K) of all vocabulary terms and its training Gram factor."""
    Phi = term_matrix(ctx.X, VOCABULARY)
    tr = ctx.train
    mu = Phi[tr].mean(0)
    mu[0] = 0.0
    sd = Phi[tr].std(0)
    sd[0] = 1.0
    keep = sd > 0
    A = (Phi[:, keep] - mu[keep]) / sd[keep]
    G = A[tr].T @ A[tr] + 1e-3 * tr.sum() * np.eye(A.shape[1])
    return A, np.linalg.cholesky(G)


def noise_residual(ctx: DiagContext, R: np.ndarray) -> np.ndarray:
    """Held-out residual (N_test, 6) left by a ridge quadratic in all regressors fitted on the training rows.

    What no catalogue aero term could explain: the noise level against which candidates are judged.
    """
    from scipy.linalg import cho_solve

    A, L = _ridge_design(ctx)
    tr, te = ctx.train, ctx.test
    th = cho_solve((L, True), A[tr].T @ np.nan_to_num(R[tr]))
    return np.nan_to_num(R[te]) - A[te] @ th


def _structured_share(ctx: DiagContext, r: np.ndarray, A: np.ndarray, L: np.ndarray) -> float:
    """Share (0..1) of the held-out residual that a quadratic in the regressors, fitted on training, predicts."""
    from scipy.linalg import cho_solve

    tr, te = ctx.train, ctx.test
    th = cho_solve((L, True), A[tr].T @ r[tr])
    e0 = np.sum(r[te] ** 2)
    e1 = np.sum((r[te] - A[te] @ th) ** 2)
    return float(max(0.0, 1.0 - e1 / e0)) if e0 > 0 else 0.0


def _bin_index(x: np.ndarray, ref: np.ndarray, n_bins: int) -> np.ndarray:
    """Quantile-bin index (T,) of ``x`` with edges from ``ref`` (the training rows)."""
    edges = np.quantile(ref, np.linspace(0, 1, n_bins + 1)[1:-1])
    return np.searchsorted(edges, x, side="right")


def binned_structure(ctx: DiagContext, r: np.ndarray, n_bins: int = 8, shrink: float = 10.0) -> dict:
    """Structure of a residual that no polynomial needs to describe: held-out share predicted by cell means.

    For every regressor and every pair of regressors, the valid rows are cut into quantile
    cells (``n_bins`` per regressor, edges from the training rows); the residual's mean in
    each cell, shrunk towards 0 by ``n / (n + shrink)``, is fitted on the training rows and
    predicts the held-out rows. The best projection's share of the held-out residual
    (``1 - SSE_after / SSE_before``) says how much of the residual is a function of the
    flight condition, whatever its shape (a sin-shaped term, a hysteresis loop split by the
    sign of a rate...), which a quadratic misses.

    Args:
        ctx: diagnosis context (regressors, training and held-out rows).
        r: residual of one coefficient, (T,).
        n_bins: cells per regressor. shrink: pseudo-count of the shrinkage.

    Returns:
        ``{"share": 0..1, "regressors": [names], "cell": {name: [lo, hi]}, "cell_mean": float}``
        (alpha and beta ranges in degrees, with ``_deg`` appended to the name).
    """
    tr, te, v = ctx.train, ctx.test, ctx.valid
    r = np.nan_to_num(r)
    e0 = float(np.sum(r[te] ** 2))
    best = {"share": 0.0, "regressors": [], "cell": {}, "cell_mean": 0.0}
    if e0 <= 0 or tr.sum() < 4 * n_bins or te.sum() < n_bins:
        return best
    cols = [i for i in range(len(REGRESSORS)) if np.ptp(ctx.X[tr, i]) > 0]
    idx = {i: _bin_index(np.nan_to_num(ctx.X[:, i]), ctx.X[tr, i], n_bins) for i in cols}
    combos = [(i,) for i in cols] + [(i, j) for a, i in enumerate(cols) for j in cols[a + 1:]]
    for combo in combos:
        cell = np.zeros(len(r), int)
        for i in combo:
            cell = cell * n_bins + idx[i]
        m = n_bins ** len(combo)
        n = np.bincount(cell[tr], minlength=m)
        mean = np.bincount(cell[tr], weights=r[tr], minlength=m) / np.maximum(n, 1) * (n / (n + shrink))
        share = 1.0 - float(np.sum((r[te] - mean[cell[te]]) ** 2)) / e0
        if share > best["share"]:
            k = int(np.argmax(np.abs(mean) * (n >= shrink)))
            where = {}
            for pos, i in enumerate(combo):
                b = (k // n_bins ** (len(combo) - 1 - pos)) % n_bins
                x = ctx.X[v & (cell == k), i]
                scale, name = (np.degrees(1.0), REGRESSORS[i] + "_deg") if REGRESSORS[i] in ("alpha", "beta") \
                    else (1.0, REGRESSORS[i])
                where[name] = [float(np.min(x) * scale), float(np.max(x) * scale)] if x.size else [float(b), float(b)]
            best = {"share": share, "regressors": [REGRESSORS[i] for i in combo], "cell": where,
                    "cell_mean": float(mean[k])}
    return best


def unexplained_report(ctx: DiagContext, R: np.ndarray, threshold_pct: float = 20.0,
                       min_size_pct: float = 2.0) -> list[dict]:
    """Per coefficient: size of the held-out residual and where it lives.

    ``structured_percent`` is the share of the held-out residual variance that a
    quadratic in all regressors (ridge, fitted on the training rows) or cell means over
    any one or two regressors (:func:`binned_structure`, for shapes no polynomial
    follows) predict, whichever is larger;
    the entry is ``above_threshold`` when it reaches ``threshold_pct``, i.e. the
    residual is systematic, not noise, and that systematic part is at least
    ``min_size_pct`` percent of the RMS of the measured coefficient (smaller is
    below what a model of the coefficient is expected to reach). ``where`` gives the regressor most
    correlated with the residual, the alpha and V bins and the 5-s time window
    with the largest RMS; ``where["structure"]`` the projection and cell where the structure lives.
    """
    te = ctx.test
    out = []
    alpha = np.degrees(ctx.x("alpha"))
    V = ctx.x("V")
    A, L = _ridge_design(ctx)
    for j, coef in enumerate(COEFFICIENTS):
        r = R[:, j]
        y = ctx.Y[te, j]
        rms = float(np.sqrt(np.mean(r[te] ** 2)))
        rms_y = float(np.sqrt(np.mean(y**2)))
        share_q = _structured_share(ctx, r, A, L)
        binned = binned_structure(ctx, r)
        share = max(share_q, binned["share"])
        corr = {}
        for i, name in enumerate(REGRESSORS):
            x = ctx.X[te, i]
            if np.std(x) > 0 and np.std(r[te]) > 0:
                corr[name] = float(np.corrcoef(x, r[te])[0, 1])
        top = max(corr, key=lambda k: abs(corr[k])) if corr else None
        where = {"correlated_with": top, "correlation": corr.get(top) if top else None}
        v = ctx.valid
        for label, x in (("alpha_deg", alpha), ("V_mps", V)):
            edges = np.quantile(x[v], np.linspace(0, 1, 6))
            k = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, 4)
            rm = [np.sqrt(np.mean(r[v & (k == b)] ** 2)) if np.any(v & (k == b)) else 0.0 for b in range(5)]
            b = int(np.argmax(rm))
            where[label] = [float(edges[b]), float(edges[b + 1])]
            where[label + "_rms"] = float(rm[b])
        win = np.floor((ctx.t - ctx.t[0]) / 5.0).astype(int)
        rw = np.bincount(win[v], weights=r[v] ** 2, minlength=win.max() + 1)
        nw = np.bincount(win[v], minlength=win.max() + 1)
        with np.errstate(invalid="ignore", divide="ignore"):
            rmsw = np.sqrt(np.where(nw > 0, rw / nw, 0.0))
        w = int(np.argmax(rmsw))
        where["time_s"] = [float(ctx.t[0] + 5.0 * w), float(ctx.t[0] + 5.0 * (w + 1))]
        where["structure"] = {"quadratic_percent": float(100 * share_q), "binned_percent": float(100 * binned["share"]),
                              "regressors": binned["regressors"], "cell": binned["cell"],
                              "cell_mean": binned["cell_mean"]}
        if not ctx.active[j]:
            out.append({"coefficient": coef, "rms": rms, "rms_measured": rms_y,
                        "percent_of_measured": float(100 * rms / rms_y) if rms_y > 0 else None,
                        "structured_percent": None, "above_threshold": False, "identifiable": False,
                        "where": {}})
            continue
        out.append({"coefficient": coef, "rms": rms, "rms_measured": rms_y,
                    "percent_of_measured": float(100 * rms / rms_y) if rms_y > 0 else None,
                    "structured_percent": float(100 * share),
                    "structured_percent_of_measured": float(100 * np.sqrt(share) * rms / rms_y) if rms_y > 0 else 0.0,
                    "above_threshold": bool(100 * share >= threshold_pct
                                            and np.sqrt(share) * rms >= min_size_pct / 100 * rms_y),
                    "where": where})
    return out
