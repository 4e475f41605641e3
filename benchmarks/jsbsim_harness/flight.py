"""Fly a stock JSBSim aircraft through system-identification maneuvers and record the exact truth.

The aircraft glides (engines shut down, so that every non-gravity force is aerodynamic and the
pipeline's CX needs no thrust model) from a calibrated-airspeed initial condition, a simple
stabilising autopilot (pitch attitude with airspeed hold, wings level, yaw damper) holds it while
the maneuver inputs are added to the autopilot's surface commands (as ArduPlane's SYSID mode adds
them to the controller outputs), and the sum reaches JSBSim through first-order, rate-limited servos. JSBSim's
MIL-F-8785C (``Milspec``) Dryden turbulence, with its rotational components, and a steady wind act on it.

Truth (SI, body axes x fwd / y right / z down, NED) is read from JSBSim's own properties at every
log tick: aerodynamic forces ``forces/fb{x,y,z}-aero-lbs`` and moments ``moments/{l,m,n}-aero-lbsft``
(JSBSim transfers the moments from its aerodynamic reference point to the CG, ``FGAerodynamics``;
checked against ``J w_dot + w x J w``: 1e-11 on the minisgs, 0.2 % with the rounded airframe file in
``tests/jsbsim``), ``aero/alpha-rad``, ``aero/alphadot-rad_sec`` (what the XMLs' ``Cm_alphadot`` terms read: it
carries the gust's vertical acceleration), ``aero/beta-rad``, ``velocities/vt-fps``, ``aero/qbar-psf``, the inertial body rates
``velocities/{p,q,r}i-rad_sec`` and their derivatives, and ``atmosphere/total-wind-*-fps``
(steady wind plus turbulence, the velocity of the air over the ground).

References:
    Berndt, J. S. et al., *JSBSim Reference Manual* (jsbsim.sourceforge.net / jsbsim-team.github.io),
    axes, units and property names. MIL-F-8785C, sec. 3.7 (turbulence models).
    Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016, ch. 9 (inputs).
"""

from __future__ import annotations

import os
import zlib
from dataclasses import asdict, dataclass, field
from typing import Mapping

import jsbsim
import numpy as np

from gcs_sysid.signals import doublet, multisine, three_two_one_one

from .aircraft import AircraftSpec, aircraft

__all__ = ["FlightConfig", "Recording", "fly", "load_model", "turbulence_seed", "maneuver_inputs", "speed_schedule",
           "sideslip_holds", "slip_scale", "PLANS", "TURBULENCE", "LBF", "FT", "SLUG", "SLUG_FT2"]

LBF = 4.4482216152605      # N per lbf
FT = 0.3048                # m per ft
SLUG = 14.593902937        # kg per slug
SLUG_FT2 = SLUG * FT * FT  # kg m^2 per slug ft^2
KT = 0.514444              # m/s per kt

#: Turbulence levels: (JSBSim Milspec severity index, wind speed at 20 ft in kt). MIL-F-8785C
#: gives 15 kt (light), 30 kt (moderate) and 45 kt (severe) at 20 ft; the severity index selects
#: the probability-of-exceedance curve of its Fig. 7 for the medium/high-altitude model (above
#: 2000 ft AGL): light is the 1e-2 curve (index 3), moderate the 1e-3 curve (index 4), as JSBSim's
#: FGWinds.h documents them. Until the fifteenth session the harness flew index 1 as "light" (the
#: 2e-1 curve: a fifth to a tenth of light's intensity, none above 7500 ft) and index 3 as
#: "moderate"; that setting is kept as ``"calm"`` for the tests written against it
#: (docs/jsbsim.md, "Turbulence levels").
TURBULENCE = {"none": (0, 0.0), "calm": (1, 15.0), "light": (3, 15.0), "moderate": (4, 30.0)}

#: Flight plans: ``"standard"`` holds one trim airspeed; ``"sweep"`` adds a speed sweep (several
#: trim airspeeds, reached by slow pull-ups and push-overs) and steady-heading sideslips at each of
#: them, so that alpha spans several degrees and sideslip happens at different alpha
#: (:func:`speed_schedule`, :func:`sideslip_holds`); ``"sweep_turn"`` flies the sweep in a steady
#: turn that carries the heading through up to :data:`TURN_HEADING_DEG` (:func:`turn_rate`), so that
#: the wind triangle separates the wind from a pitot error (the heading-sweep form of the cloverleaf
#: calibration: USNTPS FTM 108, ch. 9; Lewis 2003).
PLANS = ("standard", "sweep", "sweep_turn")
#: Plans that fly the speed sweep and its sideslips.
SWEEP_PLANS = ("sweep", "sweep_turn")
#: Sensor noise draws (``FlightConfig.sensor_draw``): ``"shared"`` seeds the noise from the flight's seed
#: alone, so every aircraft's flight of one seed carries the same noise sequences (among them the
#: autopilot wind estimate's wander); ``"per_aircraft"`` mixes the aircraft's name into the sensor seed, so
#: that a roster's sensor noise is independent draws (thirty-fourth session, issue 9).
SENSOR_DRAWS = ("shared", "per_aircraft")
#: JSBSim's turbulence draws (``FlightConfig.turbulence_draw``, the same two values): ``"shared"`` sets
#: ``simulation/randomseed`` to the flight's seed, so every aircraft's flight of one seed flies the same
#: random sequence (the slow aircraft's seed-100 references shared their gusts: thirty-fourth session,
#: pitot_scale_gate); ``"per_aircraft"`` mixes the aircraft's name in (:func:`turbulence_seed`).
TURBULENCE_DRAWS = SENSOR_DRAWS

