"""Actuator and engine faults read from the telemetry itself: ``stuck:<control>`` and ``thrust_loss``.

An autopilot that loses a surface or its engine keeps demanding; what changes is that
one output stops following. ArduPlane's fault injection (``DISABLE_<SURFACE>``,
``DISABLE_THROTTLE``; the ALFA dataset, Keipour, Mousaei and Scherer, IJRR 2021,
doi 10.1177/0278364920966642) freezes the affected ``SERVO_OUTPUT_RAW`` channel, at trim
or at full throw (throttle at its floor), while the loops around it go on. The
signatures looked for here, on the decoded :class:`~gcs_sysid.telemetry.types.Flight`
(no model, no coefficients; servo telemetry at 3 Hz is enough):

- **stuck surface** (``stuck:delta_e|delta_a|delta_r``): a servo channel that moved
  before (std over the ``before_s`` window at least ``min_active_us``) holds one PWM
  value (within ``pwm_tol_us``) for at least ``min_frozen_s`` while airborne, *and*
  the demand on that axis keeps moving: the autopilot's attitude error
  (NAV_CONTROLLER_OUTPUT ``nav_roll``/``nav_pitch`` minus ATTITUDE) or the body rate
  of that axis, or a twin servo of the same control that used to move with it
  (correlation at least ``min_twin_corr`` before) keeps moving while this one is flat.
  The evidence names the servo channel(s), the frozen PWM and deflection, and how
  the response of the aircraft to the surface changed.
- **engine** (``thrust_loss``): the throttle channel frozen at its floor for at least
  ``min_frozen_s`` while the autopilot's energy demand says it should push: for
  at least ``min_underspeed_s`` of that time the aircraft is both below its target
  altitude and slower than its target airspeed (NAV_CONTROLLER_OUTPUT ``alt_error``
  and ``aspd_error`` positive, the latter by ``min_aspd_error`` m/s; a healthy
  total-energy controller never idles there). Without the demand in the log, an
  abrupt drop to the floor (from at least ``min_drop_fraction`` of the throttle range
  within ``max_drop_s``) followed by a loss of specific energy is required instead.
  The along-x specific force before and after is reported as evidence.

The onset is placed between the last sample that moved and the first frozen one
(``onset_window_s`` gives both). Thresholds are a frozen :class:`FaultThresholds`;
they were set on the ALFA flights listed in ``docs/benchmarks.md`` (one fault flight
kept out) and on the project's simulation.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..airframe import Airframe
from .saturation import saturation_check

__all__ = ["FaultThresholds", "detect_faults", "frozen_runs"]

_G = 9.80665
_AXIS = {"delta_a": ("p", "roll"), "delta_e": ("q", "pitch"), "delta_r": ("r", "roll")}
_COEF = {"delta_a": "Cl", "delta_e": "Cm", "delta_r": "Cn", "delta_t": "CX"}


@dataclass(frozen=True)
class FaultThresholds:
    """Detection thresholds (frozen before the ALFA evaluation; see the module docstring).

    Attributes:
        pwm_tol_us: largest PWM change, us, between samples of a frozen run.
        min_frozen_s: shortest frozen run, s. min_samples: fewest samples in it.
        min_airborne_speed: groundspeed (or airspeed), m/s, above which the aircraft counts as flying.
        before_s: window before the onset, s, for "it used to move".
        min_active_us: PWM std, us, a channel must have had in that window.
        min_rate_std_dps: body-rate std of the surface's axis during the run, deg/s, for "demand moving".
        min_error_std_deg: std of the autopilot's attitude error during the run, deg.
        min_twin_corr: correlation of a twin servo with this one before the onset.
        min_twin_std_us: PWM std of the twin during the run, us.
        min_aspd_error: airspeed error (target minus current), m/s, counted as "too slow".
        min_underspeed_s: time, s, the aircraft must be both too slow and too low while the throttle is frozen.
        floor_fraction: a frozen throttle counts as "at its floor" below this fraction of its PWM range.
        min_drop_fraction, max_drop_s: without the demand in the log: the throttle must fall from at least
            this fraction of its range to the floor within ``max_drop_s``.
        min_energy_loss_m: and the specific energy (h + V^2 / 2g) must fall by at least this much during the run.
        secondary_after_s: a channel that goes flat more than this long after an earlier fault is reported
            with that fault (``evidence.after_it``), not as a finding of its own.
        sat_stop_tol_us: a frozen output within this of an end stop (PWM range or deflection limit) is at its stop.
        sat_fit_s: window before the run, s, on which the demand model of the channel is fitted.
        sat_min_beyond: share of the run with the attitude error pushing the output into the stop, for saturation.
        sat_min_r2: a demand model explaining at least this share of the PWM variance before the run vetoes
            saturation when it puts the demand inside the throw for more than ``1 - sat_min_beyond`` of the run.
        sat_min_t: |t| the error term of the demand model needs before the error's sign is trusted.
        sat_min_toward: share of the run with the attitude moving towards the demand, for saturation.
            (The ``sat_*`` thresholds were set on the project's simulation, after the ALFA evaluation of the
            others; :mod:`gcs_sysid.diagnose.saturation`.)
    """

    pwm_tol_us: float = 0.5
    min_frozen_s: float = 4.0
    min_samples: int = 8
    min_airborne_speed: float = 6.0
    before_s: float = 20.0
    min_active_us: float = 1.0
    min_rate_std_dps: float = 3.0
    min_error_std_deg: float = 2.0
    min_twin_corr: float = 0.8
    min_twin_std_us: float = 5.0
    min_aspd_error: float = 0.5
    min_underspeed_s: float = 1.0
    floor_fraction: float = 0.15
    min_drop_fraction: float = 0.25
    max_drop_s: float = 1.5
    min_energy_loss_m: float = 5.0
    secondary_after_s: float = 1.0
    sat_stop_tol_us: float = 3.0
    sat_fit_s: float = 30.0
    sat_min_r2: float = 0.8
    sat_min_beyond: float = 0.8
    sat_min_t: float = 3.0
    sat_min_toward: float = 0.6


def frozen_runs(t: np.ndarray, pwm: np.ndarray, tol: float, min_s: float, min_n: int) -> list[tuple[int, int]]:
    """Maximal runs of a PWM channel that do not move.

    Args:
        t: sample times (N,), s, increasing. pwm: (N,) PWM, us.
        tol: largest change between consecutive samples, us, inside a run.
        min_s: shortest run, s (first to last sample). min_n: fewest samples.

    Returns:
        list of (i0, i1) index pairs, inclusive, in time order.
    """
    pwm = np.asarray(pwm, float)
    if len(pwm) < 2:
        return []
    brk = np.nonzero(~(np.abs(np.diff(pwm)) <= tol))[0]          # NaN breaks a run too
    starts = np.concatenate([[0], brk + 1])
    ends = np.concatenate([brk, [len(pwm) - 1]])
    return [(int(a), int(b)) for a, b in zip(starts, ends)
            if b - a + 1 >= min_n and t[b] - t[a] >= min_s and np.isfinite(pwm[a])]


def _on(stream, key, t):
    """``stream[key]`` interpolated onto ``t`` (NaN outside)."""
    return np.interp(t, stream.t, np.asarray(stream[key], float), left=np.nan, right=np.nan)


def _std(x) -> float:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(np.std(x)) if x.size >= 3 else 0.0


def _airborne(flight, t: np.ndarray, th: FaultThresholds) -> np.ndarray:
    """(N,) True where the aircraft is flying (ground- or airspeed above the threshold); all True when unknown."""
    speeds = []
    if flight.has("vfr_hud"):
        h = flight["vfr_hud"]
        for k in ("groundspeed", "airspeed"):
            if k in h.fields:
                speeds.append(_on(h, k, t))
    if flight.has("gps") and "vn" in flight["gps"].fields:
        g = flight["gps"]
        speeds.append(np.hypot(_on(g, "vn", t), _on(g, "ve", t)))
    if not speeds:
        return np.ones(len(t), bool)
    s = np.nanmax(np.vstack([np.nan_to_num(x, nan=-1.0) for x in speeds]), axis=0)
    return s >= th.min_airborne_speed


def _rates(flight):
    """(t, p, q, r) rad/s from the first IMU, else ATTITUDE; None if neither."""
    for name in ("imu", "attitude"):
        if flight.has(name) and all(k in flight[name].fields for k in "pqr"):
            s = flight[name]
            return s.t, {k: np.asarray(s[k], float) for k in "pqr"}
    return None


def _window(t, x, t0, t1):
    m = (t >= t0) & (t <= t1)
    return x[m]


def _onset(t, i0):
    """Onset estimate and window: between the last sample that moved and the first frozen one."""
    if i0 == 0:
        return float(t[0]), [float(t[0]), float(t[0])]
    return float(0.5 * (t[i0 - 1] + t[i0])), [float(t[i0 - 1]), float(t[i0])]


def _main_control(servo) -> str | None:
    mix = {k: abs(v) for k, v in servo.mix.items() if k in _AXIS and v != 0}
    return max(mix, key=mix.get) if mix else None


def _surface_candidates(flight, airframe: Airframe, th: FaultThresholds, checked: list) -> list[dict]:
    srv = flight["servo"]
    t = np.asarray(srv.t, float)
    air = _airborne(flight, t, th)
    rates = _rates(flight)
    nav = flight["nav"] if flight.has("nav") else None
    att = flight["attitude"] if flight.has("attitude") else None
    out = []
    for s in airframe.servos:
        u = _main_control(s)
        key = f"pwm{s.channel}"
        if u is None or key not in srv.fields:
            continue
        pwm = np.asarray(srv[key], float)
        twins = [o for o in airframe.servos if o is not s and _main_control(o) == u and f"pwm{o.channel}" in srv.fields]
        for i0, i1 in frozen_runs(t, pwm, th.pwm_tol_us, th.min_frozen_s, th.min_samples):
            if air[i0:i1 + 1].mean() < 0.5:
                continue
            t0, t1 = float(t[i0]), float(t[i1])
            before = (t >= t0 - th.before_s) & (t < t0)
            ev: dict = {"channel": s.channel, "servo": s.name, "pwm_frozen_us": float(pwm[i0]),
                        "frozen_from_s": t0, "frozen_to_s": t1, "frozen_samples": int(i1 - i0 + 1),
                        "pwm_std_before_us": _std(pwm[before])}
            reasons = []
            if ev["pwm_std_before_us"] < th.min_active_us:
                checked.append({**ev, "control": u, "accepted": False, "why": "did not move before either"})
                continue
            # the demand on the axis keeps moving
            rate_key, att_key = _AXIS[u]
            if rates is not None:
                tr, rr = rates
                ev["rate_std_during_dps"] = float(np.degrees(_std(_window(tr, rr[rate_key], t0, t1))))
                ev["rate_std_before_dps"] = float(np.degrees(_std(_window(tr, rr[rate_key], t0 - th.before_s, t0))))
                if ev["rate_std_during_dps"] >= th.min_rate_std_dps:
                    reasons.append(f"{rate_key} keeps moving (std {ev['rate_std_during_dps']:.1f} deg/s)")
            err = None
            if nav is not None and att is not None and f"{att_key}_demand" in nav.fields:
                att_n = _on(att, att_key, nav.t)
                e = np.asarray(nav[f"{att_key}_demand"], float) - att_n
                err = (np.asarray(nav.t, float), e, att_n)
                ev["attitude_error_std_deg"] = float(np.degrees(_std(_window(nav.t, e, t0, t1))))
                if ev["attitude_error_std_deg"] >= th.min_error_std_deg:
                    reasons.append(f"the autopilot's {att_key} error keeps moving "
                                   f"(std {ev['attitude_error_std_deg']:.1f} deg)")
            for o in twins:
                q = np.asarray(srv[f"pwm{o.channel}"], float)
                c = np.corrcoef(pwm[before], q[before])[0, 1] if before.sum() >= 5 and _std(q[before]) > 0 \
                    and _std(pwm[before]) > 0 else np.nan
                sd = _std(q[i0:i1 + 1])
                ev.setdefault("twins", []).append({"channel": o.channel, "servo": o.name,
                                                   "corr_before": float(c), "std_during_us": sd})
                # the twin's mix may be of opposite sign: a mirror image counts as moving together
                if np.isfinite(c) and abs(c) >= th.min_twin_corr and sd >= th.min_twin_std_us:
                    reasons.append(f"twin channel {o.channel} ({o.name}) moved with it before (corr {c:+.2f}) "
                                   f"and keeps moving (std {sd:.0f} us)")
            twin_moving = any("twin channel" in r for r in reasons)
            stop = saturation_check(t, pwm, i0, i1, s, err, (tr, rr[rate_key]) if rates is not None else None, th) \
                if reasons else None
            if stop is not None:
                ev["end_stop"] = stop
            if stop is not None and stop["saturated"] and not twin_moving:
                checked.append({**ev, "control": u, "accepted": False, "saturation": True, "why": stop["why"]})
                continue                               # a later run of this channel may still be a failure
            ok = bool(reasons)
            checked.append({**ev, "control": u, "accepted": ok,
                            "why": "; ".join(reasons) if ok else "the demand on the axis did not move either"})
            if ok:
                ev["demand_moving"] = reasons
                ev["deflection_rad"] = float(s.deflection(np.array([pwm[i0]]))[0])
                out.append({"control": u, "servo": s, "i0": i0, "t": t, "ev": ev})
                break                                  # the first accepted run of this channel
    return out


def _response_change(flight, airframe, u, chans, t_on) -> dict:
    """How the axis rate followed the control before and after the onset (correlation of rate with PWM)."""
    rates = _rates(flight)
    if rates is None:
        return {}
    srv = flight["servo"]
    tr, rr = rates
    rate = np.interp(srv.t, tr, rr[_AXIS[u][0]])
    out = {}
    for ch in chans:
        x = np.asarray(srv[f"pwm{ch}"], float)
        for label, m in (("before", (srv.t < t_on) & (srv.t >= t_on - 30.0)), ("after", srv.t >= t_on)):
            c = np.corrcoef(x[m], rate[m])[0, 1] if m.sum() >= 5 and _std(x[m]) > 0 and _std(rate[m]) > 0 else 0.0
            out[f"corr_rate_pwm{ch}_{label}"] = float(c)
    return out


def _stuck_findings(flight, airframe: Airframe, th: FaultThresholds, checked: list) -> list[dict]:
    by_u: dict[str, list[dict]] = {}
    for c in _surface_candidates(flight, airframe, th, checked):
        by_u.setdefault(c["control"], []).append(c)
    out = []
    for u, cs in by_u.items():
        cs.sort(key=lambda c: c["ev"]["frozen_from_s"])
        first = cs[0]
        onset, win = _onset(first["t"], first["i0"])
        s = first["servo"]
        slope = abs(s.deflection(np.array([s.pwm_trim + 1.0]))[0] - s.deflection(np.array([s.pwm_trim]))[0])
        chans = [c["ev"]["channel"] for c in cs]
        ev = {"domain": "telemetry (servo outputs against the autopilot's demand)", "channels": chans,
              "servos": [c["ev"] for c in cs], "onset_window_s": win, "separable": True, "rivals": [],
              "score": None, **_response_change(flight, airframe, u, chans, onset)}
        out.append({"cause": f"stuck:{u}", "coefficient": _COEF[u], "estimate": float(first["ev"]["deflection_rad"]),
                    "std_error": float(slope / np.sqrt(12.0)), "onset_s": onset, "evidence": ev,
                    "gain": {}, "kind": "fault",
                    "summary": f"servo channel{'s' if len(chans) > 1 else ''} {', '.join(map(str, chans))} "
                               f"({', '.join(c['ev']['servo'] for c in cs)}) frozen at "
                               f"{', '.join(str(round(c['ev']['pwm_frozen_us'])) for c in cs)} us from "
                               f"{onset:.1f} s while {first['ev']['demand_moving'][0]}"})
    return out


def _energy(flight, t):
    """Specific energy h + V^2/(2g), m, on ``t`` (NaN where unknown)."""
    if not flight.has("vfr_hud"):
        return np.full(len(t), np.nan)
    h = flight["vfr_hud"]
    V = _on(h, "airspeed", t) if "airspeed" in h.fields else np.full(len(t), np.nan)
    if not np.any(np.nan_to_num(V) > 1.0):
        V = _on(h, "groundspeed", t)
    return _on(h, "alt", t) + V**2 / (2 * _G)


def _thrust_findings(flight, airframe: Airframe, th: FaultThresholds, checked: list) -> list[dict]:
    thr = airframe.throttle
    srv = flight["servo"]
    key = f"pwm{thr.channel}" if thr is not None else None
    if thr is None or key not in srv.fields:
        return []
    t = np.asarray(srv.t, float)
    pwm = np.asarray(srv[key], float)
    rng = float(thr.pwm_max - thr.pwm_min)
    air = _airborne(flight, t, th)
    nav = flight["nav"] if flight.has("nav") and "aspd_error" in flight["nav"].fields else None
    for i0, i1 in frozen_runs(t, pwm, th.pwm_tol_us, th.min_frozen_s, th.min_samples):
        frac = (pwm[i0] - thr.pwm_min) / rng
        if air[i0:i1 + 1].mean() < 0.5 or frac > th.floor_fraction:
            continue
        t0, t1 = float(t[i0]), float(t[i1])
        ev: dict = {"channel": thr.channel, "pwm_frozen_us": float(pwm[i0]), "frozen_from_s": t0, "frozen_to_s": t1,
                    "throttle_fraction_frozen": float(frac)}
        prev = (t >= t0 - th.max_drop_s) & (t < t0)
        ev["throttle_fraction_before"] = float((np.max(pwm[prev]) - thr.pwm_min) / rng) if prev.any() else None
        reasons = []
        if nav is not None:
            m = (nav.t >= t0) & (nav.t <= t1)
            under = (np.asarray(nav["aspd_error"])[m] >= th.min_aspd_error) & (np.asarray(nav["alt_error"])[m] > 0)
            dtn = float(np.median(np.diff(nav.t))) if len(nav) > 1 else 0.0
            ev["underspeed_and_low_s"] = float(under.sum() * dtn)
            ev["aspd_error_max_mps"] = float(np.max(np.asarray(nav["aspd_error"])[m])) if m.any() else None
            ev["alt_error_max_m"] = float(np.max(np.asarray(nav["alt_error"])[m])) if m.any() else None
            if ev["underspeed_and_low_s"] >= th.min_underspeed_s:
                reasons.append(f"the autopilot is {ev['underspeed_and_low_s']:.1f} s both below its target altitude "
                               f"and slower than its target airspeed (up to {ev['aspd_error_max_mps']:.1f} m/s) "
                               "with the throttle at its floor")
        else:
            E = _energy(flight, np.array([t0, t1]))
            ev["energy_loss_m"] = float(E[0] - E[1]) if np.all(np.isfinite(E)) else None
            drop = ev["throttle_fraction_before"]
            if drop is not None and drop >= th.min_drop_fraction and (ev["energy_loss_m"] or 0) >= th.min_energy_loss_m:
                reasons.append(f"the throttle fell from {100 * drop:.0f} % to its floor within {th.max_drop_s:g} s "
                               f"and stayed there while the aircraft lost {ev['energy_loss_m']:.0f} m of "
                               "specific energy (no autopilot demand in the log)")
        if flight.has("imu") and "ax" in flight["imu"].fields:
            im = flight["imu"]
            ax = np.asarray(im["ax"], float)
            ev["ax_before_mps2"] = float(np.mean(ax[(im.t >= t0 - 10) & (im.t < t0 - 1)])) \
                if np.any((im.t >= t0 - 10) & (im.t < t0 - 1)) else None
            ev["ax_after_mps2"] = float(np.mean(ax[(im.t > t0 + 1) & (im.t <= t0 + 10)])) \
                if np.any((im.t > t0 + 1) & (im.t <= t0 + 10)) else None
        ok = bool(reasons)
        checked.append({**ev, "control": "delta_t", "accepted": ok,
                        "why": "; ".join(reasons) if ok else "the autopilot did not ask for thrust meanwhile"})
        if ok:
            onset, win = _onset(t, i0)
            ev.update({"domain": "telemetry (throttle output against the autopilot's energy demand)",
                       "channels": [thr.channel], "onset_window_s": win, "demand": reasons, "separable": True,
                       "rivals": [], "score": None})
            return [{"cause": "thrust_loss", "coefficient": "CX", "estimate": float(frac),
                     "std_error": float(1.0 / rng), "onset_s": onset, "evidence": ev, "gain": {}, "kind": "fault",
                     "summary": f"throttle channel {thr.channel} frozen at {pwm[i0]:.0f} us from {onset:.1f} s: "
                                + reasons[0]}]
    return []


def detect_faults(flight, airframe: Airframe, thresholds: FaultThresholds | None = None) -> tuple[list[dict], dict]:
    """Actuator and engine faults from the servo outputs and the autopilot's demand.

    Args:
        flight: decoded :class:`~gcs_sysid.telemetry.types.Flight` with a ``servo`` stream (PWM, us);
            ``nav`` (NAV_CONTROLLER_OUTPUT), ``attitude``, ``imu``, ``vfr_hud`` are used when present.
            Parameters and status texts are never read.
        airframe: servo channels, mixing (which control each servo serves) and the throttle channel.
        thresholds: detection thresholds (default: the frozen :class:`FaultThresholds`).

    Returns:
        (findings, summary): findings are ``diagnosis.json`` finding dicts (``cause``: ``stuck:<control>``
        or ``thrust_loss``; ``onset_s`` vehicle time, s; ``estimate``: the frozen deflection, rad, or
        throttle fraction; ``evidence`` naming the channel(s)); summary lists every frozen run
        looked at (``checked``), what was missing, and the thresholds.
    """
    th = thresholds or FaultThresholds()
    summary: dict = {"thresholds": asdict(th), "checked": [], "missing": []}
    if not flight.has("servo"):
        summary["missing"].append("servo outputs (SERVO_OUTPUT_RAW / RCOU): faults cannot be looked for")
        return [], summary
    if not flight.has("nav"):
        summary["missing"].append("NAV_CONTROLLER_OUTPUT (the autopilot's demand): judged on body rates, twin "
                                  "servos and energy instead")
    findings = _stuck_findings(flight, airframe, th, summary["checked"])
    findings += _thrust_findings(flight, airframe, th, summary["checked"])
    findings.sort(key=lambda f: f["onset_s"])
    # one failure at a time: a channel that goes flat well after an earlier fault is most likely a loop
    # saturated by it (an aircraft that lost its engine ends with its pitch loop at the limit), which
    # cannot be told from a second failure; it is reported with the first, not as a finding of its own
    if findings:
        first = findings[0]
        later = [f for f in findings[1:] if f["onset_s"] > first["onset_s"] + th.secondary_after_s]
        for f in later:
            first["evidence"].setdefault("after_it", []).append(
                {"cause": f["cause"], "onset_s": f["onset_s"], "channels": f["evidence"]["channels"],
                 "note": "went flat later: a loop saturated by the first fault, or a second failure"})
        findings = [f for f in findings if f not in later]
    return findings, summary
