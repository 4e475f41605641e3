"""The gyro's rates as stand-ins for the air-relative rates: their flight-common errors, stated for the band at
exact conditions.

The aerodynamics reads the body's rotation relative to the air, ``p - p_g`` and ``r - r_g``; the model's inputs are the
gyro's ``p_hat`` and ``r_hat`` (the training targets of Cl, and optionally Cn, are moved towards the air's rate by
:func:`gcs_sysid.aero.gustfilter.air_roll_target` and :func:`gcs_sysid.aero.airyaw.air_yaw_target`, the inputs not).
A model learned on such inputs is off at exact conditions (``gcs-sysid predict`` at the air-relative rates) by the
errors in variables the rotational gusts leave in its slopes. Two are stated here, in the form the band at exact
conditions already carries for the aided air angles (``docs/gp.md``, "The band at exact conditions"; the model's
``scale_var`` and ``map_cov``):

* **Roll: a scale error of ``p_hat``.** With ``p_hat = p_hat_air + p_hat_g`` and the rolling gust uncorrelated with the
  air-relative rate, a slope fitted on the gyro's rate is the air-rate slope times the reliability ratio
  ``var(p_hat_air) / var(p_hat) = 1 - rho``, ``rho = var(p_hat_g) / var(p_hat)`` (Fuller, *Measurement Error Models*,
  Wiley 1987, sec. 1.1: the attenuation of the least-squares slope). At exact conditions the model is then off by
  about ``dm/dp_hat rho (p_hat - mean p_hat)`` (first order in ``rho``: the model's own slope stands in for the true
  one; exactly it is ``rho / (1 - rho)`` of the model's slope): the scale term with ``scale_var[p_hat] = rho^2``.
  ``rho`` is estimated as ``var(g) / var(p_hat)`` over the roll fit's training rows, ``g`` the filter-error method's
  smoothed rolling gust (:func:`gcs_sysid.aero.gustfilter.fit_roll_gust`). Measured on 24 JSBSim flights of the
  tuning roster (``docs/benchmarks.md``, "Sixty-fourth session"): the GP's ``Cl_p`` reads 0.03-0.66 of the truth's
  too weak (median 0.23); the roll fit's instrumented ``Cl_p`` is too weak as well (median 0.15).
* **Yaw: a linear map of ``r_hat``'s error.** The yaw gust rate moves with the sideslip (a directionally stable
  aircraft turns into a lateral gust; correlation -0.23 to -0.76 on JSBSim's flights), so the gyro's ``r_hat`` carries
  an error ``r_hat_g`` that follows the regressors: ``e_r(x) = M (x - mean x)``. As for the aided angles
  (:func:`gcs_sysid.estimation.airangles._map_disagreement`), ``M`` is the least-squares slope of the estimated
  ``r_hat_g`` (:func:`gcs_sysid.aero.airyaw.yaw_gust_hat`, the path-yaw frame) on the centred training regressors,
  and the stated second moment is ``M M^T + Cov_jk(M)`` (delete-a-block jackknife, Kuensch 1989).

Both change the band at exact conditions only: the model's mean and the two bands at the flight's own regressors are
untouched (there the rates are the gyro's, as in training).
"""

from __future__ import annotations

import numpy as np

from .table import REGRESSORS

__all__ = ["RATE_ERRORS", "roll_rate_scale", "roll_rate_variances", "roll_fit_refusal", "yaw_rate_map",
           "stated_rate_errors"]

#: Whether the replay states the rates' errors for the band at exact conditions (``ReplayOptions.rate_errors`` None).
#: On since the sixty-fourth session, by a rule written before its run on fresh JSBSim flights (seeds 10-12): Cl's
#: pooled coverage there 69.5 -> 94.3 %, issue 8's per-coefficient band count +46/-17 and +48/-14 at two GP seeds
#: (``docs/benchmarks.md``, "Sixty-fourth session, lead"); the six-output flight mean loses (+15/-18, +15/-17).
RATE_ERRORS = True
_MIN_ROWS = 150
_IP, _IR = REGRESSORS.index("p_hat"), REGRESSORS.index("r_hat")


