"""Write a harness flight as an ArduPilot-like .tlog (with the project's own tlog writer) and its truth.

The log is written by :func:`gcs_sysid.sim.tlog.write_tlog` (real MAVLink 2 bytes from pymavlink's
``ardupilotmega`` dialect behind 8-byte tlog timestamps) at the harness's stream rates
(:data:`~benchmarks.jsbsim_harness.sensors.SENSOR_RATES_HZ`); SERVO_OUTPUT_RAW carries JSBSim's
surface positions mapped to PWM through the aircraft's airframe file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

from gcs_sysid.airframe import load_airframe
from gcs_sysid.sim.tlog import write_tlog

from .aircraft import aircraft
from .flight import FlightConfig, Recording, fly
from .sensors import SENSOR_RATES_HZ, make_sensors
from .truth import save_truth

__all__ = ["write_log", "make_flight", "FlightFiles"]


@dataclass(frozen=True)
class FlightFiles:
    """Paths of one harness flight: the .tlog the pipeline reads, the truth it never reads, the airframe."""

    tlog: Path
    truth: Path
    airframe: Path
    recording: Recording


def write_log(rec: Recording, path: str | Path, aoa: str = "ahrs", sensors: dict | None = None) -> int:
    """Write ``rec`` as a .tlog; returns the number of packets.

    Args:
        rec: the flight.
        path: output .tlog.
        aoa: AOA_SSA variant, ``"ahrs"`` or ``"vane"`` (:func:`~benchmarks.jsbsim_harness.sensors.make_sensors`).
        sensors: the sensor streams to write (default ``make_sensors(rec, aoa)``; ``effects.py``
            passes them with a sensor error added).
    """
    spec = aircraft(rec.config.aircraft)
    af = load_airframe(spec.airframe_path)
    tr = rec.truth
    result = SimpleNamespace(
        t=rec.t, rate_hz=rec.config.log_rate_hz, sensors=make_sensors(rec, aoa) if sensors is None else sensors, airframe=af,
        commands={k: tr[k] for k in ("delta_e", "delta_a", "delta_r", "delta_t")},
        truth={"psi": tr["psi"]}, seed=rec.config.seed,
        demand={},   # the harness's stabiliser demand is not recorded: no NAV_CONTROLLER_OUTPUT
        plan=SimpleNamespace(name=f"jsbsim {spec.model} {rec.config.turbulence}",
                             setpoints=[SimpleNamespace(airspeed=float(tr["V"].mean()))]))
    return write_tlog(result, path, af, rates_hz=SENSOR_RATES_HZ)


def make_flight(config: FlightConfig, out_dir: str | Path, aoa: str = "ahrs", stem: str | None = None) -> FlightFiles:
    """Fly ``config`` and write ``<stem>.tlog`` and ``<stem>-truth.npz`` into ``out_dir``.

    With ``aoa="vane"`` the airframe is the aircraft's file plus ``[air_data] angles = "vane"``
    (``docs/airframe.md``: the log's AOA_SSA are vane measurements), written as
    ``<stem>-airframe.toml``; otherwise the checked-in ``data/airframes/jsbsim-<name>.toml``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = stem or f"{config.aircraft}-{config.turbulence}-s{config.seed}-{aoa}"
    rec = fly(config)
    tlog, truth = out / f"{stem}.tlog", out / f"{stem}-truth.npz"
    write_log(rec, tlog, aoa)
    save_truth(rec, truth)
    airframe = aircraft(config.aircraft).airframe_path
    if aoa == "vane":
        vane = out / f"{stem}-airframe.toml"
        vane.write_text(airframe.read_text() + '\n[air_data]\nangles = "vane"\n')
        airframe = vane
    return FlightFiles(tlog, truth, airframe, rec)
