"""Airframe description: mass properties, reference geometry, servo maps and mixing.

The airframe file is TOML (format in ``docs/airframe.md``). Everything inside is
SI (kg, m, kg m^2, rad); the file gives servo deflections in degrees and servo
commands in PWM microseconds because that is how servos are set up on the bench.

Servo -> control mixing is linear: each servo's deflection (rad, positive by the
surface's own sign convention, trailing edge down for ailerons, elevators,
elevons and ruddervators, trailing edge left for a rudder) contributes
``mix[control] * deflection`` to the effective controls delta_e, delta_a,
delta_r. Examples (``docs/airframe.md``): two ailerons ``delta_a = 0.5*right -
0.5*left``; elevons ``delta_e = 0.5*(left+right)``, ``delta_a = 0.5*(right-left)``.
Sign conventions follow DEVELOPERS.md: delta_e trailing edge down, delta_a right
aileron trailing edge down, delta_r trailing edge left are positive.

The optional thrust model is a static-thrust form (e.g. Beard and McLain, *Small
Unmanned Aircraft*, 2012, sec. 4.3, simplified)::

    T(delta_t, V) = T_static * delta_t**exponent * max(0, 1 - V / V_zero)   [N]

acting along body x through the CG.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .errors import InputError
from .tomlfile import read_toml

__all__ = [
    "CONTROLS",
    "Servo",
    "Throttle",
    "ThrustModel",
    "Limits",
    "CanActuator",
    "Airframe",
    "load_airframe",
    "airframe_from_dict",
    "airframe_to_dict",
]

CONTROLS = ("delta_e", "delta_a", "delta_r")


@dataclass(frozen=True)
class Servo:
    """One servo output and its PWM -> deflection map.

    The map is piecewise linear through three points: ``pwm_min -> deflection
    at pwm_min``, ``pwm_trim -> 0`` and ``pwm_max -> deflection at pwm_max``;
    the result is clipped to ``[limit_min, limit_max]``. A reversed servo is
    expressed by the signs of the two end deflections.

    Attributes:
        name: surface name, e.g. ``"elevator"`` or ``"aileron_left"``.
        channel: 1-based servo output channel (SERVO_OUTPUT_RAW servoN_raw, RCOU CN).
        pwm_min, pwm_trim, pwm_max: PWM in microseconds, ``pwm_min < pwm_trim < pwm_max``.
        deflection_at_min, deflection_at_max: deflection in rad at the PWM ends.
        limit_min, limit_max: deflection limits in rad.
        mix: contribution of this servo's deflection to each control in CONTROLS.
    """

    name: str
    channel: int
    pwm_min: float
    pwm_trim: float
    pwm_max: float
    deflection_at_min: float
    deflection_at_max: float
    limit_min: float
    limit_max: float
    mix: Mapping[str, float]

    def deflection(self, pwm: np.ndarray) -> np.ndarray:
        """Deflection (rad) for PWM commands (us), any shape; NaN where pwm <= 0."""
        pwm = np.asarray(pwm, dtype=float)
        up = (pwm - self.pwm_trim) / (self.pwm_max - self.pwm_trim) * self.deflection_at_max
        down = (self.pwm_trim - pwm) / (self.pwm_trim - self.pwm_min) * self.deflection_at_min
        d = np.where(pwm >= self.pwm_trim, up, down)
        d = np.clip(d, self.limit_min, self.limit_max)
        return np.where(pwm > 0, d, np.nan)

    def pwm(self, deflection: np.ndarray) -> np.ndarray:
        """Inverse map: PWM (us) for a deflection (rad), any shape; clipped to the ends."""
        d = np.clip(np.asarray(deflection, dtype=float), self.limit_min, self.limit_max)
        same_sign_max = np.sign(d) == np.sign(self.deflection_at_max)
        up = self.pwm_trim + d / self.deflection_at_max * (self.pwm_max - self.pwm_trim)
        down = self.pwm_trim - d / self.deflection_at_min * (self.pwm_trim - self.pwm_min)
        p = np.where(same_sign_max | (d == 0), up, down)
        return np.clip(p, self.pwm_min, self.pwm_max)


@dataclass(frozen=True)
class Throttle:
    """Throttle channel: ``delta_t = (pwm - pwm_min) / (pwm_max - pwm_min)`` clipped to [0, 1]."""

    channel: int
    pwm_min: float = 1000.0
    pwm_max: float = 2000.0

    def delta_t(self, pwm: np.ndarray) -> np.ndarray:
        """Throttle fraction in [0, 1] for PWM (us); NaN where pwm <= 0."""
        pwm = np.asarray(pwm, dtype=float)
        x = np.clip((pwm - self.pwm_min) / (self.pwm_max - self.pwm_min), 0.0, 1.0)
        return np.where(pwm > 0, x, np.nan)

    def pwm(self, delta_t: np.ndarray) -> np.ndarray:
        """PWM (us) for a throttle fraction."""
        return self.pwm_min + np.clip(np.asarray(delta_t, float), 0, 1) * (self.pwm_max - self.pwm_min)


@dataclass(frozen=True)
class ThrustModel:
    """Static-thrust model ``T = T_static * delta_t**exponent * max(0, 1 - V/V_zero)`` (N)."""

    T_static: float
    V_zero: float
    exponent: float = 2.0

    def thrust(self, delta_t, V):
        """Thrust in N along body x for throttle fraction ``delta_t`` and true airspeed ``V`` (m/s).

        Works on numpy and JAX arrays (broadcasting)."""
        xp = _array_module(delta_t, V)
        dt = xp.clip(delta_t, 0.0, 1.0)
        return self.T_static * dt**self.exponent * xp.maximum(0.0, 1.0 - V / self.V_zero)


def _array_module(*xs):
    for x in xs:
        if type(x).__module__.startswith("jax"):
            import jax.numpy as jnp

            return jnp
    return np


@dataclass(frozen=True)
class Limits:
    """Flight and surface limits that no suggested maneuver may exceed (the airframe's ``[limits]``).

    Every field is optional in the file; a missing one is None here and is filled in from the flown
    envelope by :func:`gcs_sysid.maneuvers.limits.effective_limits` (which says so).

    Attributes:
        V_min, V_max: airspeed range, m/s (true airspeed).
        n_max: largest load factor, g (positive; the push-over side is limited to ``2 - n_max``).
        alpha_max: largest angle of attack, rad.
        throw: control -> largest deflection from neutral a maneuver may command, rad.
        rate: control -> largest surface rate, rad/s.
    """

    V_min: float | None = None
    V_max: float | None = None
    n_max: float | None = None
    alpha_max: float | None = None
    throw: Mapping[str, float] = field(default_factory=dict)
    rate: Mapping[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The file's ``[limits]`` table (degrees at the edge), missing fields left out."""
        d: dict[str, Any] = {}
        for key, v, scale in (("V_min_mps", self.V_min, 1.0), ("V_max_mps", self.V_max, 1.0),
                              ("n_max", self.n_max, 1.0), ("alpha_max_deg", self.alpha_max, 180 / math.pi)):
            if v is not None:
                d[key] = float(v) * scale
        if self.throw:
            d["throw_deg"] = {k: math.degrees(v) for k, v in self.throw.items()}
        if self.rate:
            d["rate_dps"] = {k: math.degrees(v) for k, v in self.rate.items()}
        return d


@dataclass(frozen=True)
class Airframe:
    """Mass properties, reference geometry, servos and thrust of one aircraft.

    Attributes:
        name: airframe name.
        mass: kg.
        Ixx, Iyy, Izz, Ixz: body-axis inertia in kg m^2 (Ixz = integral of x z dm;
            the tensor is ``[[Ixx, 0, -Ixz], [0, Iyy, 0], [-Ixz, 0, Izz]]``).
        S: wing reference area, m^2. b: span, m. c: mean aerodynamic chord, m.
        servos: the control-surface servos.
        throttle: the throttle channel, or None (glider).
        thrust: optional thrust model; without one CX includes thrust.
        imu_lever_arm: IMU position relative to the CG in body axes, m, shape (3,).
        source: path of the file it was read from ("" if built in code).
        notes: free-text provenance of the values.
        limits: the ``[limits]`` table (:class:`Limits`), or None when the file has none.
        can_actuators: the ``[[can_actuator]]`` map (:class:`CanActuator`): which DroneCAN actuator id
            measures which servo's surface; empty when the file has none.
        air_angles: what the log's AOA_SSA / AOA angles are: ``"estimate"`` (the autopilot's own
            lagged estimate from velocity and wind; the default, ArduPilot's AHRS) or ``"vane"``
            (measured by vanes at the CG; the estimator then uses them as alpha and beta).
            ``[air_data] angles`` in the file.
        CL_alpha: the whole aircraft's stated lift-curve slope (wing, tail and body), 1/rad, > 0, or None
            (``[aero] CL_alpha``: a wind-tunnel or DATCOM number). CL_q: its stated lift per unit
            ``q_hat = q c / (2 V)`` (``[aero] CL_q``; the tail's, ``2 a_t V_H eta`` in Etkin 1972 sec. 5.5), or
            None. Used only with the opt-in :data:`gcs_sysid.estimation.airangles.STATED_LIFT_SLOPE` (the aided
            alpha's lift-slope floor; ``docs/estimation.md``, "The lift-slope floor as a fixed point").
        CL0: the whole aircraft's stated lift coefficient at ``alpha = 0``, ``q_hat = 0``, ``delta_e = 0``
            (``[aero] CL0``; ``-CL_alpha alpha_0L``, from a wind tunnel, DATCOM or a glide-polar test), or None.
            CL_delta_e: its stated lift per radian of elevator (``[aero] CL_delta_e``), or None (taken as 0).
            CL0_sigma: the stated 1-sigma of the lift line's level at the flight's mean condition, in CL
            (``[aero] CL0_sigma``; None: :data:`gcs_sysid.estimation.airangles.STATED_CL0_SIGMA`). Used only with the
            opt-in :data:`gcs_sysid.estimation.airangles.STATED_LIFT_LEVEL` (the aided alpha's flight mean from the
            stated lift line; ``docs/estimation.md``, "A stated lift line sets alpha's level"); they need
            ``CL_alpha``.
    """

    name: str
    mass: float
    Ixx: float
    Iyy: float
    Izz: float
    Ixz: float
    S: float
    b: float
    c: float
    servos: tuple[Servo, ...]
    throttle: Throttle | None = None
    thrust: ThrustModel | None = None
    imu_lever_arm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    source: str = ""
    notes: str = ""
    limits: Limits | None = None
    air_angles: str = "estimate"
    can_actuators: tuple["CanActuator", ...] = ()
    CL_alpha: float | None = None
    CL_q: float | None = None
    CL0: float | None = None
    CL_delta_e: float | None = None
    CL0_sigma: float | None = None

    @property
    def authority(self) -> dict[str, float]:
        """Control -> largest deflection (rad) the servos can give that control both ways (mixing x limits)."""
        return {cn: float(sum(abs(s.mix.get(cn, 0.0)) * min(-s.limit_min, s.limit_max) for s in self.servos))
                for cn in CONTROLS}

    @property
    def inertia(self) -> np.ndarray:
        """Inertia tensor (3, 3) in kg m^2, body axes."""
        return np.array([[self.Ixx, 0.0, -self.Ixz], [0.0, self.Iyy, 0.0], [-self.Ixz, 0.0, self.Izz]])

    @property
    def mixing(self) -> np.ndarray:
        """Mixing matrix (3, n_servos): controls (delta_e, delta_a, delta_r) = M @ servo deflections."""
        return np.array([[s.mix.get(cn, 0.0) for s in self.servos] for cn in CONTROLS])

    @property
    def channels(self) -> list[int]:
        """All servo and throttle channels used (1-based)."""
        ch = [s.channel for s in self.servos]
        return ch + ([self.throttle.channel] if self.throttle else [])

    def controls_from_pwm(self, pwm: Mapping[int, np.ndarray]) -> dict[str, np.ndarray]:
        """Effective controls from servo PWM.

        Args:
            pwm: channel (1-based) -> PWM array in us, all of shape (T,).

        Returns:
            dict with ``delta_e``, ``delta_a``, ``delta_r`` (rad) and ``delta_t``
            (0..1), each of shape (T,). A control whose servos are all missing is
            absent from the dict; a missing throttle channel omits ``delta_t``.
        """
        out: dict[str, np.ndarray] = {}
        defl = {s.name: s.deflection(pwm[s.channel]) for s in self.servos if s.channel in pwm}
        for cn in CONTROLS:
            used = [s for s in self.servos if s.mix.get(cn, 0.0) != 0.0]
            if used and all(s.name in defl for s in used):
                out[cn] = sum(s.mix[cn] * defl[s.name] for s in used)
        if self.throttle and self.throttle.channel in pwm:
            out["delta_t"] = self.throttle.delta_t(pwm[self.throttle.channel])
        return out

    def pwm_from_controls(self, controls: Mapping[str, np.ndarray]) -> dict[int, np.ndarray]:
        """Servo PWM (us) that produce the given controls (least-squares inverse of the mixing).

        Args:
            controls: ``delta_e``, ``delta_a``, ``delta_r`` (rad) and optionally
                ``delta_t`` (0..1), arrays of one shape (T,); missing controls are 0.

        Returns:
            channel -> PWM array of shape (T,).
        """
        shape = np.shape(next(iter(controls.values())))
        u = np.stack([np.broadcast_to(np.asarray(controls.get(cn, 0.0), float), shape) for cn in CONTROLS])
        defl = np.linalg.pinv(self.mixing) @ u.reshape(3, -1)
        out = {s.channel: s.pwm(defl[i].reshape(shape)) for i, s in enumerate(self.servos)}
        if self.throttle is not None:
            out[self.throttle.channel] = self.throttle.pwm(controls.get("delta_t", np.zeros(shape)))
        return out


# ----------------------------------------------------------------------------- loading


def _req(d: Mapping[str, Any], key: str, where: str, src: str, positive: bool = False) -> float:
    if key not in d:
        raise InputError(f"{src}: {where} is missing required field '{key}'")
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(f"{src}: {where} field '{key}' must be a finite number, got {v!r}")
    if positive and v <= 0:
        raise InputError(f"{src}: {where} field '{key}' must be > 0, got {v!r}")
    return float(v)


def _positives(d: Mapping[str, Any], keys: tuple[str, ...], where: str, src: str) -> list[float]:
    """The required positive numbers ``keys`` of the table ``d`` (:func:`_req`), in order; the first that is missing
    or not a positive finite number raises its :class:`InputError`."""
    return [_req(d, k, where, src, positive=True) for k in keys]


def _opt(d: Mapping[str, Any], key: str, default: float, where: str, src: str) -> float:
    return _req(d, key, where, src) if key in d else default


def _channel(d: Mapping[str, Any], where: str, src: str) -> int:
    ch = d.get("channel")
    if isinstance(ch, bool) or not isinstance(ch, int) or not 1 <= ch <= 32:
        raise InputError(f"{src}: {where} field 'channel' must be an integer servo channel 1..32, got {ch!r}")
    return ch


def airframe_from_dict(doc: Mapping[str, Any], source: str = "<airframe>") -> Airframe:
    """Build and validate an :class:`Airframe` from a parsed TOML document.

    Args:
        doc: the parsed file (format in ``docs/airframe.md``).
        source: file name used in error messages.

    Raises:
        InputError: a field is missing, has the wrong type or an impossible value;
            the message names the file and the field.
    """
    src = source
    known = {"name", "mass", "inertia", "geometry", "servo", "throttle", "thrust", "imu_lever_arm", "notes",
             "limits", "air_data", "can_actuator", "aero"}
    for k in doc:
        if k not in known:
            raise InputError(f"{src}: unknown top-level field '{k}' (expected one of {sorted(known)})")
    name = doc.get("name")
    if not isinstance(name, str) or not name:
        raise InputError(f"{src}: field 'name' must be a non-empty string")
    mass = _req(doc, "mass", "top level", src, positive=True)
    inertia = doc.get("inertia")
    if not isinstance(inertia, Mapping):
        raise InputError(f"{src}: missing table [inertia] with Ixx, Iyy, Izz (kg m^2) and optional Ixz")
    Ixx, Iyy, Izz = _positives(inertia, ("Ixx", "Iyy", "Izz"), "[inertia]", src)
    Ixz = _opt(inertia, "Ixz", 0.0, "[inertia]", src)
    if Ixx * Izz - Ixz**2 <= 0:
        raise InputError(f"{src}: [inertia] tensor is not positive definite (Ixx*Izz must exceed Ixz^2)")
    if Ixx + Iyy < Izz or Iyy + Izz < Ixx or Ixx + Izz < Iyy:
        raise InputError(f"{src}: [inertia] violates the triangle inequality (e.g. Ixx + Iyy >= Izz)")
    geom = doc.get("geometry")
    if not isinstance(geom, Mapping):
        raise InputError(f"{src}: missing table [geometry] with S (m^2), b (m), c (m)")
    S, b, c = _positives(geom, ("S", "b", "c"), "[geometry]", src)

    servos_doc = doc.get("servo")
    if not isinstance(servos_doc, list) or not servos_doc:
        raise InputError(f"{src}: needs at least one [[servo]] table (control-surface servo)")
    servos = []
    used_channels: dict[int, str] = {}
    for i, sd in enumerate(servos_doc):
        if not isinstance(sd, Mapping):
            raise InputError(f"{src}: [[servo]] #{i + 1} must be a table")
        sname = sd.get("name")
        if not isinstance(sname, str) or not sname:
            raise InputError(f"{src}: [[servo]] #{i + 1} needs a string 'name'")
        where = f"[[servo]] '{sname}'"
        ch = _channel(sd, where, src)
        if ch in used_channels:
            raise InputError(f"{src}: {where} channel {ch} is already used by '{used_channels[ch]}'")
        used_channels[ch] = sname
        pmin = _opt(sd, "pwm_min", 1100.0, where, src)
        ptrim = _opt(sd, "pwm_trim", 1500.0, where, src)
        pmax = _opt(sd, "pwm_max", 1900.0, where, src)
        if not pmin < ptrim < pmax:
            raise InputError(
                f"{src}: {where} needs pwm_min < pwm_trim < pwm_max, got {pmin:g}, {ptrim:g}, {pmax:g}"
            )
        dmin = math.radians(_req(sd, "deflection_at_pwm_min_deg", where, src))
        dmax = math.radians(_req(sd, "deflection_at_pwm_max_deg", where, src))
        if dmin == 0 or dmax == 0 or np.sign(dmin) == np.sign(dmax):
            raise InputError(
                f"{src}: {where} deflection_at_pwm_min_deg and deflection_at_pwm_max_deg must be non-zero "
                f"and of opposite sign, got {math.degrees(dmin):g} and {math.degrees(dmax):g}"
            )
        lim = sd.get("limit_deg", [min(dmin, dmax) * 180 / math.pi, max(dmin, dmax) * 180 / math.pi])
        if (not (isinstance(lim, list) and len(lim) == 2 and all(isinstance(x, (int, float)) for x in lim))
                or not lim[0] < 0 < lim[1]):
            raise InputError(f"{src}: {where} limit_deg must be [negative, positive] degrees, got {lim!r}")
        mix = sd.get("mix")
        if not isinstance(mix, Mapping) or not mix:
            raise InputError(f"{src}: {where} needs a 'mix' table, e.g. mix = {{ delta_e = 1.0 }}")
        for k, v in mix.items():
            if k not in CONTROLS:
                raise InputError(f"{src}: {where} mix key '{k}' is not one of {', '.join(CONTROLS)}")
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise InputError(f"{src}: {where} mix.{k} must be a number, got {v!r}")
        servos.append(
            Servo(sname, ch, pmin, ptrim, pmax, dmin, dmax, math.radians(lim[0]), math.radians(lim[1]),
                  {k: float(v) for k, v in mix.items()})
        )
    throttle = None
    if "throttle" in doc:
        td = doc["throttle"]
        if not isinstance(td, Mapping):
            raise InputError(f"{src}: [throttle] must be a table with 'channel'")
        tch = _channel(td, "[throttle]", src)
        if tch in used_channels:
            raise InputError(f"{src}: [throttle] channel {tch} is already used by servo '{used_channels[tch]}'")
        tmin = _opt(td, "pwm_min", 1000.0, "[throttle]", src)
        tmax = _opt(td, "pwm_max", 2000.0, "[throttle]", src)
        if not tmin < tmax:
            raise InputError(f"{src}: [throttle] needs pwm_min < pwm_max, got {tmin:g}, {tmax:g}")
        throttle = Throttle(tch, tmin, tmax)
    thrust = None
    if "thrust" in doc:
        th = doc["thrust"]
        if not isinstance(th, Mapping):
            raise InputError(f"{src}: [thrust] must be a table with T_static (N) and V_zero (m/s)")
        thrust = ThrustModel(
            _req(th, "T_static", "[thrust]", src, positive=True),
            _req(th, "V_zero", "[thrust]", src, positive=True),
            _opt(th, "exponent", 2.0, "[thrust]", src),
        )
        if throttle is None:
            raise InputError(f"{src}: [thrust] is given but there is no [throttle] channel to drive it")
    arm = doc.get("imu_lever_arm", [0.0, 0.0, 0.0])
    if not (isinstance(arm, list) and len(arm) == 3
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in arm)):
        raise InputError(f"{src}: imu_lever_arm must be [x, y, z] in metres, got {arm!r}")
    notes = doc.get("notes", "")
    if not isinstance(notes, str):
        raise InputError(f"{src}: notes must be a string")
    air = doc.get("air_data", {})
    if not isinstance(air, Mapping) or set(air) - {"angles"}:
        raise InputError(f"{src}: [air_data] must be a table with only 'angles' (\"estimate\" or \"vane\")")
    angles = air.get("angles", "estimate")
    if angles not in ("estimate", "vane"):
        raise InputError(f"{src}: [air_data] angles must be \"estimate\" (autopilot's AOA_SSA estimate) or "
                         f"\"vane\" (AOA_SSA/AOA carry vane measurements), got {angles!r}")
    aero = doc.get("aero", {})
    if not isinstance(aero, Mapping) or set(aero) - {"CL_alpha", "CL_q", "CL0", "CL_delta_e", "CL0_sigma"}:
        raise InputError(f"{src}: [aero] must be a table with only 'CL_alpha' (1/rad), 'CL_q' (per q_hat), 'CL0', "
                         f"'CL_delta_e' (1/rad) and 'CL0_sigma'")
    for k in ("CL_q", "CL0", "CL_delta_e", "CL0_sigma"):
        if k in aero and "CL_alpha" not in aero:
            raise InputError(f"{src}: [aero] {k} is used only with CL_alpha (the stated lift slope and line)")
    if ("CL_delta_e" in aero or "CL0_sigma" in aero) and "CL0" not in aero:
        raise InputError(f"{src}: [aero] CL_delta_e and CL0_sigma are used only with CL0 (the stated lift line)")
    cla = _req(aero, "CL_alpha", "[aero]", src, positive=True) if "CL_alpha" in aero else None
    clq = _req(aero, "CL_q", "[aero]", src) if "CL_q" in aero else None
    if clq is not None and clq < 0:
        raise InputError(f"{src}: [aero] field 'CL_q' must be >= 0 (a tail's lift grows with the pitch rate), "
                         f"got {clq!r}")
    cl0 = _req(aero, "CL0", "[aero]", src) if "CL0" in aero else None
    clde = _req(aero, "CL_delta_e", "[aero]", src) if "CL_delta_e" in aero else None
    cl0s = _req(aero, "CL0_sigma", "[aero]", src, positive=True) if "CL0_sigma" in aero else None
    af = Airframe(name, mass, Ixx, Iyy, Izz, Ixz, S, b, c, tuple(servos), throttle, thrust,
                  tuple(float(x) for x in arm), source, notes, air_angles=angles, CL_alpha=cla, CL_q=clq,
                  CL0=cl0, CL_delta_e=clde, CL0_sigma=cl0s)
    if "limits" in doc:
        af = replace(af, limits=_limits(doc["limits"], af, src))
    if "can_actuator" in doc:
        af = replace(af, can_actuators=_can_actuators(doc["can_actuator"], af, src))
    return af


