"""A search beyond the catalogue: forward stepwise selection over a wide candidate library, by PRESS.

What the named causes leave in a coefficient is regressed on a library much wider than the
model file's vocabulary: every monomial of degree 1 to 3 in the nine non-dimensional
regressors (products with the controls and the throttle included), hinge functions
``max(0, alpha - a_k)`` at the training quantiles of alpha (a piecewise-linear spline),
the non-dimensional ``alpha_dot_hat = alpha_dot c / (2 V)``, and lag corrections
``delta(t - tau) - delta(t)`` of each surface. Terms enter one at a time (forward stepwise
regression) by the prediction error sum of squares over ``folds`` contiguous blocks of the
*training* rows only (block PRESS: Morelli and Klein, *Aircraft System Identification*,
sec. 5.4; blocks rather than single rows because the residuals are coloured); selection
stops when the next term lowers the PRESS by less than ``min_press_gain`` of it. The gain
of the selected terms is then measured once, on the held-out rows that no step of the
selection saw.

Everything is done on the Gram matrices of the folds, so a step costs small solves only
(Brunton, Proctor and Kutz, PNAS 113 (2016) 3932, do the same selection with sequentially
thresholded least squares; forward stepwise with PRESS keeps the model small and ordered).
"""

from __future__ import annotations

from itertools import combinations_with_replacement

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from .context import DiagContext

__all__ = ["LIBRARY_REGRESSORS", "candidate_library", "alpha_quantile_knots", "press_stepwise", "search_residual"]

#: The regressors the candidate library builds its monomials from (products to degree 3), in the order a term's
#: factors are written (``alpha*beta``, ``alpha^2``); shared with :mod:`.sparse`, which parses and names the terms.
LIBRARY_REGRESSORS = ("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a", "delta_r", "delta_t")


def candidate_library(ctx: DiagContext, degree: int = 3, n_hinges: int = 4,
                      lags_s: tuple[float, ...] = (0.05, 0.1, 0.2),
                      alpha_knots: np.ndarray | None = None,
                      control_trim: dict[str, float] | None = None,
                      drop_constant: bool = True) -> tuple[list[str], np.ndarray]:
    """The candidate terms, evaluated on every row.

    Args:
        ctx: the diagnosis context (regressors on a uniform time grid, training rows).
        degree: highest monomial degree. n_hinges: hinges in alpha at training quantiles.
        lags_s: lags of the surface lag corrections, s.
        alpha_knots: hinge positions in alpha, rad (default: the ``n_hinges`` inner quantiles of
            the training rows' alpha); give another flight's to share one library between flights.
        control_trim: ``{regressor: value}`` (rad for the surfaces): the monomials' factors in these regressors are
            measured about the given values, ``delta_e - delta_e0`` (the reference flight's trim, so that a product
            such as ``alpha^2*delta_e`` is not ``delta_e0`` times ``alpha^2`` at a large trim: Marquardt, JASA 75
            (1980) 87, nonessential ill-conditioning; Morelli and Klein, *Aircraft System Identification*, sec. 5.4,
            regressors about the reference condition). A product's own coefficient is unchanged by it; its
            lower-order parents then read their slopes at the trim. Hinges, ``alpha_dot_hat`` and the lag
            differences do not depend on it. None (the default): the measured values.
        drop_constant: leave out the columns that are constant on the valid rows (the search's library).
            False keeps every candidate: for a library rebuilt at perturbed regressors to re-evaluate terms
            already selected (a hinge whose knot the perturbed alpha no longer crosses is all zeros there).

    Returns:
        (names, Phi): names (K,) and values (T, K); constant columns left out unless ``drop_constant`` is False.
    """
    X = np.nan_to_num(ctx.X)
    cols = {n: X[:, REGRESSORS.index(n)] - float((control_trim or {}).get(n, 0.0)) for n in LIBRARY_REGRESSORS}
    names, out = [], []
    for d in range(1, degree + 1):
        for combo in combinations_with_replacement(LIBRARY_REGRESSORS, d):
            v = np.prod([cols[n] for n in combo], axis=0)
            parts = []
            for n in dict.fromkeys(combo):
                k = combo.count(n)
                parts.append(n if k == 1 else f"{n}^{k}")
            names.append("*".join(parts))
            out.append(v)
    a = X[:, REGRESSORS.index("alpha")]
    tr = ctx.train
    if alpha_knots is None:
        alpha_knots = alpha_quantile_knots(ctx, n_hinges)
    for ak in alpha_knots:
        names.append(f"max(0,alpha-{np.degrees(ak):.1f}deg)")
        out.append(np.maximum(0.0, a - ak))
    t = ctx.t
    if len(t) > 2:
        V = np.maximum(X[:, REGRESSORS.index("V")], 1.0)
        names.append("alpha_dot_hat")
        out.append(np.gradient(a, t) * ctx.airframe.c / (2 * V))
        for u in ("delta_e", "delta_a", "delta_r"):
            for tau in lags_s:
                names.append(f"{u}(t-{tau:g})-{u}")
                out.append(np.interp(t - tau, t, X[:, REGRESSORS.index(u)]) - X[:, REGRESSORS.index(u)])
    Phi = np.column_stack(out)
    if not drop_constant:
        return names, Phi
    keep = np.ptp(Phi[ctx.valid], axis=0) > 0 if ctx.valid.any() else np.zeros(Phi.shape[1], bool)
    return [n for n, k in zip(names, keep) if k], Phi[:, keep]


