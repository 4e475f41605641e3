"""Scores of the pipeline's output against a harness truth file (shared by the tests and the benchmarks).

The error metric is the project's (``docs/conventions.md``): ``100 * RMS(est - truth) / RMS(truth)``.
"""

from __future__ import annotations

import numpy as np

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.pipeline import error_pct

from .truth import Truth

__all__ = ["score_table", "coefficient_errors"]


def coefficient_errors(estimate: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    """``error_pct`` per coefficient of ``estimate`` against ``truth``, both (N, 6) in COEFFICIENTS order, %."""
    return {c: error_pct(estimate[:, i], truth[:, i]) for i, c in enumerate(COEFFICIENTS)}


def score_table(table, truth: Truth, sign: float = 1.0, mask: np.ndarray | None = None) -> dict[str, float]:
    """Errors of a :class:`~gcs_sysid.aero.table.CoefficientTable` against ``truth``.

    Args:
        table: the pipeline's coefficients and regressors.
        truth: the flight's truth (interpolated to ``table.t``).
        sign: multiplies the truth (a test flips it to show that the scores can fail).
        mask: optional (T,) rows to score (e.g. the held-out segment); always limited to the
            table's valid rows where the truth exists.

    Returns:
        ``CX`` ... ``Cn``: error in %; ``alpha_deg``, ``beta_deg``: RMS errors of the air angles, deg.
    """
    X, Y = truth.at(table.t)
    m = table.valid & np.isfinite(Y).all(1) & np.isfinite(table.Y).all(1)
    if mask is not None:
        m &= np.asarray(mask, bool)
    out = coefficient_errors(table.Y[m], sign * Y[m])
    out["alpha_deg"] = float(np.degrees(np.sqrt(np.mean((table.X[m, 0] - sign * X[m, 0]) ** 2))))
    out["beta_deg"] = float(np.degrees(np.sqrt(np.mean((table.X[m, 1] - sign * X[m, 1]) ** 2))))
    return out