def _limits(d: Any, af: Airframe, src: str) -> Limits:
    """Parse and check the ``[limits]`` table against itself and the servos (docs/airframe.md)."""
    if not isinstance(d, Mapping):
        raise InputError(f"{src}: [limits] must be a table (V_min_mps, V_max_mps, n_max, alpha_max_deg, "
                         f"throw_deg, rate_dps)")
    known = {"V_min_mps", "V_max_mps", "n_max", "alpha_max_deg", "throw_deg", "rate_dps"}
    for k in d:
        if k not in known:
            raise InputError(f"{src}: [limits] unknown field '{k}' (expected one of {', '.join(sorted(known))})")
    val = {k: (_req(d, k, "[limits]", src, positive=True) if k in d else None)
           for k in ("V_min_mps", "V_max_mps", "n_max", "alpha_max_deg")}
    if val["V_min_mps"] is not None and val["V_max_mps"] is not None and not val["V_min_mps"] < val["V_max_mps"]:
        raise InputError(f"{src}: [limits] V_min_mps ({val['V_min_mps']:g}) must be below V_max_mps "
                         f"({val['V_max_mps']:g})")
    if val["n_max"] is not None and not 1.0 < val["n_max"] <= 15.0:
        raise InputError(f"{src}: [limits] n_max must lie in (1, 15] g (level flight is 1 g), got {val['n_max']:g}")
    if val["alpha_max_deg"] is not None and not val["alpha_max_deg"] <= 40.0:
        raise InputError(f"{src}: [limits] alpha_max_deg must lie in (0, 40] deg, got {val['alpha_max_deg']:g}")
    auth = af.authority
    per: dict[str, dict[str, float]] = {}
    for key, unit in (("throw_deg", "deg"), ("rate_dps", "deg/s")):
        t = d.get(key, {})
        if not isinstance(t, Mapping):
            raise InputError(f"{src}: [limits] {key} must be a table keyed by {', '.join(CONTROLS)}, "
                             f"e.g. {key} = {{ delta_e = 15 }}")
        per[key] = {}
        for c, v in t.items():
            if c not in CONTROLS:
                raise InputError(f"{src}: [limits] {key} key '{c}' is not one of {', '.join(CONTROLS)}")
            v = _req(t, c, f"[limits] {key}", src, positive=True)
            if key == "throw_deg":
                if auth[c] <= 0:
                    raise InputError(f"{src}: [limits] throw_deg.{c} is given but no [[servo]] drives {c}")
                if math.radians(v) > auth[c] + 1e-9:
                    raise InputError(f"{src}: [limits] throw_deg.{c} = {v:g} deg exceeds the servos' travel "
                                     f"({math.degrees(auth[c]):.1f} deg from limit_deg and mix)")
            per[key][c] = math.radians(v)
    alpha = val["alpha_max_deg"]
    return Limits(val["V_min_mps"], val["V_max_mps"], val["n_max"],
                  None if alpha is None else math.radians(alpha), per["throw_deg"], per["rate_dps"])