def alpha_quantile_knots(ctx: DiagContext, n_hinges: int = 4) -> np.ndarray:
    """The ``n_hinges`` inner quantiles of alpha on the training rows, rad (zeros without training rows)."""
    a = np.nan_to_num(ctx.X[:, REGRESSORS.index("alpha")])
    qs = np.linspace(0, 1, n_hinges + 2)[1:-1]
    return np.quantile(a[ctx.train], qs) if ctx.train.any() else np.zeros(n_hinges)


def press_stepwise(Phi: np.ndarray, r: np.ndarray, fold: np.ndarray, max_terms: int = 6,
                   min_press_gain: float = 0.02, blocks: list[tuple[int, ...]] | None = None) -> dict:
    """Forward stepwise selection by block PRESS on the training rows.

    Args:
        Phi: candidates on the training rows (N, K). r: residual on the same rows (N,).
        fold: (N,) fold index 0..F-1 of each row (contiguous time blocks).
        max_terms: most terms selected. min_press_gain: smallest relative PRESS decrease to go on.
        blocks: column groups that may also enter together in one step, as one candidate, when none of
            their columns is selected yet and they fit within ``max_terms`` (e.g. ``(alpha^2, alpha)``, a
            curvature with its first parent: :func:`gcs_sysid.diagnose.sparse.power_parent_blocks`). A block
            is offered at a step only when its first column is not that step's best single column (the block
            rescues a square that a correlated single beats; a square that wins alone enters alone, as
            without blocks); it is then compared with the single columns by the same block PRESS, and when it
            wins its columns are appended in the given order and the PRESS path gets one entry for the step.
            None: singles only.

    Returns:
        ``{"selected": [k...], "press": [PRESS after 0, 1, ... steps], "scale": (K,), "steps": [[k...] per
        step]}``; columns are standardised internally (``scale``: their training RMS).
    """
    scale = np.sqrt(np.mean(Phi**2, axis=0))
    scale = np.where(scale > 0, scale, 1.0)
    A = Phi / scale
    F = int(fold.max()) + 1
    Gk = np.stack([A[fold == k].T @ A[fold == k] for k in range(F)])           # (F, K, K)
    bk = np.stack([A[fold == k].T @ r[fold == k] for k in range(F)])           # (F, K)
    rk = np.array([r[fold == k] @ r[fold == k] for k in range(F)])
    G, b = Gk.sum(0), bk.sum(0)
    ridge = 1e-9 * np.trace(G) / G.shape[0]
    sel: list[int] = []
    press = [float(rk.sum())]
    steps: list[list[int]] = []
    K = A.shape[1]
    eye = np.eye(K)

    def set_press(S: list[int]) -> float:
        # the same fold-out arithmetic for one column set
        Sa = np.asarray(S, dtype=int)
        Gks = Gk[:, Sa[:, None], Sa[None, :]]                                             # (F, s, s)
        bks = bk[:, Sa]
        Gm = G[Sa[:, None], Sa[None, :]][None] - Gks + ridge * eye[:Sa.size, :Sa.size]
        th = np.linalg.solve(Gm, (b[Sa][None] - bks)[..., None])[..., 0]                 # (F, s)
        return float((rk - 2 * np.einsum("fs,fs->f", th, bks) + np.einsum("fs,fst,ft->f", th, Gks, th)).sum())

    while len(sel) < max_terms:
        # every candidate c and fold k of this step at once: the fold-out normal equations of sel + [c]
        # (Gm = G_S - Gk_S, stacked (F, C, s, s)) solved in one batched call, then the fold's PRESS term
        # rk - 2 th.bk_S + th.Gk_S.th; the same arithmetic as one solve per (c, k), without the Python loop
        cand = np.array([c for c in range(K) if c not in sel], dtype=int)
        if cand.size == 0:
            break
        S = np.column_stack([np.tile(np.asarray(sel, dtype=int), (cand.size, 1)), cand])    # (C, s)
        ii, jj = S[:, :, None], S[:, None, :]
        Gks = Gk[:, ii, jj]                                                                 # (F, C, s, s)
        bks = bk[:, S]                                                                      # (F, C, s)
        Gm = G[ii, jj][None] - Gks + ridge * np.eye(S.shape[1])
        th = np.linalg.solve(Gm, (b[S][None] - bks)[..., None])[..., 0]                     # (F, C, s)
        p = (rk[:, None] - 2 * np.einsum("fcs,fcs->fc", th, bks)
             + np.einsum("fcs,fcst,fct->fc", th, Gks, th)).sum(0)                           # (C,)
        i = int(np.argmin(p))                                  # the first of equal minima, as the loop did
        step, best = [int(cand[i])], float(p[i])
        for blk in blocks or ():
            # a block is offered only in lieu of its first column: when that column is not this step's best
            # single (the square that a correlated single beats); a square that wins alone enters alone and
            # its parent follows on its own PRESS, one term a step (Morelli and Klein sec. 5.4)
            if len(sel) + len(blk) > max_terms or any(c in sel for c in blk) or blk[0] == int(cand[i]):
                continue
            pb = set_press(sel + list(blk))
            if pb < best:
                step, best = [int(c) for c in blk], pb
        if not best < press[-1] or press[-1] - best < min_press_gain * press[-1]:
            break
        sel += step
        steps.append(step)
        press.append(best)
    return {"selected": sel, "press": press, "scale": scale, "steps": steps}


