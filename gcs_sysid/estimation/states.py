"""Smoothed flight states on a uniform time grid: the estimation layer's output."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["STATE_KEYS", "FlightStates"]

#: Keys of :attr:`FlightStates.data`, all arrays of shape (T,), SI units.
STATE_KEYS = (
    "phi", "theta", "psi",            # rad, Euler angles 3-2-1
    "p", "q", "r",                    # rad/s, body rates (gyro bias removed)
    "p_dot", "q_dot", "r_dot",        # rad/s^2
    "u", "v", "w",                    # m/s, body-axis velocity relative to the ground
    "vn", "ve", "vd",                 # m/s, NED ground velocity
    "ax", "ay", "az",                 # m/s^2, specific force at the CG, body axes (accel bias and lever arm removed)
    "V", "alpha", "beta",             # true airspeed m/s, rad, rad
    "qbar", "rho",                    # Pa, kg/m^3
    "wn", "we", "wd",                 # m/s, wind (air velocity over ground) NED
    "alt",                            # m, altitude AMSL (or relative if that is all there is)
    "delta_e", "delta_a", "delta_r",  # rad
    "delta_t",                        # 0..1
)


@dataclass
class FlightStates:
    """States smoothed by the EKF + RTS pass, sampled on a uniform grid.

    Attributes:
        t: vehicle time, s, shape (T,), uniform spacing ``1/rate_hz``.
        rate_hz: grid rate.
        data: key (see :data:`STATE_KEYS`) -> array (T,). A key absent from the
            dict could not be estimated (listed in ``missing``).
        sigma: key -> 1-sigma uncertainty (T,) where the smoother provides one.
        valid: (T,) bool, True where all inputs needed for coefficients were present
            and the aircraft was flying (V above a floor).
        sources: key -> one-line description of where it came from
            (e.g. ``"V": "VFR_HUD airspeed (EAS) -> TAS with rho from SCALED_PRESSURE"``).
        missing: keys or inputs not available, with why.
        notes: other one-line remarks for the report (e.g. stream rate too low).
        identifiability: quantity -> ``(ok, reason)`` for what later stages may
            trust: keys ``"rate_derivatives"``, ``"moment_coefficients"``,
            ``"force_coefficients"``, ``"alpha"``, ``"beta"``, ``"controls"`` and
            one per coefficient ``"CX"`` ... ``"Cn"`` (e.g. ``(False, "gyro at 4.2 Hz: ...")``).
        offsets: key -> 1-sigma of an error common to the whole flight (one offset, not per-sample
            noise; also inside ``sigma[key]``): ``"alpha"``, rad, the flight-mean vertical wind over the
            airspeed (:attr:`gcs_sysid.estimation.airangles.AxisFit.bias_sigma`). Empty when not estimated.
        angle_fits: ``"alpha"`` / ``"beta"`` -> the :class:`gcs_sysid.estimation.airangles.AxisFit` of the
            specific-force aiding (its force model and gust parameters); empty when the angles were not aided.
            Another flight of the same aircraft can be aided with them (``estimate_states(angle_models=...)``).
        rate_bandwidth_hz: ``(3,)`` the rate smoother's bandwidth on p, q, r, Hz (maximum likelihood;
            :attr:`gcs_sysid.estimation.rates.RateEstimate.bandwidth_hz`): what a later stage needs to say which part of
            an angular acceleration the smoother cut off (:mod:`gcs_sysid.estimation.smootherror`). None where the
            rates were not smoothed (no gyro) or the states were read back from a result file.
    """

    t: np.ndarray
    rate_hz: float
    data: dict[str, np.ndarray]
    sigma: dict[str, np.ndarray] = field(default_factory=dict)
    valid: np.ndarray | None = None
    sources: dict[str, str] = field(default_factory=dict)
    missing: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    identifiability: dict[str, tuple[bool, str]] = field(default_factory=dict)
    offsets: dict[str, float] = field(default_factory=dict)
    angle_fits: dict = field(default_factory=dict)
    rate_bandwidth_hz: np.ndarray | None = None

    def __getitem__(self, key: str) -> np.ndarray:
        return self.data[key]

    def __contains__(self, key: str) -> bool:
        return key in self.data

    def __len__(self) -> int:
        return int(self.t.shape[0])