def load_airframe(path: str | Path) -> Airframe:
    """Read and validate an airframe TOML file.

    Raises:
        InputError: the file is missing, not TOML, or a field is invalid (the
            message names the file and the field).
    """
    return airframe_from_dict(read_toml(path, "airframe file"), str(path))


def airframe_to_dict(a: Airframe) -> dict[str, Any]:
    """Inverse of :func:`airframe_from_dict` (for writing a TOML file with tomli_w)."""
    d: dict[str, Any] = {
        "name": a.name,
        "mass": a.mass,
        "inertia": {"Ixx": a.Ixx, "Iyy": a.Iyy, "Izz": a.Izz, "Ixz": a.Ixz},
        "geometry": {"S": a.S, "b": a.b, "c": a.c},
        "imu_lever_arm": list(a.imu_lever_arm),
        "servo": [
            {
                "name": s.name, "channel": s.channel, "pwm_min": s.pwm_min, "pwm_trim": s.pwm_trim,
                "pwm_max": s.pwm_max, "deflection_at_pwm_min_deg": math.degrees(s.deflection_at_min),
                "deflection_at_pwm_max_deg": math.degrees(s.deflection_at_max),
                "limit_deg": [math.degrees(s.limit_min), math.degrees(s.limit_max)], "mix": dict(s.mix),
            }
            for s in a.servos
        ],
    }
    if a.throttle:
        d["throttle"] = {"channel": a.throttle.channel, "pwm_min": a.throttle.pwm_min, "pwm_max": a.throttle.pwm_max}
    if a.thrust:
        d["thrust"] = {"T_static": a.thrust.T_static, "V_zero": a.thrust.V_zero, "exponent": a.thrust.exponent}
    if a.notes:
        d["notes"] = a.notes
    if a.limits is not None:
        d["limits"] = a.limits.to_dict()
    if a.air_angles != "estimate":
        d["air_data"] = {"angles": a.air_angles}
    if a.CL_alpha is not None:
        d["aero"] = {"CL_alpha": a.CL_alpha} | {k: v for k, v in (("CL_q", a.CL_q), ("CL0", a.CL0),
                                                                  ("CL_delta_e", a.CL_delta_e),
                                                                  ("CL0_sigma", a.CL0_sigma)) if v is not None}
    if a.can_actuators:
        d["can_actuator"] = [{"id": c.actuator_id, "servo": c.servo, "sign": c.sign, "scale": c.scale,
                              "zero_deg": math.degrees(c.zero)} for c in a.can_actuators]
    return d


