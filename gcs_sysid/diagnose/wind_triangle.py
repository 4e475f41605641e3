"""Pitot calibration from the flight itself: the wind triangle.

A flight-test engineer checks an airspeed system by flying the *wind triangle*: the air velocity is
the ground velocity (GPS) minus the wind, so the pitot's true airspeed must equal
``|v_gps - w|``. Over several headings (the "cloverleaf" or heading-sweep calibration) the wind and the
pitot error are solved together; on a straight flight the along-heading wind and a pitot bias are
the same unknown, and only an independent wind (the autopilot's own estimate, WIND / XKF2) separates
them, to within that estimate's systematic error.

:func:`wind_triangle` solves both cases with one generalised least-squares problem on the pitot's own
samples ``i``:

    ``V_pitot,i - |v_gps,i - w_ap,i| = b - h_i . dw + e_i``

with ``h_i`` the horizontal air-velocity direction (unit per m/s of airspeed), ``b`` the pitot bias
(m/s TAS), ``dw`` a constant correction to the wind (north, east), ``e_i`` coloured noise (gusts the
wind estimate cannot follow, the pitot's noise). Where the log carries the autopilot's wind,
``dw`` has the prior ``N(0, WIND_SYSTEMATIC_MPS^2)`` per component (that estimate's slow wander);
without it, ``w_ap`` is a constant wind solved for by Gauss-Newton with no prior (the cloverleaf: it
is only determined when the heading turns). The noise variance is the residual's, inflated by the
effective-sample factor of its autocorrelation (Bartlett window), as the coefficient fits' coloured
standard errors are (Morelli and Klein sec. 5.3).

What changed since the reference flight is ``b - b_ref``: a pitot bias the reference flight had too
is a calibration to correct, not a change (:func:`change_since_references`).

Assumption: the autopilot's wind estimate does not itself use the pitot (ArduPilot with the airspeed
not fused, ``ARSPD_USE = 0``, or a wind from turns). An estimator that fuses the biased pitot takes the
bias up in its wind, and the triangle then reads no change: a missed bias, never an invented one.

References:
    Lewis, "A Flight Test Technique Using GPS for Position Error Correction Testing", Cockpit (SETP),
    2003 (the cloverleaf); USNTPS FTM 108, ch. 9 (airspeed calibration); Cho, Kim, Lee and Kim,
    "Wind estimation and airspeed calibration using a UAV with a single-antenna GPS receiver and pitot
    tube", IEEE TAES 47(1), 2011; Morelli and Klein, *Aircraft System Identification*, 2nd ed., ch. 10.
"""

from __future__ import annotations

import numpy as np

from .regression import effective_samples

__all__ = ["WIND_SYSTEMATIC_MPS", "autopilot_wind", "wind_triangle", "triangle_gain", "change_since_references"]

#: 1-sigma systematic error (m/s, per horizontal component) of an autopilot's wind estimate over a flight:
#: its slow wander (also the pitot cause's wind check, :func:`gcs_sysid.diagnose.pitot.wind_shift`).
WIND_SYSTEMATIC_MPS = 0.3
#: Pitot samples below this true airspeed (m/s), or below half the flight's 90th percentile, are not used
#: (taxi, launch, landing).
MIN_TAS_MPS = 5.0
RHO0 = 1.225


def _pitot(flight) -> tuple[np.ndarray, np.ndarray] | None:
    """The pitot's own samples: (t (N,) s, EAS (N,) m/s), from ``airspeed`` or ``vfr_hud``."""
    for name, key in (("airspeed", "eas"), ("vfr_hud", "airspeed")):
        if flight is not None and flight.has(name) and key in flight[name].fields:
            t = np.asarray(flight[name].t, float)
            v = np.asarray(flight[name][key], float)
            ok = np.isfinite(t) & np.isfinite(v)
            if ok.sum() >= 50 and np.nanmax(v[ok]) > 1.0:
                return t[ok], v[ok]
    return None


def autopilot_wind(flight, t: np.ndarray) -> np.ndarray | None:
    """The autopilot's horizontal wind estimate at the times ``t`` (N,) s.

    Returns:
        ``(N, 2)`` north and east wind, m/s (WIND message, linear interpolation, NaN outside its
        samples); None without a ``wind`` stream with ``wn``/``we`` or with fewer than 5 finite samples.
    """
    if flight is None or not flight.has("wind"):
        return None
    s = flight["wind"]
    if not all(k in s.fields for k in ("wn", "we")):
        return None
    ts = np.asarray(s.t, float)
    out = []
    for k in ("wn", "we"):
        x = np.asarray(s[k], float)
        ok = np.isfinite(x)
        if ok.sum() < 5:
            return None
        out.append(np.interp(t, ts[ok], x[ok], left=np.nan, right=np.nan))
    return np.stack(out, axis=1)


