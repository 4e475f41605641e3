"""Aliased explanations: candidates a flight cannot tell apart from a named term (issue 9).

Two candidate columns that are (nearly) proportional on a flight explain its residual equally
well, and which of them the forward selection takes is then decided by whatever small part of the
residual the two columns do not share (here: the reference model's own imperfections), not by the
physics. The classic case is a side-force scale ``scale:CY`` against a change of ``CY:beta`` on an
aircraft whose side force is a single sideslip term: the model's CY *is* ``CY_beta beta``, so
``(k - 1) CY_model`` and ``delta CY_beta beta`` are one regressor (the JSBSim T-6 of the ninth
session's final evaluation: partial correlation 0.99997).

Criterion (collinearity diagnostics, Belsley, Kuh and Welsch, *Regression Diagnostics*, Wiley 1980,
ch. 3; Morelli and Klein, *Aircraft System Identification*, 2nd ed., sec. 5.4, data collinearity):
the named term's column and a rival's are taken *after* the constant and the other selected terms
are projected out (the partial columns, on the rows and in the space the selection saw); their
correlation ``rho`` gives the condition index of the standardised pair,
``eta = sqrt((1 + |rho|) / (1 - |rho|))`` (the square root of the ratio of the two eigenvalues of
their correlation matrix), and the two are *aliased* when ``eta >= 30``: Belsley, Kuh and Welsch's
threshold of a strong near-dependence (their "moderate to strong" band starts at 30), i.e.
``|rho| >= 0.99778``, a variance inflation ``1 / (1 - rho^2) >= 225`` for either given the other.
The rule depends on the columns only, not on the size of the effect: a flight that cannot give the
two regressors different histories cannot say which one changed, however large the change.

Nothing here names or drops a cause: the diagnosis names what it named before, and reports the
aliases beside it, each with its own estimate (the rival fitted in place of the named term, with the
same other terms, on the same residual and rows) and what flight would separate them.
"""

from __future__ import annotations

import numpy as np

from ..aero.table import REGRESSORS

__all__ = ["ALIAS_CONDITION_INDEX", "condition_index", "partial_correlations", "find_aliases", "term_regressors",
           "separation_advice"]

#: Belsley, Kuh and Welsch (1980, ch. 3): a condition index of 30 or more marks a strong near-dependence.
ALIAS_CONDITION_INDEX = 30.0


def condition_index(rho) -> np.ndarray:
    """Condition index of two standardised columns of correlation ``rho``: ``sqrt((1+|rho|)/(1-|rho|))``.

    Args:
        rho: correlation(s), scalar or array, in [-1, 1].

    Returns:
        the condition index (``inf`` at ``|rho| = 1``), same shape as ``rho``.
    """
    a = np.minimum(np.abs(np.asarray(rho, float)), 1.0)
    with np.errstate(divide="ignore"):
        return np.sqrt(np.where(a < 1.0, (1.0 + a) / np.maximum(1.0 - a, 0.0), np.inf))


def partial_correlations(A: np.ndarray, k0: int, others: list[int]) -> np.ndarray:
    """Correlation of every column of ``A`` with column ``k0``, the constant and ``others`` projected out.

    Args:
        A: (N, K) candidate columns on the rows the selection saw. k0: the named term's column.
        others: the other selected columns (kept in both fits, so projected out of both).

    Returns:
        (K,) partial correlations (0 where a column has nothing left after the projection; 1 at ``k0``).

    Raises:
        ValueError: ``A`` is not 2-D or ``k0`` is out of range.
    """
    A = np.asarray(A, float)
    if A.ndim != 2 or not 0 <= k0 < A.shape[1]:
        raise ValueError(f"partial_correlations: A must be (N, K) with 0 <= k0 < K, got {A.shape} and k0={k0}")
    B = np.hstack([np.ones((A.shape[0], 1)), A[:, list(others)]])
    Q, _ = np.linalg.qr(B)
    P = A - Q @ (Q.T @ A)
    nrm = np.linalg.norm(P, axis=0)
    x0 = P[:, k0]
    ok = (nrm > 1e-12 * max(float(np.linalg.norm(A, axis=0).max()), 1e-300)) & (nrm[k0] > 0)
    out = np.zeros(A.shape[1])
    out[ok] = (P[:, ok].T @ x0) / (nrm[ok] * nrm[k0])
    return np.clip(out, -1.0, 1.0)