# ----------------------------------------------------------------------------- DroneCAN actuator map


@dataclass(frozen=True)
class CanActuator:
    """Which DroneCAN actuator measures which servo's surface (``[[can_actuator]]``, docs/airframe.md).

    A DroneCAN servo reports ``uavcan.equipment.actuator.Status.position`` (rad for a rotary servo, by
    the servo's own sign and zero). The surface deflection of servo :attr:`servo`, by the surface's own
    sign convention (the ``[[servo]]`` table's), is::

        deflection = sign * scale * (position - zero)        [rad]

    Attributes:
        actuator_id: DroneCAN ``actuator_id`` (0..255).
        servo: name of the ``[[servo]]`` whose surface it measures.
        sign: +1 or -1 (servo sense against the surface convention).
        scale: surface rad per reported rad (linkage ratio), > 0.
        zero: reported position at zero surface deflection, rad.
    """

    actuator_id: int
    servo: str
    sign: float = 1.0
    scale: float = 1.0
    zero: float = 0.0

    def deflection(self, position: np.ndarray) -> np.ndarray:
        """Surface deflection (rad) from reported positions (rad), any shape."""
        return self.sign * self.scale * (np.asarray(position, float) - self.zero)


def _can_actuators(d: Any, af: Airframe, src: str) -> tuple[CanActuator, ...]:
    """Parse and check the ``[[can_actuator]]`` tables against the servos."""
    if not isinstance(d, list) or not d:
        raise InputError(f"{src}: can_actuator must be [[can_actuator]] tables with id, servo, sign, scale")
    names = {s.name for s in af.servos}
    out: list[CanActuator] = []
    for i, t in enumerate(d):
        where = f"[[can_actuator]] #{i + 1}"
        if not isinstance(t, Mapping):
            raise InputError(f"{src}: {where} must be a table")
        extra = set(t) - {"id", "servo", "sign", "scale", "zero_deg"}
        if extra:
            raise InputError(f"{src}: {where} unknown field '{sorted(extra)[0]}' (expected id, servo, sign, scale, "
                             f"zero_deg)")
        aid = t.get("id")
        if isinstance(aid, bool) or not isinstance(aid, int) or not 0 <= aid <= 255:
            raise InputError(f"{src}: {where} field 'id' must be a DroneCAN actuator id 0..255, got {aid!r}")
        servo = t.get("servo")
        if servo not in names:
            raise InputError(f"{src}: {where} field 'servo' must name a [[servo]] ({', '.join(sorted(names))}), "
                             f"got {servo!r}")
        sign = t.get("sign", 1)
        if isinstance(sign, bool) or sign not in (1, -1):
            raise InputError(f"{src}: {where} field 'sign' must be 1 or -1, got {sign!r}")
        scale = _opt(t, "scale", 1.0, where, src)
        if scale <= 0:
            raise InputError(f"{src}: {where} field 'scale' must be > 0 (the sign goes in 'sign'), got {scale:g}")
        zero = math.radians(_opt(t, "zero_deg", 0.0, where, src))
        if any(c.actuator_id == aid for c in out):
            raise InputError(f"{src}: {where} actuator id {aid} is listed twice")
        if any(c.servo == servo for c in out):
            raise InputError(f"{src}: {where} servo '{servo}' already has an actuator")
        out.append(CanActuator(int(aid), servo, float(sign), scale, zero))
    return tuple(out)
