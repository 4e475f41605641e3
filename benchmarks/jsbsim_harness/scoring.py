"""Scores of the pipeline's output against a harness truth file (shared by the tests and the benchmarks).

The error metric is the project's (``docs/conventions.md``): ``100 * RMS(est - truth) / RMS(truth)``.
"""

from __future__ import annotations

import numpy as np

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.pipeline import error_pct

from .truth import Truth

#: Welch segment of :func:`wiener_floor`, s (0.1 Hz resolution: the side force's Dutch-roll band resolved).
FLOOR_WINDOW_S = 10.24

__all__ = ["score_table", "coefficient_errors", "white_noise_psd", "wiener_floor"]


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


def white_noise_psd(x: np.ndarray, dt: float, f_min_frac: float = 0.6) -> float:
    """One-sided white-noise PSD of a logged channel, read far above the flight dynamics.

    Args:
        x: (n,) raw samples (e.g. the log's ``ay``, m/s^2), no NaN, n >= 64.
        dt: sample step, s.
        f_min_frac: the floor is the median PSD above ``f_min_frac`` x Nyquist (as
            :func:`gcs_sysid.estimation.wiener.residual_wiener` reads it).

    Returns:
        PSD in (units of x)^2 / Hz; a white noise of standard deviation ``s`` sampled at ``1/dt``
        gives ``2 s^2 dt``.
    """
    from scipy.signal import welch

    f, S = welch(np.asarray(x, float), 1.0 / dt, nperseg=min(256, len(x)))
    return float(np.median(S[f > f_min_frac * 0.5 / dt]))


def wiener_floor(signal: np.ndarray, noise_psd: float, dt: float, window_s: float = FLOOR_WINDOW_S) -> float:
    """RMS error of the best stationary linear estimate of ``signal`` from ``signal + white noise``.

    The non-causal Wiener filter's error spectrum is ``S N / (S + N)`` (``S`` the signal's PSD, ``N``
    the noise's), so ``sqrt(sum S N / (S + N) df)`` bounds every time-invariant linear smoother of the
    one noisy channel (a smoother that models the signal's non-stationarity, such as the control-step
    transients of :func:`gcs_sysid.estimation.rates.smooth_specific_force`, can go below it). Used by the
    evaluations only, with the truth's signal: the floor of a measured coefficient that comes from
    one sensor channel (docs/benchmarks.md, "Tenth session, i8-cy").

    Args:
        signal: (n,) the true signal (e.g. JSBSim's aerodynamic side force over the mass, m/s^2), no NaN.
        noise_psd: one-sided white-noise PSD of the sensor, (units)^2 / Hz (:func:`white_noise_psd`).
        dt: sample step, s.
        window_s: Welch segment length, s.

    Returns:
        the error's RMS, in the signal's units.

    Raises:
        ValueError: ``signal`` shorter than one segment or not finite.

    Source: Bendat and Piersol, *Random Data*, 4th ed., Wiley 2010, sec. 6.1 (optimum linear filter;
    error spectrum ``S N / (S + N)``); Morelli and Klein, *Aircraft System Identification*, 2nd ed.,
    2016, sec. 11.1.
    """
    from scipy.signal import welch

    x = np.asarray(signal, float)
    nper = int(round(window_s / dt))
    if len(x) < nper or not np.isfinite(x).all():
        raise ValueError(f"wiener_floor needs a finite signal of at least {nper} samples, got {len(x)}")
    f, S = welch(x - x.mean(), 1.0 / dt, nperseg=nper)
    return float(np.sqrt(np.sum(S * noise_psd / (S + noise_psd)) * (f[1] - f[0])))
