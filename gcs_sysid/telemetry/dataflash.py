"""ArduPilot DataFlash (.bin) -> :class:`~gcs_sysid.telemetry.types.Flight`, read with pymavlink's DFReader.

DFReader applies the format-character multipliers (``c``/``C`` x0.01, ``L`` degE7 -> deg ...), so
fields arrive in the units of the log's FMTU table: deg, deg/s, m, m/s, Pa, degC. Every message
carries ``TimeUS`` (us since boot), which is the vehicle clock; a fall of ``TimeUS`` (a reboot in the
middle of one file) starts a new re-based segment as for tlogs.

References:
    ArduPilot log message reference, https://ardupilot.org/plane/docs/logmessages.html
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import tempfile
from typing import Callable

import numpy as np
from pymavlink import DFReader

from gcs_sysid.errors import InputError
from gcs_sysid.telemetry.assemble import finish_flight
from gcs_sysid.telemetry.clock import VehicleClock
from gcs_sysid.telemetry.types import Flight, Stream

__all__ = ["DF_SPECS", "read_dataflash"]

_D2R = np.pi / 180.0


def _imu(v):
    return {"ax": v[:, 4], "ay": v[:, 5], "az": v[:, 6], "p": v[:, 1], "q": v[:, 2], "r": v[:, 3]}


def _gps(v):
    spd, crs = v[:, 4], v[:, 5] * _D2R
    return {"lat": v[:, 1] * _D2R, "lon": v[:, 2] * _D2R, "alt": v[:, 3],
            "vn": spd * np.cos(crs), "ve": spd * np.sin(crs), "vd": v[:, 6]}


def _ekf(v):
    return {"roll": v[:, 1] * _D2R, "pitch": v[:, 2] * _D2R, "yaw": v[:, 3] * _D2R,
            "vn": v[:, 4], "ve": v[:, 5], "vd": v[:, 6],
            "gyro_bias_x": v[:, 10] * _D2R, "gyro_bias_y": v[:, 11] * _D2R, "gyro_bias_z": v[:, 12] * _D2R}


def _local(v):
    return {"x": v[:, 7], "y": v[:, 8], "z": v[:, 9], "vx": v[:, 4], "vy": v[:, 5], "vz": v[:, 6]}


_EKF1 = ("TimeUS", "Roll", "Pitch", "Yaw", "VN", "VE", "VD", "PN", "PE", "PD", "GX", "GY", "GZ")

# name -> (instance field or None, [(stream, fields, converter), ...]); fields[0] is TimeUS.
DF_SPECS: dict[str, tuple[str | None, list[tuple[str, tuple[str, ...], Callable]]]] = {
    "IMU": ("I", [("imu", ("TimeUS", "GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ"), _imu)]),
    "ATT": (None, [("attitude", ("TimeUS", "Roll", "Pitch", "Yaw"),
                    lambda v: {"roll": v[:, 1] * _D2R, "pitch": v[:, 2] * _D2R, "yaw": v[:, 3] * _D2R})]),
    "RCOU": (None, [("servo", ("TimeUS",) + tuple(f"C{i}" for i in range(1, 15)),
                     lambda v: {f"pwm{i}": v[:, i] for i in range(1, v.shape[1])})]),
    "RCIN": (None, [("rc", ("TimeUS",) + tuple(f"C{i}" for i in range(1, 15)),
                     lambda v: {f"pwm{i}": v[:, i] for i in range(1, v.shape[1])})]),
    "ARSP": ("I", [("airspeed", ("TimeUS", "Airspeed", "DiffPress"),
                    lambda v: {"eas": v[:, 1], "diff_pressure": v[:, 2]})]),
    "GPS": ("I", [("gps", ("TimeUS", "Lat", "Lng", "Alt", "Spd", "GCrs", "VZ"), _gps)]),
    "BARO": ("I", [("pressure", ("TimeUS", "Press", "Temp"),
                    lambda v: {"press_abs": v[:, 1], "temperature": v[:, 2] + 273.15})]),
    "AOA": (None, [("aoa_ssa", ("TimeUS", "AOA", "SSA"),
                    lambda v: {"alpha": v[:, 1] * _D2R, "beta": v[:, 2] * _D2R})]),
    "XKF1": ("C", [("ekf", _EKF1, _ekf), ("local_position", _EKF1, _local)]),
    "NKF1": ("C", [("ekf", _EKF1, _ekf), ("local_position", _EKF1, _local)]),
    "XKF2": ("C", [("wind", ("TimeUS", "VWN", "VWE"), lambda v: {"wn": v[:, 1], "we": v[:, 2]})]),
    "CTUN": (None, [("vfr_hud", ("TimeUS", "As"), lambda v: {"airspeed": v[:, 1]})]),
    "SIM": (None, [("sim_truth", ("TimeUS", "Roll", "Pitch", "Yaw", "Alt", "Lat", "Lng"),
                    lambda v: {"roll": v[:, 1] * _D2R, "pitch": v[:, 2] * _D2R, "yaw": v[:, 3] * _D2R,
                               "alt": v[:, 4], "lat": v[:, 5] * _D2R, "lon": v[:, 6] * _D2R})]),
}
_TEXT = ("PARM", "MSG", "VER")
_FIRMWARE_TYPES = {"ArduPlane": "MAV_TYPE_FIXED_WING", "ArduCopter": "MAV_TYPE_QUADROTOR",
                   "ArduRover": "MAV_TYPE_GROUND_ROVER", "ArduSub": "MAV_TYPE_SUBMARINE"}


@contextlib.contextmanager
def _captured_output():
    """Capture what DFReader prints, from Python and from its compiled indexer (file descriptor 2).

    Yields a dict whose ``"text"`` holds the captured stderr once the block has exited.
    """
    out = {"text": ""}
    py_err = io.StringIO()
    with tempfile.TemporaryFile() as tmp:
        sys.stderr.flush()
        saved = os.dup(2)
        os.dup2(tmp.fileno(), 2)
        try:
            with contextlib.redirect_stderr(py_err), contextlib.redirect_stdout(io.StringIO()):
                yield out
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            out["text"] = py_err.getvalue() + tmp.read().decode("utf-8", "replace")


def _columns(reader, name: str) -> set[str]:
    fmt = reader.formats.get(reader.name_to_id.get(name, -1))
    return set(fmt.columns) if fmt is not None else set()


def read_dataflash(path: str, progress: Callable[[float], None] | None = None) -> Flight:
    """Decode an ArduPilot DataFlash log.

    Args:
        path: the .bin file (checked by the caller to start with the 0xA3 0x95 header).
        progress: optional callable(fraction done).

    Returns:
        The :class:`Flight` (format ``"bin"``). ``messages["BAD_DATA"]`` counts the bad headers
        DFReader skipped.

    Raises:
        InputError: DFReader cannot open the file, or no message could be decoded.
    """
    with _captured_output() as chatter:  # DFReader prints "bad header ..." for each skipped byte
        try:
            reader = DFReader.DFReader_binary(path, zero_time_base=False)
        except Exception as exc:  # DFReader raises assorted errors on malformed files
            raise InputError(f"{path}: not a readable DataFlash log ({type(exc).__name__}: {exc})") from None
        counts = {reader.id_to_name[i]: int(c) for i, c in enumerate(reader.counts)
                  if c and i in reader.id_to_name}
        plans = {}
        for name, (inst, outs) in DF_SPECS.items():
            cols = _columns(reader, name)
            outs = [(st, f, c) for st, f, c in outs if set(f) <= cols]
            if outs:
                plans[name] = (inst if inst in cols else None, outs)
        want = set(plans) | {t for t in _TEXT if t in reader.name_to_id}
        rows: dict[tuple[str, int], list] = {}
        texts: list[tuple[str, int, float, dict]] = []
        warnings: list[str] = []
        n = 0
        size = max(reader.data_len, 1)
        while want:
            try:
                m = reader.recv_match(type=want)
            except Exception as exc:  # a corrupt tail: keep what decoded
                warnings.append(f"DataFlash decoding stopped early ({type(exc).__name__}: {exc}); kept what decoded")
                break
            if m is None:
                break
            n += 1
            if progress is not None and n % 8192 == 0:
                progress(min(reader.offset / size, 1.0))
            name = m.get_type()
            plan = plans.get(name)
            if plan is None:
                if name in _TEXT:
                    texts.append((name, n, m.TimeUS * 1e-6, m.to_dict()))
                continue
            inst = int(getattr(m, plan[0])) if plan[0] else 0
            rows.setdefault((name, inst), []).append((n,) + tuple(getattr(m, f) for f in plan[1][0][1]))
    if progress is not None:
        progress(1.0)
    bad = chatter["text"].count("bad header")
    damage = [w for w in warnings if w.startswith("DataFlash decoding stopped early")]
    if bad:
        counts["BAD_DATA"] = bad
        damage.append(f"{bad:,} corrupt byte(s) skipped (bad DataFlash headers); decoding resumed after each")
    unknown = chatter["text"].count("unknown msg type")
    end_note = _end_of_log(reader)
    if end_note:
        damage.append(end_note)
    elif unknown:
        damage.append("DataFlash indexing stopped at a record of an unknown type (a damaged header): "
                      "the rest of the log was not read")
    if not counts or not sum(counts.values()):
        raise InputError(f"{path}: no DataFlash messages could be decoded; expected an ArduPilot .bin log")
    return _assemble(path, plans, rows, texts, counts, warnings, damage)


def _end_of_log(reader) -> str | None:
    """A note when the log ends inside a record (truncated) or stops before its end, else None.

    The end of the last complete record is the largest ``offset + length`` over the records that
    DFReader indexed. A record running past the end of the file, or the start of a record header
    (0xA3 0x95) in the bytes after it, means the file was cut off mid-record; other bytes after it
    (not the 0x00 / 0xFF padding of block logs) were not read.
    """
    size = int(getattr(reader, "data_len", 0) or 0)
    ends = []
    for mtype, offs in enumerate(getattr(reader, "offsets", []) or []):
        fmt = reader.formats.get(mtype)
        if offs and fmt is not None and getattr(fmt, "len", None):
            ends.append((offs[-1] + int(fmt.len), fmt.name))
    if not ends or size <= 0:
        return None
    last, name = max(ends)
    if last > size:
        return (f"log is truncated (ends inside a {name} record at byte {size:,}): kept the records "
                "before it")
    tail = bytes(reader.data_map[last:size])
    if not tail.strip(b"\x00\xff"):
        return None
    if tail[:2] == b"\xa3\x95"[:len(tail[:2])] and len(tail) < 3 + 256:
        return f"log is truncated (ends inside a record header at byte {size:,}): kept the records before it"
    return f"{len(tail):,} byte(s) after the last complete record at byte {last:,} could not be read"


def _assemble(path, plans, rows, texts, counts, warnings, damage=()) -> Flight:
    arrays = {k: np.asarray(v, float) for k, v in rows.items()}
    clock = None
    if arrays:
        seq = np.concatenate([a[:, 0] for a in arrays.values()])
        raw = np.concatenate([a[:, 1] for a in arrays.values()]) * 1e-6
        # no separate log clock in DataFlash: use TimeUS itself for the spacing at a reboot
        clock = VehicleClock.from_track(seq, raw, raw, "vehicle clock (TimeUS)", float(raw.min()))
        warnings.extend(clock.warnings)
        damage = [w for w in clock.warnings if w.startswith("reboot")] + list(damage)
    streams: dict[str, Stream] = {}
    for (name, inst), v in sorted(arrays.items(), key=lambda kv: (list(DF_SPECS).index(kv[0][0]), kv[0][1])):
        if name == "NKF1" and any(k[0] == "XKF1" for k in arrays):
            continue  # EKF3 preferred over EKF2
        t = v[:, 1] * 1e-6 + clock.segment_offset(v[:, 0])
        for stream, _fields, conv in plans[name][1]:
            sname = stream if inst == 0 else (f"imu{inst + 1}" if stream == "imu" else None)
            if sname is None or sname in streams:
                continue
            src = f"{name}[{inst}]" if plans[name][0] else name
            streams[sname] = Stream(sname, src, t, conv(v[:, 1:]))
    params: dict[str, float] = {}
    stext: list[tuple[float, str]] = []
    vehicle: dict[str, object] = {"autopilot": "MAV_AUTOPILOT_ARDUPILOTMEGA"}
    for kind, n, tus, d in texts:
        off = float(clock.segment_offset(np.array([n]))[0]) if clock is not None else 0.0
        if kind == "PARM":
            params[str(d["Name"])] = float(d["Value"])
        elif kind == "MSG":
            stext.append((tus + off, str(d["Message"])))
        elif kind == "VER":
            vehicle["firmware"] = fws = str(d.get("FWS", ""))
            for key, mav_type in _FIRMWARE_TYPES.items():
                if key in fws:
                    vehicle["mav_type"] = mav_type
    return finish_flight(path, "bin", streams, {}, vehicle, params, counts, warnings, stext,
                         imu_sources="IMU", servo_sources="RCOU", damage=list(damage))