def search_residual(ctx: DiagContext, R: np.ndarray, coefficients=None, folds: int = 5, max_terms: int = 6,
                    min_press_gain: float = 0.02, max_rows: int = 6000) -> list[dict]:
    """Search the wide library for what each coefficient's residual needs; gain measured once, held out.

    Args:
        ctx: the diagnosis context. R: residual measured minus model (T, 6).
        coefficients: names to search (default: the active ones).
        folds: contiguous blocks of the training rows for PRESS.
        max_terms, min_press_gain: as :func:`press_stepwise`.
        max_rows: the training rows are thinned evenly to at most this many for the selection
            (the final fit uses all of them).

    Returns:
        one dict per coefficient: ``terms`` (``term``, ``estimate``, ``std_error``), ``press`` path,
        ``held_out`` (``rms_before``, ``rms_after``, ``percent``) and ``n_candidates``.
    """
    from .regression import ols

    names, Phi = candidate_library(ctx)
    tr, te = np.nonzero(ctx.train)[0], np.nonzero(ctx.test)[0]
    out = []
    if tr.size < 10 * folds or te.size < 10:
        return out
    sub = tr[:: max(1, int(np.ceil(tr.size / max_rows)))]
    fold = np.minimum((np.arange(sub.size) * folds) // sub.size, folds - 1)
    for j, coef in enumerate(COEFFICIENTS):
        if (coefficients is not None and coef not in coefficients) or not ctx.active[j]:
            continue
        r = np.nan_to_num(R[:, j])
        res = press_stepwise(Phi[sub], r[sub], fold, max_terms, min_press_gain)
        sel = res["selected"]
        before = float(np.sqrt(np.mean(r[te] ** 2)))
        entry = {"coefficient": coef, "n_candidates": len(names), "press": res["press"], "terms": [],
                 "held_out": {"rms_before": before, "rms_after": before, "percent": 0.0}}
        if sel:
            fit = ols(Phi[tr][:, sel], r[tr], [names[k] for k in sel])
            after = float(np.sqrt(np.mean((r[te] - Phi[te][:, sel] @ fit.theta) ** 2)))
            entry["terms"] = [{"term": names[k], "estimate": float(th), "std_error": float(se)}
                              for k, th, se in zip(sel, fit.theta, fit.std_error)]
            entry["held_out"] = {"rms_before": before, "rms_after": after,
                                 "percent": float(100 * (1 - after / before)) if before > 0 else 0.0}
        out.append(entry)
    return out
