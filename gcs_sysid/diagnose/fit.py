"""``gcs-sysid fit``: equation-error model of each coefficient by stepwise regression.

For each of CX CY CZ Cl Cm Cn, stepwise regression (Morelli and Klein sec. 5.4)
picks terms from the vocabulary (``1`` plus monomials of degree 1 or 2 in the
regressors), the final least-squares fit gives each term's value with a
standard error corrected for coloured residuals (sec. 5.3) and the fit
statistics R^2, F0 and PSE. The result is a model file ``simulate`` reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..aero.table import COEFFICIENTS, CoefficientTable
from ..errors import DataError
from ..sim.model_file import AeroModel
from .regression import stepwise
from .terms import VOCABULARY, canonical_term

__all__ = ["FitReport", "fit_model", "DEFAULT_POOL"]

#: Default candidate pool: every term but the intercept (which is forced in).
DEFAULT_POOL: tuple[str, ...] = VOCABULARY[1:]


@dataclass
class FitReport:
    """Per-coefficient fit results.

    Attributes:
        coefficients: coef -> {"terms": {term: {"value", "std_error", "std_error_white"}},
            "r2", "f0", "pse", "s2", "n", "condition", "history"}.
        n_rows: rows used. t_range: (first, last) vehicle time, s.
        notes: remarks (e.g. a coefficient left with the intercept only).
    """

    coefficients: dict[str, dict] = field(default_factory=dict)
    n_rows: int = 0
    t_range: tuple[float, float] = (float("nan"), float("nan"))
    notes: list[str] = field(default_factory=list)

    def to_json(self) -> dict:
        """JSON-able document."""
        return {"coefficients": self.coefficients, "n_rows": self.n_rows, "t_range_s": list(self.t_range),
                "notes": self.notes}

    def header(self) -> str:
        """Comment lines for the model file: the fit statistics and standard errors."""
        lines = [f"Fitted by gcs-sysid fit (stepwise equation-error least squares, Morelli & Klein ch. 5) "
                 f"on {self.n_rows} samples, t = {self.t_range[0]:.1f}..{self.t_range[1]:.1f} s."]
        for c, d in self.coefficients.items():
            lines.append(f"{c}: R^2 = {d['r2']:.4f}, F0 = {d['f0']:.1f}, PSE = {d['pse']:.3g}; "
                         + ", ".join(f"{t} = {v['value']:.4g} +- {v['std_error']:.2g}" for t, v in d["terms"].items()))
        return "\n".join(lines)


def fit_model(table: CoefficientTable, terms=None, mask: np.ndarray | None = None, *, forced=("1",),
              f_in: float = 4.0, f_out: float = 4.0, max_terms: int = 12, colored: bool = True,
              name: str = "fitted", min_rows: int = 100) -> tuple[AeroModel, FitReport]:
    """Fit an aero model to a coefficient table by stepwise regression per coefficient.

    Args:
        table: measured coefficients and regressors (T rows).
        terms: candidate pool (term strings), or a mapping coef -> pool; default
            :data:`DEFAULT_POOL`.
        mask: (T,) rows to use (default ``table.valid``); combined with finiteness.
        forced: terms always in the model.
        f_in, f_out: partial-F thresholds to enter / stay.
        max_terms: largest number of terms per coefficient.
        colored: coloured-residual standard errors (and partial F).
        name: model name.
        min_rows: fewest usable rows.

    Returns:
        (model, report): an :class:`~gcs_sysid.sim.model_file.AeroModel` and a :class:`FitReport`.

    Raises:
        DataError: fewer than ``min_rows`` usable rows.
    """
    m = np.asarray(table.valid if mask is None else mask, bool)
    m &= np.all(np.isfinite(table.X), axis=1) & np.all(np.isfinite(table.Y), axis=1)
    if m.sum() < min_rows:
        raise DataError(f"fit: {int(m.sum())} usable rows, need at least {min_rows}")
    X, Y = table.X[m], table.Y[m]
    report = FitReport(n_rows=int(m.sum()), t_range=(float(table.t[m][0]), float(table.t[m][-1])))
    out: dict[str, dict[str, float]] = {}
    for j, coef in enumerate(COEFFICIENTS):
        pool = terms.get(coef, DEFAULT_POOL) if isinstance(terms, dict) else (terms or DEFAULT_POOL)
        pool = [canonical_term(t) for t in pool]
        res = stepwise(X, Y[:, j], pool, forced=forced, f_in=f_in, f_out=f_out, colored=colored,
                       max_terms=max_terms)
        fit = res.fit
        out[coef] = {t: float(v) for t, v in zip(fit.terms, fit.theta)}
        d = fit.as_dict()
        d["history"] = res.history
        report.coefficients[coef] = d
        if len(fit.terms) <= len(forced):
            report.notes.append(f"{coef}: no term beyond {', '.join(forced)} passed the entry test "
                                "(not excited, or no dependence)")
    model = AeroModel({c: out[c] for c in COEFFICIENTS}, name,
                      f"stepwise regression on {report.n_rows} samples", "")
    return model, report
