"""Effects the simulation can hide in a flight: every cause of the issue-3 catalogue.

An :class:`Effects` makes the *truth* differ from what the engineer's model and
airframe say: extra or changed aero terms, actuator delay / lag / a surface stuck
from an onset time, sensor bias and scale, a steady wind, mass and inertia errors
and a CG offset. The plan file's ``[effects]`` table (``docs/sim.md``) reads into
it; :meth:`Effects.causes` lists the catalogue names (``diagnosis.json``
vocabulary) of what is switched on, for tests that hide an effect.

Meaning of each field (the truth, compared with the nominal inputs):

- ``aero``: (coef, term, delta) added to the model's value of that term.
- ``delay``, ``lag``: pure delay and first-order lag time constant (s) of the
  actuator of each control (delta_e, delta_a, delta_r, delta_t).
- ``stuck``: vehicle time (s) from which the surface stays where it is (inf: never), under
  a logged command that keeps moving (a surface that comes off its servo).
- ``disable``, ``disable_at``: ArduPlane's fault injection (``DISABLE_ELEVATOR`` ...,
  ``DISABLE_THROTTLE``): from vehicle time ``disable`` (s; inf: never) the channel's
  *output* is held at ``disable_at`` (rad for surfaces, 0 = trim; throttle fraction,
  0 = floor), so the log shows the frozen servo output while the autopilot's demand,
  and what it does to the other channels, goes on. A surface reads as ``stuck:<control>``,
  the throttle as ``thrust_loss``.
- ``airspeed_bias`` (m/s), ``airspeed_scale``: measured EAS = scale * EAS + bias.
- ``alpha_bias``, ``beta_bias`` (rad): added to the logged AOA_SSA estimate.
- ``gyro_bias`` (rad/s), ``accel_bias`` (m/s^2): body x y z, added to RAW_IMU.
- ``wind_ned`` (m/s): steady wind added to the plan's ``[wind]``.
- ``mass_delta`` (kg), ``inertia_delta`` (Ixx, Iyy, Izz, Ixz in kg m^2): truth = nominal + delta.
- ``cg_offset`` (m, body axes): true CG minus nominal CG; aero moments of the model
  are about the nominal CG, and the IMU sits at the nominal lever arm from the
  nominal CG, so both the dynamics and the IMU lever arm change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Mapping

from ..aero.table import COEFFICIENTS
from ..airframe import Airframe
from ..errors import InputError
from .model_file import AeroModel, parse_term

__all__ = ["CONTROL_NAMES", "Effects", "effects_from_dict"]

#: The four simulated controls, the column order of every (T, 4) control array.
CONTROL_NAMES = ("delta_e", "delta_a", "delta_r", "delta_t")
_AXES = ("x", "y", "z")
_INERTIA = ("Ixx", "Iyy", "Izz", "Ixz")
_INF = float("inf")


@dataclass(frozen=True)
class Effects:
    """Truth deviations from the nominal model, airframe and sensors (see the module docstring)."""

    aero: tuple[tuple[str, str, float], ...] = ()
    delay: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    lag: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    stuck: tuple[float, float, float, float] = (_INF, _INF, _INF, _INF)
    disable: tuple[float, float, float, float] = (_INF, _INF, _INF, _INF)
    disable_at: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    airspeed_bias: float = 0.0
    airspeed_scale: float = 1.0
    alpha_bias: float = 0.0
    beta_bias: float = 0.0
    gyro_bias: tuple[float, float, float] = (0.0, 0.0, 0.0)
    accel_bias: tuple[float, float, float] = (0.0, 0.0, 0.0)
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass_delta: float = 0.0
    inertia_delta: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    cg_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def apply_model(self, model: AeroModel) -> AeroModel:
        """The truth aero model: ``model`` with the ``aero`` deltas added."""
        upd: dict[str, dict[str, float]] = {}
        for c, term, v in self.aero:
            upd.setdefault(c, {})[term] = upd.get(c, {}).get(term, 0.0) + v
        return model.with_terms(upd, add=True) if upd else model

    def apply_airframe(self, airframe: Airframe) -> Airframe:
        """The truth airframe: mass and inertia deltas applied (CG offset is handled by the dynamics).

        Raises:
            InputError: the truth mass or inertia would not be physical.
        """
        if self.mass_delta == 0 and not any(self.inertia_delta):
            return airframe
        m = airframe.mass + self.mass_delta
        Ixx, Iyy, Izz, Ixz = (getattr(airframe, k) + d for k, d in zip(_INERTIA, self.inertia_delta))
        if m <= 0 or min(Ixx, Iyy, Izz) <= 0 or Ixx * Izz <= Ixz**2:
            raise InputError(f"[effects] mass_delta / inertia_delta make the truth airframe unphysical "
                             f"(mass {m:g} kg, Ixx {Ixx:g}, Iyy {Iyy:g}, Izz {Izz:g}, Ixz {Ixz:g})")
        return replace(airframe, mass=m, Ixx=Ixx, Iyy=Iyy, Izz=Izz, Ixz=Ixz)

    def causes(self) -> list[str]:
        """Catalogue names (issue 3 / ``diagnosis.json``) of the effects switched on."""
        out = [f"{c}:{t}" for c, t, v in self.aero if v != 0]
        out += [f"delay:{n}" for n, d in zip(CONTROL_NAMES, self.delay) if d > 0]
        out += [f"delay:{n}" for n, d in zip(CONTROL_NAMES, self.lag) if d > 0 and f"delay:{n}" not in out]
        out += [f"stuck:{n}" for n, s in zip(CONTROL_NAMES, self.stuck) if math.isfinite(s)]
        out += [f"stuck:{n}" if n != "delta_t" else "thrust_loss" for n, s in zip(CONTROL_NAMES, self.disable)
                if math.isfinite(s) and f"stuck:{n}" not in out]
        out += ["bias:airspeed"] if self.airspeed_bias else []
        out += ["scale:airspeed"] if self.airspeed_scale != 1.0 else []
        out += ["bias:alpha"] if self.alpha_bias else []
        out += ["bias:beta"] if self.beta_bias else []
        out += [f"bias:gyro_{a}" for a, v in zip(_AXES, self.gyro_bias) if v]
        out += [f"bias:accel_{a}" for a, v in zip(_AXES, self.accel_bias) if v]
        out += ["wind"] if any(self.wind_ned) else []
        out += ["mass"] if self.mass_delta else []
        out += [f"inertia:{k}" for k, v in zip(_INERTIA, self.inertia_delta) if v]
        out += ["cg_offset"] if any(self.cg_offset) else []
        return out

    def to_dict(self) -> dict[str, Any]:
        """The ``[effects]`` table (inverse of :func:`effects_from_dict`), only non-default entries."""
        d: dict[str, Any] = {}
        if self.aero:
            d["aero"] = {f"{c}:{t}": v for c, t, v in self.aero}
        for key, vals in (("delay_s", self.delay), ("lag_s", self.lag)):
            if any(vals):
                d[key] = {n: v for n, v in zip(CONTROL_NAMES, vals) if v}
        if any(math.isfinite(s) for s in self.stuck):
            d["stuck_s"] = {n: s for n, s in zip(CONTROL_NAMES, self.stuck) if math.isfinite(s)}
        if any(math.isfinite(s) for s in self.disable):
            d["disable_s"] = {n: s for n, s in zip(CONTROL_NAMES, self.disable) if math.isfinite(s)}
            if any(self.disable_at):
                d["disable_at"] = {n: v for n, v in zip(CONTROL_NAMES, self.disable_at) if v}
        bias = {"airspeed": self.airspeed_bias, "alpha": self.alpha_bias, "beta": self.beta_bias}
        bias.update({f"gyro_{a}": v for a, v in zip(_AXES, self.gyro_bias)})
        bias.update({f"accel_{a}": v for a, v in zip(_AXES, self.accel_bias)})
        if any(bias.values()):
            d["bias"] = {k: v for k, v in bias.items() if v}
        if self.airspeed_scale != 1.0:
            d["scale"] = {"airspeed": self.airspeed_scale}
        if any(self.wind_ned):
            d["wind_ned"] = list(self.wind_ned)
        if self.mass_delta:
            d["mass_delta_kg"] = self.mass_delta
        if any(self.inertia_delta):
            d["inertia_delta"] = {k: v for k, v in zip(_INERTIA, self.inertia_delta) if v}
        if any(self.cg_offset):
            d["cg_offset_m"] = list(self.cg_offset)
        return d


def _num(v: Any, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(f"{where} must be a finite number, got {v!r}")
    return float(v)


def _per_name(d: Any, names: tuple[str, ...], where: str, default: float, nonneg: bool = False) -> tuple:
    if not isinstance(d, Mapping):
        raise InputError(f"{where} must be a table keyed by {', '.join(names)}")
    out = [default] * len(names)
    for k, v in d.items():
        if k not in names:
            raise InputError(f"{where} key '{k}' is not one of {', '.join(names)}")
        out[names.index(k)] = _num(v, f"{where}.{k}")
        if nonneg and out[names.index(k)] < 0:
            raise InputError(f"{where}.{k} must be >= 0, got {v!r}")
    return tuple(out)


def _vec3(v: Any, where: str) -> tuple[float, float, float]:
    if not (isinstance(v, list) and len(v) == 3):
        raise InputError(f"{where} must be a list of 3 numbers, got {v!r}")
    return tuple(_num(x, where) for x in v)  # type: ignore[return-value]


def effects_from_dict(doc: Mapping[str, Any], source: str = "<plan>") -> Effects:
    """Read an ``[effects]`` table (format in ``docs/sim.md``).

    Raises:
        InputError: unknown key, unknown coefficient / term / control / sensor,
            or a value of the wrong type (the message names the file and key).
    """
    w = f"{source}: [effects]"
    known = {"aero", "delay_s", "lag_s", "stuck_s", "disable_s", "disable_at", "bias", "scale", "wind_ned",
             "mass_delta_kg", "inertia_delta", "cg_offset_m"}
    for k in doc:
        if k not in known:
            raise InputError(f"{w} unknown key '{k}' (expected one of {', '.join(sorted(known))})")
    kw: dict[str, Any] = {}
    aero = doc.get("aero", {})
    if not isinstance(aero, Mapping):
        raise InputError(f"{w} aero must be a table of \"<coef>:<term>\" = value")
    terms = []
    for cause, v in aero.items():
        coef, sep, term = cause.partition(":")
        if not sep or coef not in COEFFICIENTS:
            raise InputError(f"{w} aero key '{cause}' must be '<coef>:<term>' with coef in {', '.join(COEFFICIENTS)}")
        parse_term(term, source, coef)
        terms.append((coef, term, _num(v, f"{w} aero.'{cause}'")))
    kw["aero"] = tuple(terms)
    for key, attr in (("delay_s", "delay"), ("lag_s", "lag")):
        if key in doc:
            kw[attr] = _per_name(doc[key], CONTROL_NAMES, f"{w} {key}", 0.0, nonneg=True)
    if "stuck_s" in doc:
        kw["stuck"] = _per_name(doc["stuck_s"], CONTROL_NAMES, f"{w} stuck_s", _INF)
    if "disable_s" in doc:
        kw["disable"] = _per_name(doc["disable_s"], CONTROL_NAMES, f"{w} disable_s", _INF)
    if "disable_at" in doc:
        kw["disable_at"] = _per_name(doc["disable_at"], CONTROL_NAMES, f"{w} disable_at", 0.0)
        if "disable_s" not in doc:
            raise InputError(f"{w} disable_at needs disable_s (the onset of each disabled output)")
    if "bias" in doc:
        names = ("airspeed", "alpha", "beta") + tuple(f"gyro_{a}" for a in _AXES) + tuple(f"accel_{a}" for a in _AXES)
        b = _per_name(doc["bias"], names, f"{w} bias", 0.0)
        kw.update(airspeed_bias=b[0], alpha_bias=b[1], beta_bias=b[2], gyro_bias=b[3:6], accel_bias=b[6:9])
    if "scale" in doc:
        kw["airspeed_scale"] = _per_name(doc["scale"], ("airspeed",), f"{w} scale", 1.0)[0]
        if kw["airspeed_scale"] <= 0:
            raise InputError(f"{w} scale.airspeed must be > 0")
    if "wind_ned" in doc:
        kw["wind_ned"] = _vec3(doc["wind_ned"], f"{w} wind_ned")
    if "mass_delta_kg" in doc:
        kw["mass_delta"] = _num(doc["mass_delta_kg"], f"{w} mass_delta_kg")
    if "inertia_delta" in doc:
        kw["inertia_delta"] = _per_name(doc["inertia_delta"], _INERTIA, f"{w} inertia_delta", 0.0)
    if "cg_offset_m" in doc:
        kw["cg_offset"] = _vec3(doc["cg_offset_m"], f"{w} cg_offset_m")
    return Effects(**kw)

