"""Surface deflections on the grid: measured (DroneCAN actuator status) where there, commanded PWM elsewhere.

The autopilot logs what it *commands* (SERVO_OUTPUT_RAW / RCOU); the surface gets there later (servo
lag, rate limit, backlash, a load that stalls it). A DroneCAN servo reports where it *is*
(``uavcan.equipment.actuator.Status.position``), which the telemetry layer merges as streams
``actuator<id>`` (:mod:`gcs_sysid.telemetry.can_merge`). The airframe's ``[[can_actuator]]`` map
(:class:`gcs_sysid.airframe.CanActuator`) says which servo each id measures, with its sign, scale and
zero. Per servo, the measured deflection is used where the actuator stream covers the grid point
(linear interpolation, within its gaps rule), the PWM-derived deflection elsewhere (before the first
report, across a gap, or for a servo without an actuator); the effective controls delta_e delta_a
delta_r are then mixed as from PWM (``Airframe.mixing``). Each control's source says which it was.

A measured control is not given to the rate and force smoothers as a *step* input (their known-input
model, :mod:`gcs_sysid.estimation.inputs`, puts acceleration jumps where a PWM command steps; a
measured surface moves continuously behind its servo's lag, and the moment follows it without a
jump): its source does not start with ``servo``, which is what ``estimate_states`` selects step
inputs by. On the lagging-servo test flight (tests/estimation/test_measured_deflection.py) taking
them as steps as well gave Cl/Cm/Cn model errors of 36/43/31 % against 20/36/32 % without.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from ..airframe import CONTROLS, Airframe
from .align import Aligned

__all__ = ["surface_controls"]


def surface_controls(al: Aligned, airframe: Airframe, pwm: Mapping[int, np.ndarray]
                     ) -> tuple[dict[str, np.ndarray], dict[str, str], list[str]]:
    """Effective controls from measured surface positions, falling back to PWM per servo and sample.

    Args:
        al: the aligned flight (``actuator<id>`` streams with field ``pos``, rad, when merged).
        airframe: servo maps, mixing and the ``[[can_actuator]]`` map.
        pwm: channel -> PWM on the grid (us), shape (T,) each (zero-order hold).

    Returns:
        ``(controls, sources, notes)``: ``delta_e delta_a delta_r`` (rad) and ``delta_t`` (0..1) of
        shape (T,) (a control whose servos have neither measurement nor PWM is absent); a source
        line per control; one note per measured servo (share of the grid measured).
    """
    T = len(al.t)
    defl: dict[str, np.ndarray] = {}
    how: dict[str, str] = {}
    notes: list[str] = []
    by_servo = {c.servo: c for c in airframe.can_actuators}
    for s in airframe.servos:
        cmd = s.deflection(pwm[s.channel]) if s.channel in pwm else None
        act = by_servo.get(s.name)
        stream = f"actuator{act.actuator_id}" if act is not None else None
        if act is not None and al.has(stream, "pos"):
            meas = act.deflection(al.get(stream, "pos"))
            ok = np.isfinite(meas)
            if cmd is not None:
                meas = np.where(ok, meas, cmd)
            defl[s.name] = meas
            share = 100.0 * ok.mean() if T else 0.0
            how[s.name] = "measured" if share >= 99.5 or cmd is None else "mixed"
            notes.append(f"{s.name}: measured position (DroneCAN actuator {act.actuator_id}, "
                         f"{al.rates.get(stream, 0.0):.0f} Hz) on {share:.1f} % of the grid"
                         + (", commanded PWM elsewhere" if cmd is not None and share < 100.0 else ""))
        elif cmd is not None:
            defl[s.name] = cmd
            how[s.name] = "pwm"
            if act is not None:
                notes.append(f"{s.name}: no DroneCAN actuator {act.actuator_id} in the data; commanded PWM used")
    unmapped = sorted(n for n in al.values if n.startswith("actuator")
                      and n[len("actuator"):] not in {str(c.actuator_id) for c in airframe.can_actuators})
    if unmapped:
        notes.append(f"DroneCAN {', '.join(unmapped)} in the data but not in the airframe's [[can_actuator]] map: "
                     "not used (docs/airframe.md)")
    out: dict[str, np.ndarray] = {}
    sources: dict[str, str] = {}
    for cn in CONTROLS:
        used = [s for s in airframe.servos if s.mix.get(cn, 0.0) != 0.0]
        if not used or not all(s.name in defl for s in used):
            continue
        out[cn] = sum(s.mix[cn] * defl[s.name] for s in used)
        kinds = {how[s.name] for s in used}
        if kinds == {"pwm"}:
            sources[cn] = f"servo PWM (zero-order hold) through the {airframe.name} servo map"
        else:
            parts = ", ".join(f"{s.name} {how[s.name]}" for s in used)
            sources[cn] = (f"measured surface position (DroneCAN actuator status, linear interpolation; "
                           f"commanded PWM where not measured: {parts})")
    if airframe.throttle and airframe.throttle.channel in pwm:
        out["delta_t"] = airframe.throttle.delta_t(pwm[airframe.throttle.channel])
        sources["delta_t"] = f"servo PWM (zero-order hold) through the {airframe.name} servo map"
    return out, sources, notes