#: The sweep's trim airspeeds: (start as a fraction of the logged duration, airspeed / initial
#: airspeed). The last 20 % of the flight (the held-out segment) holds two levels of its own.
#: Within every aircraft's envelope: the slowest, 0.75 of the initial calibrated airspeed, is
#: 60 kt on the c172x and pa28 (power-off stall, flaps up, about 48-50 kt) and 37.5 kt on the
#: SGS 2-33 (stall about 27 kt); the fastest, 1.12, is 90 kt (c172x, pa28; never-exceed 158-
#: 160 kt) and 56 kt (SGS 2-33; never-exceed 85 kt). Faster levels were tried: the SGS's glide
#: cannot reach 1.25 (its drag grows as the autopilot pushes, and alpha went to -12 deg).
SWEEP_LEVELS = ((0.0, 1.0), (0.07, 0.75), (0.27, 1.12), (0.47, 0.82), (0.64, 1.08), (0.81, 0.75),
                (0.91, 1.12))
#: Largest sideslip of a flight in the envelope, deg: beyond it the aircraft has departed (an
#: injected effect that reverses the dihedral effect at high alpha can do that).
MAX_BETA_DEG = 20.0
SWEEP_RAMP_S = 8.0       # duration of each speed change (cosine ramp), s
SWEEP_MAX_PITCH_FF = 0.15  # largest pitch-attitude feedforward of a speed change, rad
SWEEP_SLIP_RUDDER = 0.5    # rudder of a steady-heading sideslip, share of the maneuver amplitude
#: Sideslip at the slow levels: the rudder of a steady-heading sideslip is scaled by
#: ``clip((level - SLIP_SLOW_FROM) / (1 - SLIP_SLOW_FROM), SLIP_SLOW_MIN, 1)`` of the level's
#: airspeed factor (full at the initial speed and above, half at 0.75), as a test pilot limits
#: sideslip near the stall, where the dihedral effect can reverse (added 2026-11-22, issue 9).
SLIP_SLOW_FROM = 0.5
SLIP_SLOW_MIN = 0.5
#: Knock-it-off limits of the maneuvers (the test pilot's abort): when the sideslip exceeds
#: ``ABORT_BETA_DEG`` or the bank ``ABORT_BANK_DEG``, the maneuver inputs and the speed sweep's
#: feedforward are faded out and the pilot recovers for ``RECOVER_S`` s: rudder against the
#: sideslip (``RECOVER_K_BETA`` rad per rad), wings level, and the nose lowered to at least the
#: initial airspeed (unloading restores the dihedral effect that high alpha took away); then the
#: inputs fade back in over ``RECOVER_FADE_S`` s. Inside :data:`MAX_BETA_DEG`, so that a departing
#: maneuver is stopped before the envelope check ends the flight; ``meta["aborts"]`` lists them.
ABORT_BETA_DEG = 15.0
ABORT_BANK_DEG = 45.0
RECOVER_S = 6.0
RECOVER_FADE_S = 1.5
RECOVER_K_BETA = 0.5
#: ``"sweep_turn"``: the heading turned through over the logged flight (deg), the largest bank the turn
#: may need (deg; a faster aircraft turns through less), and the roll-in time at the start (s).
TURN_HEADING_DEG = 300.0
TURN_MAX_BANK_DEG = 25.0
TURN_ROLL_IN_S = 5.0


