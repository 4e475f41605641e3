"""Input checks and the input/output standardisation stored inside the model."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DataError, InputError

__all__ = ["Standardiser", "check_inputs", "check_training"]

#: A column whose standard deviation is below this fraction of ``1 + |mean|`` is treated as constant.
_CONSTANT_REL = 1e-9


def check_inputs(X, n_inputs: int | None = None, what: str = "X") -> np.ndarray:
    """Return ``X`` as a float64 array of shape ``(N, D)``.

    Raises:
        InputError: ``X`` is not two-dimensional, or has ``D != n_inputs`` columns.
    """
    try:
        X = np.asarray(X, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"gp: {what} must be a numeric array of shape (N, D): {exc}") from None
    if X.ndim != 2:
        raise InputError(f"gp: {what} must have shape (N, D), got shape {X.shape}")
    if n_inputs is not None and X.shape[1] != n_inputs:
        raise InputError(f"gp: {what} must have {n_inputs} columns (the model's regressors), got {X.shape[1]}")
    return X


def check_training(X, Y, n_inputs: int | None = None, n_outputs: int | None = None,
                   min_rows: int = 1, partial: bool = False, output_names=None
                   ) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Validate training data and drop rows with a non-finite value.

    Args:
        X: ``(N, D)`` regressors. Y: ``(N, P)`` coefficients.
        n_inputs, n_outputs: expected ``D`` and ``P`` (None: any).
        min_rows: fewest finite rows accepted.
        partial: keep rows that miss some outputs (NaN in ``Y``; heterotopic data): only rows with a
            non-finite regressor or with no finite output are dropped, and the missing entries are
            returned as NaN (infinite values become NaN), with a note per output that misses some.
        output_names: names of the ``P`` outputs for that note (default ``output 0``, ...).

    Returns:
        ``(X, Y, notes)`` float64 finite rows and one-line notes (rows dropped).

    Raises:
        InputError: wrong shapes or row counts that differ.
        DataError: fewer than ``min_rows`` finite rows.
    """
    X = check_inputs(X, n_inputs, "X")
    Y = check_inputs(Y, None, "Y")
    if n_outputs is not None and Y.shape[1] != n_outputs:
        raise InputError(f"gp: Y must have {n_outputs} columns (the model's outputs), got {Y.shape[1]}")
    if X.shape[0] != Y.shape[0]:
        raise InputError(f"gp: X and Y must have the same number of rows, got {X.shape[0]} and {Y.shape[0]}")
    ok = np.isfinite(X).all(1) & (np.isfinite(Y).any(1) if partial else np.isfinite(Y).all(1))
    notes = []
    if not ok.all():
        notes.append(f"gp: dropped {int((~ok).sum())} of {len(ok)} rows with NaN or infinite values")
        X, Y = X[ok], Y[ok]
    if partial and not np.isfinite(Y).all():
        Y = np.where(np.isfinite(Y), Y, np.nan)
        miss = (~np.isfinite(Y)).sum(0)
        notes.append(f"gp: {int((~np.isfinite(Y)).any(1).sum())} of {len(Y)} rows miss some outputs (" + ", ".join(
            f"{output_names[p] if output_names is not None else f'output {p}'}: {int(m)}" for p, m in enumerate(miss)
            if m) + "); each output is conditioned on the rows "
            "that carry it, the others inform it through the coregionalisation")
    if X.shape[0] < min_rows:
        raise DataError(f"gp: need at least {min_rows} finite rows of (X, Y) to fit, got {X.shape[0]}")
    return X, Y, notes


@dataclass(frozen=True)
class Standardiser:
    """Affine scaling of inputs and outputs to zero mean and unit variance.

    Inputs that do not vary in the training data (a surface never moved) are
    *inactive*: their standardised value is fixed at 0, so neither the kernels nor
    the linear mean depend on them and their length-scales are not learned.

    Attributes:
        x_mean, x_std: ``(D,)``. active: ``(D,)`` bool. y_mean, y_std: ``(P,)``.
    """

    x_mean: np.ndarray
    x_std: np.ndarray
    active: np.ndarray
    y_mean: np.ndarray
    y_std: np.ndarray

    @classmethod
    def fit(cls, X: np.ndarray, Y: np.ndarray, names: tuple[str, ...] | None = None
            ) -> tuple["Standardiser", list[str]]:
        """Scaler from training data ``X (N, D)``, ``Y (N, P)``; returns it and notes on constant columns."""
        x_mean, x_std = X.mean(0), X.std(0)
        active = x_std > _CONSTANT_REL * (1.0 + np.abs(x_mean))
        if np.all(np.isfinite(Y)):
            y_mean, y_std = Y.mean(0), Y.std(0)
        else:                                      # missing outputs (NaN): over the rows that carry each
            y_mean, y_std = np.nanmean(Y, 0), np.nanstd(Y, 0)
        notes = []
        for d in np.flatnonzero(~active):
            name = names[d] if names is not None and d < len(names) else f"input {d}"
            notes.append(f"gp: {name} is constant in the data ({x_mean[d]:.4g}); the model ignores it")
        y_const = y_std <= _CONSTANT_REL * (1.0 + np.abs(y_mean))
        for p in np.flatnonzero(y_const):
            notes.append(f"gp: output {p} is constant in the data ({y_mean[p]:.4g})")
        return cls(x_mean, np.where(active, x_std, 1.0), active, y_mean, np.where(y_const, 1.0, y_std)), notes

    def x(self, X: np.ndarray) -> np.ndarray:
        """Standardised inputs ``(N, D)``; inactive columns are 0."""
        return np.where(self.active, (X - self.x_mean) / self.x_std, 0.0)

    def y(self, Y: np.ndarray) -> np.ndarray:
        """Standardised outputs ``(N, P)``."""
        return (Y - self.y_mean) / self.y_std

    def y_back(self, mean: np.ndarray, var: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance ``(N, P)`` back in the data's units."""
        return mean * self.y_std + self.y_mean, var * self.y_std**2

    def to_arrays(self, prefix: str = "scaler_") -> dict[str, np.ndarray]:
        """Arrays for saving (npz)."""
        return {prefix + k: np.asarray(getattr(self, k)) for k in ("x_mean", "x_std", "active", "y_mean", "y_std")}

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "scaler_") -> "Standardiser":
        """Inverse of :meth:`to_arrays`."""
        return cls(*(np.asarray(arrays[prefix + k]) for k in ("x_mean", "x_std", "active", "y_mean", "y_std")))
