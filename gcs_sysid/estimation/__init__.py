"""Estimation layer: align streams on a grid, smooth states (EKF + RTS), derive air data.

Entry point: :func:`estimate_states` (``Flight`` + ``Airframe`` -> ``FlightStates``).
Details and the choices made are in ``docs/estimation.md``.

:func:`estimate_states` is imported on first use (PEP 562 module ``__getattr__``): it pulls in
filterpy and SciPy (about half a second), which the data types here do not need, so that the
replay can import them while its worker process is already decoding the log.
"""

from .states import STATE_KEYS, FlightStates

__all__ = ["estimate_states", "FlightStates", "STATE_KEYS"]


def __getattr__(name: str):
    if name == "estimate_states":
        from .estimate import estimate_states

        return estimate_states
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
