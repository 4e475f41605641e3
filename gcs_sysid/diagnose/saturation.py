"""A servo output flat at its end stop: saturation (the demand asks for more) or a failure at full throw.

A surface whose servo output holds one value while the autopilot's demand moves is the
signature of ArduPlane's output failure (:mod:`gcs_sysid.diagnose.faults`). A healthy loop
shows the same flat output when it asks for more deflection than the surface has: the output
rides its end stop (``SERVOn_MIN`` / ``SERVOn_MAX``, or the airframe's deflection limit)
until the demand comes back within the throw. The two differ in what the demand and the
aircraft do during the flat run:

- **saturation**: the demand asks for *more* than the stop on the stop's side for (nearly) the
  whole run, and the aircraft keeps responding to the surface it has: its attitude moves
  towards the demand (the attitude error and the attitude's rate of change agree in sign);
- **stuck at full throw**: the demand moves back inside the throw (the autopilot asks for less,
  or the other way) while the output stays at the stop, or the aircraft moves away from the
  demand.

"The demand asks for more" is read from the attitude error of the axis (NAV_CONTROLLER_OUTPUT's
demand minus ATTITUDE): it keeps pushing the output into the stop (its sign times the sign of the
loop's gain, on the stop's side) for at least ``sat_min_beyond`` of the run. The loop's gain comes
from a linear model of the channel's PWM on that error and the axis body rate (a PD law, the form
of ArduPlane's attitude controllers), fitted by least squares on the samples of the ``sat_fit_s``
seconds before the run that are not at a stop; its error term must be significant
(``|t| >= sat_min_t``). Where that model explains the output well before the run
(``R^2 >= sat_min_r2``) and, evaluated during the run, puts the demand back inside the throw, it
vetoes saturation (a weak model, from a quiet axis with a few us of travel, is not trusted to
extrapolate). Without the autopilot's demand in the log (no NAV_CONTROLLER_OUTPUT) nothing is
claimed and the run is judged as before. Thresholds: :class:`~gcs_sysid.diagnose.faults.FaultThresholds`
(``sat_*``), set on the project's simulation and checked on the ALFA flights.
"""

from __future__ import annotations

import numpy as np

__all__ = ["end_stops", "saturation_check"]


def end_stops(servo) -> np.ndarray:
    """PWM values (us) where a servo's output ends: its PWM range and its deflection limits.

    Args:
        servo: :class:`~gcs_sysid.airframe.Servo`.

    Returns:
        (4,) PWM, us: ``pwm_min``, ``pwm_max`` and the PWM of ``limit_min`` and ``limit_max``.
    """
    lim = servo.pwm(np.array([servo.limit_min, servo.limit_max]))
    return np.array([servo.pwm_min, servo.pwm_max, float(lim[0]), float(lim[1])], float)


def _interp(t_src, x, t):
    return np.interp(t, t_src, np.asarray(x, float), left=np.nan, right=np.nan)