def roll_rate_scale(fit, table, train: np.ndarray) -> float | None:
    """``rho``, the rolling gust's variance over the gyro's ``p_hat``'s on the roll fit's training rows.

    Args:
        fit: :class:`gcs_sysid.aero.gustfilter.RollGustFit` (``g`` ``(T,)`` the smoothed ``p_hat_g``, ``used``
            ``(T,)`` bool).
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` (``X`` ``(T, 10)`` with the gyro's ``p_hat``).
        train: ``(T,)`` bool, the training rows.

    Returns:
        ``rho`` (dimensionless, >= 0; the relative scale error's standard deviation), or None with fewer than 150
        rows or a constant ``p_hat``.

    Raises:
        ValueError: ``train`` or the fit's arrays not ``(T,)``.

    Source: Fuller (1987) sec. 1.1 (the reliability ratio).
    """
    v = roll_rate_variances(fit, table, train)
    return None if v is None else v[0] / v[1]


def roll_rate_variances(fit, table, train: np.ndarray) -> tuple[float, float] | None:
    """The two variances :func:`roll_rate_scale` divides: ``(var(g), var(p_hat))`` over the roll fit's training rows.

    Pooled over several stretches of one flight (the live learner's windows, :mod:`gcs_sysid.aero.errorpool`) the
    ratio of the row-weighted sums is the flight's ``rho``; a mean of the stretches' ratios would let one stretch with
    little roll excitation (a small ``var(p_hat)``) dominate.

    Args:
        fit, table, train: as :func:`roll_rate_scale`.

    Returns:
        ``(var_g, var_p)`` (``p_hat``'s units squared, ``var_p > 0``), or None with fewer than 150 rows or a constant
        ``p_hat``.

    Raises:
        ValueError: ``train`` or the fit's arrays not ``(T,)``.
    """
    T = len(table.t)
    g, used, train = np.asarray(fit.g, float), np.asarray(fit.used, bool), np.asarray(train, bool)
    if g.shape != (T,) or used.shape != (T,) or train.shape != (T,):
        raise ValueError(f"roll_rate_scale: the fit's g and used and train must be ({T},), got {g.shape}, "
                         f"{used.shape}, {train.shape}")
    p = np.asarray(table.X, float)[:, _IP]
    rows = used & train & np.isfinite(g) & np.isfinite(p)
    if rows.sum() < _MIN_ROWS or not np.var(p[rows]) > 0:
        return None
    return float(np.var(g[rows])), float(np.var(p[rows]))


def roll_fit_refusal(why: str) -> str:
    """Why there is no roll fit, in this module's words: :func:`gcs_sysid.aero.gustfilter.air_roll_fit`'s refusal
    (said in the gust filter's words, ``"gust filter not run: ..."``) as ``"no roll fit: ..."``."""
    for pre in ("gust filter not run: ", "gust filter not applied: "):
        why = "no roll fit: " + why[len(pre):] if why.startswith(pre) else why
    return why


