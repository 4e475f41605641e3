"""Estimation layer: align streams on a grid, smooth states (EKF + RTS), derive air data.

Entry point: :func:`estimate_states` (``Flight`` + ``Airframe`` -> ``FlightStates``).
Details and the choices made are in ``docs/estimation.md``.
"""

from .estimate import estimate_states
from .states import STATE_KEYS, FlightStates

__all__ = ["estimate_states", "FlightStates", "STATE_KEYS"]
