"""Aero layer: body-axis coefficients CX CY CZ Cl Cm Cn and their regressors.

Entry point: :func:`compute_coefficients` (``FlightStates`` + ``Airframe`` -> ``CoefficientTable``).
"""

from .coefficients import aero_moments, compute_coefficients
from .table import COEFFICIENTS, REGRESSORS, CoefficientTable

__all__ = ["compute_coefficients", "aero_moments", "CoefficientTable", "COEFFICIENTS", "REGRESSORS"]