@dataclass(frozen=True)
class FlightConfig:
    """What to fly.

    Attributes:
        aircraft: harness aircraft name (:data:`benchmarks.jsbsim_harness.aircraft.AIRCRAFT`).
        duration_s: logged flight time after the settling phase, s.
        turbulence: ``"none"``, ``"calm"``, ``"light"`` or ``"moderate"`` (:data:`TURBULENCE`).
        seed: seeds JSBSim's turbulence (``simulation/randomseed``, :func:`turbulence_seed`) and, in
            ``sensors``, the noise.
        wind_ned: steady wind, the air's velocity over the ground, NED, m/s.
        sim_rate_hz: JSBSim integration rate, Hz.
        log_rate_hz: truth and fast-stream rate, Hz (a whole divisor of ``sim_rate_hz``).
        settle_s: unlogged flight before the log starts, s (the autopilot settles the glide).
        amplitude_scale: multiplies the aircraft's maneuver amplitudes.
        servo_tau_s: time constant of the servos, s: the surfaces follow the commands (autopilot +
            maneuvers) through a first-order lag with a rate limit of ``servo_rate_deg_s`` (JSBSim's
            stock models move their surfaces instantly). 0 = ideal servos.
        servo_rate_deg_s: servo rate limit, deg/s of the project's deflection.
        plan: ``"standard"`` (one trim airspeed), ``"sweep"`` (:data:`PLANS`): the same
            maneuvers plus a speed sweep and steady-heading sideslips that span alpha, or
            ``"sweep_turn"``: the sweep flown in a steady turn (:func:`turn_rate`).
        sensor_draw: ``"shared"`` or ``"per_aircraft"`` (:data:`SENSOR_DRAWS`): whether the sensor
            noise is seeded by ``seed`` alone or by ``seed`` and the aircraft's name.
        turbulence_draw: ``"shared"`` or ``"per_aircraft"`` (:data:`TURBULENCE_DRAWS`): the same
            for JSBSim's turbulence (:func:`turbulence_seed`).
    """

    aircraft: str = "c172x"
    duration_s: float = 120.0
    turbulence: str = "light"
    seed: int = 0
    wind_ned: tuple[float, float, float] = (3.0, -2.0, 0.0)
    sim_rate_hz: float = 200.0
    log_rate_hz: float = 50.0
    settle_s: float = 15.0
    amplitude_scale: float = 1.0
    servo_tau_s: float = 0.04
    servo_rate_deg_s: float = 300.0
    plan: str = "standard"
    sensor_draw: str = "shared"
    turbulence_draw: str = "shared"

    def __post_init__(self):
        if self.plan not in PLANS:
            raise ValueError(f"plan must be one of {', '.join(PLANS)}, got '{self.plan}'")
        if self.sensor_draw not in SENSOR_DRAWS:
            raise ValueError(f"sensor_draw must be one of {', '.join(SENSOR_DRAWS)}, got '{self.sensor_draw}'")
        if self.turbulence_draw not in TURBULENCE_DRAWS:
            raise ValueError(f"turbulence_draw must be one of {', '.join(TURBULENCE_DRAWS)}, "
                             f"got '{self.turbulence_draw}'")
        if self.turbulence not in TURBULENCE:
            raise ValueError(f"turbulence must be one of {', '.join(TURBULENCE)}, got '{self.turbulence}'")
        if abs(self.sim_rate_hz / self.log_rate_hz - round(self.sim_rate_hz / self.log_rate_hz)) > 1e-9:
            raise ValueError(f"log_rate_hz {self.log_rate_hz} must divide sim_rate_hz {self.sim_rate_hz}")
        if not self.duration_s > 0:
            raise ValueError(f"duration_s must be > 0, got {self.duration_s}")


@dataclass
class Recording:
    """A flown flight: truth on the log grid, SI.

    Attributes:
        t: vehicle time, s, shape (T,), starting at 0 at the end of the settling phase.
        truth: name -> (T,) arrays (see :data:`TRUTH_FIELDS` in ``truth.py`` for the list).
        constants: mass kg, Ixx Iyy Izz Ixz kg m^2 (project convention, Ixz = integral x z dm),
            S m^2, b m, c m, home lat/lon rad and ground altitude m.
        config: the :class:`FlightConfig`.
    """

    t: np.ndarray
    truth: dict[str, np.ndarray]
    constants: dict[str, float]
    config: FlightConfig
    meta: dict = field(default_factory=dict)


def turbulence_seed(config: FlightConfig) -> int:
    """JSBSim's ``simulation/randomseed`` for ``config``: the flight's seed with
    ``turbulence_draw="shared"``; with ``"per_aircraft"`` a CRC-32 of the aircraft's name and the seed,
    kept to 31 bits (JSBSim's property is a C int), so that a roster's turbulence is independent
    draws and each aircraft's flight of a seed is still the same every time."""
    if config.turbulence_draw == "shared":
        return int(config.seed)
    return zlib.crc32(f"{config.aircraft}/{config.seed}".encode()) & 0x7FFFFFFF


