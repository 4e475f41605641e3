"""Errors in the regressors: a named term's estimate corrected for the noise of the estimated air angles.

The sparse search (:mod:`gcs_sysid.diagnose.sparse`) fits a term such as ``alpha^2`` or ``alpha*beta`` by least
squares on monomials of the *reconstructed* angle of attack and sideslip. When the reconstruction carries a
random error ``u`` (``W = alpha + u``), least squares estimates the best linear predictor of the residual from
``W``, not the term's coefficient in the true angle: the estimate is attenuated (Fuller, *Measurement Error
Models*, Wiley 1987, sec. 1.1; Carroll, Ruppert, Stefanski and Crainiceanu, *Measurement Error in Nonlinear
Models*, 2nd ed., Chapman & Hall 2006, ch. 3). For a slope the factor is ``var(alpha) / (var(alpha) +
var(u))``.

The correction here is the method-of-moments (corrected normal equations) estimator of Fuller (1987, ch. 2:
``theta = (M_XX - S_uu)^-1 (M_Xy - S_uy)``), extended to polynomial regressors by corrected scores
(Stefanski 1989, *Commun. Statist. Theory Methods* 18, 4335; Cheng and Schneeweiss, *J. R. Statist. Soc. B* 60
(1998) 189; Carroll et al. 2006, ch. 7): every moment of the true angles in the normal equations is replaced
by a function of the measured angle whose expectation, given the truth, is that moment. Under a Gaussian error
of variance ``v`` these functions are the scaled Hermite polynomials, ``E[He_n(W; v) | alpha] = alpha^n`` with
``He_0 = 1``, ``He_1 = W``, ``He_{n+1} = W He_n - n v He_{n-1}`` (so ``alpha^2 -> W^2 - v``, ``alpha^3 -> W^3 -
3 v W``); alpha's and beta's errors are taken independent of each other and of the other regressors, so a
product ``alpha^n beta^m z`` becomes ``He_n(W_alpha; v_alpha) He_m(W_beta; v_beta) z``. ``v`` is the estimator's
*stated* per-sample variance of the angle (``FlightStates.sigma``: the Kalman/RTS smoother's posterior variance of
the aided angle), never the truth. Columns that are not monomials (hinges in alpha, ``alpha_dot_hat``, lagged
surfaces, ``scale:<coef>``) have no closed form and are taken as measured (their moments uncorrected).

The response's own error is left alone (``S_uy = 0``): the residual's part that follows the angle error through
the model's derivatives is what the diagnosis's angle nuisance removes before the search
(:func:`gcs_sysid.diagnose.sparse.angle_nuisance`).

What this does *not* correct: an error of the angle that is proportional to the angle (a scale error; measured on
the JSBSim rascal: the aided alpha is 1.8-2.4 times the true excursions, ``docs/benchmarks.md``, *Fourteenth
session, i9-eiv*). That is not classical measurement error and no variance corrects it.
"""

from __future__ import annotations

import numpy as np

from ..aero.table import REGRESSORS

__all__ = ["hermite_unbiased", "monomial_exponents", "corrected_fit", "ANGLES", "MIN_RELIABILITY"]

#: the regressors whose errors are corrected (the estimated air angles)
ANGLES = ("alpha", "beta")

#: a correction is applied only when every direction of the corrected (centred) normal matrix keeps at least this
#: share of the measured one (generalised eigenvalues of ``M_corrected`` against ``M``): with less, the stated error
#: variance is as large as the signal and the corrected moments are not identified (Fuller 1987 modifies the
#: estimator near that boundary; here it is simply not applied)
MIN_RELIABILITY = 0.2


def hermite_unbiased(w: np.ndarray, var: np.ndarray | float, n: int) -> np.ndarray:
    """Unbiased estimate of ``x^n`` from ``w = x + u``, ``u ~ N(0, var)``: the scaled Hermite polynomial.

    Args:
        w: (T,) measured values. var: (T,) or scalar error variance (same units squared). n: power, >= 0.

    Returns:
        (T,) ``He_n(w; var)``, with ``E[He_n(w; var) | x] = x^n`` (Stefanski 1989; Cheng and Schneeweiss 1998).

    Raises:
        ValueError: negative ``n``.
    """
    if n < 0:
        raise ValueError(f"hermite_unbiased: power must be >= 0, got {n}")
    w = np.asarray(w, float)
    h0, h1 = np.ones_like(w), w
    if n == 0:
        return h0
    for k in range(1, n):
        h0, h1 = h1, w * h1 - k * var * h0
    return h1


