"""Scores of a measured coefficient table against a harness truth file (shared by tests and benchmarks)."""

from __future__ import annotations

import numpy as np

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.pipeline import error_pct


def score_table(table, truth, sign: float = 1.0) -> dict[str, float]:
    """Errors of ``table`` against ``truth``: ``error_pct`` per coefficient (%) and alpha/beta RMS
    errors (deg), on the valid rows of the table where the truth exists. ``sign`` multiplies the
    truth (a test flips it to show the scores can fail)."""
    X, Y = truth.at(table.t)
    m = table.valid & np.isfinite(Y).all(1) & np.isfinite(table.Y).all(1)
    out = {c: error_pct(table.Y[m, i], sign * Y[m, i]) for i, c in enumerate(COEFFICIENTS)}
    out["alpha_deg"] = float(np.degrees(np.sqrt(np.mean((table.X[m, 0] - sign * X[m, 0]) ** 2))))
    out["beta_deg"] = float(np.degrees(np.sqrt(np.mean((table.X[m, 1] - sign * X[m, 1]) ** 2))))
    return out
