"""The aero model file: body-axis coefficients as sums of derivative x regressor-term products.

A model gives each coefficient of :data:`gcs_sysid.aero.table.COEFFICIENTS`
(CX CY CZ Cl Cm Cn) as a linear combination of *terms*::

    C(x) = sum over terms  value[term] * term(x)

where a term is ``"1"`` (the constant, e.g. Cm0) or a monomial of degree 1 or 2
in the regressors of :data:`gcs_sysid.aero.table.REGRESSORS` (alpha, beta,
p_hat, q_hat, r_hat, delta_e, delta_a, delta_r, delta_t, V), written with ``*``
and ``^2`` in that order of variables: ``"alpha"``, ``"alpha^2"``,
``"alpha*beta"``, ``"q_hat"``, ``"delta_e"``. The value of term ``"alpha"`` in
``Cm`` is the stability derivative Cm_alpha (per rad). The file format is TOML,
documented in ``docs/model-file.md``::

    name = "sim-trainer"
    [Cm]
    "1" = 0.02
    alpha = -0.8
    q_hat = -12.0
    delta_e = -1.0

API (shared by ``sim`` and ``diagnose``; ``diagnose fit`` writes this format):

- :func:`parse_term` / :func:`canonical_term`: term text <-> factor indices.
- :func:`load_model` / :func:`save_model`: file <-> :class:`AeroModel`.
- :class:`AeroModel`: ``terms[coef][term] -> value``; ``evaluate(X)`` on arrays
  ``(T, 10) -> (T, 6)``; ``with_terms(...)`` returns a changed copy;
  ``weights()`` the dense ``(66, 6)`` matrix over :data:`VOCABULARY`.
- :func:`features` / :func:`evaluate_weights`: the JAX-traceable evaluation used
  by the dynamics (``features(x) @ W`` with ``x`` of shape (..., 10)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from ..errors import InputError
from ..tomlfile import read_toml

__all__ = [
    "VOCABULARY",
    "AeroModel",
    "parse_term",
    "canonical_term",
    "load_model",
    "save_model",
    "model_from_dict",
    "features",
    "evaluate_weights",
]


def _vocabulary() -> tuple[tuple[int, ...], ...]:
    n = len(REGRESSORS)
    out: list[tuple[int, ...]] = [()] + [(i,) for i in range(n)]
    out += [(i, j) for i in range(n) for j in range(i, n)]
    return tuple(out)


_FACTORS = _vocabulary()


def canonical_term(factors: tuple[int, ...] | list[int]) -> str:
    """Canonical spelling of a term from its regressor indices (``()`` -> ``"1"``).

    Args:
        factors: 0, 1 or 2 indices into REGRESSORS, any order.

    Raises:
        InputError: degree above 2 or an index out of range.
    """
    f = tuple(sorted(int(i) for i in factors))
    if len(f) > 2 or any(not 0 <= i < len(REGRESSORS) for i in f):
        raise InputError(f"term factors {factors!r} must be at most 2 indices in 0..{len(REGRESSORS) - 1}")
    if not f:
        return "1"
    if len(f) == 1:
        return REGRESSORS[f[0]]
    return f"{REGRESSORS[f[0]]}^2" if f[0] == f[1] else f"{REGRESSORS[f[0]]}*{REGRESSORS[f[1]]}"


#: Every admissible term in canonical spelling: "1", 10 linear and 55 quadratic (66).
VOCABULARY: tuple[str, ...] = tuple(canonical_term(f) for f in _FACTORS)
_INDEX = {t: k for k, t in enumerate(VOCABULARY)}


def parse_term(text: str, source: str = "<model>", coefficient: str | None = None) -> tuple[int, ...]:
    """Regressor indices of a term written in canonical form.

    Args:
        text: e.g. ``"1"``, ``"alpha"``, ``"alpha^2"``, ``"alpha*beta"``.
        source: file name for error messages.
        coefficient: coefficient the term belongs to, for error messages.

    Returns:
        sorted tuple of 0, 1 or 2 indices into REGRESSORS.

    Raises:
        InputError: unknown variable, variables out of the REGRESSORS order, a
            repeated factor not written as ``^2``, or degree above 2; the message
            names the file, coefficient and term and gives the canonical form
            where there is one.
    """
    where = f"{source}: [{coefficient}] term '{text}'" if coefficient else f"{source}: term '{text}'"
    s = text.strip()
    if s == "1":
        return ()
    if not s:
        raise InputError(f"{where} is empty (expected '1' or a monomial such as 'alpha*beta')")
    idx: list[int] = []
    for part in s.split("*"):
        name, power = part.strip(), 1
        if name.endswith("^2"):
            name, power = name[:-2], 2
        elif "^" in name:
            raise InputError(f"{where}: only '^2' powers are allowed (degree at most 2)")
        if name not in REGRESSORS:
            raise InputError(f"{where}: unknown variable '{name}' (expected one of {', '.join(REGRESSORS)})")
        idx += [REGRESSORS.index(name)] * power
    if len(idx) > 2:
        raise InputError(f"{where} has degree {len(idx)}; at most 2 is allowed")
    canon = canonical_term(idx)
    if s.replace(" ", "") != canon:
        raise InputError(f"{where} is not in canonical form; write '{canon}' (variables in the order "
                         f"{', '.join(REGRESSORS)}, squares as '^2')")
    return tuple(sorted(idx))


@dataclass(frozen=True)
class AeroModel:
    """A stability-and-control-derivative model of CX CY CZ Cl Cm Cn.

    Attributes:
        terms: coefficient -> {canonical term -> value}; every coefficient of
            COEFFICIENTS is present (possibly empty). Values are per rad for
            angle and deflection regressors, dimensionless for p_hat q_hat r_hat
            and delta_t, per (m/s) for V.
        name: model name.
        notes: free-text provenance.
        source: file it was read from ("" if built in code).
    """

    terms: Mapping[str, Mapping[str, float]]
    name: str = ""
    notes: str = ""
    source: str = ""

    def value(self, coefficient: str, term: str) -> float:
        """Value of one term (0.0 when absent)."""
        return float(self.terms.get(coefficient, {}).get(term, 0.0))

    def weights(self) -> np.ndarray:
        """Dense weights of shape (66, 6): rows VOCABULARY, columns COEFFICIENTS."""
        W = np.zeros((len(VOCABULARY), len(COEFFICIENTS)))
        for j, c in enumerate(COEFFICIENTS):
            for term, v in self.terms.get(c, {}).items():
                W[_INDEX[term], j] = v
        return W

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """Coefficients from regressors.

        Args:
            X: regressors, shape (T, 10) (or (10,)), columns REGRESSORS.

        Returns:
            coefficients, shape (T, 6) (or (6,)), columns COEFFICIENTS.
        """
        return evaluate_weights(np.asarray(X, float), self.weights())

    def with_terms(self, updates: Mapping[str, Mapping[str, float]], add: bool = False) -> "AeroModel":
        """A copy with terms set (or, with ``add=True``, added to the present values).

        Args:
            updates: coefficient -> {term -> value}; terms in canonical form.

        Raises:
            InputError: unknown coefficient or term.
        """
        new = {c: dict(self.terms.get(c, {})) for c in COEFFICIENTS}
        for c, tv in updates.items():
            if c not in COEFFICIENTS:
                raise InputError(f"unknown coefficient '{c}' (expected one of {', '.join(COEFFICIENTS)})")
            for term, v in tv.items():
                parse_term(term, self.source or "<model>", c)
                new[c][term] = (new[c].get(term, 0.0) if add else 0.0) + float(v)
        return AeroModel(new, self.name, self.notes, self.source)

    def to_dict(self) -> dict[str, Any]:
        """The TOML document (inverse of :func:`model_from_dict`)."""
        d: dict[str, Any] = {"name": self.name or "model"}
        if self.notes:
            d["notes"] = self.notes
        for c in COEFFICIENTS:
            tv = self.terms.get(c, {})
            d[c] = {t: float(tv[t]) for t in VOCABULARY if t in tv}
        return d


def features(x):
    """All 66 VOCABULARY terms of regressors ``x`` of shape (..., 10) -> (..., 66).

    Works on numpy and JAX arrays (traceable: fixed shapes, no Python branching
    on values), so the dynamics can evaluate a model with ``features(x) @ W``.
    """
    xp = np
    if type(x).__module__.startswith("jax"):
        import jax.numpy as xp  # noqa: N813
    ones = xp.ones(x.shape[:-1] + (1,), dtype=x.dtype)
    i, j = np.triu_indices(len(REGRESSORS))
    quad = x[..., i] * x[..., j]
    return xp.concatenate([ones, x, quad], axis=-1)


def evaluate_weights(X, W):
    """Coefficients ``features(X) @ W``: X (..., 10), W (66, 6) -> (..., 6); numpy or JAX."""
    return features(X) @ W


# ----------------------------------------------------------------------------- files


def model_from_dict(doc: Mapping[str, Any], source: str = "<model>") -> AeroModel:
    """Validate a parsed model document.

    Raises:
        InputError: unknown top-level key or coefficient, a term not in canonical
            form, or a value that is not a finite number (names file and term).
    """
    known = {"name", "notes", "format_version", *COEFFICIENTS}
    for k in doc:
        if k not in known:
            raise InputError(f"{source}: unknown table or field '{k}' (expected coefficients "
                             f"{', '.join(COEFFICIENTS)} and optional name, notes)")
    name = doc.get("name", "")
    notes = doc.get("notes", "")
    if not isinstance(name, str) or not isinstance(notes, str):
        raise InputError(f"{source}: 'name' and 'notes' must be strings")
    terms: dict[str, dict[str, float]] = {}
    for c in COEFFICIENTS:
        tv = doc.get(c, {})
        if not isinstance(tv, Mapping):
            raise InputError(f"{source}: [{c}] must be a table of term = value")
        terms[c] = {}
        for term, v in tv.items():
            parse_term(term, source, c)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f"{source}: [{c}] term '{term}' must be a finite number, got {v!r}")
            terms[c][term] = float(v)
    return AeroModel(terms, name, notes, source)


def load_model(path: str | Path) -> AeroModel:
    """Read and validate a model file.

    Raises:
        InputError: missing file, not TOML, or invalid content (names file and term).
    """
    return model_from_dict(read_toml(path, "model file"), str(path))


def save_model(model: AeroModel, path: str | Path, header: str = "") -> None:
    """Write a model file (TOML via tomli_w), optionally after a ``#`` comment header."""
    import tomli_w

    text = tomli_w.dumps(model.to_dict())
    if header:
        text = "".join(f"# {line}\n" for line in header.splitlines()) + text
    Path(path).write_text(text, encoding="utf-8")