def _samples(t_grid: np.ndarray, states: dict, valid: np.ndarray, flight):
    """The pitot's usable samples on ``valid`` rows: ``(tas (N,), v_gps (N, 3), w_ap (N, 2), has_prior)``, or None
    (no pitot, ground velocity or density; fewer than 100 usable samples). ``w_ap`` is zeros without an autopilot
    wind."""
    if not all(k in states for k in ("vn", "ve", "vd", "rho")):
        return None
    p = _pitot(flight)
    if p is None:
        return None
    tp, eas = p
    t_grid = np.asarray(t_grid, float)
    use = np.interp(tp, t_grid, np.asarray(valid, float), left=0.0, right=0.0) > 0.999
    rho = np.interp(tp, t_grid, np.asarray(states["rho"], float))
    tas = eas * np.sqrt(RHO0 / rho)
    vg = np.stack([np.interp(tp, t_grid, np.asarray(states[k], float)) for k in ("vn", "ve", "vd")], axis=1)
    use &= np.isfinite(tas) & np.isfinite(vg).all(axis=1)
    if use.sum() < 100:
        return None
    use &= tas > max(MIN_TAS_MPS, 0.5 * float(np.percentile(tas[use], 90)))
    w_ap = autopilot_wind(flight, tp)
    if w_ap is not None:
        use &= np.isfinite(w_ap).all(axis=1)
    if use.sum() < 100:
        return None
    tas, vg = tas[use], vg[use]
    prior = w_ap is not None
    w0 = w_ap[use] if prior else np.zeros((len(tas), 2))
    return tas, vg, w0, prior


def triangle_gain(t_grid: np.ndarray, states: dict, rows: np.ndarray, flight, before_mps: float,
                  after_mps: float) -> dict | None:
    """Gain of a pitot correction in the sensor's own units: the residual against the logged wind on ``rows``.

    The residual is ``V_pitot - |v_gps - w_ap| - b`` (m/s TAS) on the pitot's samples that fall in ``rows``
    (rows no fit has used: the diagnosis' untouched rows), with the autopilot's wind ``w_ap`` *as logged*
    and the pitot bias ``b`` = ``before_mps`` (what the reference flight(s) read: nothing changed) and then
    ``after_mps`` (the named bias added). Not centred: a bias *is* the residual's level. The gain in the
    sensor's own units, as for the other data-compatibility sensor causes (:mod:`gcs_sysid.diagnose.compat`:
    every sensor against the kinematics; Morelli and Klein, *Aircraft System Identification*, 2nd ed., ch. 10).

    Why the logged wind and not the wind correction :func:`wind_triangle` fits (twelfth session, branch
    i9-pitot; ``docs/diagnose.md``): that correction is fitted *together with* the bias, so keeping it while
    the bias is set back to ``before_mps`` scores a "before" the data never supported, and the bias earns a
    gain for whatever the correction traded against it. On the project's own simulated flights (two headings,
    the autopilot's wind wandering 0.3 m/s with a 20-s time constant) the joint fit reads a pitot bias of
    +0.50 +- 0.13 m/s where there is none, with a wind correction of (0.78, 0.54) m/s, 3 of its prior's standard
    errors; the residual against the logged wind has a level of -0.004 m/s there. A pitot bias is a constant
    offset of the pitot against GPS minus the wind whatever the heading, so it shows in that residual itself;
    an offset made by a fitted wind correction does not.

    Args:
        t_grid: (T,) times of the state grid, s. states, flight: as :func:`wind_triangle`.
        rows: (T,) rows of the grid to score on.
        before_mps, after_mps: the pitot bias without and with the correction, m/s TAS.

    Returns:
        ``{"rms_before", "rms_after", "level" (m/s), "percent", "n", "unit", "wind"}`` (``level``: the residual's
        mean on ``rows``), or None (no pitot, ground velocity, density or autopilot wind, or fewer than 100
        usable pitot samples in ``rows``).
    """
    smp = _samples(t_grid, states, rows, flight)
    if smp is None or not smp[3]:
        return None
    tas, vg, w0, _ = smp
    a = vg.copy()
    a[:, :2] -= w0
    r = tas - np.linalg.norm(a, axis=1)
    b = float(np.sqrt(np.mean((r - before_mps) ** 2)))
    f = float(np.sqrt(np.mean((r - after_mps) ** 2)))
    return {"rms_before": b, "rms_after": f, "level": float(np.mean(r)),
            "percent": float(100.0 * (1.0 - f / b)) if b > 0 else 0.0,
            "n": int(len(r)), "unit": "m/s", "wind": "autopilot's, as logged"}