def yaw_rate_map(table, r_hat_g: np.ndarray, train: np.ndarray, block_s: float = 15.0) -> np.ndarray | None:
    """Second moment of the gyro's ``r_hat``'s flight-common linear error along the regressors, ``(10, 10)``.

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` (``t`` ``(T,)`` s, ``X`` ``(T, 10)``, ``valid``).
        r_hat_g: ``(T,)`` the yaw gust rate as a hat (:func:`gcs_sysid.aero.airyaw.yaw_gust_hat`).
        train: ``(T,)`` bool, the training rows.
        block_s: the jackknife's block length, s.

    Returns:
        ``M M^T + Cov_jk(M)`` over :data:`~gcs_sysid.aero.table.REGRESSORS` (``r_hat^2 / (x_d x_e)``; zero rows and
        columns for constant regressors), or None with fewer than 150 rows or a rank-deficient fit.

    Raises:
        ValueError: ``r_hat_g`` or ``train`` not ``(T,)``.

    Source: the aided angles' map (:func:`gcs_sysid.estimation.airangles._map_disagreement`, the same
    :func:`gcs_sysid.jackknife.slope_second_moment`); Kuensch (1989).
    """
    from ..jackknife import slope_second_moment

    T = len(table.t)
    g, train = np.asarray(r_hat_g, float), np.asarray(train, bool)
    if g.shape != (T,) or train.shape != (T,):
        raise ValueError(f"yaw_rate_map: r_hat_g and train must be ({T},), got {g.shape} and {train.shape}")
    X = np.asarray(table.X, float)
    rows = train & np.asarray(table.valid, bool) & np.isfinite(g) & np.all(np.isfinite(X), axis=1)
    if rows.sum() < _MIN_ROWS:
        return None
    keep = np.nonzero(X[rows].std(axis=0) > 1e-12)[0]
    C = slope_second_moment(np.asarray(table.t, float)[rows], X[rows][:, keep] - X[rows][:, keep].mean(axis=0),
                            g[rows], block_s)
    if C is None:
        return None
    out = np.zeros((len(REGRESSORS), len(REGRESSORS)))
    out[np.ix_(keep, keep)] = C
    return out


def stated_rate_errors(table, train: np.ndarray, roll_fit=None,
                       r_hat_g: np.ndarray | None = None) -> tuple[np.ndarray | None, np.ndarray | None, str]:
    """The table's stated regressor errors with the rates' added: ``(scale_var, map_cov, note)``.

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable`; its ``x_scale_var`` ``(10,)`` and ``x_map_cov``
            ``(10, 10, 10)`` (either None) are copied, never changed.
        train: ``(T,)`` bool, the training rows.
        roll_fit: the air-rate pair's :class:`~gcs_sysid.aero.gustfilter.RollGustFit` (or why there is none, a str
            said in the note, or None): ``scale_var[p_hat] = rho^2`` (:func:`roll_rate_scale`).
        r_hat_g: ``(T,)`` the yaw gust rate as a hat, or None (none known, or ``r_hat`` is the air's already):
            ``map_cov[r_hat]`` (:func:`yaw_rate_map`).

    Returns:
        ``scale_var`` ``(10,)`` and ``map_cov`` ``(10, 10, 10)`` for
        :func:`gcs_sysid.gp.discrepancy.with_offset_covariance` (each the table's where nothing is added, None where
        the table had none and nothing is added), and a one-line note of what was stated and what was not.

    Raises:
        ValueError: from :func:`roll_rate_scale` and :func:`yaw_rate_map`.
    """
    D = len(REGRESSORS)
    sv = None if table.x_scale_var is None else np.array(table.x_scale_var, float)
    mc = None if table.x_map_cov is None else np.array(table.x_map_cov, float)
    said = []
    rho = None if roll_fit is None or isinstance(roll_fit, str) else roll_rate_scale(roll_fit, table, train)
    if rho is None:
        if isinstance(roll_fit, str):
            why = roll_fit_refusal(roll_fit)
        else:
            why = "no roll fit" if roll_fit is None else "too few rows"
        said.append(f"p_hat: none ({why})")
    else:
        sv = np.zeros(D) if sv is None else sv
        sv[_IP] = rho**2
        said.append(f"p_hat scale error {rho:.2f} (the rolling gust's share of its variance)")
    C = None if r_hat_g is None else yaw_rate_map(table, r_hat_g, train)
    if C is None:
        said.append("r_hat: none (" + ("no yaw gust rate given" if r_hat_g is None else "too few rows") + ")")
    else:
        mc = np.zeros((D, D, D)) if mc is None else mc
        mc[_IR] = C
        said.append(f"r_hat linear error (its slope on beta {np.sqrt(C[1, 1]):.3f} rms, the yaw gust rate's)")
    return sv, mc, "rates' errors in the band at exact conditions: " + "; ".join(said)
