"""The maneuver plan file: what to fly, in what air, with which hidden effects (format in ``docs/sim.md``).

All times in a plan are *vehicle time* in s (since autopilot boot), the clock of
the log: the flight starts at ``start_time_s`` (default 30 s) and lasts
``duration_s``. Angles in the file are in degrees (``*_deg``), everything else SI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..errors import InputError
from ..tomlfile import read_toml
from ..signals import KINDS, duration_of, multisine_frequencies
from .effects import CONTROL_NAMES, Effects, effects_from_dict
from .environment import W20_BY_INTENSITY
from .sensors import SensorConfig

__all__ = ["Maneuver", "Setpoint", "Plan", "load_plan", "plan_from_dict"]


@dataclass(frozen=True)
class Maneuver:
    """One excitation.

    Attributes:
        kind: ``doublet``, ``3211`` or ``multisine``.
        controls: controls excited (several only for a multisine: orthogonal harmonics).
        start: vehicle time, s.
        amplitude: per control, rad (delta_t: fraction of full throttle).
        pulse: pulse width s (doublet, 3211). duration: s (total; for a multisine its period).
        band: (f_low, f_high) Hz for a multisine.
        mode: ``closed`` (added to the autopilot output) or ``open`` (channel output frozen).
        settle: s after the end during which an open-loop channel stays frozen.
    """

    kind: str
    controls: tuple[str, ...]
    start: float
    amplitude: tuple[float, ...]
    pulse: float
    duration: float
    band: tuple[float, float] | None = None
    mode: str = "closed"
    settle: float = 1.0

    @property
    def end(self) -> float:
        """Vehicle time at which the input returns to zero, s."""
        return self.start + self.duration


@dataclass(frozen=True)
class Setpoint:
    """Autopilot targets from ``start`` (vehicle time s) on: airspeed m/s, altitude m AMSL, heading rad."""

    start: float
    airspeed: float
    altitude: float
    heading: float


@dataclass(frozen=True)
class Plan:
    """A parsed plan file; see ``docs/sim.md`` for the fields."""

    name: str
    duration: float
    rate_hz: float
    internal_rate_hz: float
    start_time: float
    seed: int
    setpoints: tuple[Setpoint, ...]
    maneuvers: tuple[Maneuver, ...]
    home: tuple[float, float, float]            # lat rad, lon rad, ground altitude m AMSL
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0)
    w20: float = 0.0
    effects: Effects = field(default_factory=Effects)
    sensors: Mapping[str, float] = field(default_factory=dict)
    rate_limit: tuple[float, float, float, float] = (math.inf,) * 4
    source: str = ""

    @property
    def n_ticks(self) -> int:
        """Number of samples T."""
        return int(round(self.duration * self.rate_hz))


def _num(d: Mapping[str, Any], key: str, where: str, default: Any = None, positive: bool = False) -> float:
    if key not in d:
        if default is None:
            raise InputError(f"{where} is missing '{key}'")
        return default
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(f"{where} '{key}' must be a finite number, got {v!r}")
    if positive and v <= 0:
        raise InputError(f"{where} '{key}' must be > 0, got {v!r}")
    return float(v)


def _maneuver(d: Mapping[str, Any], where: str, t0: float, t1: float) -> Maneuver:
    known = {"kind", "control", "controls", "start_s", "amplitude_deg", "amplitude", "pulse_s", "duration_s",
             "band_hz", "mode", "settle_s"}
    for k in d:
        if k not in known:
            raise InputError(f"{where} unknown key '{k}' (expected {', '.join(sorted(known))})")
    kind = d.get("kind")
    if kind not in KINDS:
        raise InputError(f"{where} kind must be one of {', '.join(KINDS)}, got {kind!r}")
    ctl = d.get("controls", [d["control"]] if "control" in d else None)
    if not isinstance(ctl, list) or not ctl or any(c not in CONTROL_NAMES for c in ctl) or len(set(ctl)) != len(ctl):
        raise InputError(f"{where} needs control = one of {', '.join(CONTROL_NAMES)} "
                         f"(or controls = [...] for a multisine)")
    if len(ctl) > 1 and kind != "multisine":
        raise InputError(f"{where} a {kind} excites one control; use several [[maneuver]] entries")
    if "amplitude_deg" in d:
        amp, scale = d["amplitude_deg"], math.pi / 180
    elif "amplitude" in d:
        amp, scale = d["amplitude"], 1.0
    else:
        raise InputError(f"{where} needs amplitude_deg (surfaces) or amplitude (rad, or throttle fraction)")
    amp = amp if isinstance(amp, list) else [amp] * len(ctl)
    if len(amp) != len(ctl) or any(isinstance(a, bool) or not isinstance(a, (int, float)) for a in amp):
        raise InputError(f"{where} amplitude must be a number or a list with one number per control")
    amps = []
    for c, a in zip(ctl, amp):
        amps.append(float(a) * (1.0 if c == "delta_t" else scale))
    start = _num(d, "start_s", where)
    band = None
    if kind == "multisine":
        dur = _num(d, "duration_s", where, positive=True)
        b = d.get("band_hz")
        ok = isinstance(b, list) and len(b) == 2 and all(isinstance(x, (int, float)) for x in b)
        if not (ok and 0 < b[0] < b[1]):
            raise InputError(f"{where} band_hz must be [f_low, f_high] Hz with 0 < f_low < f_high, got {b!r}")
        band = (float(b[0]), float(b[1]))
        pulse = dur
        try:
            for i in range(len(ctl)):
                multisine_frequencies(dur, band, len(ctl), i)
        except InputError as e:
            raise InputError(f"{where} {e}") from None
    else:
        pulse = _num(d, "pulse_s", where, positive=True)
        dur = duration_of(kind, pulse)
    mode = d.get("mode", "closed")
    if mode not in ("closed", "open"):
        raise InputError(f"{where} mode must be 'closed' or 'open', got {mode!r}")
    if start < t0 or start + dur > t1:
        raise InputError(f"{where} runs {start:g}-{start + dur:g} s, outside the flight {t0:g}-{t1:g} s (vehicle time)")
    return Maneuver(kind, tuple(ctl), start, tuple(amps), pulse, dur, band, mode,
                    _num(d, "settle_s", where, 1.0))


def plan_from_dict(doc: Mapping[str, Any], source: str = "<plan>") -> Plan:
    """Validate a parsed plan document.

    Raises:
        InputError: a missing or malformed field (names the file and field).
    """
    s = source
    known = {"name", "duration_s", "rate_hz", "internal_rate_hz", "start_time_s", "seed", "initial", "home",
             "setpoint", "maneuver", "wind", "turbulence", "effects", "sensors", "actuators"}
    for k in doc:
        if k not in known:
            raise InputError(f"{s}: unknown key '{k}' (expected one of {', '.join(sorted(known))})")
    dur = _num(doc, "duration_s", f"{s}:", positive=True)
    rate = _num(doc, "rate_hz", f"{s}:", 50.0, positive=True)
    irate = _num(doc, "internal_rate_hz", f"{s}:", 4 * rate, positive=True)
    if abs(irate / rate - round(irate / rate)) > 1e-9:
        raise InputError(f"{s}: internal_rate_hz ({irate:g}) must be a whole multiple of rate_hz ({rate:g})")
    t0 = _num(doc, "start_time_s", f"{s}:", 30.0)
    seed = doc.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"{s}: seed must be a non-negative integer, got {seed!r}")
    ini = doc.get("initial")
    if not isinstance(ini, Mapping):
        raise InputError(f"{s}: missing table [initial] with airspeed_mps, altitude_m (AMSL), heading_deg")
    sp = [Setpoint(t0, _num(ini, "airspeed_mps", f"{s}: [initial]", positive=True),
                   _num(ini, "altitude_m", f"{s}: [initial]"),
                   math.radians(_num(ini, "heading_deg", f"{s}: [initial]", 0.0)))]
    for i, d in enumerate(doc.get("setpoint", [])):
        w = f"{s}: [[setpoint]] #{i + 1}"
        st = _num(d, "start_s", w)
        if not sp[-1].start < st < t0 + dur:
            raise InputError(f"{w} start_s must increase and lie inside the flight, got {st:g}")
        sp.append(Setpoint(st, _num(d, "airspeed_mps", w, sp[-1].airspeed, positive=True),
                           _num(d, "altitude_m", w, sp[-1].altitude),
                           math.radians(_num(d, "heading_deg", w, math.degrees(sp[-1].heading)))))
    mans = tuple(_maneuver(d, f"{s}: [[maneuver]] #{i + 1}", t0, t0 + dur)
                 for i, d in enumerate(doc.get("maneuver", [])))
    home = doc.get("home", {})
    home_t = (math.radians(_num(home, "lat_deg", f"{s}: [home]", 47.3977)),
              math.radians(_num(home, "lon_deg", f"{s}: [home]", 8.5456)),
              _num(home, "alt_m", f"{s}: [home]", sp[0].altitude - 100.0))
    wind = doc.get("wind", {})
    spd = _num(wind, "speed_mps", f"{s}: [wind]", 0.0)
    frm = math.radians(_num(wind, "from_deg", f"{s}: [wind]", 0.0))
    wind_ned = (-spd * math.cos(frm), -spd * math.sin(frm), _num(wind, "down_mps", f"{s}: [wind]", 0.0))
    turb = doc.get("turbulence", {})
    if "w20_mps" in turb:
        w20 = _num(turb, "w20_mps", f"{s}: [turbulence]", 0.0)
    else:
        level = turb.get("intensity", "none")
        if level not in W20_BY_INTENSITY:
            raise InputError(f"{s}: [turbulence] intensity must be one of {', '.join(W20_BY_INTENSITY)}, got {level!r}")
        w20 = W20_BY_INTENSITY[level]
    act = doc.get("actuators", {})
    rl = act.get("rate_limit_dps", {})
    if not isinstance(rl, Mapping) or any(k not in CONTROL_NAMES for k in rl):
        raise InputError(f"{s}: [actuators] rate_limit_dps must be a table keyed by {', '.join(CONTROL_NAMES)}")
    rate_limit = tuple(math.radians(_num(rl, c, f"{s}: [actuators] rate_limit_dps", math.inf, positive=True))
                       if c in rl else math.inf for c in CONTROL_NAMES)
    sensors = doc.get("sensors", {})
    if not isinstance(sensors, Mapping):
        raise InputError(f"{s}: [sensors] must be a table of noise levels")
    SensorConfig.from_dict(sensors, s)
    return Plan(str(doc.get("name", Path(source).stem)), dur, rate, irate, t0, seed, tuple(sp), mans, home_t,
                wind_ned, w20, effects_from_dict(doc.get("effects", {}), source), dict(sensors), rate_limit, source)


def load_plan(path: str | Path) -> Plan:
    """Read and validate a plan file.

    Raises:
        InputError: missing file, not TOML, or an invalid field.
    """
    return plan_from_dict(read_toml(path, "plan file"), str(path))
