"""The pitch gust rate's moment as a nuisance of the sparse search's Cm residual (opt-in).

The aerodynamic pitching moment depends on the body's pitch rate relative to the air, ``q - q_g``; the gyro
measures ``q``, and the model under test is evaluated with the gyro's ``q_hat = q c / (2V)``. So in turbulence
Cm's residual holds ``-Cm_q q_g c / (2V)``, a moment that no term of the library explains (its regressor is not
measured) and that is independent from one part of the flight to the next. On the search's untouched final
segment it is the largest part of Cm's residual after the injected effect: on the JSBSim ka350 (King Air 350,
82 m/s, light turbulence) the exact ``Cm:alpha^2 = -8`` gains only 51-55 % of the untouched residual, 62-76 %
with JSBSim's own gust pitch rate removed (``benchmarks/search_jsbsim_cm.py --decompose``; ``docs/benchmarks.md``,
*Twenty-fourth session, i9-misses*).

The pitch gust rate is estimated from the reconstructed wind (``FlightStates`` ``wn we wd``: mean wind plus
gusts) with MIL-F-8785C's Dryden gradient filter and Taylor's frozen field along the flight path
(:func:`gcs_sysid.estimation.gustrates.gust_rates`, frame ``"path"``: ``q_g = -(s/V)/(1 + 4b s/(pi V)) w_g``, Etkin,
*Dynamics of Atmospheric Flight*, 1972, ch. 13). Its sign relative to the aerodynamics is left free: Etkin's
``q_g = -dw_g/dx`` and JSBSim's turbulence (``FGWinds::Turbulence``, ``ttMilspec``, eq. 34: ``+d xi_w/dt / V``)
disagree (``docs/estimation.md``, gust rates). So the column ``g = q_g c / (2V)`` is fitted to Cm's residual with
a free constant (ordinary least squares; its slope reads ``-Cm_q c/(2V)``-scaled in Etkin's sign, the opposite
in JSBSim's) and ``slope (g - mean g)`` is removed from the residual on every row, before the search selects and
before any gain is measured. Nothing is named from it. The slope is fitted on the reference flight's residual
(all its rows, before its inadequacy is fitted) and the same slope is used on the flight under test, whose own
fit would take a share of any change correlated with the column (``sparse.THRESHOLDS["pitch_gust_nuisance"]``
``True``); ``"own"`` fits it on the test flight's training rows instead.

Source of the model: Etkin (1972) ch. 13 (gust gradients), MIL-F-8785C sec. 3.7.2 (Dryden form).
"""

from __future__ import annotations

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS
from .context import DiagContext

__all__ = ["pitch_gust_column", "pitch_gust_nuisance"]

_STATES = ("phi", "theta", "psi", "wn", "we", "wd")


def _moving_mean(x: np.ndarray, n: int) -> np.ndarray:
    """Centred moving mean over ``n`` samples (odd), the ends reflected; shape of ``x``."""
    h = n // 2
    xp = np.r_[x[h:0:-1], x, x[-2:-h - 2:-1]]
    c = np.cumsum(np.r_[0.0, xp])
    return (c[n:] - c[:-n]) / n


def pitch_gust_column(ctx: DiagContext, highpass_s: float = 0.0) -> np.ndarray | None:
    """The estimated pitch gust rate, normalised like ``q_hat``: ``q_g c / (2V)``, shape ``(T,)``.

    Args:
        ctx: diagnosis context; needs ``ctx.states`` ``phi theta psi`` (rad) and ``wn we wd`` (m/s, the
            reconstructed air velocity over the ground, gusts included) on ``ctx.t``, and the airspeed
            regressor ``V`` (m/s) in ``ctx.X``.
        highpass_s: > 0: the column less its centred moving mean over this many seconds. A gust gradient's
            rate lives above ``1 / (4b / (pi V))`` rad/s (0.27 s on the ka350); what the column holds below a
            few seconds is the derivative of the reconstructed wind's slow error (an alpha error along a speed
            sweep), which follows the flight's alpha trend and takes a share of an alpha^2 change.

    Returns:
        ``(T,)`` array (0 where an input is not finite), or None when a state is missing or there are fewer
        than 3 rows.
    """
    from ..estimation.ekf import dcm
    from ..estimation.gustrates import gust_rates

    st = ctx.states or {}
    if any(k not in st for k in _STATES) or len(ctx.t) < 3:
        return None
    V = np.asarray(ctx.X[:, REGRESSORS.index("V")], float)
    dt = float(np.median(np.diff(ctx.t)))
    G = gust_rates(dt, dcm(st["phi"], st["theta"], st["psi"]), np.stack([st["wn"], st["we"], st["wd"]], axis=1),
                   V, float(ctx.airframe.b), "path")
    g = G.rates[:, 1] * float(ctx.airframe.c) / (2.0 * np.where(np.isfinite(V) & (V > 1.0), V, np.inf))
    g = np.nan_to_num(g)
    if highpass_s > 0:
        n = int(round(highpass_s / dt)) | 1
        if 3 <= n < g.size:
            g = g - _moving_mean(g, n)
    return g


def pitch_gust_nuisance(ctx: DiagContext, R: np.ndarray, rows: np.ndarray,
                        slope: float | None = None, highpass_s: float = 0.0) -> tuple[np.ndarray, dict]:
    """Cm's part of the residual that the estimated pitch gust rate explains, fitted on ``rows``.

    Args:
        ctx: diagnosis context (:func:`pitch_gust_column`'s inputs).
        R: residual measured minus model, shape ``(T, 6)`` (coefficients in ``COEFFICIENTS`` order).
        rows: training row indices the slope is fitted on (at least 10).
        slope: None: fitted here; a number: this slope (the reference flight's, which carries no injected
            change for the fit to take a share of), only its level taken from ``rows``.
        highpass_s: :func:`pitch_gust_column`'s.

    Returns:
        ``(N, info)``: ``N`` of shape ``(T, 6)``, zero but for Cm, ``slope (g - mean_rows g)`` (subtract it from
        ``R``); ``info`` ``{"slope", "std_error", "t", "rms_removed", "n"}`` (slope per unit of ``q_g c/(2V)``;
        ``std_error`` the ordinary least-squares one, white residual assumed: reported, not decided on), or
        ``{"skipped": why}`` with ``N`` all zero.
    """
    T = len(ctx.t)
    N = np.zeros((T, 6))
    j = COEFFICIENTS.index("Cm")
    rows = np.asarray(rows, int)
    if not ctx.active[j]:
        return N, {"skipped": "Cm not active"}
    if rows.size < 10:
        return N, {"skipped": "fewer than 10 training rows"}
    g = pitch_gust_column(ctx, highpass_s)
    if g is None:
        return N, {"skipped": "no attitude or reconstructed wind in the states"}
    r = np.nan_to_num(np.asarray(R, float)[:, j])
    gc = g - g[rows].mean()
    rc = r[rows] - r[rows].mean()
    ss = float(gc[rows] @ gc[rows])
    if not ss > 0:
        return N, {"skipped": "no pitch gust rate on the training rows"}
    own = float(gc[rows] @ rc) / ss
    e = rc - own * gc[rows]
    se = float(np.sqrt((e @ e) / max(rows.size - 2, 1) / ss))
    used = own if slope is None else float(slope)
    N[:, j] = used * gc
    return N, {"slope": used, "own_slope": own, "std_error": se, "t": own / se if se > 0 else float("inf"),
               "slope_from": "this flight" if slope is None else "given (the reference flight's)",
               "rms_removed": float(np.std(N[rows, j])), "n": int(rows.size)}
