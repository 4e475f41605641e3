"""The regressor-term vocabulary of the aero model: ``1`` and monomials of degree 1 or 2.

A term is written with the regressor names of :data:`gcs_sysid.aero.table.REGRESSORS`
joined by ``*`` in that order, a square as ``^2``: ``"1"``, ``"alpha"``,
``"alpha^2"``, ``"alpha*beta"``, ``"q_hat*delta_e"``. This is the vocabulary of
the model file (``gcs_sysid.sim.model_file``) and of the ``<coef>:<term>`` causes
in ``diagnosis.json`` (issue 3).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from ..errors import InputError

__all__ = ["VOCABULARY", "canonical_term", "term_factors", "term_matrix", "terms_using", "split_cause"]


def _build_vocabulary() -> tuple[str, ...]:
    out = ["1"]
    out += list(REGRESSORS)
    for i, a in enumerate(REGRESSORS):
        for j in range(i, len(REGRESSORS)):
            out.append(f"{a}^2" if i == j else f"{a}*{REGRESSORS[j]}")
    return tuple(out)


#: Every admissible term, 1 + 10 + 55 = 66 entries, canonical spelling.
VOCABULARY: tuple[str, ...] = _build_vocabulary()


@lru_cache(maxsize=4096)
def term_factors(term: str) -> tuple[int, ...]:
    """Regressor column indices whose product is the term (``()`` for ``"1"``).

    Accepts any order and spacing (``"beta * alpha"``, ``"alpha*alpha"``).

    Raises:
        InputError: a factor is not a regressor name or the degree exceeds 2.
    """
    s = term.replace(" ", "")
    if s in ("1", ""):
        if s == "":
            raise InputError("empty model term (expected '1' or a monomial such as 'alpha*beta')")
        return ()
    idx: list[int] = []
    for part in s.split("*"):
        power = 1
        if part.endswith("^2"):
            part, power = part[:-2], 2
        if part not in REGRESSORS:
            raise InputError(f"model term '{term}': unknown variable '{part}' "
                             f"(expected one of {', '.join(REGRESSORS)})")
        idx += [REGRESSORS.index(part)] * power
    if len(idx) > 2:
        raise InputError(f"model term '{term}' has degree {len(idx)} (at most 2 allowed)")
    return tuple(sorted(idx))


def canonical_term(term: str) -> str:
    """The canonical spelling of a term (e.g. ``"beta*alpha"`` -> ``"alpha*beta"``).

    Raises:
        InputError: as :func:`term_factors`.
    """
    f = term_factors(term)
    if not f:
        return "1"
    if len(f) == 1:
        return REGRESSORS[f[0]]
    if f[0] == f[1]:
        return f"{REGRESSORS[f[0]]}^2"
    return f"{REGRESSORS[f[0]]}*{REGRESSORS[f[1]]}"


def term_matrix(X: np.ndarray, terms) -> np.ndarray:
    """Evaluate terms on regressors.

    Args:
        X: regressors, shape (T, 10), columns :data:`REGRESSORS`.
        terms: sequence of K term strings.

    Returns:
        array of shape (T, K).
    """
    X = np.asarray(X, float)
    out = np.empty((X.shape[0], len(terms)))
    for k, term in enumerate(terms):
        f = term_factors(term)
        if not f:
            out[:, k] = 1.0
        elif len(f) == 1:
            out[:, k] = X[:, f[0]]
        else:
            out[:, k] = X[:, f[0]] * X[:, f[1]]
    return out


def terms_using(variable: str, terms) -> list[str]:
    """The terms among ``terms`` that contain regressor ``variable``."""
    i = REGRESSORS.index(variable)
    return [t for t in terms if i in term_factors(t)]


def split_cause(cause: str) -> tuple[str, str]:
    """Split ``"Cm:alpha^2"`` into ``("Cm", "alpha^2")`` (canonical term).

    Raises:
        InputError: not of the form ``<coef>:<term>`` with a known coefficient and term.
    """
    coef, sep, term = cause.partition(":")
    if not sep or coef not in COEFFICIENTS:
        raise InputError(f"'{cause}' is not an aero-term cause '<coef>:<term>' with coef in {COEFFICIENTS}")
    return coef, canonical_term(term)
