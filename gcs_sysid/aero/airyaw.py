"""The yaw gust rate in the moments' training targets: Cn (and optionally Cl) learned at the air-relative yaw rate,
every input left at the gyro's rates.

The aerodynamics reads the body's yaw rate relative to the air, ``r - r_g`` (Etkin, *Dynamics of Atmospheric Flight*,
1972, ch. 13; JSBSim's ``FGAuxiliary``: ``vAeroPQR = vPQR - TurbPQR``); a gyro measures ``r``. In a lateral gust field
a directionally stable aircraft turns into the gust, so its sideslip and the yaw gust rate
``r_g = +(s/V)/(1 + 3b s/(pi V)) v_g`` (MIL-F-8785C's Dryden form, :mod:`gcs_sysid.estimation.gustrates`) move
together: on JSBSim's flights their correlation is -0.23 to -0.76, and a fit of Cn or Cl at the gyro's ``r`` puts
``Cn_r r_g`` and ``Cl_r r_g`` into ``Cn_beta`` and ``Cl_beta`` (the rascal's exact ``Cn_beta`` 0.129 fits as 0.091;
``docs/benchmarks.md``, "Sixty-third session, lead").

Taking ``r_g`` out of the shared input (``ReplayOptions.gust_rates="path-yaw"``) moves every output, CY included,
whose slopes the sideslip aiding built at the gyro's rate (the aided sideslip is made from CY with the aiding's own
rate slope, and the GP's CY returns that model). Here, as :func:`gcs_sysid.aero.gustfilter.air_roll_target` does for
the rolling gust, only the targets of :data:`AIR_YAW_OUTPUTS` move: on the training rows

    C + C_r r_hat_g,        r_hat_g = r_g b / (2 V)

with ``C_r`` the slope of ``r_hat - r_hat_g`` in a least-squares fit of ``C`` on ``[1, alpha, beta, p_hat,
r_hat - r_hat_g, delta_a, delta_r]``. ``C`` on a training row is then what the aircraft's moment would be with its
air-relative yaw rate equal to the gyro's ``r_hat``: a model learned on the gyro's ``r_hat`` with this target is a model
at the air-relative rate, to be asked at ``r_hat - r_hat_g`` where it predicts a measured moment (the held-out rows) and
at the air's own rate at exact conditions. A change of the training target only (Jategaonkar, *Flight Vehicle System
Identification*, 2nd ed., AIAA 2015, ch. 5: the turbulence's state estimate used offline).
"""

from __future__ import annotations

import numpy as np

from .table import COEFFICIENTS, REGRESSORS

__all__ = ["AIR_YAW", "AIR_YAW_OUTPUTS", "yaw_gust_hat", "air_yaw_target"]

#: Whether the replay trains :data:`AIR_YAW_OUTPUTS` on the air-relative yaw rate (``ReplayOptions.air_yaw`` None).
#: Off: opt-in (sixty-third session; ``docs/benchmarks.md``, "Sixty-third session, lead").
AIR_YAW = False
#: The outputs whose training target moves to the air-relative yaw rate, and which are asked at ``r_hat - r_hat_g``.
#: Cn alone: with Cl too, Cl held out got worse (17.3 -> 20.3 %, median of 75 JSBSim flights) and lost 45 of 48 flights
#: against the fair least-squares line (the sixty-third session's rule 3, ``docs/benchmarks.md``).
AIR_YAW_OUTPUTS = ("Cn",)
#: The lateral model whose ``r_hat`` slope the correction uses
_LAT = ("alpha", "beta", "p_hat", "r_hat", "delta_a", "delta_r")
_MIN_ROWS = 50


def yaw_gust_hat(states, b: float) -> tuple[np.ndarray | None, str]:
    """The yaw gust rate as a hat, ``r_hat_g = r_g b / (2 V)``, from the states' reconstructed wind.

    ``r_g`` is :func:`gcs_sysid.estimation.gustrates.gust_rates`' frame ``"path-yaw"`` (body axes, Etkin's sign, the
    MIL-F-8785C Dryden lag over ``3 b / (pi V)``).

    Args:
        states: smoothed states with ``phi theta psi`` (rad), ``wn we wd`` (m/s, NED) and ``V`` (m/s) on a uniform
            grid ``t`` (s).
        b: wing span, m.

    Returns:
        ``((T,) r_hat_g, note)``; ``(None, why)`` when a field is missing or the grid is shorter than 3 samples.
    """
    from ..estimation.gustrates import states_gust_hat

    g, why = states_gust_hat(states, b, "path-yaw", "r", b)
    return g, why if g is not None else why.replace("no gust rate", "no yaw gust rate")


