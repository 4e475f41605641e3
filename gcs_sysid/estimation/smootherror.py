"""The rate smoother's angular-acceleration error, split into what the gyro noise makes and what the model assumes.

The steady-state RTS smoother of :mod:`.rates` states the angular acceleration's error variance
``s2 Ps[1, 1]`` (``RateEstimate.accel_sigma``, before the coefficients' and the Wiener correction's
parts). For a time-invariant smoother that variance is the sum of two parts (Wiener's smoothing error
in the frequency domain; Bendat and Piersol 2010, sec. 6.1; Kailath, Sayed and Hassibi 2000, ch. 7):

    s2 Ps[1, 1] = s2 int |D|^2 dnu  +  int |D - j 2 pi f|^2 S_model(f) df
                 (noise-driven)        (distortion of the signal under the model's prior)

with ``D`` the smoother's transfer function from the gyro to the angular acceleration (``S_ay / (S_yy +
1)`` for unit noise), ``s2`` the gyro's white-noise variance per sample (maximum likelihood on the flight)
and ``S_model`` the white-snap model's rate spectrum at the chosen bandwidth. The first part depends only
on the smoother and the measured gyro noise: it is the flight's own, and it is what the smoothed
residuals of a later fit can show. The second is the model's *prior* for the signal the smoother cuts
off: the angular acceleration above the bandwidth. On the flights measured (JSBSim, 9 aircraft,
docs/benchmarks.md "Thirteenth session, i8-sigma") the prior is 0.15-2.6x the true cut-off part (RMS), and
4-94 % of the true error's variance lies above 3 Hz, where the rate signal is a few % of the gyro noise's
power or less: no gyro-based statistic reads it.

:func:`accel_error_split` returns both parts for a smoother (bandwidth, gyro noise), so a caller can tell
the stated error the residuals can show from the part they cannot. :func:`cutoff_gain` is the distortion's
weight ``|D - j 2 pi f|^2`` alone, for a caller with a better prior than white snap for some part of the signal
(the rolling gust's roll acceleration, :func:`gcs_sysid.aero.rollgust.gust_cutoff_variance`).

References:
    J. S. Bendat and A. G. Piersol, *Random Data*, 4th ed., Wiley 2010, sec. 6.1 (the Wiener filter
    and its error).
    T. Kailath, A. H. Sayed and B. Hassibi, *Linear Estimation*, Prentice Hall 2000, ch. 7 (smoothing
    error in the frequency domain).
"""

from __future__ import annotations

import numpy as np

__all__ = ["N_FREQ", "model_response", "accel_error_split", "cutoff_gain"]

#: Frequencies of the midpoint rule over (0, pi) rad/sample (the parts sum to ``Ps[1, 1]`` within 1e-5).
N_FREQ = 4096


def model_response(F: np.ndarray, Q: np.ndarray, H: np.ndarray, omega: np.ndarray, state: int = 1) -> np.ndarray:
    """The steady-state Wiener (RTS) smoother's transfer function from the measurement to ``state``.

    Args:
        F, Q, H: (n, n), (n, n), (1, n) the discrete model for unit white measurement noise
            (:func:`gcs_sysid.estimation.rates._nominal_model`).
        omega: (K,) normalised angular frequencies, rad/sample, in (0, pi].
        state: the state estimated (1: the rate's derivative).

    Returns:
        (K,) complex ``S_xy / (S_yy + 1)``, the state per unit of measurement (1/s for the derivative
        of a rate measured in rad/s).

    Raises:
        numpy.linalg.LinAlgError: ``omega`` hits an eigenvalue of ``F`` on the unit circle (``omega = 0``
            for the white-snap model).
    """
    n = len(F)
    A = np.exp(1j * np.asarray(omega, float))[:, None, None] * np.eye(n)[None] - F[None]
    G = np.linalg.inv(A)
    S = G @ Q @ np.conj(np.transpose(G, (0, 2, 1)))
    h = H[0]
    Syy = np.real(np.einsum("i,kij,j->k", h, S, h))
    Sxy = np.einsum("kj,j->k", S[:, state, :], h)
    return Sxy / (Syy + 1.0)


def accel_error_split(dt: float, bandwidth_hz: float, noise_std: float) -> tuple[float, float]:
    """The rate smoother's angular-acceleration error variance as (noise-driven, prior distortion).

    Args:
        dt: grid step, s.
        bandwidth_hz: the smoother's bandwidth on the axis (``RateEstimate.bandwidth_hz``), Hz.
        noise_std: the gyro's white noise on the axis (``RateEstimate.noise_std``), rad/s.

    Returns:
        ``(noise_var, distortion_var)`` in (rad/s^2)^2; their sum is the steady-state ``s2 Ps[1, 1]``.

    Raises:
        ValueError: ``dt``, ``bandwidth_hz`` or ``noise_std`` not positive and finite.

    Source: module docstring.
    """
    from .kalman import steady_state
    from .rates import _nominal_model

    for name, v in (("dt", dt), ("bandwidth_hz", bandwidth_hz), ("noise_std", noise_std)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be positive and finite, got {v}")
    F, Q, H = _nominal_model(dt, bandwidth_hz)
    omega = np.pi * (np.arange(N_FREQ) + 0.5) / N_FREQ
    s2 = float(noise_std) ** 2
    total = s2 * float(steady_state(F, Q, H, np.eye(1)).Ps[1, 1])
    noise = s2 * float(np.mean(np.abs(model_response(F, Q, H, omega)) ** 2))
    return noise, max(total - noise, 0.0)


def cutoff_gain(dt: float, bandwidth_hz: float, omega: np.ndarray) -> np.ndarray:
    """``|D(omega) - j omega/dt|^2``: the squared error the rate smoother makes of a rate's derivative, per unit of the
    rate's spectrum (the distortion's weight in the module docstring's split).

    A rate component with spectral density ``S(omega)`` (rad/s)^2 per unit of normalised frequency gives the smoothed
    angular acceleration an error of variance ``mean over (0, pi) of cutoff_gain * S`` (rad/s^2)^2 (the noise-driven
    part not included): about ``omega^2/dt^2 S`` above the smoother's bandwidth, where it follows nothing, and near 0
    below it.

    Args:
        dt: grid step, s.
        bandwidth_hz: the smoother's bandwidth on the axis (``RateEstimate.bandwidth_hz``), Hz.
        omega: (K,) normalised angular frequencies, rad/sample, in (0, pi].

    Returns:
        (K,) the gain, 1/s^2.

    Raises:
        ValueError: ``dt`` or ``bandwidth_hz`` not positive and finite.

    Source: Bendat and Piersol (2010), sec. 6.1 (the error of a linear estimate at each frequency).
    """
    from .rates import _nominal_model

    for name, v in (("dt", dt), ("bandwidth_hz", bandwidth_hz)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be positive and finite, got {v}")
    F, Q, H = _nominal_model(dt, bandwidth_hz)
    omega = np.asarray(omega, float)
    return np.abs(model_response(F, Q, H, omega) - 1j * omega / dt) ** 2
