"""The coefficient's band at a flight's own regressors from the out-of-sample residual and the stated measurement error.

The replay states two bands at a flight's estimated regressors (``docs/gp.md``, "Two bands"): one for a new
*measurement* and one for the *coefficient itself* (what a simulator needs, and what JSBSim's truth is). Write the
model's error against the true coefficient as the sum of its residual against the measurement and the measurement's
own error:

    T = m(x) - C = (m(x) - Y) + (Y - C) = R + E,      var T = var R + var E + 2 cov(R, E)

``var R`` is what the blocked cross-validation measures on time blocks the fit did not see: ``cv_p``, the mean
squared error of each held-back block (:mod:`gcs_sysid.gp.discrepancy`, there split into ``d_p + w_p``). ``var E``
is the measured coefficient's error, which the estimator states row by row from its smoothers (the specific force's
and the angular accelerations' 1-sigma through the force and moment equations,
:func:`gcs_sysid.aero.coefficients.stated_output_variance`). The covariance depends on whether the model can follow
the measurement's error:

- **an output that aids an air angle** (CZ aids alpha, CY aids beta: the specific-force aiding of
  :mod:`gcs_sysid.estimation.airangles`): the angle takes up the measured coefficient's error, the model at the
  estimated angle gives the measurement back with its error, and ``R`` does not contain ``E`` (``cov(R, E) ~ 0``):
  ``var T = cv + var E``;
- **any other output**: the regressors do not carry the measurement's error, the model averages it out, ``R``
  contains ``-E`` (``cov(R, E) ~ -var E``): ``var T = cv - var E``.

So the band is ``max(cv_p + s_p var E_p(x), latent_p(x) + input_p(x))`` with ``s_p = +1`` or ``-1`` per output,
floored at what the model's own posterior says (the latent variance and NIGP's learned input noise through the
slope, McHutchon and Rasmussen 2011, eq. 4) so that a row far from the data keeps its width. ``s_p = 0`` takes the
out-of-sample residual alone: the averaged regime without its correction, the conservative choice where the stated
``E`` is short or incomplete. ``less_white`` takes the averaged regime's correction from the residuals instead of the
stated error: ``cv_p`` less the white nugget ``w_p`` (the lag-1 semivariogram of the training residuals), which is the
model discrepancy ``d_p = max(0, cv_p - w_p)`` of :mod:`gcs_sysid.gp.discrepancy`. A white measurement error shows in
full in ``w_p`` and the model averages it out; what persists in time (a model error, a gust the regressors miss)
stays. It leaves the coloured part of the measured error in the band (conservative where that part is averaged out
too) and needs nothing stated. The variance decomposition is the errors-in-variables one (Fuller, *Measurement Error
Models*, Wiley 1987, sec. 1.1: the observed response is the true one plus its error, and what a regression on an
error-free regressor averages out); the out-of-sample residual variance is cross-validation's (Rasmussen and Williams
2006, sec. 5.3).

Measured on issue 8's JSBSim flights (``docs/benchmarks.md``, "Seventy-first session"): on the held-out segment
CZ's error is ``sqrt(R^2 + E^2)`` (1.41 and 0.73 against 1.56 % of the truth's RMS, medians of 75 flights), Cn's close
to ``sqrt(R^2 - E^2)`` (13.7 and 8.3 against 11.6 %), and the stated ``E`` of the forces is 0.8-1.0 of the true one, of
the moments 0.5-0.7 (the rate smoother's prior part). The replay's signs (:data:`gcs_sysid.pipeline.STATED_BAND_SIGN`)
were chosen on those flights: ``+1`` for CZ and Cm (Cm's error there was the residual plus about a third of its
measured error, which the short stated error through ``+1`` matches), ``0`` for Cn (``-1`` with the short stated
error put too many flights below 90 %); CX, CY and Cl keep the white band (CY's and CX's tie it; Cl's held-out rows
are asked at the held-out air roll rate, :mod:`gcs_sysid.aero.gustfilter`, whose own stated variance sets its band,
and the training rows' cross-validation does not measure that query).

References:
    C. E. Rasmussen and C. K. I. Williams (2006), *Gaussian Processes for Machine Learning*, MIT Press, sec. 5.3.
    A. McHutchon and C. E. Rasmussen (2011), "Gaussian process training with input noise", NIPS 24.
    W. A. Fuller (1987), *Measurement Error Models*, Wiley, sec. 1.1.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["cv_variance", "stated_band_variance"]


def cv_variance(model) -> np.ndarray | None:
    """``(P,)`` the blocked cross-validation's mean squared error per output in the outputs' units squared
    (``d_p + w_p`` of the model's discrepancy, :mod:`gcs_sysid.gp.discrepancy`), or None when the model has none
    (the validation did not run)."""
    if model.discrepancy is None:
        return None
    D = np.asarray(model.discrepancy, float)
    return (D[0] + D[1]) * np.asarray(model.scaler.y_std, float) ** 2


def stated_band_variance(model, X: np.ndarray, y_var: np.ndarray, sign, parts=None, less_white=None) -> np.ndarray:
    """The coefficient's band variance at a flight's own regressors (module docstring).

    Args:
        model: a :class:`gcs_sysid.gp.LocalGlobalGP` with ``P`` outputs and a discrepancy (blocked validation).
        X: ``(N, D)`` the model's inputs at the rows (data units; NaN rows give NaN).
        y_var: ``(N, P)`` the stated variance of the measured outputs' errors (outputs' units squared; NaN where
            none is stated: NaN out).
        sign: ``(P,)`` ``+1`` (the regressors carry the output's measured error: ``cv + var E``), ``-1`` (the model
            averages it out: ``cv - var E``), ``0`` (``cv`` alone: ``y_var`` not read) or NaN (not applied: NaN out).
        parts: ``(latent, learned_input)``, each ``(N, P)``, from :meth:`gcs_sysid.gp.LocalGlobalGP.predict_parts` at
            ``X`` when the caller has them (the replay's one pass), or None (computed here).
        less_white: ``(P,)`` bool, or None (all False): True takes the discrepancy ``d_p = max(0, cv_p - w_p)`` in
            place of ``cv_p`` (the white nugget out; module docstring), with that output's ``sign``.

    Returns:
        ``(N, P)`` variance in the outputs' units squared, NaN where the row, its ``y_var`` (sign +-1) or the
        output's sign gives none (the caller keeps its other band there).

    Raises:
        InputError: the model has no discrepancy, or ``y_var`` / ``sign`` / ``less_white`` do not match ``X`` and
            the outputs.
    """
    cv = cv_variance(model)
    if cv is None:
        raise InputError("stated coefficient band: the model has no blocked cross-validation (discrepancy)")
    X = np.asarray(X, float)
    y_var = np.asarray(y_var, float)
    s = np.asarray(sign, float)
    P = model.n_outputs
    lw = np.zeros(P, bool) if less_white is None else np.asarray(less_white, bool)
    if y_var.shape != (len(X), P) or s.shape != (P,) or lw.shape != (P,):
        raise InputError(f"stated coefficient band: y_var must be ({len(X)}, {P}), sign and less_white ({P},), "
                         f"got {y_var.shape}, {s.shape} and {lw.shape}")
    d = np.asarray(model.discrepancy, float)[0] * np.asarray(model.scaler.y_std, float) ** 2
    cv = np.where(lw, d, cv)                                   # d_p = max(0, cv_p - w_p)
    out = np.full((len(X), P), np.nan)
    applied = np.isfinite(s)
    if not len(X) or not applied.any():
        return out
    lat, learned = model.predict_parts(X)[2:] if parts is None else parts
    ok = np.all(np.isfinite(X), axis=1)
    floor = np.asarray(lat, float) + np.asarray(learned, float)
    stated = np.where((s == 0)[None, :], 0.0, y_var)          # cv alone needs no stated error
    with np.errstate(invalid="ignore"):
        v = np.maximum(cv[None, :] + np.where(applied, s, 0.0)[None, :] * stated, floor)
    return np.where(applied[None, :] & np.isfinite(stated) & ok[:, None], v, np.nan)
