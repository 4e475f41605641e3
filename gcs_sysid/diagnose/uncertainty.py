"""Standard uncertainty of a named term's estimate: coloured residuals, the reference fit, the air angles.

A term the sparse search names (``Cm:alpha^2``, ``Cl:alpha*beta``, ``scale:CY`` ...) is a *change*: this
flight's least-squares fit minus what the reference flight's fit holds. Its standard uncertainty is
combined from uncorrelated components in quadrature (GUM, JCGM 100:2008, sec. 5.1, eq. 10):

* **type A, this flight**: the larger of Morelli and Klein's coloured-residual standard error
  (*Aircraft System Identification*, 2nd ed., sec. 5.3: ``(X'X)^-1 X' R_vv X (X'X)^-1``, the LS covariance
  corrected for the residual autocorrelation) and the delete-a-block jackknife over contiguous blocks of
  ``block_s`` seconds (Kuensch, *Ann. Statist.* 17 (1989) 1217-1241; Efron and Tibshirani 1993, ch. 11).
  Gust-driven residuals are coloured on the scale of seconds, so a 90-s flight holds few independent
  samples; the jackknife also carries a slowly varying error of the *regressor* (an air angle that misses
  slow gusts) aligned by chance with the manoeuvres, which the LS covariance (regressor held fixed) does
  not. The jackknife has only ``B - 1`` degrees of freedom (5-6 blocks in a 90-s training segment), so
  the analytic form is kept as a floor;
* **type A, the reference flight**: the same two forms of the same terms on the reference flight's
  residual after its inadequacy (the change is a difference of two fits);
* **type B, the air angles** (GUM sec. 4.3): the reconstructed angle of attack (and sideslip) has a
  per-flight scale error (the aiding's force slope) and an offset (the flight-mean vertical wind, which
  no sensor observes). A term in those angles is biased by them. The pipeline's *own* assessment of
  its air-data uncertainty (:func:`air_data_uncertainty`: the estimator's standard errors of the aiding
  slope and its 1-sigma of the mean vertical wind over the airspeed), never the truth, gives a standard
  uncertainty ``u_s`` of the relative scale and ``u_o`` of the offset; each is propagated through the
  fit by a central difference (GUM sec. 5.1.3, sensitivity coefficients found numerically): the selected
  terms' columns are rebuilt on the angle scaled about its flight mean by ``1 +- u_s`` (shifted by
  ``+- u_o``) and refitted on the same residual, ``u = |theta(+) - theta(-)| / 2``.

Nothing here changes which cause is named, its estimate or its gain: the diagnosis's decisions keep the
standard errors they were frozen with (``evidence.std_error_decision``).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..jackknife import block_jackknife_cov
from .regression import ols

__all__ = ["BLOCK_S", "block_jackknife_cov", "fit_standard_errors", "type_a", "air_data_uncertainty",
           "pair_slope_scale", "elevator_loading", "sideslip_loadings", "angle_sensitivity", "combine"]

#: block length of the delete-a-block jackknife, s (the diagnosis's ``alpha_jackknife_s``: longer than the
#: gusts' correlation times of 1-5 s at light aircraft speeds, short enough to give 5-8 blocks per flight)
BLOCK_S = 15.0


def fit_standard_errors(t: np.ndarray, A: np.ndarray, r: np.ndarray, labels: list[str],
                        block_s: float = BLOCK_S) -> dict:
    """Coloured-residual and block-jackknife standard errors of one least-squares fit.

    Args:
        t: (N,) time, s. A: (N, P) regressors, the first column the constant. r: (N,) response.
        labels: (P,) names of the columns.

    Returns:
        ``{"theta": (P,), "coloured": (P,), "jackknife": (P,) (NaN where the jackknife is not
        possible), "blocks": int}``: Morelli and Klein's all-lags form (sec. 5.3,
        :func:`gcs_sysid.diagnose.regression.colored_covariance` ``method="morelli"``) and
        :func:`block_jackknife_cov`.

    Raises:
        ValueError: from :func:`gcs_sysid.diagnose.regression.ols` (too few rows, singular).
    """
    fit = ols(A, r, labels, cov_method="morelli")
    cov = block_jackknife_cov(t, A, r, block_s)
    jk = np.sqrt(np.maximum(np.diag(cov), 0.0)) if cov is not None else np.full(A.shape[1], np.nan)
    return {"theta": np.asarray(fit.theta, float), "coloured": np.asarray(fit.std_error, float), "jackknife": jk,
            "blocks": int(np.floor((np.nanmax(t) - np.nanmin(t)) / block_s) + 1) if cov is not None else 0}


def type_a(res: dict) -> np.ndarray:
    """The type-A standard error of each coefficient of a :func:`fit_standard_errors` result: the larger of
    the coloured-residual and the block-jackknife standard error ((P,); the jackknife where the analytic
    form is NaN and the other way round)."""
    return np.fmax(np.asarray(res["coloured"], float), np.asarray(res["jackknife"], float))


def air_data_uncertainty(angle_fits: dict | None, reference_fits: dict | None = None,
                         pair_scale: str = "quadrature") -> dict:
    """The reconstruction's own standard uncertainty of each air angle's scale and offset.

    From the estimator's fits of the specific-force aiding
    (:class:`gcs_sysid.estimation.airangles.AxisFit`, ``FlightStates.angle_fits``): the aided angle's
    excursions are the force coefficient's divided by the aiding slope (``CZ_alpha``, ``CY_beta``), so a
    relative error of that slope is a relative scale error of the angle: ``u_s = coef_sigma[1] /
    |coef[1]|`` (the slope's own standard error, instrumental-variable or OLS as fitted). The offset:
    alpha's ``bias_sigma`` (the flight-mean vertical wind, which no sensor observes, over the airspeed:
    :func:`gcs_sysid.estimation.angleerrors.mean_wind_sigma`); beta's mean is set by the wind fit and a
    symmetric airframe's ``CY0 ~ 0``, whose spread the estimator does not report, so its offset
    uncertainty is left out (0). An axis the aiding did not use (kinematic angle kept) or a slope given
    from another flight carries no scale uncertainty of its own here (0). The scale also takes the aided
    and the kinematic angle's disagreement in scale (``AxisFit.scale_sigma``) in quadrature: the kinematic
    angle's scale is set by geometry, the aided one's by a force slope that errors in variables attenuate.
    Alpha also gets ``"curvature"``, 1/rad: the aided angle's flight-common curvature error
    (:attr:`gcs_sysid.estimation.airangles.AxisFit.curvature_sigma`, the aiding's fitted ``CZ_alpha2`` over
    ``|CZ_alpha|``); only the naming test under no change reads it
    (:func:`gcs_sysid.diagnose.null_uncertainty.angle_null_sensitivity`; twentieth session, branch i9-curv).

    The change is this flight's fit minus the reference's, and the reference's angle errors stay in the
    model (the angle nuisance brings this flight's angle to the reference's scale; a term of degree ``k``
    comes out ``(1 + s_ref)^-k`` of its size), so with ``reference_fits`` each component is the two
    flights' in quadrature (independent flights).

    Args:
        angle_fits: ``{"alpha": AxisFit, "beta": AxisFit}`` of this flight, or None.
        reference_fits: the same of the reference flight, or None.

    Alpha also gets ``"loading_delta_e"`` (:func:`elevator_loading`, rad/rad; where the aiding has a ``delta_e``
    column), and with ``reference_fits`` in its place ``"map_delta_e"``: the two loadings' absolute difference (not
    their quadrature sum: a signed property of how each alpha was built), the alpha error along ``delta_e`` that only
    the naming test under no change reads, with ``sparse.THRESHOLDS["coverage_map_delta_e"]`` (twentieth session,
    branch i9-elev; off).

    ``pair_scale`` (with ``reference_fits``; ``sparse.THRESHOLDS["coverage_scale_pair"]``, twenty-second session,
    branch i9-aiddef; the diagnosis passes ``"slopes"`` since the forty-first session): ``"quadrature"`` (this
    function's default) states only the two flights' own scales in quadrature, as
    above; ``"slopes"`` adds alpha's ``"scale_null"``, :func:`pair_slope_scale`: the two aidings' lift slopes' ratio
    (the test flight's alpha scale against the reference's) with both slopes' standard errors in quadrature, without
    ``AxisFit.scale_sigma``, which on a gusty flight is the gust's share of the aided angle, not a scale
    (``docs/diagnose.md``, item 23). Only the naming test under no change reads it (there a scale common to both
    flights cancels); a named change's estimate is scaled by the common error too, so its type B keeps ``"scale"``.
    Beta is unchanged.

    Beta also gets ``"along_<column>"`` for each column of the side-force model the sideslip was aided with besides
    the angle (``p_hat``, ``r_hat``, ``delta_a``, ``delta_r``; :func:`sideslip_loadings`): the standard uncertainty of
    the aided sideslip's loading on that column, rad per unit, with ``reference_fits`` the two flights' in quadrature
    (independent flights). Only the naming test under no change reads it, with
    ``sparse.THRESHOLDS["coverage_beta_along"]`` (forty-second session).

    Returns:
        ``{"alpha": {"scale": u_s, "offset_rad": u_o, "curvature": u_c[, "map_delta_e": u_m][, "scale_null": u_p]},
        "beta": {"scale": u_s, "offset_rad": u_o[, "along_<column>": u_l ...]}}`` (dimensionless, rad, 1/rad, rad/rad,
        dimensionless, rad per unit; 0 where unknown).

    Raises:
        ValueError: an unknown ``pair_scale``.
    """
    if pair_scale not in ("quadrature", "slopes"):
        raise ValueError(f"pair_scale must be 'quadrature' or 'slopes', not {pair_scale!r}")
    if reference_fits is not None:
        a, b = air_data_uncertainty(angle_fits), air_data_uncertainty(reference_fits)
        # a loading one flight's aiding had and the other's not (a column that did not vary) counts 0 there
        out = {n: {k: float(np.hypot(a[n].get(k, 0.0), b[n].get(k, 0.0))) for k in {**a[n], **b[n]}
                   if k != "loading_delta_e"} for n in a}
        if pair_scale == "slopes":
            ps = pair_slope_scale((angle_fits or {}).get("alpha"), (reference_fits or {}).get("alpha"))
            if ps is not None:
                out["alpha"]["scale_null"] = ps
        la, lb = a["alpha"].get("loading_delta_e"), b["alpha"].get("loading_delta_e")
        if la is not None and lb is not None:
            # a signed property of how each flight's alpha was built, not an independent error: their difference
            out["alpha"]["map_delta_e"] = float(abs(la - lb))
        return out
    out = {}
    for name in ("alpha", "beta"):
        fit = (angle_fits or {}).get(name)
        us, uo = 0.0, 0.0
        if fit is not None and getattr(fit, "used", False):
            c, s = np.asarray(fit.coef, float), np.asarray(fit.coef_sigma, float)
            if c.size > 1 and s.size > 1 and np.isfinite(s[1]) and abs(c[1]) > 0:
                us = float(abs(s[1] / c[1]))
            d = float(getattr(fit, "scale_sigma", float("nan")))
            us = float(np.hypot(us, d)) if np.isfinite(d) else us
            b = float(getattr(fit, "bias_sigma", float("nan")))
            uo = b if np.isfinite(b) else 0.0
        out[name] = {"scale": us, "offset_rad": uo}
        if name == "alpha":
            uc = float(getattr(fit, "curvature_sigma", float("nan")))
            out[name]["curvature"] = uc if np.isfinite(uc) else 0.0
            ld = elevator_loading(fit)
            if ld is not None:
                out[name]["loading_delta_e"] = ld
        else:
            out[name].update({f"along_{k}": v for k, v in sideslip_loadings(fit).items()})
    return out


#: the side-force model's columns besides the angle whose loading on the aided sideslip :func:`sideslip_loadings` states
SIDESLIP_ALONG = ("p_hat", "r_hat", "delta_a", "delta_r")


def sideslip_loadings(fit) -> dict[str, float]:
    """Standard uncertainty of the aided sideslip's loading on each other column of its side-force model.

    The aided sideslip is the side force's excursion less the model's other terms, over the slope
    (:class:`gcs_sysid.estimation.airangles.AxisFit`: ``beta = (CY - CY_0 - sum_k CY_k x_k) / CY_beta`` where the
    force-derived angle leads), so an error ``e_k`` of a fitted ``CY_k`` is a sideslip error ``-e_k / CY_beta x_k``.
    A side-force coefficient then fitted on that sideslip gives ``CY_k`` back whatever the air did: the diagnosis's
    ``CY:r_hat`` on a clean JSBSim SGS 1-26 flight (s12) was the two flights' aiding fits' ``CY_r_hat``, -1.07
    against -0.54, where JSBSim's side force has no yaw-rate term and each fit states +- 0.01
    (``docs/benchmarks.md``, *Forty-second session, lead*). The aiding's later passes refit on the aided angle, so
    their standard errors are circular; the first pass's block jackknife (:attr:`AxisFit.slope_jackknife`, on the
    kinematic angle) is the scatter a second flight shows: there +- 0.30 and +- 0.49.

    Args:
        fit: the sideslip's ``AxisFit`` (or None).

    Returns:
        ``{column: slope_jackknife_k / |CY_beta|}`` (rad per unit of the column) for the columns of
        :data:`SIDESLIP_ALONG` in the fit with a finite jackknife; {} where the axis was not aided or has none.
    """
    if fit is None or not getattr(fit, "used", False):
        return {}
    cols = list(getattr(fit, "columns", ()) or ())
    c = np.asarray(getattr(fit, "coef", ()), float)
    jk = np.asarray(getattr(fit, "slope_jackknife", ()), float)
    if "beta" not in cols or c.size != len(cols) or jk.size != len(cols):
        return {}
    slope = abs(float(c[cols.index("beta")]))
    if not (np.isfinite(slope) and slope > 0):
        return {}
    return {k: float(jk[cols.index(k)] / slope) for k in SIDESLIP_ALONG
            if k in cols and np.isfinite(jk[cols.index(k)])}


def pair_slope_scale(fit, reference_fit) -> float | None:
    """Standard uncertainty of a flight's aided-alpha scale *against its reference flight's*, from the two lift slopes.

    The aided angle's excursions are the normal-force coefficient's over the aiding's slope ``CZ_alpha``
    (:class:`gcs_sysid.estimation.airangles.AxisFit` ``coef[1]``; the later passes refit it on the angle the last one
    aided, so the flight keeps its first pass's slope), so two flights of one aircraft aided with slopes ``c_f`` and
    ``c_ref`` read the same true alpha excursion with the relative scale ``c_ref / c_f``. The part of the scale error
    common to both (the lift-slope floor against the aircraft's true slope, the same on every flight of one aircraft)
    cancels in a change between the flights and in the naming test under no change; what is left is
    ``d = c_ref / c_f - 1``, a signed property of the two fits (like :func:`elevator_loading`'s difference, taken
    whole), with both slopes' standard errors in quadrature (GUM JCGM 100:2008 eq. 10). Measured against JSBSim's
    alpha (c172p light, the reference and five test flights, alpha profiled): the test flight's scale error less the
    reference's, from a fit on the true angle with the curvature and the elevator beside it, is -0.042, +0.132,
    +0.008, +0.005, -0.026; ``d`` is -0.021, +0.128, -0.001, +0.004, -0.010 (``docs/benchmarks.md``,
    *Twenty-second session, i9-aiddef*). ``AxisFit.scale_sigma`` on the same flights is 0.42-0.92.

    Args:
        fit, reference_fit: the two flights' alpha ``AxisFit`` (or None).

    Returns:
        ``sqrt(d^2 + (se_f / c_f)^2 + (se_ref / c_ref)^2)`` (dimensionless), or None where either axis was not aided
        or a slope is missing (the caller keeps the quadrature).
    """
    cs = []
    for f in (fit, reference_fit):
        if f is None or not getattr(f, "used", False):
            return None
        c, s = np.asarray(f.coef, float), np.asarray(f.coef_sigma, float)
        if c.size < 2 or not np.isfinite(c[1]) or c[1] == 0.0:
            return None
        cs.append((float(c[1]), float(s[1]) if s.size > 1 and np.isfinite(s[1]) else 0.0))
    (cf, sf), (cr, sr) = cs
    return float(np.sqrt((cr / cf - 1.0) ** 2 + (sf / cf) ** 2 + (sr / cr) ** 2))


def elevator_loading(fit) -> float | None:
    """The aided alpha's loading on the elevator, rad of alpha per rad of ``delta_e``: ``-CZ_delta_e / CZ_alpha``
    of the aiding's force model (:class:`gcs_sysid.estimation.airangles.AxisFit`; the aided angle is the lift's
    excursion less the model's other terms over the slope, so an error ``e`` in the fitted ``CZ_delta_e`` is an
    alpha error ``-e / CZ_alpha * delta_e``). The aircraft's true ``CZ_delta_e`` is a share of it common to two flights
    of one aircraft, so only a difference of two loadings is an angle error. None: alpha not aided, or no ``delta_e``
    column.

    Two flights' aiding fits of the same aircraft differ in ``CZ_delta_e`` by errors in variables (the kinematic
    witness's gust error, the elevator's correlation with alpha), so their alphas differ by ``(l_f - l_ref)
    delta_e``, which loads every elevator term: on the c172p's clean seed 13 ``l`` 0.277 against the reference's
    0.151 (against JSBSim's alpha the error's slope on ``delta_e`` is 0.342 against 0.210) made ``Cm:delta_e``
    +0.19 and ``CZ:delta_e`` +0.55 (``docs/benchmarks.md``, "Twentieth session, i9-elev").
    """
    if fit is None or not getattr(fit, "used", False):
        return None
    cols = list(getattr(fit, "columns", ()) or ())
    c = np.asarray(getattr(fit, "coef", ()), float)
    if "delta_e" not in cols or "alpha" not in cols or c.size != len(cols):
        return None
    a, d = float(c[cols.index("alpha")]), float(c[cols.index("delta_e")])
    if not (np.isfinite(a) and np.isfinite(d)) or a == 0.0:
        return None
    return -d / a


def angle_sensitivity(columns: Callable[[np.ndarray], np.ndarray], X: np.ndarray, r: np.ndarray,
                      rows: np.ndarray, index: int, k_angle: int, scale: float, offset: float,
                      scale_step: float = 0.0) -> dict:
    """Standard uncertainty of one fitted coefficient from an air angle's scale and offset (type B).

    Args:
        columns: ``X -> (T, P)`` the fit's regressors (constant first) built from regressors ``X``.
        X: (T, 10) the regressors the fit used. r: (T,) the response. rows: (N,) row indices of the fit.
        index: column of the coefficient in ``columns``' output. k_angle: column of the angle in ``X``.
        scale: standard uncertainty of the angle's relative scale (about its mean over ``rows``).
        offset: standard uncertainty of its offset, rad.
        scale_step: the largest relative step of the scale's central difference; with ``scale > scale_step > 0``
            the difference is taken at ``+- scale_step`` and multiplied by ``scale / scale_step``: the first-order
            sensitivity coefficient times the standard uncertainty (GUM, JCGM 100:2008, eq. 10), as
            :func:`gcs_sysid.diagnose.null_uncertainty.angle_null_sensitivity` does under no change. At ``+- scale``
            with a stated scale uncertainty near 1 the minus branch shrinks the angle's excursions to nearly nothing
            and a term in a power of the angle comes out without bound (JSBSim c172x seed 3, ``Cm:alpha^2`` -8:
            alpha's stated scale uncertainty 0.98, the reported standard error 3138 on an estimate of -1.9). 0: the
            step is ``scale`` (as before).

    Returns:
        ``{"scale": u, "offset": u}``: ``|theta(+h) - theta(-h)| / 2 * u / h`` for each, ``h = u`` but for the scale
        above ``scale_step`` (0 when its input is 0).
    """
    mean = float(np.nanmean(X[rows, k_angle]))
    out = {}
    for what, u in (("scale", scale), ("offset", offset)):
        if not u > 0:
            out[what] = 0.0
            continue
        h = float(scale_step) if what == "scale" and 0.0 < scale_step < u else float(u)
        th = []
        for sgn in (1.0, -1.0):
            Xp = X.copy()
            if what == "scale":
                Xp[:, k_angle] = mean + (1.0 + sgn * h) * (X[:, k_angle] - mean)
            else:
                Xp[:, k_angle] = X[:, k_angle] + sgn * h
            A = np.nan_to_num(np.asarray(columns(Xp), float)[rows])
            th.append(np.linalg.lstsq(A, r[rows], rcond=None)[0][index])
        out[what] = float(abs(th[0] - th[1]) / 2.0 * (u / h))
    return out


def combine(parts: dict) -> float:
    """Root sum of squares of uncorrelated standard uncertainties (GUM eq. 10 with unit sensitivities);
    NaN and missing parts count as 0."""
    v = np.array([p for p in parts.values() if p is not None and np.isfinite(p)], float)
    return float(np.sqrt(np.sum(v**2))) if v.size else float("nan")
