"""Write a harness flight as an ArduPilot-like .tlog (with the project's own tlog writer) and its truth.

The log is written by :func:`gcs_sysid.sim.tlog.write_tlog` (real MAVLink 2 bytes from pymavlink's
``ardupilotmega`` dialect behind 8-byte tlog timestamps) at the harness's stream rates
(:data:`~benchmarks.jsbsim_harness.sensors.SENSOR_RATES_HZ`); SERVO_OUTPUT_RAW carries JSBSim's
surface positions mapped to PWM through the aircraft's airframe file.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import json
from dataclasses import asdict, dataclass
from pathlib import Path
from types import SimpleNamespace

from gcs_sysid.airframe import load_airframe
from gcs_sysid.sim.tlog import write_tlog

from .aircraft import aircraft
from .flight import FlightConfig, Recording, fly
from .sensors import SENSOR_RATES_HZ, make_sensors
from .truth import save_truth

__all__ = ["write_log", "make_flight", "FlightFiles", "harness_fingerprint", "fingerprint"]

_REPO = Path(__file__).resolve().parents[2]
#: The sources that decide what a flight's files hold (harness, the project's tlog writer and
#: maneuver waveforms); with the aircraft's airframe file and the JSBSim version they make the
#: fingerprint under which a flight may be reused.
FINGERPRINT_SOURCES = tuple(f"benchmarks/jsbsim_harness/{m}.py" for m in
                            ("aircraft", "flight", "sensors", "logfile", "truth", "effects")) + (
    "gcs_sysid/signals.py", "gcs_sysid/sim/tlog.py")


@dataclass(frozen=True)
class FlightFiles:
    """Paths of one harness flight: the .tlog the pipeline reads, the truth it never reads, the airframe."""

    tlog: Path
    truth: Path
    airframe: Path
    recording: Recording | None     # None when the files were reused (``make_flight(reuse=True)``)


#: Module-level names of ``aircraft.py`` that list the aircraft and their roles. The fingerprint
#: leaves them out of that file's code and takes the flown aircraft's own spec instead
#: (:func:`fingerprint`), so that adding an aircraft, or making one tuning or untouched, keeps the
#: other aircraft's flights (since the ninth session, 2026-11-22; before, any edit of
#: ``aircraft.py`` changed every aircraft's fingerprint).
ROSTER_NAMES = ("AIRCRAFT", "TUNING_AIRCRAFT", "HELD_OUT_AIRCRAFT", "UNTOUCHED_AIRCRAFT")


def _assigned(node: ast.stmt) -> set[str]:
    """The plain names a module-level (annotated) assignment binds; empty for any other statement."""
    targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
    return {t.id for t in targets if isinstance(t, ast.Name)}


@functools.lru_cache(maxsize=64)
def _code(text: str, drop: tuple[str, ...] = ()) -> str:
    """The code of a Python source without its comments, layout and docstrings (``ast.dump``), and
    without the module-level assignments to the names in ``drop``."""
    tree = ast.parse(text)
    tree.body = [n for n in tree.body if not _assigned(n) & set(drop)]
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body \
                and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant) \
                and isinstance(node.body[0].value.value, str):
            node.body = node.body[1:] or [ast.Pass()]
    return ast.dump(tree)


def fingerprint(spec, sources: dict[str, str], airframe: bytes, version: str) -> str:
    """A 16-hex-digit SHA-256 of what makes one aircraft's flight files.

    Args:
        spec: the aircraft's ``AircraftSpec`` (its ``repr``: every field).
        sources: path (as in :data:`FINGERPRINT_SOURCES`) -> source text; their code, comments and
            docstrings left out, ``aircraft.py`` also without the :data:`ROSTER_NAMES` (the other
            aircraft's specs and everyone's roles).
        airframe: the bytes of the aircraft's airframe file.
        version: the JSBSim version.
    """
    h = hashlib.sha256(version.encode())
    for rel, text in sources.items():
        drop = ROSTER_NAMES if rel.endswith("jsbsim_harness/aircraft.py") else ()
        h.update(rel.encode() + b"\0" + _code(text, drop).encode())
    h.update(b"spec\0" + repr(spec).encode())
    h.update(airframe)
    return h.hexdigest()[:16]


@functools.lru_cache(maxsize=None)
def harness_fingerprint(name: str) -> str:
    """The fingerprint (:func:`fingerprint`) of aircraft ``name``'s flight files: the code of the
    sources in :data:`FINGERPRINT_SOURCES` (comments and docstrings left out, so that a change of
    wording keeps the flights; the aircraft list and roles left out of ``aircraft.py``, its own spec
    put in), its airframe file and the JSBSim version. A flight written under another fingerprint is
    flown again rather than reused."""
    import jsbsim

    spec = aircraft(name)
    return fingerprint(spec, {rel: (_REPO / rel).read_text() for rel in FINGERPRINT_SOURCES},
                       spec.airframe_path.read_bytes(), jsbsim.__version__)


def _stamp(config: FlightConfig, aoa: str) -> dict:
    """What ``<stem>-flight.json`` holds, as read back from JSON (tuples as lists)."""
    return json.loads(json.dumps({"config": asdict(config), "aoa": aoa,
                                  "harness": harness_fingerprint(config.aircraft)}))


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
        t=rec.t, rate_hz=rec.config.log_rate_hz, sensors=make_sensors(rec, aoa) if sensors is None else sensors,
        airframe=af,
        commands={k: tr[k] for k in ("delta_e", "delta_a", "delta_r", "delta_t")},
        truth={"psi": tr["psi"]}, seed=rec.config.seed,
        demand={},   # the harness's stabiliser demand is not recorded: no NAV_CONTROLLER_OUTPUT
        plan=SimpleNamespace(name=f"jsbsim {spec.model} {rec.config.turbulence}",
                             setpoints=[SimpleNamespace(airspeed=float(tr["V"].mean()))]))
    return write_tlog(result, path, af, rates_hz=SENSOR_RATES_HZ)


def make_flight(config: FlightConfig, out_dir: str | Path, aoa: str = "ahrs", stem: str | None = None,
                reuse: bool = False) -> FlightFiles:
    """Fly ``config`` and write ``<stem>.tlog`` and ``<stem>-truth.npz`` into ``out_dir``.

    With ``aoa="vane"`` the airframe is the aircraft's file plus ``[air_data] angles = "vane"``
    (``docs/airframe.md``: the log's AOA_SSA are vane measurements), written as
    ``<stem>-airframe.toml``; otherwise the checked-in ``data/airframes/jsbsim-<name>.toml``.
    Every flight also gets ``<stem>-flight.json``: its configuration, AOA variant and
    :func:`harness_fingerprint`.

    Args:
        reuse: when the files are already in ``out_dir`` with the same ``<stem>-flight.json``
            (same configuration, AOA variant and harness fingerprint), return them without flying
            (``recording`` is then None); otherwise fly and overwrite.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = stem or f"{config.aircraft}-{config.turbulence}-s{config.seed}-{aoa}"
    tlog, truth, stamp = out / f"{stem}.tlog", out / f"{stem}-truth.npz", out / f"{stem}-flight.json"
    airframe = aircraft(config.aircraft).airframe_path
    if aoa == "vane":
        vane = out / f"{stem}-airframe.toml"
        vane_text = airframe.read_text() + '\n[air_data]\nangles = "vane"\n'
    want = _stamp(config, aoa)
    if reuse and tlog.is_file() and truth.is_file() and stamp.is_file() and json.loads(stamp.read_text()) == want \
            and (aoa != "vane" or (vane.is_file() and vane.read_text() == vane_text)):
        return FlightFiles(tlog, truth, vane if aoa == "vane" else airframe, None)
    stamp.unlink(missing_ok=True)
    rec = fly(config)
    write_log(rec, tlog, aoa)
    save_truth(rec, truth)
    if aoa == "vane":
        vane.write_text(vane_text)
        airframe = vane
    stamp.write_text(json.dumps(want, indent=1))
    return FlightFiles(tlog, truth, airframe, rec)