def load_model(spec: AircraftSpec, dt: float, seed: int = 0, aircraft_path: str | None = None) -> jsbsim.FGFDMExec:
    """A JSBSim executive with ``spec``'s model loaded from the wheel's own data (no network).

    ``aircraft_path``: a folder holding ``<model>/<model>.xml`` to load instead of the wheel's
    (an edited copy, ``effects.py``); engines and systems still come from the wheel.

    Point masses off the aircraft's centre plane are emptied (the c172x carries an 80 lb mass at
    its right wing tip): the project's airframe file has no Ixy/Iyz, and JSBSim's moments of
    those products of inertia would otherwise be an error no estimator could remove.
    """
    jsbsim.FGJSBBase().debug_lvl = 0      # no start-up banner on stdout
    fdm = jsbsim.FGFDMExec(None)          # root dir: the wheel's packaged aircraft/engine/systems
    fdm.set_debug_level(0)
    if aircraft_path is not None:
        fdm.set_aircraft_path(str(aircraft_path))
    if not fdm.load_model(spec.model):
        raise RuntimeError(f"JSBSim could not load model '{spec.model}'")
    # the models' own <output> elements (the c172x writes JSBout172B.csv into the cwd) go nowhere
    for n in range(16):
        try:
            if not fdm.get_output_filename(n):
                break
        except Exception:       # no output n: JSBSim raises (IndexError/RuntimeError by version)
            break
        fdm.set_output_filename(n, os.devnull)
    fdm.disable_output()
    fdm.set_dt(dt)
    # JSBSim 1.3.3 integrates the body rates and the attitude with rectangular Euler by default
    # (``simulation/integrator/*/rotational`` = 1) and the velocities with Adams-Bashforth 2: the
    # logged rates then trail the logged moments by half a step (2.5 ms at 200 Hz; found by
    # i8-measured, up to 1 point of every moment coefficient's error). Adams-Bashforth 2 (= 3) for
    # both rotational integrators puts rates, attitude and velocities on the same footing.
    fdm["simulation/integrator/rate/rotational"] = 3
    fdm["simulation/integrator/position/rotational"] = 3
    fdm["simulation/randomseed"] = int(seed)
    i = 0
    while True:
        key = f"inertia/pointmass-location-Y-inches[{i}]"
        try:
            y = fdm[key]
        except KeyError:
            break
        if abs(y) > 1e-6:
            fdm[f"inertia/pointmass-weight-lbs[{i}]"] = 0.0
        i += 1
    return fdm