def air_yaw_target(table, Y: np.ndarray, r_hat_g: np.ndarray, train: np.ndarray,
                   outputs: tuple[str, ...] | None = None) -> tuple[np.ndarray, dict]:
    """The training target of ``outputs`` at the air-relative yaw rate, ``C + C_r r_hat_g`` (module docstring), every
    other output and row as given.

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` (``X`` ``(T, 10)`` with the gyro's ``r_hat``).
        Y: ``(T, 6)`` the target so far (e.g. :func:`gcs_sysid.aero.gustfilter.air_roll_target`'s, Cl at the
            air-relative roll rate).
        r_hat_g: ``(T,)`` the yaw gust rate as a hat (:func:`yaw_gust_hat`).
        train: ``(T,)`` bool, the training rows (the only rows fitted or changed).
        outputs: names among ``Cl``, ``Cn``; None: :data:`AIR_YAW_OUTPUTS`.

    Returns:
        ``(Y_new, info)``: a copy of ``Y`` with the outputs' columns changed on the fitted rows, and ``{"slopes":
        {output: C_r}, "rows": (T,) bool, "sd": {output: SD of the correction}, "note": str}``; an output with
        fewer than 50 usable rows or a singular fit is left unchanged (said in the note).

    Raises:
        ValueError: ``Y``, ``r_hat_g`` or ``train`` not of the table's length.
    """
    outputs = AIR_YAW_OUTPUTS if outputs is None else tuple(outputs)
    T = len(table.t)
    Y, g, train = np.asarray(Y, float), np.asarray(r_hat_g, float), np.asarray(train, bool)
    if Y.shape != (T, len(COEFFICIENTS)) or g.shape != (T,) or train.shape != (T,):
        raise ValueError(f"air_yaw_target: expected Y ({T}, {len(COEFFICIENTS)}), r_hat_g and train ({T},); got "
                         f"{Y.shape}, {g.shape}, {train.shape}")
    cols = [REGRESSORS.index(k) for k in _LAT]
    X = np.asarray(table.X, float)[:, cols].copy()
    X[:, _LAT.index("r_hat")] -= g
    rows = train & np.asarray(table.valid, bool) & np.isfinite(g) & np.all(np.isfinite(X), axis=1)
    out, slopes, sds, said = Y.copy(), {}, {}, []
    for name in outputs:
        k = COEFFICIENTS.index(name)
        ok = rows & np.isfinite(Y[:, k])
        if ok.sum() < _MIN_ROWS:
            said.append(f"{name} unchanged ({int(ok.sum())} rows)")
            continue
        A = np.column_stack([np.ones(int(ok.sum())), X[ok]])
        c, _, rank, _ = np.linalg.lstsq(A, Y[ok, k], rcond=None)
        if rank < A.shape[1]:
            said.append(f"{name} unchanged (singular lateral fit)")
            continue
        slope = float(c[1 + _LAT.index("r_hat")])
        out[ok, k] = Y[ok, k] + slope * g[ok]
        slopes[name], sds[name] = slope, float(np.std(slope * g[ok]))
        said.append(f"{name} + {name}_r r_hat_g ({name}_r {slope:+.3g} at the air-relative rate; correction SD "
                    f"{sds[name]:.2g})")
    g_sd = float(np.nanstd(g[rows])) if rows.any() else 0.0
    note = (f"yaw gust rate in the training targets ({' and '.join(outputs)} learned at the air-relative yaw "
            f"rate, inputs at the gyro's): {'; '.join(said)}; r_hat_g SD {g_sd:.2g}")
    return out, {"slopes": slopes, "rows": rows, "sd": sds, "note": note}