def saturation_check(t: np.ndarray, pwm: np.ndarray, i0: int, i1: int, servo, error: tuple | None,
                     rate: tuple | None, th) -> dict | None:
    """Is a frozen run of a surface channel a saturation (output at its stop, demand beyond it)?

    Args:
        t: servo sample times (N,), s. pwm: the channel's PWM (N,), us.
        i0, i1: the frozen run, inclusive indices into ``t``.
        servo: the channel's :class:`~gcs_sysid.airframe.Servo` (end stops, trim).
        error: ``(t_e, e, att)`` the autopilot's attitude error of the axis (demand minus attitude) and the
            attitude, rad, on the demand's own times (NAV_CONTROLLER_OUTPUT); None when the log has no demand.
        rate: ``(t_r, w)`` the axis body rate, rad/s, on its own times; None when missing.
        th: :class:`~gcs_sysid.diagnose.faults.FaultThresholds` (``sat_*`` fields).

    Returns:
        None when the run is not at an end stop; otherwise a dict (JSON-able) with ``at_stop_us``,
        ``side`` (+1 upper, -1 lower), ``push_share`` (share of the run with the error pushing into the
        stop), ``error_t_statistic``, ``demand_model_r2``, ``beyond_share`` (share of the run with the
        modelled demand at or beyond the stop), ``toward_share`` (share of the run with the attitude
        moving towards the demand), ``saturated`` (bool) and ``why`` (one line).
    """
    stops = end_stops(servo)
    frozen = float(pwm[i0])
    k = int(np.argmin(np.abs(stops - frozen)))
    if abs(stops[k] - frozen) > th.sat_stop_tol_us:
        return None
    side = 1.0 if frozen > servo.pwm_trim else -1.0
    out: dict = {"at_stop_us": float(stops[k]), "side": int(side), "demand_model_r2": None, "beyond_share": None,
                 "toward_share": None, "saturated": False}
    if error is None:
        out["why"] = "at its end stop, but the log has no autopilot demand to tell saturation from a failure"
        return out
    t0, t1 = float(t[i0]), float(t[i1])
    te, e, att = error
    e_s = _interp(te, e, t)
    w_s = _interp(rate[0], rate[1], t) if rate is not None else np.zeros(len(t))
    at_stop = np.min(np.abs(pwm[:, None] - stops[None, :]), axis=1) <= th.sat_stop_tol_us
    fit = (t >= t0 - th.sat_fit_s) & (t < t0) & ~at_stop & np.isfinite(e_s) & np.isfinite(w_s) & np.isfinite(pwm)
    run = (t >= t0) & (t <= t1) & np.isfinite(e_s) & np.isfinite(w_s)
    if fit.sum() < 10 or run.sum() < 3:
        out["why"] = "at its end stop, too few samples before the run to model the demand"
        return out
    A = np.column_stack([np.ones(fit.sum()), e_s[fit], w_s[fit]])
    coef, *_ = np.linalg.lstsq(A, pwm[fit], rcond=None)
    res = pwm[fit] - A @ coef
    ss = float(np.sum((pwm[fit] - pwm[fit].mean()) ** 2))
    r2 = 1.0 - float(np.sum(res**2)) / ss if ss > 0 else 0.0
    s2 = float(np.sum(res**2)) / max(fit.sum() - 3, 1)
    cov = s2 * np.linalg.pinv(A.T @ A)
    t_err = float(coef[1] / np.sqrt(cov[1, 1])) if cov[1, 1] > 0 else 0.0
    demand = coef[0] + coef[1] * e_s[run] + coef[2] * w_s[run]
    beyond = float(np.mean(side * (demand - frozen) >= 0.0))
    # where the PWM model is weak (a quiet axis before the run), the sign of the attitude error alone:
    # does the error keep pushing the output into the stop (the error's sign learnt from the same fit)?
    push = float(np.mean(side * np.sign(coef[1]) * e_s[run] > 0.0))
    # the aircraft still answers the surface it has: the attitude moves towards the demand
    m = (te >= t0) & (te <= t1)
    toward = None
    if m.sum() >= 3:
        att_rate = np.gradient(np.asarray(att, float)[m], np.asarray(te, float)[m])
        ee = np.asarray(e, float)[m]
        ok = np.isfinite(att_rate) & np.isfinite(ee) & (ee != 0) & (att_rate != 0)
        toward = float(np.mean(att_rate[ok] * ee[ok] > 0)) if ok.any() else None
    out.update({"demand_model_r2": float(r2), "beyond_share": beyond, "push_share": push,
                "error_t_statistic": t_err, "toward_share": toward,
                "demand_model_us": {"1": float(coef[0]), "error_per_rad": float(coef[1]),
                                    "rate_per_rad_s": float(coef[2])}})
    # the error pushes into the stop; a PWM model that explains the output well before the run can veto it
    # (it says the demand is back inside the throw); a weak one (a quiet axis) is not trusted to extrapolate
    veto = r2 >= th.sat_min_r2 and beyond < 1.0 - th.sat_min_beyond
    asks_more = abs(t_err) >= th.sat_min_t and push >= th.sat_min_beyond and not veto
    how = (f"the attitude error pushes into the stop for {100 * push:.0f} % of the run (error term t {t_err:.1f}); "
           f"the PWM model (R^2 {r2:.2f}) puts the demand at or beyond the stop for {100 * beyond:.0f} %")
    sat = bool(asks_more and toward is not None and toward >= th.sat_min_toward)
    out["saturated"] = sat
    if sat:
        out["why"] = (f"saturation, not a failure: at its end stop ({stops[k]:.0f} us) while the autopilot asks for "
                      f"more on that side ({how}) and the aircraft moves towards "
                      f"the demand {100 * toward:.0f} % of the time")
    else:
        parts = []
        if not asks_more:
            parts.append(f"the demand does not keep asking for more than the stop ({how})")
        if toward is None or toward < th.sat_min_toward:
            parts.append("the aircraft does not move towards the demand" if toward is not None
                         else "no attitude during the run")
        out["why"] = "at its end stop but not saturation: " + "; ".join(parts)
    return out