def find_aliases(A: np.ndarray, k0: int, others: list[int], min_index: float = ALIAS_CONDITION_INDEX,
                 max_aliases: int = 5) -> list[tuple[int, float, float]]:
    """The columns of ``A`` aliased with column ``k0`` given ``others`` (see the module docstring).

    Args:
        A: (N, K) candidate columns. k0: the named term's column. others: the other selected columns.
        min_index: the condition index from which two columns count as aliased.
        max_aliases: at most this many, the most collinear first.

    Returns:
        ``[(column, partial correlation, condition index), ...]``, ``k0`` and ``others`` excluded.
    """
    rho = partial_correlations(A, k0, others)
    eta = condition_index(rho)
    skip = {k0, *others}
    ks = [k for k in np.argsort(-np.abs(rho)) if k not in skip and eta[k] >= min_index]
    return [(int(k), float(rho[k]), float(eta[k])) for k in ks[:max_aliases]]


def term_regressors(term: str) -> list[str]:
    """The regressors a library term is made of (``alpha^2*delta_e`` -> alpha, delta_e; a lag term -> its
    surface; ``max(0,alpha-0.05)`` -> alpha; ``alpha_dot_hat`` -> alpha); [] for a scale or an unknown term."""
    if term.startswith("scale:"):
        return []
    if "(t-" in term:
        return [term.split("(t-")[0]]
    if term == "alpha_dot_hat":
        return ["alpha"]
    if term.startswith("max(0,"):
        return [term[6:].split("-")[0]]
    out = []
    for part in term.split("*"):
        base = part.partition("^")[0]
        if base in REGRESSORS and base not in out:
            out.append(base)
    return out


_HOW = {
    "alpha": "elevator inputs at several airspeeds (vary alpha)",
    "beta": "rudder doublets or steady sideslips (vary beta)",
    "p_hat": "aileron doublets (roll rate)",
    "q_hat": "elevator doublets (pitch rate)",
    "r_hat": "rudder doublets (yaw rate)",
    "delta_e": "elevator 3-2-1-1",
    "delta_a": "aileron 3-2-1-1",
    "delta_r": "rudder 3-2-1-1",
    "delta_t": "throttle steps",
    "V": "steady segments at several airspeeds",
}


_LATERAL = ("delta_r", "r_hat", "p_hat", "delta_a")
_LONGITUDINAL = ("delta_e", "q_hat", "delta_t", "V")


def separation_advice(coef: str, named_term: str, alias_term: str, model_terms: list[str]) -> str:
    """One line: what data would tell ``named_term`` and ``alias_term`` of ``coef`` apart.

    Args:
        coef: the coefficient (``"CY"``). named_term, alias_term: library terms or ``scale:<coef>``.
        model_terms: the reference model's terms of ``coef`` (for a scale: the regressors it is made of).

    Returns:
        advice text naming the regressors that must move independently of each other.
    """
    def regs(term: str) -> list[str]:
        if term.startswith("scale:"):
            return list(dict.fromkeys(r for t in model_terms if t != "1" for r in term_regressors(t)))
        return term_regressors(term)

    a, b = regs(named_term), regs(alias_term)
    scale = [t for t in (named_term, alias_term) if t.startswith("scale:")]
    if scale:
        term = alias_term if scale[0] == named_term else named_term
        rest = [t for t in model_terms if t not in ("1", term)]
        if not rest:
            return (f"the reference model's {coef} is {' + '.join(model_terms) or 'empty'}: a scale of {coef} and a "
                    f"change of {coef}:{term} are one regressor on any flight with this model; they separate only "
                    f"once the model holds a second {coef} term excited independently of {term} ("
                    + "; ".join(_HOW[r] for r in (_LATERAL if coef in ("CY", "Cl", "Cn") else _LONGITUDINAL)
                                if r not in term_regressors(term))
                    + "), fitted on a reference flight that excites it")
        only = [r for r in regs(scale[0]) if r not in term_regressors(term)]
        return (f"a flight that moves the model's other {coef} terms ({', '.join(rest)}) independently of {term}: "
                + ("; ".join(_HOW[r] for r in only if r in _HOW) or "a longer flight with all axes excited"))
    diff = [r for r in dict.fromkeys(a + b) if (r in a) != (r in b)]
    if diff:
        return (f"a flight where {', '.join(diff)} move independently of "
                f"{', '.join(r for r in a + b if r not in diff) or 'each other'}: "
                + "; ".join(_HOW[r] for r in diff if r in _HOW))
    same = ", ".join(dict.fromkeys(a + b)) or "the regressors"
    return (f"{named_term} and {alias_term} are functions of the same regressor(s) ({same}) that this flight "
            f"covers too narrowly to tell apart: a wider range of {same}")