def wind_triangle(t_grid: np.ndarray, states: dict, valid: np.ndarray, flight,
                  wind_systematic: float = WIND_SYSTEMATIC_MPS) -> dict | None:
    """Pitot bias from the wind triangle on one flight (see the module docstring).

    Args:
        t_grid: (T,) times of the state grid, s.
        states: the pipeline's states on that grid: ``vn ve vd`` (smoothed GPS ground velocity, m/s) and
            ``rho`` (air density, kg/m^3), each (T,).
        valid: (T,) rows to use (the diagnosis' valid rows).
        flight: the decoded flight: the pitot (``airspeed`` EAS or ``vfr_hud`` airspeed, m/s EAS) and,
            when present, the autopilot's wind (``wind`` ``wn we``, m/s).
        wind_systematic: 1-sigma prior of the constant correction to the autopilot's wind, m/s.

    Returns:
        None without a pitot, ground velocity or density, or with fewer than 100 usable samples; else
        ``{"bias_mps", "std_error", "wind_correction_mps" (north, east), "heading_span_deg", "n",
        "n_eff", "residual_rms_mps", "wind": "autopilot prior" | "solved (no autopilot wind)"}``.
    """
    smp = _samples(t_grid, states, valid, flight)
    if smp is None:
        return None
    tas, vg, w0, prior = smp
    dw_total = np.zeros(2)
    theta, cov, r, A = np.zeros(3), np.eye(3), np.zeros(len(tas)), np.zeros((len(tas), 3))
    for _ in range(8 if not prior else 3):       # Gauss-Newton on the wind; linear in b
        a = vg.copy()
        a[:, :2] -= w0 + dw_total[None, :]
        V = np.maximum(np.linalg.norm(a, axis=1), 1e-3)
        h = a[:, :2] / V[:, None]
        A = np.column_stack([np.ones(len(V)), -h])
        r = tas - V                               # = b - h . (dw - dw_total) + e
        # the unknowns relative to the current linearisation point: (b, dw - dw_total)
        e0, *_ = np.linalg.lstsq(A, r, rcond=None)
        res = r - A @ e0
        n_eff = effective_samples(res)
        s2 = float(np.mean(res ** 2)) * len(res) / max(n_eff, 1.0)
        info = A.T @ A / s2
        rhs = A.T @ r / s2
        if prior:                                 # dw ~ N(0, sigma^2): its deviation from the current point
            info[1:, 1:] += np.eye(2) / wind_systematic ** 2
            rhs[1:] += -dw_total / wind_systematic ** 2
        else:                                     # a tiny ridge keeps a straight flight's system solvable
            info[1:, 1:] += np.eye(2) / 1e4
        try:
            cov = np.linalg.inv(info)
        except np.linalg.LinAlgError:
            return None
        theta = cov @ rhs
        dw_total = dw_total + theta[1:]
        if np.linalg.norm(theta[1:]) < 1e-4:
            break
    res = r - A @ theta
    hd = np.degrees(np.arctan2(vg[:, 1] - w0[:, 1], vg[:, 0] - w0[:, 0]))
    span = float(np.ptp(np.degrees(np.unwrap(np.radians(hd)))))
    return {"bias_mps": float(theta[0]), "std_error": float(np.sqrt(max(cov[0, 0], 0.0))),
            "wind_correction_mps": [float(x) for x in dw_total], "heading_span_deg": span,
            "n": int(len(tas)), "n_eff": float(effective_samples(res)),
            "residual_rms_mps": float(np.sqrt(np.mean(res ** 2))),
            "wind": "autopilot prior" if prior else "solved (no autopilot wind)"}


def change_since_references(flight_cal: dict | None, ref_cals: list[dict]) -> dict | None:
    """The pitot bias's change since the reference flight(s): ``b - b_ref`` and its standard error.

    Args:
        flight_cal: :func:`wind_triangle` of the flight (None: none).
        ref_cals: :func:`wind_triangle` of each reference flight (the references' inverse-variance mean
            is the baseline; none: the baseline is 0 with no error, an absolute calibration).

    Returns:
        None without the flight's calibration, else ``{"change_mps", "std_error", "flight_mps",
        "reference_mps" (None without references), "t_statistic"}``.
    """
    if flight_cal is None:
        return None
    refs = [c for c in ref_cals if c is not None and c["std_error"] > 0]
    b, s = flight_cal["bias_mps"], flight_cal["std_error"]
    ref = None
    if refs:
        w = np.array([1.0 / c["std_error"] ** 2 for c in refs])
        ref = float(np.sum(w * [c["bias_mps"] for c in refs]) / w.sum())
        s = float(np.hypot(s, 1.0 / np.sqrt(w.sum())))
    d = b - (ref or 0.0)
    return {"change_mps": float(d), "std_error": float(s), "flight_mps": float(b), "reference_mps": ref,
            "t_statistic": float(d / s) if s > 0 else 0.0}