def _segments(spec: AircraftSpec, duration: float) -> list[tuple[str, int, float, float, float]]:
    """(kind, axis, start s, amplitude rad, pulse s or period s) of the maneuvers. Axis 0 delta_e,
    1 delta_a, 2 delta_r, -1 all three (multisine).

    The first 80 % of the flight repeats a block of single-axis 3-2-1-1s and doublets and a
    three-axis multisine (alternating signs); the last 20 % (the replay's held-out segment) is one
    three-axis multisine, so that the held-out segment excites every axis."""
    ae, aa, ar = np.radians(spec.amplitude_deg)
    pe, pa, pr = spec.pulse_s
    block = [("3211", 0, ae, pe), ("doublet", 1, aa, pa), ("doublet", 2, ar, pr), ("3211", 1, aa, pa),
             ("3211", 2, ar, pr), ("doublet", 0, ae * 1.5, pe), ("multisine", -1, 1.0, 16.0)]
    out, t, k = [], 2.0, 0
    train_end = 0.8 * duration
    while True:
        kind, axis, amp, w = block[k % len(block)]
        length = {"3211": 7 * w, "doublet": 2 * w, "multisine": w}[kind]
        if t + length > train_end - 1.0:
            break
        sgn = -1.0 if (k // len(block)) % 2 else 1.0     # alternate signs on repeats
        out.append((kind, axis, t, sgn * amp, w))
        t += length + (3.0 if kind != "multisine" else 2.0)
        k += 1
    last = duration - train_end - 1.5
    if last >= 4.0:
        out.append(("multisine", -1, train_end + 0.75, 1.0, last))
    return out


def speed_schedule(t: np.ndarray, duration: float, plan: str = "standard") -> tuple[np.ndarray, np.ndarray]:
    """Airspeed reference of the plan as a multiple of the initial airspeed, and its rate.

    ``"sweep"`` steps through :data:`SWEEP_LEVELS`, each change a cosine ramp of
    :data:`SWEEP_RAMP_S` (a slow pull-up to slow down, a push-over to speed up: the autopilot adds
    the pitch attitude ``-(dV_ref/dt)/g`` that the change of speed needs in a glide, limited to
    :data:`SWEEP_MAX_PITCH_FF`). A speed sweep
    is how a flight-test engineer spans alpha at 1 g (Morelli and Klein, sec. 9.1: data at several
    flight conditions for nonlinear terms); ``"standard"`` holds 1.

    Args:
        t: log times, s, shape (T,), 0 at the end of the settling phase.
        duration: logged duration, s. plan: one of :data:`PLANS`.

    Returns:
        (factor (T,), d factor / dt (T,) in 1/s).
    """
    t = np.asarray(t, float)
    f, df = np.ones_like(t), np.zeros_like(t)
    if plan not in SWEEP_PLANS:
        return f, df
    for (_, prev), (frac, lev) in zip(SWEEP_LEVELS[:-1], SWEEP_LEVELS[1:]):
        t0 = frac * duration
        x = np.clip((t - t0) / SWEEP_RAMP_S, 0.0, 1.0)
        f += (lev - prev) * 0.5 * (1 - np.cos(np.pi * x))
        df += np.where((x > 0) & (x < 1), (lev - prev) * 0.5 * np.pi / SWEEP_RAMP_S * np.sin(np.pi * x), 0.0)
    return f, df


def sideslip_holds(spec: AircraftSpec, duration: float, plan: str = "standard") -> list[tuple[float, float]]:
    """(start s, rudder deflection rad) of the plan's steady-heading sideslips (none for ``"standard"``).

    One per speed level of :data:`SWEEP_LEVELS` (so at a different alpha each), starting when
    60 % of the level's speed change is done, alternating in sign; each ramps in over 0.75 s,
    holds 2.5 s and ramps out over 0.75 s, with the rudder at :data:`SWEEP_SLIP_RUDDER` of the
    aircraft's maneuver amplitude times the slow-level limit (:func:`slip_scale`).
    The autopilot's roll and heading loops supply the opposite aileron and the bank, as a pilot
    flying a steady-heading sideslip does. Levels too short to hold one are skipped.
    """
    if plan not in SWEEP_PLANS:
        return []
    ar = SWEEP_SLIP_RUDDER * np.radians(spec.amplitude_deg[2])
    starts = [frac * duration for frac, _ in SWEEP_LEVELS] + [duration]
    out = []
    for k in range(len(SWEEP_LEVELS)):
        t0 = starts[k] + (0.6 * SWEEP_RAMP_S if k else 3.0)
        if t0 + _SLIP_S <= starts[k + 1] - 0.3:
            out.append((t0, ar * slip_scale(SWEEP_LEVELS[k][1]) * (1.0 if len(out) % 2 == 0 else -1.0)))
    return out


def slip_scale(level: float) -> float:
    """Share of the full sideslip rudder flown at airspeed factor ``level`` (:data:`SLIP_SLOW_FROM`).

    Near the stall a pilot flies smaller sideslips: the dihedral effect weakens or reverses at
    high alpha and a large sideslip there can end in a departure (Morelli and Klein, sec. 9.1:
    inputs sized to keep the aircraft near the condition being identified).
    """
    x = (float(level) - SLIP_SLOW_FROM) / (1.0 - SLIP_SLOW_FROM)
    return float(np.clip(x, SLIP_SLOW_MIN, 1.0))


def turn_rate(plan: str, v_ref: float, duration: float) -> float:
    """Heading rate of the plan's steady turn, rad/s (0 unless ``plan == "sweep_turn"``).

    :data:`TURN_HEADING_DEG` over ``duration``, or the rate a coordinated turn reaches at
    :data:`TURN_MAX_BANK_DEG` at ``v_ref`` (``g tan(phi) / V``) when that is less.

    Args:
        plan: one of :data:`PLANS`. v_ref: the initial true airspeed, m/s. duration: logged time, s.
    """
    if plan != "sweep_turn":
        return 0.0
    return float(min(np.radians(TURN_HEADING_DEG) / duration,
                     9.80665 * np.tan(np.radians(TURN_MAX_BANK_DEG)) / max(v_ref, 1.0)))


_SLIP_S = 4.0        # ramp in 0.75 s, hold 2.5 s, ramp out 0.75 s


def _slip(t: np.ndarray, start: float, amp: float) -> np.ndarray:
    x = t - start
    up = np.clip(x / 0.75, 0.0, 1.0)
    down = np.clip((_SLIP_S - x) / 0.75, 0.0, 1.0)
    return amp * np.minimum(up, down) * ((x >= 0) & (x <= _SLIP_S))


def maneuver_inputs(spec: AircraftSpec, t: np.ndarray, duration: float, scale: float = 1.0,
                    plan: str = "standard") -> np.ndarray:
    """Maneuver deflections added to the autopilot's, rad, shape (T, 3): delta_e, delta_a, delta_r.

    3-2-1-1s and doublets on each axis in turn, then an orthogonal phase-optimised multisine on all
    three axes together (0.1-1.5 Hz, ``gcs_sysid.signals``), repeated with alternating signs; the last
    20 % of the flight is one three-axis multisine (see :func:`_segments`). The ``"sweep"`` plan adds
    the rudder of its steady-heading sideslips (:func:`sideslip_holds`).
    """
    u = np.zeros((len(t), 3))
    amps = np.radians(spec.amplitude_deg) * scale
    for kind, axis, start, amp, w in _segments(spec, duration):
        if kind == "multisine":
            for j in range(3):
                u[:, j] += multisine(t, start, w, (max(0.1, 3.0 / w), 1.5), 0.8 * amps[j] * np.sign(amp), 3, j)
        elif kind == "3211":
            u[:, axis] += three_two_one_one(t, start, w, amp * scale)
        else:
            u[:, axis] += doublet(t, start, w, amp * scale)
    for start, amp in sideslip_holds(spec, duration, plan):
        u[:, 2] += _slip(t, start, amp * scale)
    return u


_PROPS = {
    "phi": ("attitude/phi-rad", 1.0), "theta": ("attitude/theta-rad", 1.0), "psi": ("attitude/psi-rad", 1.0),
    "p": ("velocities/pi-rad_sec", 1.0), "q": ("velocities/qi-rad_sec", 1.0), "r": ("velocities/ri-rad_sec", 1.0),
    "p_dot": ("accelerations/pidot-rad_sec2", 1.0), "q_dot": ("accelerations/qidot-rad_sec2", 1.0),
    "r_dot": ("accelerations/ridot-rad_sec2", 1.0),
    "p_aero": ("velocities/p-aero-rad_sec", 1.0), "q_aero": ("velocities/q-aero-rad_sec", 1.0),
    "r_aero": ("velocities/r-aero-rad_sec", 1.0),
    "u": ("velocities/u-fps", FT), "v": ("velocities/v-fps", FT), "w": ("velocities/w-fps", FT),
    "vn": ("velocities/v-north-fps", FT), "ve": ("velocities/v-east-fps", FT), "vd": ("velocities/v-down-fps", FT),
    "V": ("velocities/vt-fps", FT), "alpha": ("aero/alpha-rad", 1.0), "beta": ("aero/beta-rad", 1.0),
    "alpha_dot": ("aero/alphadot-rad_sec", 1.0),    # what the XMLs' Cm_alphadot / CL_alphadot terms read
    "qbar": ("aero/qbar-psf", LBF / FT**2), "rho": ("atmosphere/rho-slugs_ft3", SLUG / FT**3),
    "press_abs": ("atmosphere/P-psf", LBF / FT**2), "temperature": ("atmosphere/T-R", 5.0 / 9.0),
    "wn": ("atmosphere/total-wind-north-fps", FT), "we": ("atmosphere/total-wind-east-fps", FT),
    "wd": ("atmosphere/total-wind-down-fps", FT),
    "lat": ("position/lat-geod-rad", 1.0), "lon": ("position/long-gc-rad", 1.0), "alt": ("position/h-sl-meters", 1.0),
    "Fx_aero": ("forces/fbx-aero-lbs", LBF), "Fy_aero": ("forces/fby-aero-lbs", LBF),
    "Fz_aero": ("forces/fbz-aero-lbs", LBF),
    "Fx_total": ("forces/fbx-total-lbs", LBF), "Fy_total": ("forces/fby-total-lbs", LBF),
    "Fz_total": ("forces/fbz-total-lbs", LBF),
    "L_aero": ("moments/l-aero-lbsft", LBF * FT), "M_aero": ("moments/m-aero-lbsft", LBF * FT),
    "N_aero": ("moments/n-aero-lbsft", LBF * FT),
    "L_total": ("moments/l-total-lbsft", LBF * FT), "M_total": ("moments/m-total-lbsft", LBF * FT),
    "N_total": ("moments/n-total-lbsft", LBF * FT),
    "elevator_pos": ("fcs/elevator-pos-rad", 1.0), "rudder_pos": ("fcs/rudder-pos-rad", 1.0),
    "mass": ("inertia/mass-slugs", SLUG),
}


def _set_ic(fdm: jsbsim.FGFDMExec, spec: AircraftSpec, cfg: FlightConfig) -> None:
    fdm["ic/h-sl-ft"] = spec.altitude_ft
    fdm["ic/vc-kts"] = spec.airspeed_kts
    fdm["ic/gamma-deg"] = -4.0
    fdm["ic/psi-true-deg"] = 30.0
    fdm["ic/lat-geod-deg"] = 47.397742
    fdm["ic/long-gc-deg"] = 8.545594
    sev, w20 = TURBULENCE[cfg.turbulence]
    fdm["atmosphere/turb-type"] = 3 if sev else 0            # 3 = ttMilspec (Dryden form)
    fdm["atmosphere/turbulence/milspec/severity"] = sev
    fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20 * KT / FT
    if not fdm.run_ic():
        raise RuntimeError(f"JSBSim could not initialise {spec.model}")
    # the steady wind goes in after run_ic: run_ic resets JSBSim's atmosphere wind to zero (jsbsim
    # 1.3.3, checked: 10 ft/s set before run_ic reads 0 after it), so every flight before this fix
    # flew in turbulence alone. The step from still air to the wind is flown off in the unlogged
    # settling phase (``settle_s``).
    wn, we, wd = cfg.wind_ned
    fdm["atmosphere/wind-north-fps"] = wn / FT
    fdm["atmosphere/wind-east-fps"] = we / FT
    fdm["atmosphere/wind-down-fps"] = wd / FT
    for i in range(fdm.get_propulsion().get_num_engines()):
        fdm[f"propulsion/engine[{i}]/set-running"] = 0
    fdm["fcs/throttle-cmd-norm"] = 0.0
    fdm["fcs/mixture-cmd-norm"] = 0.0
    if spec.gear_up:
        fdm["gear/gear-cmd-norm"] = 0.0


def _deflections(fdm: jsbsim.FGFDMExec, spec: AircraftSpec) -> tuple[float, float, float]:
    """(delta_e, delta_a, delta_r) in the project's conventions, rad."""
    de = spec.elevator_sign * fdm["fcs/elevator-pos-rad"]
    left, right = spec.aileron_props
    raw = 0.5 * (fdm[left] - fdm[right]) if right else fdm[left]
    return de, spec.aileron_sign * raw, spec.rudder_sign * fdm["fcs/rudder-pos-rad"]


def fly(config: FlightConfig, aircraft_path: str | None = None) -> Recording:
    """Fly ``config`` and return the truth on the log grid.

    ``aircraft_path``: load an edited copy of the model from there (:func:`load_model`).

    Raises:
        ValueError: unknown aircraft or bad configuration.
        RuntimeError: JSBSim failed to load or initialise the model, or the aircraft left the
            flight envelope (airspeed below half or above twice the initial value, bank beyond
            70 deg, sideslip beyond :data:`MAX_BETA_DEG`) even with the pilot's knock-it-off and
            recovery (:data:`ABORT_BETA_DEG`; the aborts flown are listed in ``meta["aborts"]``),
            which means the autopilot or the maneuvers need retuning for it.
    """
    spec = aircraft(config.aircraft)
    dt = 1.0 / config.sim_rate_hz
    dec = int(round(config.sim_rate_hz / config.log_rate_hz))
    fdm = load_model(spec, dt, turbulence_seed(config), aircraft_path)
    _set_ic(fdm, spec, config)
    k_th, k_q, k_v, k_phi, k_p, k_r = spec.gains
    v_ref = fdm["velocities/vt-fps"] * FT
    theta_ref0 = fdm["attitude/theta-rad"]
    psi_ref0 = fdm["attitude/psi-rad"]
    omega_turn = turn_rate(config.plan, v_ref, config.duration_s)
    de_int = 0.0
    servo = np.zeros(3)          # surface positions the servos hold (project deltas), rad
    first = True
    a_servo = 1.0 - np.exp(-dt / config.servo_tau_s) if config.servo_tau_s > 0 else 1.0
    max_step = np.radians(config.servo_rate_deg_s) * dt
    n_settle = int(round(config.settle_s * config.sim_rate_hz))
    n_log = int(round(config.duration_s * config.log_rate_hz))
    t_log = np.arange(n_log) / config.log_rate_hz
    u_man = maneuver_inputs(spec, t_log, config.duration_s, config.amplitude_scale, config.plan)
    v_fac, v_rate = speed_schedule(t_log, config.duration_s, config.plan)
    rec = {k: np.empty(n_log) for k in list(_PROPS) + ["delta_e", "delta_a", "delta_r", "delta_t"]}
    n_total = n_settle + n_log * dec
    aborts: list[dict] = []
    t_abort = -np.inf            # time of the last knock-it-off, s of logged time
    for i in range(n_total):
        j = (i - n_settle) // dec
        t_now = (i - n_settle) * dt
        # knock-it-off: the maneuvers fade out, the autopilot recovers, then they fade back in
        w_man = float(np.clip((t_now - t_abort - RECOVER_S) / RECOVER_FADE_S, 0.0, 1.0))
        if i >= n_settle and (abs(fdm["aero/beta-rad"]) > np.radians(ABORT_BETA_DEG)
                              or abs(fdm["attitude/phi-rad"]) > np.radians(ABORT_BANK_DEG)):
            if t_now - t_abort > RECOVER_S:
                aborts.append({"t_s": round(t_now, 3), "beta_deg": round(float(np.degrees(fdm["aero/beta-rad"])), 2),
                               "bank_deg": round(float(np.degrees(fdm["attitude/phi-rad"])), 2)})
            t_abort, w_man = t_now, 0.0
        man = u_man[j] * w_man if i >= n_settle else np.zeros(3)
        v_cmd = v_ref * (v_fac[j] if i >= n_settle else 1.0)
        v_cmd += (1.0 - w_man) * max(0.0, v_ref - v_cmd)          # recovery: unload to >= initial speed
        # glide-path change for dV/dt (a pull-up to slow down, a push-over to speed up), limited
        theta_ff = w_man * float(np.clip(-v_ref * (v_rate[j] if i >= n_settle else 0.0) / 9.80665,
                                         -SWEEP_MAX_PITCH_FF, SWEEP_MAX_PITCH_FF))
        theta, q, V = fdm["attitude/theta-rad"], fdm["velocities/q-rad_sec"], fdm["velocities/vt-fps"] * FT
        phi, p, r = fdm["attitude/phi-rad"], fdm["velocities/p-rad_sec"], fdm["velocities/r-rad_sec"]
        theta_ref0 += 0.2 * k_v * (V - v_cmd) * dt            # slow trim of the pitch reference
        theta_ref = theta_ref0 + k_v * (V - v_cmd) + theta_ff
        e_th = theta - theta_ref
        de_int += 0.5 * k_th * e_th * dt
        de = de_int + k_th * e_th + k_q * q + man[0]
        # the heading reference: fixed, or turning at omega_turn after a roll-in (``"sweep_turn"``)
        t_turn = max(t_now, 0.0)
        w_in = min(t_turn / TURN_ROLL_IN_S, 1.0)
        psi_ref = psi_ref0 + omega_turn * (0.5 * TURN_ROLL_IN_S * w_in * w_in if w_in < 1.0
                                           else t_turn - 0.5 * TURN_ROLL_IN_S)
        psi_err = (fdm["attitude/psi-rad"] - psi_ref + np.pi) % (2 * np.pi) - np.pi
        phi_ff = float(np.arctan(V * omega_turn * w_in / 9.80665))   # coordinated-turn bank
        phi_ref = phi_ff + float(np.clip(-0.5 * psi_err, -0.2, 0.2))     # weak heading hold
        da = k_phi * (phi - phi_ref) + k_p * p + man[1]
        r_turn = omega_turn * w_in * np.cos(phi) * np.cos(theta)          # the turn's own yaw rate
        dr = k_r * (r - r_turn) + man[2] - (1.0 - w_man) * RECOVER_K_BETA * fdm["aero/beta-rad"]   # + recovery
        cmd = np.array([de, da, dr])
        if first:
            servo, first = cmd.copy(), False
        servo = servo + np.clip(a_servo * (cmd - servo), -max_step, max_step)   # lag + rate limit
        de, da, dr = servo
        fdm["fcs/elevator-cmd-norm"] = float(np.clip(de * spec.elevator_sign * spec.cmd_per_rad[0], -1, 1))
        fdm["fcs/aileron-cmd-norm"] = float(np.clip(da * spec.aileron_sign * spec.cmd_per_rad[1], -1, 1))
        fdm["fcs/rudder-cmd-norm"] = float(np.clip(dr * spec.rudder_sign * spec.cmd_per_rad[2], -1, 1))
        if not fdm.run():
            raise RuntimeError(f"JSBSim stopped at t = {i * dt:.2f} s")
        if i >= n_settle and (i - n_settle) % dec == dec - 1:
            for k, (prop, scale) in _PROPS.items():
                rec[k][j] = fdm[prop] * scale
            rec["delta_e"][j], rec["delta_a"][j], rec["delta_r"][j] = _deflections(fdm, spec)
            rec["delta_t"][j] = 0.0
            if not (0.5 * v_ref < rec["V"][j] < 2 * v_ref) or abs(rec["phi"][j]) > np.radians(70) \
                    or abs(rec["beta"][j]) > np.radians(MAX_BETA_DEG):
                raise RuntimeError(f"{spec.name}: left the envelope at t = {t_log[j]:.1f} s "
                                   f"(V {rec['V'][j]:.1f} m/s, bank {np.degrees(rec['phi'][j]):.0f} deg, "
                                   f"sideslip {np.degrees(rec['beta'][j]):.0f} deg)")
    left, right = spec.aileron_props
    const = {"mass": float(fdm["inertia/mass-slugs"] * SLUG),
             "Ixx": float(fdm["inertia/ixx-slugs_ft2"] * SLUG_FT2),
             "Iyy": float(fdm["inertia/iyy-slugs_ft2"] * SLUG_FT2),
             "Izz": float(fdm["inertia/izz-slugs_ft2"] * SLUG_FT2),
             "Ixz": float(-fdm["inertia/ixz-slugs_ft2"] * SLUG_FT2),   # JSBSim's sign is the opposite
             "Ixy": float(-fdm["inertia/ixy-slugs_ft2"] * SLUG_FT2),
             "Iyz": float(-fdm["inertia/iyz-slugs_ft2"] * SLUG_FT2),
             "S": float(fdm["metrics/Sw-sqft"] * FT**2), "b": float(fdm["metrics/bw-ft"] * FT),
             "c": float(fdm["metrics/cbarw-ft"] * FT),
             "home_lat": float(rec["lat"][0]), "home_lon": float(rec["lon"][0]), "home_alt": 0.0}
    meta = {"config": asdict(config), "aircraft": asdict(spec) | {"airframe_path": str(spec.airframe_path)},
            "jsbsim_version": jsbsim.__version__, "aborts": aborts}
    meta["aircraft"].pop("airframe_path", None)
    return Recording(t=t_log, truth=rec, constants=const, config=config, meta=meta)
