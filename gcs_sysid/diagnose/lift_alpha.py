"""A slowly varying error of the measured angle of attack, read from the lift equation.

An autopilot's AOA_SSA is the EKF's ground velocity minus its wind estimate (``AP_AHRS``); a
wind-estimate error that wanders over tens of seconds leaves an angle-of-attack error of the same
kind (on the JSBSim SGS 2-33 sweep flights: standard deviation 0.4 deg, almost all of it below
0.5 Hz, a fifth of the flight's own alpha variation). A regression on such an alpha is an
errors-in-variables problem (Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016,
sec. 5.6; the slow error is neither white nor independent of the flight condition, so the
textbook attenuation correction with a noise variance does not apply): a pitching-moment term in
``alpha^2`` is selected as ``alpha^3`` or as ``alpha^2*delta_e`` (the trim elevator, measured
without error, follows the true alpha), and its held-out gain collapses.

The lift is measured well (accelerometers), and the model says how it depends on alpha. Where
the measured alpha is off by ``e``, the normal-force residual is ``R_CZ = -(dCZ/dalpha) e`` plus
turbulence, sensor noise and the model's own error. The error is therefore estimated as
``e = -LP[R_CZ] / (dCZ/dalpha)``, ``LP`` a zero-phase low-pass filter at ``cutoff_hz``, which
keeps the slow wind-estimate error and drops the faster turbulence and noise (the compatibility
idea of flight-path reconstruction, Morelli and Klein ch. 10, with the model's lift curve as the
measurement equation). The corrected alpha feeds the candidate library and the model's own
change ``M(X_c) - M(X)`` is removed from every coefficient, as for the parametric angle nuisance
(:func:`gcs_sysid.diagnose.sparse.angle_nuisance`), which runs first.

Off in the frozen thresholds of :data:`gcs_sysid.diagnose.sparse.THRESHOLDS` (``lift_alpha_hz`` 0,
2026-11-22): on the SGS tuning flights it reduced the alpha error's standard deviation only from
0.40-0.45 to 0.33-0.42 deg (the quadratic model's own lift error is of the same size) and hinges
in alpha then won over ``alpha^2``; ``thresholds={"lift_alpha_hz": 0.2}`` switches it on.

What it cannot tell apart: a slow true change of the normal force (a CZ term that varies only with
the flight condition) from an alpha error; after it, CZ's residual holds only its faster part, so
a CZ term is found from that part alone.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import butter, filtfilt

from ..aero.table import COEFFICIENTS, REGRESSORS

__all__ = ["lift_alpha_error"]


def lift_alpha_error(t: np.ndarray, X: np.ndarray, r_cz: np.ndarray, model_values, valid: np.ndarray,
                     cutoff_hz: float = 0.2, min_slope: float = 0.5, max_error_rad: float = np.radians(3.0),
                     keep_mean: bool = False) -> tuple[np.ndarray, dict]:
    """The slow error of the measured alpha that the normal-force residual implies.

    Args:
        t: (T,) time, s (uniform grid expected; the median step is used).
        X: (T, 10) regressors (columns :data:`gcs_sysid.aero.table.REGRESSORS`), alpha in rad.
        r_cz: (T,) normal-force coefficient residual, measured minus model (after whatever
            nuisance was already removed), dimensionless.
        model_values: callable ``X (T, 10) -> (T, 6)`` model coefficients (columns
            :data:`~gcs_sysid.aero.table.COEFFICIENTS`).
        valid: (T,) rows to use; elsewhere the error is interpolated.
        cutoff_hz: low-pass cut-off of the zero-phase (forward-backward, 2nd-order Butterworth) filter, Hz.
        min_slope: ``|dCZ/dalpha|`` below this (1/rad) gives no estimate (the lift curve is flat
            there, e.g. at the stall); such rows are interpolated.
        max_error_rad: the estimate is clipped to +-this, rad.
        keep_mean: read the residual's level as an alpha offset too (True: ``r_cz`` must then be
            measured against a model whose lift was fitted on a reference flight, so that its level
            means something: the alpha offset of this flight against that one; False: the residual
            is centred first and only the varying part of the error is estimated).

    Returns:
        (``e`` (T,) rad, the alpha error: corrected alpha = measured alpha - ``e``;
        ``{"cutoff_hz", "rms_deg", "slope_median"}``). All zero when fewer than 50 valid rows or
        the filter cannot run (too short a record for its cut-off).
    """
    T = len(t)
    e = np.zeros(T)
    info = {"cutoff_hz": float(cutoff_hz), "rms_deg": 0.0, "mean_deg": 0.0, "slope_median": float("nan")}
    ok = np.asarray(valid, bool) & np.isfinite(r_cz) & np.all(np.isfinite(X), axis=1)
    if ok.sum() < 50 or T < 50:
        return e, info
    ia, jz = REGRESSORS.index("alpha"), COEFFICIENTS.index("CZ")
    h = 1e-3
    Xp, Xm = np.nan_to_num(X).copy(), np.nan_to_num(X).copy()
    Xp[:, ia] += h
    Xm[:, ia] -= h
    g = (np.asarray(model_values(Xp))[:, jz] - np.asarray(model_values(Xm))[:, jz]) / (2 * h)
    use = ok & (np.abs(g) >= min_slope)
    if use.sum() < 50:
        return e, info
    raw = np.full(T, np.nan)
    rc = r_cz - (0.0 if keep_mean else np.mean(r_cz[use]))
    raw[use] = -rc[use] / g[use]
    idx = np.arange(T)
    raw = np.interp(idx, idx[use], raw[use])
    dt = float(np.median(np.diff(t)))
    wn = cutoff_hz * 2 * dt                         # fraction of the Nyquist frequency
    if not 0 < wn < 1:
        return e, info
    b, a = butter(2, wn)
    try:
        e = filtfilt(b, a, raw)
    except ValueError:                              # record shorter than the filter's padding
        return np.zeros(T), info
    e = np.clip(e, -max_error_rad, max_error_rad)
    info.update(rms_deg=float(np.degrees(np.sqrt(np.mean(e[use] ** 2)))), mean_deg=float(np.degrees(np.mean(e[use]))),
                slope_median=float(np.median(g[use])))
    return e, info
