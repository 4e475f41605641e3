"""The coefficient table: regressors and measured aerodynamic coefficients over time."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["COEFFICIENTS", "FORCE_COEFFICIENTS", "MOMENT_COEFFICIENTS", "REGRESSORS", "CoefficientTable"]

COEFFICIENTS = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")
FORCE_COEFFICIENTS = ("CX", "CY", "CZ")
MOMENT_COEFFICIENTS = ("Cl", "Cm", "Cn")
#: Regressor order used everywhere (columns of ``CoefficientTable.X``).
REGRESSORS = ("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a", "delta_r", "delta_t", "V")


@dataclass
class CoefficientTable:
    """Regressors and measured body-axis coefficients.

    Attributes:
        t: vehicle time, s, shape (T,).
        X: regressors, shape (T, 10), columns :data:`REGRESSORS` (rad, -, -, -, -,
            rad, rad, rad, 0..1, m/s).
        Y: measured coefficients, shape (T, 6), columns :data:`COEFFICIENTS`.
        valid: (T,) bool, rows usable for learning: airborne, regressors and force coefficients finite.
            The moment columns of Y may still be NaN there (rate derivatives not formed, e.g. 4 Hz data).
        qbar: dynamic pressure, Pa, shape (T,).
        notes: one-line remarks (e.g. "CX includes thrust: airframe has no thrust model").
        x_offset_cov: ``(10, 10)`` covariance of the regressors' error common to all rows of the flight
            (an offset, one draw per flight; units of the regressors squared, e.g. rad^2 for alpha), or
            None when the estimator gave none (``FlightStates.offsets``; the GP's band at exact
            conditions, ``docs/gp.md``).
        x_var: ``(T, 10)`` per-row variance of the regressors' errors that the estimator states, beyond
            the flight-common offset (units of the regressors squared; NaN where it states none), or None.
            The air angles' smoothed 1-sigma less ``bias_sigma`` (``coefficients.STATED_INPUT_NOISE``); the
            GP's band at a flight's own regressors takes the larger of it and its learned input noise
            (``docs/gp.md``, "Noisy inputs: the estimator's stated variance").
        x_scale_var: ``(10,)`` variance of the regressors' relative scale error common to the flight
            (dimensionless; 0 where none is stated), or None: the aided air angles' ``AxisFit.scale_sigma``
            squared. The GP's band at exact conditions carries it (``docs/gp.md``, "The band at exact
            conditions").
        x_map_cov: ``(10, 10, 10)`` second moment of the aided angles' flight-common linear error (``[j]``:
            regressor ``j``'s error along the regressors, ``coefficients.stated_map_covariance``), or None.
            Where stated for an angle, the GP's band at exact conditions carries it in place of that
            angle's ``x_scale_var`` (``docs/gp.md``, "The band at exact conditions").
        alpha_dot_hat: ``(T,)`` ``alpha_dot c / (2 V)`` (dimensionless; ``alpha_dot`` the estimator's state from the
            force equations, ``gcs_sysid.estimation.alpharate``), or None. Not a column of ``X``: the pipeline's GP
            takes it as a mean-only input of Cm (``docs/gp.md``, "Mean-only inputs").
        corrected_targets: the coefficients (names of :data:`COEFFICIENTS`) whose column of ``Y`` is no longer the
            measured coefficient but a corrected target (e.g. ``("Cl",)``: Cl less the rolling gust's moment,
            :func:`gcs_sysid.diagnose.air_roll.air_roll_cl_table`); () for a table as measured. A residual of such a
            coefficient is not comparable with one of a table where it was not corrected.
    """

    t: np.ndarray
    X: np.ndarray
    Y: np.ndarray
    valid: np.ndarray
    qbar: np.ndarray
    notes: list[str] = field(default_factory=list)
    x_offset_cov: np.ndarray | None = None
    x_var: np.ndarray | None = None
    x_scale_var: np.ndarray | None = None
    x_map_cov: np.ndarray | None = None
    alpha_dot_hat: np.ndarray | None = None
    corrected_targets: tuple[str, ...] = ()

    def x(self, name: str) -> np.ndarray:
        """Regressor column by name, shape (T,)."""
        return self.X[:, REGRESSORS.index(name)]

    def y(self, name: str) -> np.ndarray:
        """Coefficient column by name, shape (T,)."""
        return self.Y[:, COEFFICIENTS.index(name)]

    def select(self, mask: np.ndarray) -> "CoefficientTable":
        """Rows where ``mask`` (T,) is True."""
        return CoefficientTable(self.t[mask], self.X[mask], self.Y[mask], self.valid[mask], self.qbar[mask],
                                list(self.notes), self.x_offset_cov, None if self.x_var is None else self.x_var[mask],
                                self.x_scale_var, self.x_map_cov,
                                None if self.alpha_dot_hat is None else self.alpha_dot_hat[mask],
                                tuple(self.corrected_targets))
