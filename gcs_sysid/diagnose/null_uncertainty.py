"""The air angles' type-B uncertainty of a named change *under no change* (the naming test's null hypothesis).

A named term is a change since the reference flight, and the naming test asks whether the change exceeds what
no change could have produced (:func:`gcs_sysid.diagnose.sparse.beyond_expanded_uncertainty`: ``|change| > k u``,
GUM JCGM 100:2008 sec. 6.2-6.3, ``k = 2``). The combined uncertainty the finding *reports*
(:func:`gcs_sysid.diagnose.sparse._with_uncertainty`) carries the air angles' stated scale and offset uncertainty
through the term's *own* column times its *own* estimate (:func:`gcs_sysid.diagnose.uncertainty.angle_sensitivity`):
that sizes the change (a term of degree n in an angle whose relative scale is uncertain by ``u`` is uncertain by
``~ n u |change|``), but it is the uncertainty of the estimate under the *alternative*. It grows with the change,
so with a stated alpha-scale uncertainty above ``1 / (2 n k) ~ 0.25`` no ``alpha^2`` change of any size can pass
(c684: ``Cm:alpha^2`` -5.4 +- 7.05, 7.04 of it the stated 43 % alpha scale; ``docs/diagnose.md``).

The test's reference distribution is the estimate's distribution when nothing changed (a significance test is
computed under its null hypothesis: Lehmann and Romano, *Testing Statistical Hypotheses*, 3rd ed., sec. 3.1).
Then the coefficient the flight measures is the unchanged model's, seen through angles whose scale (about
their flight mean) and offset differ from the reference's by ``s`` and ``o``:

    R_0(t) = M(x_true(t)) - M(x(t)),  x = x_true (1 + s) (about the mean) + o,

so to first order ``R_0 ~ -(s (x - mean) + o) dM/dx`` (GUM sec. 5.1.3, a sensitivity coefficient found
numerically). What the search would read from ``R_0`` is the same chain as on the measured residual: the angle
nuisance fitted on CX and CZ and removed (:func:`gcs_sysid.diagnose.sparse.angle_nuisance`, linear in the
residual for fixed weights), then the least-squares fit of the selected terms (Morelli and Klein, *Aircraft System
Identification*, 2nd ed., sec. 5.1, eq. 5.9: ``theta = (A'A)^-1 A' r``, linear in ``r``). With ``s`` of standard
uncertainty ``u_s`` (the reconstruction's own, :func:`gcs_sysid.diagnose.uncertainty.air_data_uncertainty`: this
flight's and the reference's in quadrature) the named coefficient's type-B standard uncertainty under no change is
``|theta(R_0(+u_s)) - theta(R_0(-u_s))| / 2`` (central difference, GUM sec. 5.1.3 note), and the same for the
offset. It does not depend on the change: it is what an angle error alone makes of the *unchanged* model on this
flight (its manoeuvres, its trim, its selected columns). Combined with the type-A components (this flight's fit,
the reference's, the reference inadequacy's jackknife; GUM eq. 10) it gives the standard uncertainty of the
estimate under the null, which the naming test compares the change with (``sparse.THRESHOLDS["coverage_under_null"]``;
nineteenth session, branch i9-null). The reported ``std_error`` is left as it is (the estimate's own interval).

The angle's *curvature* (twentieth session, branch i9-curv): the aided alpha carries a flight-common error
``c (x - mean)^2`` as well, the aiding's fitted lift curvature read as the angle's
(:attr:`gcs_sysid.estimation.airangles.AxisFit.curvature_sigma`; against JSBSim's alpha, t6 clean seed 14 -0.78 /rad
and its reference +0.36: the between-flight difference makes ``CZ:alpha^2`` -5.45 on a clean flight). It is carried
the same way, ``x_true = x - c ((x - mean)^2 - mean((x - mean)^2))`` (centred over the fit's rows, so that it moves
no mean: the offset is its own component), at ``c = +- u_c`` (``sparse.THRESHOLDS["coverage_curvature"]``). A
measured angle's error entering an equation-error fit through the model is the errors-in-the-regressors case of
Morelli and Klein ch. 5; its type-B propagation is GUM sec. 5.1.3 as above.

Left out: the reference's inadequacy (the ridge of :func:`gcs_sysid.diagnose.sparse.sparse_search`) is not
differentiated, only the model (on the c684 it is 0.0014 RMS in Cm against a residual of 0.008).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["null_residual", "angle_null_sensitivity"]


def null_residual(predict: Callable[[np.ndarray], np.ndarray], X: np.ndarray, rows: np.ndarray, k_angle: int,
                  what: str, u: float, along: int | None = None) -> np.ndarray:
    """Half the difference of the no-change residual at an angle error of ``+u`` and ``-u``.

    Args:
        predict: ``X -> (T, 6)`` the unchanged model's coefficients on regressors ``X`` (finite; inactive
            coefficients 0). X: (T, 10) the measured regressors. rows: (N,) the rows the angle's mean is taken over.
        k_angle: column of the angle in ``X``. what: ``"scale"`` (relative, about the mean over ``rows``) or
            ``"offset"`` (rad) or ``"curvature"`` (1/rad: ``x = x_true + s ((x - mean)^2 - m2)``, ``m2`` the mean of
            ``(x - mean)^2`` over ``rows``; first order in ``s``) or ``"along"`` (rad per unit of regressor
            ``along``: ``x = x_true + s (X[:, along] - mean)``, the mean over ``rows``: an aided angle's error that
            follows another regressor, e.g. the elevator, ``gcs_sysid.diagnose.uncertainty.elevator_loading``).
            u: the error's standard uncertainty (> 0). along: the regressor's column (``what="along"`` only).

    Returns:
        (T, 6) ``(R_0(+u) - R_0(-u)) / 2`` with ``R_0(s) = M(x_true) - M(x)``: the measured angle ``x`` is the true
        one scaled by ``1 + s`` (shifted by ``s``), so ``x_true = mean + (x - mean) / (1 + s)`` (``x - s``).

    Raises:
        ValueError: ``what`` not ``"scale"``, ``"offset"``, ``"curvature"`` or ``"along"``, or ``"along"``
            without ``along``.
    """
    if what not in ("scale", "offset", "curvature", "along"):
        raise ValueError(f"null_residual: what must be 'scale', 'offset', 'curvature' or 'along', got {what!r}")
    if what == "along" and along is None:
        raise ValueError("null_residual: what='along' needs the column 'along'")
    X = np.nan_to_num(np.asarray(X, float))
    dv = X[:, along] - float(np.mean(X[rows, along])) if what == "along" else None
    mean = float(np.mean(X[rows, k_angle]))
    d2 = (X[:, k_angle] - mean) ** 2
    d2 = d2 - float(np.mean(d2[rows]))
    out = []
    for sgn in (1.0, -1.0):
        Xt = X.copy()
        if what == "scale":
            Xt[:, k_angle] = mean + (X[:, k_angle] - mean) / (1.0 + sgn * u)
        elif what == "curvature":
            Xt[:, k_angle] = X[:, k_angle] - sgn * u * d2
        elif what == "along":
            Xt[:, k_angle] = X[:, k_angle] - sgn * u * dv
        else:
            Xt[:, k_angle] = X[:, k_angle] - sgn * u
        out.append(np.nan_to_num(np.asarray(predict(Xt), float)))
    return (out[0] - out[1]) / 2.0


def angle_null_sensitivity(predict: Callable[[np.ndarray], np.ndarray], X: np.ndarray, A: np.ndarray, index: int,
                           j: int, rows: np.ndarray, k_angle: int, scale: float, offset: float,
                           nuisance: Callable[[np.ndarray], np.ndarray] | None = None,
                           curvature: float = 0.0, map_delta_e: float = 0.0, k_delta_e: int | None = None,
                           scale_step: float = 0.0, along: dict[str, tuple[int, float]] | None = None) -> dict:
    """Type-B standard uncertainty of one fitted coefficient under no change, from an angle's scale, offset and
    curvature.

    Args:
        predict: see :func:`null_residual`. X: (T, 10) the measured regressors (before any nuisance correction).
        A: (T, P) the fit's columns (constant first), as the search built them; held fixed (the estimator's
            columns are the measured ones). index: the named coefficient's column in ``A``. j: the coefficient
            (0-5, ``COEFFICIENTS``) the term was fitted in. rows: (N,) the fit's rows. k_angle: the angle's column
            in ``X``. scale: standard uncertainty of the angle's relative scale. offset: of its offset, rad.
        nuisance: ``R (T, 6) -> R (T, 6)`` what the search removes before fitting (the angle nuisance, linear
            in ``R``), applied to the no-change residual as to the measured one; None: nothing removed.
        curvature: standard uncertainty of the angle's curvature error, 1/rad
            (:attr:`gcs_sysid.estimation.airangles.AxisFit.curvature_sigma`); 0: left out (and not in the result).
        map_delta_e: the difference of the two flights' aided-alpha loadings on the elevator, rad/rad
            (``air_data_uncertainty(...)["alpha"]["map_delta_e"]``, ``sparse.THRESHOLDS["coverage_map_delta_e"]``),
            carried as the angle's error along column ``k_delta_e``; 0 or ``k_delta_e`` None: left out (and not in
            the result).
        scale_step: the largest relative step of the scale's central difference (``sparse.THRESHOLDS
            ["coverage_scale_step"]``; twenty-first session, branch i9-aidnull); with ``scale > scale_step > 0`` the
            difference is taken at ``+- scale_step`` and multiplied by ``scale / scale_step``: the first-order
            sensitivity coefficient times the standard uncertainty (GUM eq. 10), instead of the difference at ``+-
            scale``, which for a stated scale uncertainty near 1 reads the model at ``x_true = mean + (x - mean) /
            (1 - scale)``, the pole of the scale's parametrization (c172p seed 2, the alpha aiding profiled: 0.976
            -> alpha's excursions 42 times the measured, ``Cn:delta_a`` +- 0.104 under no change against 0.0017
            from the fits). 0: the step is ``scale`` (as before).

        along: ``{name: (column, u)}``: the angle's error along regressor ``column`` of ``X``, ``u`` rad per unit (the
            aided sideslip's loadings on its side-force model's other columns,
            :func:`gcs_sysid.diagnose.uncertainty.sideslip_loadings`; ``sparse.THRESHOLDS["coverage_beta_along"]``,
            forty-second session), each carried as ``map_delta_e`` is; None: none.

    Returns:
        ``{"scale": u, "offset": u}`` and, with ``curvature > 0``, ``"curvature": u``, with ``map_delta_e > 0``,
        ``"map_delta_e": u``, and ``"along_<name>": u`` for each entry of ``along`` (units of the coefficient; 0 where
        the input uncertainty is 0).
    """
    out = {}
    An = np.nan_to_num(np.asarray(A, float)[rows])
    parts = (("scale", scale), ("offset", offset)) + ((("curvature", curvature),) if curvature > 0 else ())
    cols_along = {}
    if map_delta_e > 0 and k_delta_e is not None:
        parts = parts + (("map_delta_e", map_delta_e),)
        cols_along["map_delta_e"] = k_delta_e
    for name, (col, u) in (along or {}).items():
        parts = parts + ((f"along_{name}", u),)
        cols_along[f"along_{name}"] = col
    for what, u in parts:
        if not u > 0:
            out[what] = 0.0
            continue
        if what in cols_along:
            d = null_residual(predict, X, rows, k_angle, "along", float(u), along=cols_along[what])
        elif what == "scale" and 0.0 < scale_step < u:
            # first order: the difference at a step where 1 / (1 + s) is linear, times u over the step
            d = null_residual(predict, X, rows, k_angle, what, float(scale_step)) * (float(u) / float(scale_step))
        else:
            d = null_residual(predict, X, rows, k_angle, what, float(u))
        if nuisance is not None:
            d = nuisance(d)
        r = np.nan_to_num(d[rows, j])
        out[what] = float(abs(np.linalg.lstsq(An, r - r.mean(), rcond=None)[0][index]))
    return out
