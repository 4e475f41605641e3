"""A plan file (format: ``docs/sim.md``) that flies the suggestions: ``gcs-sysid simulate`` reads it.

Each suggestion becomes an airspeed setpoint (its 1-g condition) held for ``speed_settle_s`` before
the input, then one ``[[maneuver]]`` with the suggestion's exact waveform parameters (kind, pulse
width or multisine period and band, amplitude per surface): the simulator builds the same input
with :func:`gcs_sysid.signals.waveform`. Short inputs (doublet, 3-2-1-1) are flown open loop (the
autopilot output of that channel frozen, as a pilot flies a test input); a multisine is added to
the autopilot's output (closed loop), which keeps the aircraft near trim over its 8-20 s.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Sequence

from ..errors import InputError
from .suggestion import Suggestion

__all__ = ["plan_document", "write_plan"]


def _floor(x: float, nd: int = 3) -> float:
    """Rounded towards zero (an amplitude written to the file never exceeds the designed one)."""
    f = 10.0**nd
    return math.floor(abs(x) * f) / f * (1 if x >= 0 else -1)


def plan_document(suggestions: Sequence[Suggestion], name: str = "fly-next", altitude_m: float = 150.0,
                  ground_m: float = 50.0, heading_deg: float = 90.0, start_time_s: float = 30.0,
                  speed_settle_s: float = 10.0, gap_s: float = 4.0, seed: int = 1,
                  wind_mps: float = 0.0, w20_mps: float = 0.0, duration_s: float | None = None) -> dict[str, Any]:
    """The plan document (a dict for ``tomli_w``) flying ``suggestions`` in order.

    Args:
        suggestions: the maneuvers to fly, in order.
        name: plan name. altitude_m: AMSL. ground_m: ground AMSL. heading_deg: initial heading.
        start_time_s: vehicle time of the first sample. speed_settle_s: s held at a new airspeed before
            its input. gap_s: s between inputs at one airspeed. seed: noise seed.
        wind_mps, w20_mps: steady wind (from the west) and turbulence intensity at 20 ft (m/s).
        duration_s: fixed flight length, s (None: as long as the maneuvers need plus 3 s).

    Returns:
        the document; :func:`gcs_sysid.sim.plan_from_dict` accepts it.

    Raises:
        InputError: no suggestions, a suggestion with zero duration or amplitude, or a fixed
            ``duration_s`` too short for the maneuvers.
    """
    if not suggestions:
        raise InputError("no suggestions to turn into a plan")
    t = start_time_s + 5.0
    V0 = float(suggestions[0].flight_condition["V"])
    setpoints, mans = [], []
    V_prev = V0
    for s in suggestions:
        V = float(s.flight_condition["V"])
        if s.input_s <= 0 or not s.amplitudes_rad or min(abs(a) for a in s.amplitudes_rad.values()) <= 0:
            raise InputError(f"suggestion #{s.rank}: zero duration or amplitude cannot be flown")
        if abs(V - V_prev) > 0.05:
            setpoints.append({"start_s": round(t, 3), "airspeed_mps": round(V, 2)})
            t += speed_settle_s
            V_prev = V
        amps = [_floor(math.degrees(s.amplitudes_rad[c])) for c in s.controls]
        m: dict[str, Any] = {"kind": s.kind, "start_s": round(t, 3)}
        if s.kind == "multisine":
            m.update({"controls": list(s.controls), "amplitude_deg": amps, "duration_s": round(s.input_s, 6),
                      "band_hz": [float(s.band_hz[0]), float(s.band_hz[1])], "mode": "closed"})
            length = s.input_s
        else:
            m.update({"control": s.controls[0], "amplitude_deg": amps[0], "pulse_s": round(s.pulse_width_s, 6),
                      "mode": "open", "settle_s": 1.0})
            length = s.input_s
        mans.append(m)
        t += length + gap_s
    need = round(t + 3.0 - start_time_s, 3)
    if duration_s is not None and duration_s < need:
        raise InputError(f"the maneuvers need {need:g} s of flight, more than the {duration_s:g} s asked for")
    doc: dict[str, Any] = {
        "name": name, "duration_s": float(duration_s) if duration_s is not None else need, "rate_hz": 50.0,
        "internal_rate_hz": 200.0,
        "start_time_s": start_time_s, "seed": int(seed),
        "initial": {"airspeed_mps": round(V0, 2), "altitude_m": altitude_m, "heading_deg": heading_deg},
        "home": {"lat_deg": 47.3977, "lon_deg": 8.5456, "alt_m": ground_m},
        "wind": {"speed_mps": wind_mps, "from_deg": 270.0}, "turbulence": {"w20_mps": w20_mps},
        "setpoint": setpoints, "maneuver": mans,
    }
    if not setpoints:
        del doc["setpoint"]
    return doc


def write_plan(suggestions: Sequence[Suggestion], path: str | Path, **kw: Any) -> Path:
    """Write :func:`plan_document` as TOML to ``path`` (with a header saying what it is).

    Returns:
        the path.
    """
    import tomli_w

    doc = plan_document(suggestions, **kw)
    head = ("# Fly-next plan written by gcs-sysid from the ranked suggestions (docs/maneuvers.md).\n"
            "# Fly it in the simulator: gcs-sysid simulate --airframe A --model M --maneuvers THIS --out F.tlog\n"
            "# Times are vehicle time (s); amplitudes in deg; each input at its 1-g trim airspeed.\n")
    p = Path(path)
    p.write_text(head + tomli_w.dumps(doc), encoding="utf-8")
    return p