def monomial_exponents(term: str) -> dict[str, int] | None:
    """``{"alpha": 2, "beta": 1}`` for ``"alpha^2*beta"``; ``{}`` for the constant ``"1"``; None for a term that
    is not a monomial in the regressors (hinges, lags, ``alpha_dot_hat``, ``scale:<coef>``)."""
    if term == "1":
        return {}
    if "(" in term or ":" in term or term == "alpha_dot_hat":
        return None
    out: dict[str, int] = {}
    for part in term.split("*"):
        base, _, pw = part.partition("^")
        if base not in REGRESSORS or (pw and not pw.isdigit()):
            return None
        out[base] = out.get(base, 0) + (int(pw) if pw else 1)
    return out


def _unbiased_product(e: dict[str, int], X: np.ndarray, var: dict[str, np.ndarray]) -> np.ndarray:
    """(T,) unbiased estimate of the true monomial with exponents ``e`` from the measured regressors ``X``."""
    out = np.ones(X.shape[0])
    for name, n in e.items():
        x = X[:, REGRESSORS.index(name)]
        out = out * (hermite_unbiased(x, var[name], n) if name in var else x**n)
    return out


def corrected_fit(terms: list[str], A: np.ndarray, y: np.ndarray, X: np.ndarray,
                  var: dict[str, np.ndarray]) -> dict:
    """Least squares of ``y`` on ``[1, A]`` with the moments corrected for the angles' measurement error.

    Args:
        terms: (P,) names of ``A``'s columns (library names: monomials are corrected, others taken as measured).
        A: (N, P) the columns on the fit's rows. y: (N,) the response on those rows.
        X: (N, 10) the regressors the columns were built from (``REGRESSORS`` order) on the same rows.
        var: ``{"alpha": (N,), "beta": (N,)}`` the stated error variance of each angle, rad^2 (NaN read as 0).

    Returns:
        ``{"applied": bool, "theta": (P+1,) corrected [constant, terms], "theta_ls": (P+1,), "G": (P+1, P+1)``
        ``(theta ~ G theta_ls, for propagating a covariance), "reliability": (P,) generalised eigenvalues of the
        corrected against the measured centred normal matrix (1: no error), "why": str}``. Not applied (``theta``
        = ``theta_ls``) when no column holds an angle, when the stated variances are absent, or when the smallest
        reliability is below :data:`MIN_RELIABILITY`.

    Raises:
        ValueError: shapes that do not match.
    """
    A = np.asarray(A, float)
    y = np.asarray(y, float)
    N, P = A.shape
    if len(terms) != P or y.shape != (N,) or X.shape[0] != N:
        raise ValueError(f"corrected_fit: {len(terms)} names, A {A.shape}, y {y.shape}, X {X.shape} do not match")
    B = np.column_stack([np.ones(N), A])
    M = B.T @ B
    m = B.T @ y
    theta_ls = np.linalg.lstsq(B, y, rcond=None)[0]
    out = {"applied": False, "theta": theta_ls, "theta_ls": theta_ls, "G": np.eye(P + 1),
           "reliability": np.ones(P), "why": ""}
    v = {k: np.nan_to_num(np.asarray(var[k], float)) for k in ANGLES if k in var and var[k] is not None}
    v = {k: a for k, a in v.items() if np.any(a > 0)}
    ex = [{}] + [monomial_exponents(t) for t in terms]
    if not v:
        out["why"] = "no stated variance of the air angles"
        return out
    if not any(e and any(k in e for k in v) for e in ex):
        out["why"] = "no selected term in an air angle"
        return out
    Mc = M.copy()
    mc = m.copy()
    for i in range(P + 1):
        if ex[i] is None:
            continue
        if any(k in ex[i] for k in v):
            mc[i] = _unbiased_product(ex[i], X, v) @ y
        for j in range(i, P + 1):
            if ex[j] is None:
                continue
            e = dict(ex[i])
            for k, n in ex[j].items():
                e[k] = e.get(k, 0) + n
            if any(k in e for k in v):
                Mc[i, j] = Mc[j, i] = float(np.sum(_unbiased_product(e, X, v)))
    # reliability of each direction: centred (the constant profiled out) corrected against measured
    def centred(S):
        return S[1:, 1:] - np.outer(S[1:, 0], S[0, 1:]) / S[0, 0]
    Sm, Sc = centred(M), centred(Mc)
    try:
        L = np.linalg.cholesky(Sm)
        Li = np.linalg.inv(L)
        rel = np.linalg.eigvalsh(Li @ Sc @ Li.T)
    except np.linalg.LinAlgError:
        out["why"] = "the measured normal matrix is singular"
        return out
    out["reliability"] = rel
    if rel.min() < MIN_RELIABILITY:
        out["why"] = (f"not applied: the stated angle error leaves {rel.min():.2f} of a direction's variance "
                      f"(< {MIN_RELIABILITY:g}); the corrected moments are not identified")
        return out
    theta = np.linalg.solve(Mc, mc)
    out.update(applied=True, theta=theta, G=np.linalg.solve(Mc, M),
               why="corrected normal equations (Fuller 1987 ch. 2; Hermite corrected scores)")
    return out
