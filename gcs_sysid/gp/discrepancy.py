"""The model's own error at exact flight conditions: model discrepancy and the inputs' common offset.

``predict(X, include_noise=False)`` gives the GP's latent variance: how well the data pin down the
function the model class can represent, *at the regressors as the estimator saw them*. Two errors
are outside it, and both matter where the model is evaluated at exact conditions (a user's flight
condition, ``gcs-sysid predict``; the truth's regressors in ``benchmarks/eval_jsbsim.py``):

1. **A flight-common offset of the regressors.** The reconstructed alpha carries the flight-mean
   vertical wind over the airspeed, ``mean(w_d) / V``, which no logged channel observes
   (``docs/estimation.md``; its 1-sigma is ``AxisFit.bias_sigma``, carried to the table as
   ``CoefficientTable.x_offset_cov``). The model learns ``m(x + delta) ~ C(x)`` with one ``delta``
   for all rows, so at the exact ``x`` its error is ``m(x) - C(x) ~ grad m(x)^T delta``: not per-row
   noise (it does not average out, and at the flight's own estimated regressors it cancels), but a
   variance at exact conditions of

       v_off,p(x) = grad m_p(x)^T Sigma_off grad m_p(x)

   with ``Sigma_off`` the offset's covariance (the first-order propagation of McHutchon and
   Rasmussen 2011, eq. 4, applied to a common error instead of a per-row one). Likewise a
   flight-common *scale* error of an aided angle (its force slope, fitted on the flight, is biased by
   errors in variables; the estimator's 1-sigma is ``AxisFit.scale_sigma``, carried as
   ``CoefficientTable.x_scale_var`` -> ``scale_var``): the model learned ``m(xbar + (1 + s)(x - xbar))
   ~ C(x)``, so at exact conditions it is off by ``-dm/dx s (x - xbar)``, variance

       v_scale,p(x) = sum_d (d m_p / d x_d)^2 scale_var_d (x_d - xbar_d)^2

   with ``xbar`` the training mean (the standardiser's), zero at the centre of the data.

2. **Model discrepancy.** The blocked cross-validation (:mod:`gcs_sysid.gp.validation`) shrinks the
   latent GP per output when its nonparametric part does not predict held-back time blocks; the
   latent variance shrinks with it, so the band then says "the linear mean is right", while the
   truth also carries what none of the regressors explains (the turbulence's rotational rates,
   ``alpha_dot``, a nonlinearity the shrunk GP no longer follows). Kennedy and O'Hagan (2001,
   "Bayesian calibration of computer models", J. R. Stat. Soc. B 63(3):425-464, sec. 2.1 and 4.3)
   write the truth as the model plus a discrepancy ``delta(x)``, separate from the observation
   error. Its size is estimated here from the blocked cross-validation the fit already runs
   (Rasmussen and Williams 2006, sec. 5.3): per output, the mean squared error of each held-back
   block predicted from the other blocks, ``cv_p``, less the white measurement noise ``w_p``:

       d_p = max(0, cv_p - w_p),        w_p = 1/2 mean_t (r_t+1,p - r_t,p)^2

   ``w_p`` is the lag-1 semivariogram of the time-ordered training residuals ``r`` (the nugget of
   the variogram, Cressie 1993, sec. 2.4; von Neumann's mean square successive difference): at
   50 Hz a white error shows in full in successive differences, a gust's or a model error's, which
   lasts hundreds of rows, hardly at all. What a held-back block shows beyond the white noise
   persists in time; a truth at exact conditions carries it too. Coloured *measurement* errors (the
   rate smoother's) are counted as well, which makes ``d_p`` conservative for the moments.

   ``d_p`` is a constant per output (a homoscedastic discrepancy); the growth of the error away
   from the data is the latent variance's (the GP and the linear mean's weights), which is kept.

At exact conditions (``predict(..., input_noise=False)``, :meth:`LocalGlobalGP.predict`'s
``model_error``) the variance is ``latent + v_off + d``; with the observation noise, ``latent +
v_off + max(noise, d + w)``: the likelihood's noise already holds the misfit that the rows show, so
the two are not added. At a flight's own estimated regressors nothing here is added (the offset
cancels there, and the band with noise was measured to cover 94-98 % of the truth,
``docs/benchmarks.md``). Everything is in the model's standardised units.

References:
    M. C. Kennedy and A. O'Hagan (2001), "Bayesian calibration of computer models", J. R. Stat.
    Soc. B 63(3):425-464, doi:10.1111/1467-9868.00294.
    C. E. Rasmussen and C. K. I. Williams (2006), *Gaussian Processes for Machine Learning*, MIT
    Press, sec. 5.3 (cross-validation).
    A. McHutchon and C. E. Rasmussen (2011), "Gaussian process training with input noise", NIPS 24.
    N. Cressie (1993), *Statistics for Spatial Data*, revised ed., Wiley, sec. 2.4.
    J. von Neumann (1941), "Distribution of the ratio of the mean square successive difference to
    the variance", Ann. Math. Stat. 12(4):367-395.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import InputError
from .validation import block_folds

__all__ = ["validation_rows", "white_noise_variance", "discrepancy_variance", "calibrate", "offset_covariance_s",
           "with_offset_covariance", "exact_condition_variance", "model_error_summary"]


def validation_rows(n: int, folds: int, val_max: int) -> int:
    """Number of validation rows :func:`gcs_sysid.gp.validation.gate_global` scores for ``n`` rows in
    ``folds`` blocks with at most ``val_max`` in all (its ``sse`` divided by this is a mean)."""
    blocks = block_folds(n, folds)
    per = max(1, val_max // max(len(blocks), 1))
    return int(sum(min(b - a, per) for a, b in blocks))


def white_noise_variance(resid: np.ndarray) -> np.ndarray:
    """White part of the residuals' variance, ``(P,)``: half the mean squared successive difference.

    Args:
        resid: ``(N, P)`` residuals in time order (N >= 2; NaN rows are dropped).

    Returns:
        ``(P,)`` the lag-1 semivariogram ``1/2 mean (r_t+1 - r_t)^2`` (Cressie 1993, sec. 2.4).
    """
    r = np.asarray(resid, float)
    r = r[np.isfinite(r).all(1)]
    if len(r) < 2:
        return np.zeros(r.shape[1])
    return 0.5 * np.mean(np.diff(r, axis=0) ** 2, axis=0)


def discrepancy_variance(cv_mse: np.ndarray, white: np.ndarray) -> np.ndarray:
    """``d_p = max(0, cv_p - w_p)`` ``(P,)`` from the blocked CV mean squared error and the white noise
    (module docstring)."""
    return np.maximum(np.asarray(cv_mse, float) - np.asarray(white, float), 0.0)


def calibrate(model, Xs: np.ndarray, Ys: np.ndarray, cv_mse) -> object:
    """``model`` with its discrepancy ``d`` and white noise ``w`` (module docstring) set.

    Args:
        model: a :class:`gcs_sysid.gp.LocalGlobalGP` (its global layer fitted).
        Xs, Ys: ``(N, D)``, ``(N, P)`` standardised training rows in time order.
        cv_mse: ``(P,)`` blocked cross-validation mean squared error of the global layer
            (standardised; ``FitHistory.validation["cv_mse"]``), or None when the check did not run:
            the model is returned without a discrepancy.

    Returns:
        A new model (``discrepancy = (d, w)`` stacked as ``(2, P)``), or ``model`` itself.
    """
    if cv_mse is None:
        return replace(model, discrepancy=None)
    from .batching import global_mean

    resid = Ys - global_mean(model.params, model.post, Xs, model.config.batch_size)
    w = white_noise_variance(resid)
    return replace(model, discrepancy=np.stack([discrepancy_variance(cv_mse, w), w]))


def offset_covariance_s(scaler, cov: np.ndarray) -> np.ndarray:
    """The regressors' common-offset covariance ``(D, D)`` in the model's standardised units (inactive
    inputs get 0: the model ignores them)."""
    s = np.where(scaler.active, 1.0 / np.asarray(scaler.x_std, float), 0.0)
    return np.asarray(cov, float) * s[:, None] * s[None, :]


def map_covariance_s(scaler, cov: np.ndarray) -> np.ndarray:
    """``(D, D, D)`` second moment of the regressors' common linear error in standardised units: ``[j]`` maps
    standardised ``x`` to standardised ``x_j``, so ``C_s[j] = C[j] * s s^T / s_j^2`` (``s`` the regressors'
    scales); inactive regressors zero."""
    s = np.where(scaler.active, scaler.x_std, 0.0)
    sj = np.where(scaler.active, scaler.x_std, np.inf)
    return np.asarray(cov, float) * (s[:, None] * s[None, :])[None, :, :] / sj[:, None, None] ** 2


def with_offset_covariance(model, cov, rows: int | None = None, scale_var=None, map_cov=None):
    """``model`` with the covariance of its training regressors' flight-common offset (and scale error).

    Args:
        model: a :class:`gcs_sysid.gp.LocalGlobalGP`.
        cov: ``(D, D)`` covariance in the regressors' units squared (``CoefficientTable.x_offset_cov``),
            or None (each of ``cov``, ``scale_var`` and ``map_cov`` may leave out the model's trailing mean-only
            inputs, ``GPConfig.mean_only_inputs``: zero there) (no offset known: the model keeps what it has).
        rows: rows of the flight ``cov`` belongs to, when ``model`` was *updated* with that flight
            after learning others: offsets of different flights are independent, and the model's
            mean follows the row-weighted mean of them, so the covariances combine as
            ``(n_old^2 S_old + n^2 S) / (n_old + n)^2`` (``n_old = model.n_used - rows``; a model
            without an offset counts as offset-free). None: the model learned this flight alone.
        scale_var: ``(D,)`` variance of the regressors' relative scale error common to the flight
            (dimensionless; ``CoefficientTable.x_scale_var``), or None (the model keeps what it has);
            combined across flights as ``cov`` is. At exact conditions it adds
            ``sum_d (dm/dx_d)^2 scale_var_d (x_d - mean x_d)^2`` (module docstring, item 1).
        map_cov: ``(D, D, D)`` second moment of the regressors' flight-common linear error
            (``CoefficientTable.x_map_cov``: ``[j]`` of regressor ``j``'s error along the regressors, in
            ``x_j^2 / (x_d x_e)``), or None (the model keeps what it has); combined across flights as ``cov``
            is. At exact conditions it adds ``sum_j (dm/dx_j)^2 (x - mean x)^T C_j (x - mean x)``, in place of
            ``scale_var_j`` for every ``j`` with a nonzero ``C_j`` (module docstring, item 1).

    Returns:
        A new model (``offset_cov`` standardised ``(D, D)``, ``scale_var`` ``(D,)``, ``map_cov`` ``(D, D, D)``).

    Raises:
        InputError: ``cov`` is not ``(D, D)``, ``scale_var`` not ``(D,)`` or ``map_cov`` not ``(D, D, D)``, or
            one is not finite.
    """
    D = model.n_inputs
    k = getattr(model, "n_mean_only", 0)
    if k:                 # the estimator states nothing for the mean-only inputs (GPConfig.mean_only_inputs): 0
        d0 = D - k

        def pad(a, nd):
            a = np.asarray(a, float)
            if a.shape != (d0,) * nd:
                return a
            out = np.zeros((D,) * nd)
            out[(slice(0, d0),) * nd] = a
            return out

        cov = None if cov is None else pad(cov, 2)
        scale_var = None if scale_var is None else pad(scale_var, 1)
        map_cov = None if map_cov is None else pad(map_cov, 3)

    def combine(old, new):
        if rows is None:
            return new
        n_new = float(rows)
        n_old = max(float(model.n_used) - n_new, 0.0)
        old = np.zeros_like(new) if old is None else old
        return (n_old**2 * old + n_new**2 * new) / max(n_old + n_new, 1.0) ** 2

    if scale_var is not None:
        S = np.asarray(scale_var, float)
        if S.shape != (D,) or not np.isfinite(S).all():
            raise InputError(f"gp: scale variance must be a finite ({D},) vector, got shape {S.shape}")
        model = replace(model, scale_var=combine(model.scale_var, np.where(model.scaler.active, S, 0.0)))
    if map_cov is not None:
        Mc = np.asarray(map_cov, float)
        if Mc.shape != (D, D, D) or not np.isfinite(Mc).all():
            raise InputError(f"gp: linear-error map covariance must be a finite ({D}, {D}, {D}) array, got shape "
                             f"{Mc.shape}")
        model = replace(model, map_cov=combine(getattr(model, "map_cov", None), map_covariance_s(model.scaler, Mc)))
    if cov is None:
        return model
    C = np.asarray(cov, float)
    if C.shape != (D, D) or not np.isfinite(C).all():
        raise InputError(f"gp: offset covariance must be a finite ({D}, {D}) matrix, got shape {C.shape}")
    return replace(model, offset_cov=combine(model.offset_cov, offset_covariance_s(model.scaler, C)))


def exact_condition_variance(model, Xs: np.ndarray, noise: np.ndarray | None = None,
                             white_noise: bool = True) -> np.ndarray:
    """What the model's error at exact conditions adds to its latent variance, ``(N, P)`` at standardised
    ``Xs (N, D)`` (standardised units; module docstring).

    Args:
        model: a :class:`gcs_sysid.gp.LocalGlobalGP`.
        Xs: ``(N, D)`` standardised exact regressors.
        noise: ``(P,)`` the observation-noise variance to include (a new measurement at exact
            conditions), or None (the coefficient itself).
        white_noise: with ``noise``, False leaves the white part ``w`` out of the noise term (what the
            coefficient carries of it: ``max(noise, d + w) - w = max(noise - w, d)``; ``docs/gp.md``, "Two
            bands"); ignored without a discrepancy (``w`` unknown: the noise is kept).

    Returns:
        ``v_off(x) + v_scale(x) + d`` without noise; ``v_off(x) + v_scale(x) + max(noise, d + w)`` with
        it (the likelihood's noise and the blocked residual both hold the misfit the rows show: the
        larger, not the sum). Zeros (plus ``noise``) when no offset, scale error or discrepancy is known.
    """
    out = np.zeros((len(Xs), model.n_outputs))
    off = model.offset_cov is not None and np.any(model.offset_cov)
    Mc = getattr(model, "map_cov", None)
    mapped = np.zeros(model.n_inputs, bool) if Mc is None else np.any(np.asarray(Mc) != 0, axis=(1, 2))
    sv = getattr(model, "scale_var", None)
    sv = None if sv is None else np.where(mapped, 0.0, np.asarray(sv))     # the map holds those angles' scale
    scale = sv is not None and np.any(sv)
    if (off or scale or mapped.any()) and len(Xs):
        from .inputnoise import mean_gradient

        g = mean_gradient(model.params, model.post, Xs, model.config.batch_size)      # (N, P, D)
        if off:
            out += np.einsum("npd,de,npe->np", g, np.asarray(model.offset_cov), g)
        if scale:       # a scale error s_d of x_d about the training mean: standardised x_d is x_d - mean
            out += np.einsum("npd,d,nd->np", g**2, sv, np.asarray(Xs) ** 2)
        for j in np.nonzero(mapped)[0]:     # x_j's error along all regressors, e_j = M_j (x - mean x)
            ve = np.einsum("nd,de,ne->n", np.asarray(Xs), np.asarray(Mc)[j], np.asarray(Xs))
            out += g[:, :, j] ** 2 * ve[:, None]
    if model.discrepancy is None:
        return out if noise is None else out + np.asarray(noise)[None, :]
    d, w = np.asarray(model.discrepancy)
    if noise is None:
        return out + d[None, :]
    return out + (np.maximum(np.asarray(noise), d + w) - (0.0 if white_noise else w))[None, :]


def model_error_summary(model) -> dict | None:
    """JSON-able ``{"discrepancy_std": {output: 1-sigma}, "white_noise_std": {...}, "offset_std": {input:
    1-sigma}, "scale_std": {input: relative 1-sigma}}`` in data units (None entries where not known; None
    when none is), for :meth:`LocalGlobalGP.summary`."""
    scale = getattr(model, "scale_var", None)
    if model.discrepancy is None and model.offset_cov is None and scale is None:
        return None
    sc = model.scaler
    out: dict = {"discrepancy_std": None, "white_noise_std": None, "offset_std": None, "scale_std": None}
    if scale is not None:
        out["scale_std"] = {n: float(np.sqrt(v)) for n, v in zip(model.input_names, np.asarray(scale)) if v > 0}
    if model.discrepancy is not None:
        d, w = np.sqrt(np.asarray(model.discrepancy)) * sc.y_std[None, :]
        out["discrepancy_std"] = dict(zip(model.output_names, d.tolist()))
        out["white_noise_std"] = dict(zip(model.output_names, w.tolist()))
    if model.offset_cov is not None:
        s = np.sqrt(np.maximum(np.diag(np.asarray(model.offset_cov)), 0.0)) * sc.x_std
        out["offset_std"] = {n: float(v) for n, v, a in zip(model.input_names, s, sc.active) if a and v > 0}
    return out
