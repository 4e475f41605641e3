"""MAVLink telemetry log (.tlog) -> :class:`~gcs_sysid.telemetry.types.Flight`.

Collects rows with :func:`~gcs_sysid.telemetry.tlog_scan.scan_tlog`, keeps the messages of the
vehicle (the system/component that sends ATTITUDE, else an autopilot HEARTBEAT), builds the vehicle
clock (:mod:`gcs_sysid.telemetry.clock`) and converts each message with
:data:`~gcs_sysid.telemetry.mavlink_streams.SPECS`.
"""

from __future__ import annotations

from collections import Counter
from typing import Callable

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from gcs_sysid.errors import InputError
from gcs_sysid.telemetry.assemble import finish_flight
from gcs_sysid.telemetry.clock import VehicleClock
from gcs_sysid.telemetry.mavlink_streams import IMU_PREFERENCE, RHO0, SPECS, wanted_fields
from gcs_sysid.telemetry.tlog_scan import TlogScan
from gcs_sysid.telemetry.tlog_split import scan_tlog_split
from gcs_sysid.telemetry.types import Flight, Stream

__all__ = ["read_tlog"]

_AUTOPILOT_INVALID = 8
_AUTOPILOT_ARDUPILOT = 3
_WRAP = {"ms": 2.0 ** 32 * 1e-3, "us32": 2.0 ** 32 * 1e-6, "us": None}
_SCALE = {"ms": 1e-3, "us32": 1e-6, "us": 1e-6}


def _enum_name(enum: str, value: int) -> str:
    entry = mavlink.enums.get(enum, {}).get(int(value))
    return entry.name if entry is not None else f"{enum}_{int(value)}"


def _main_source(scan: TlogScan) -> int | None:
    """``sys << 8 | comp`` of the vehicle: most ATTITUDE, else an autopilot HEARTBEAT, else most data."""
    att = scan.collected.get("ATTITUDE")
    if att is not None and att.src:
        return Counter(att.src).most_common(1)[0][0]
    hb = scan.collected.get("HEARTBEAT")
    if hb is not None and hb.src:
        auto = Counter(s for s, r in zip(hb.src, hb.rows) if r[1] != _AUTOPILOT_INVALID)
        if auto:
            return auto.most_common(1)[0][0]
    allsrc = Counter()
    for name, col in scan.collected.items():
        if name != "HEARTBEAT":
            allsrc.update(s for s in col.src if (s >> 8) != 255)
    return allsrc.most_common(1)[0][0] if allsrc else None


def _select(col, src: int | None):
    """(seq, stamp_s, rows) of one message type restricted to the vehicle's source."""
    srcs = np.asarray(col.src)
    seq = np.asarray(col.seq, np.int64)
    stamp = np.asarray(col.stamp_us, np.float64) * 1e-6
    if src is None or np.all(srcs == src):
        return seq, stamp, col.rows
    m = srcs == src
    return seq[m], stamp[m], [r for r, k in zip(col.rows, m) if k]


def read_tlog(path: str, data: bytes, progress: Callable[[float], None] | None = None, helper=None,
              meanwhile: Callable[[], None] | None = None) -> Flight:
    """Decode a tlog already read into memory.

    Args:
        path: file name, for messages.
        data: file content.
        progress: optional callable(fraction done).
        helper: a :class:`gcs_sysid.parallel.Helper` whose worker scans the second part of the file
            (:mod:`gcs_sysid.telemetry.tlog_split`; the result is the same); None: one scan here.
        meanwhile: optional callable run once while the worker scans (see ``scan_tlog_split``).

    Returns:
        The :class:`Flight` (format ``"tlog"``).

    Raises:
        InputError: no MAVLink record could be framed, or none of the records carries a message
            the tool uses.
    """
    scan = scan_tlog_split(data, wanted_fields(), helper, progress, meanwhile)
    if scan.records == 0:
        raise InputError(f"{path}: no MAVLink packets found; expected a MAVLink telemetry log (.tlog: "
                         "8-byte timestamp before each MAVLink v1/v2 packet)")
    warnings: list[str] = []
    repaired = _repair_stamps(scan)
    src = _main_source(scan)
    sel = {n: _select(c, src) for n, c in scan.collected.items() if c.seq}
    sel = {n: s for n, s in sel.items() if len(s[0])}
    other = sum(len(c.seq) - len(sel.get(n, ((),))[0]) for n, c in scan.collected.items() if n != "HEARTBEAT")
    if other and src is not None:
        warnings.append(f"ignored {other} messages from systems other than the vehicle "
                        f"(system {src >> 8}, component {src & 255})")
    vehicle: dict[str, object] = {}
    if "HEARTBEAT" in sel:
        r = sel["HEARTBEAT"][2][-1]
        vehicle = {"system_id": src >> 8 if src is not None else None,
                   "component_id": src & 255 if src is not None else None,
                   "mav_type": _enum_name("MAV_TYPE", r[0]), "autopilot": _enum_name("MAV_AUTOPILOT", r[1])}
    autopilot = int(sel["HEARTBEAT"][2][-1][1]) if "HEARTBEAT" in sel else None
    log_t0 = int.from_bytes(data[:8], "big") * 1e-6 if len(data) >= 8 else 0.0

    arrays = {n: (s[0], s[1], np.asarray(s[2], float)) for n, s in sel.items() if n in SPECS}
    clock = _build_clock(arrays, log_t0, warnings)

    streams: dict[str, Stream] = {}
    dropped: dict[str, int] = {}
    imus: list[Stream] = []
    for name, spec in SPECS.items():
        if name not in arrays:
            continue
        seq, stamp, v = arrays[name]
        if name == "RAW_IMU" and autopilot not in (None, _AUTOPILOT_ARDUPILOT, _AUTOPILOT_INVALID):
            warnings.append(f"RAW_IMU from {vehicle.get('autopilot')} is in sensor units: skipped")
            continue
        if name == "SERVO_OUTPUT_RAW" and np.any(v[:, 1] != 0):
            warnings.append(f"SERVO_OUTPUT_RAW: {int(np.sum(v[:, 1] != 0))} messages for ports other than 0 skipped")
            m = v[:, 1] == 0
            seq, stamp, v = seq[m], stamp[m], v[m]
            if not len(seq):
                continue
        if spec.clock is None:
            t = clock.map_untimed(seq, stamp)
        else:
            raw = v[:, 0] * _SCALE[spec.clock]
            t, same, wraps = clock.map_timed(seq, stamp, raw, _WRAP[spec.clock])
            if not same:
                warnings.append(f"{name}.{spec.fields[0]} does not follow the vehicle clock: placed by log time")
            if wraps and spec.clock == "us32":
                warnings.append(f"{name}.time_usec (uint32 us) wrapped {wraps} time(s); unwrapped against "
                                "the time_boot_ms clock")
        stream = Stream(spec.stream, name, t, spec.convert(v))
        dropped[name] = scan.duplicates.get(name, 0)
        if spec.stream == "imu":
            imus.append(stream)
        elif spec.stream == "pressure":
            dp = stream.fields.pop("diff_pressure")
            streams["pressure"] = stream
            streams["_diff_pressure"] = Stream("airspeed", name, t, {"diff_pressure": dp})
        else:
            streams[spec.stream] = stream
    imus.sort(key=lambda s: IMU_PREFERENCE.index(s.source))
    for i, s in enumerate(imus):
        s.name = "imu" if i == 0 else f"imu{i + 1}"
        streams[s.name] = s
    _airspeed(streams, warnings, params_of(sel), vehicle)
    stext = []
    if "STATUSTEXT" in sel:
        seq, stamp, rows = sel["STATUSTEXT"]
        ts = clock.map_untimed(seq, stamp)
        stext = [(float(t), str(r[1]).rstrip("\x00")) for t, r in zip(ts, rows)]
    params = params_of(sel)
    damage = [w for w in clock.warnings if w.startswith("reboot")]
    if repaired or scan.bad_stamps:
        damage.append(f"{repaired + scan.bad_stamps:,} damaged log time stamp(s) (the 8 bytes before a sound "
                      "packet) replaced by their neighbours' time")
    if scan.seq_lost:
        damage.append(f"{scan.seq_lost:,} packet(s) missing from the MAVLink sequence numbers (dropped on the "
                      "link, lost to corrupt bytes, or cut out of the file)")
    if scan.seq_disorder:
        damage.append(f"{scan.seq_disorder:,} packet(s) out of sequence (MAVLink sequence number repeated or "
                      "going back: duplicated, reordered or spliced data)")
    if scan.bad_data:
        damage.append(f"{scan.bad_data:,} corrupt packet(s) (BAD_DATA: bad CRC or broken framing) skipped; "
                      f"decoding resumed after each ({scan.records:,} sound records kept)")
    if scan.truncated:
        damage.append(f"log is truncated (ends inside a record): kept the {scan.records:,} records before it")
    return finish_flight(path, "tlog", streams, dropped, vehicle, params, dict(scan.counts), warnings, stext,
                         imu_sources="HIGHRES_IMU, SCALED_IMU*, RAW_IMU", servo_sources="SERVO_OUTPUT_RAW",
                         damage=damage)


#: Records on each side whose log stamps vote in :func:`_repair_stamps`.
_STAMP_HALF_WINDOW = 3
#: A log stamp further than this from the median of its neighbours is taken as damaged, us.
_STAMP_TOLERANCE_US = 1_000_000


def _repair_stamps(scan: TlogScan) -> int:
    """Replace damaged log stamps of the collected packets; returns how many were replaced.

    A tlog's 8-byte stamp is not covered by the packet's CRC, so a sound packet can carry a damaged
    stamp (bytes flipped below the top three, which :func:`~gcs_sysid.telemetry.tlog_scan.scan_tlog`
    checks). Stamps follow the order of the records; one further than :data:`_STAMP_TOLERANCE_US`
    from the median of the :data:`_STAMP_HALF_WINDOW` records on each side is replaced by that median.
    """
    cols = [c for c in scan.collected.values() if len(c.seq) > 0]
    if not cols:
        return 0
    seq = np.concatenate([np.asarray(c.seq, np.int64) for c in cols])
    st = np.concatenate([np.asarray(c.stamp_us, np.int64) for c in cols])
    if len(st) < 2 * _STAMP_HALF_WINDOW + 1:
        return 0
    order = np.argsort(seq, kind="stable")
    s = st[order]
    padded = np.pad(s, _STAMP_HALF_WINDOW, mode="edge")
    med = np.median(np.lib.stride_tricks.sliding_window_view(padded, 2 * _STAMP_HALF_WINDOW + 1), axis=1)
    bad = np.abs(s - med) > _STAMP_TOLERANCE_US
    n = int(bad.sum())
    if not n:
        return 0
    s = s.copy()
    s[bad] = med[bad].astype(np.int64)
    fixed = np.empty_like(st)
    fixed[order] = s
    k = 0
    for c in cols:
        m = len(c.seq)
        c.stamp_us = fixed[k:k + m].tolist()
        k += m
    return n


def _build_clock(arrays, log_t0: float, warnings: list[str]) -> VehicleClock:
    """Track from time_boot_ms messages, else 64-bit time_usec ones, else none (log time)."""
    for kind, label in (("ms", "time_boot_ms"), ("us", "time_usec")):
        parts = [(a[0], a[2][:, 0] * _SCALE[kind], a[1]) for n, a in arrays.items() if SPECS[n].clock == kind]
        if parts:
            seq = np.concatenate([p[0] for p in parts])
            raw = np.concatenate([p[1] for p in parts])
            stamp = np.concatenate([p[2] for p in parts])
            clock = VehicleClock.from_track(seq, raw, stamp, f"vehicle clock ({label})", log_t0)
            warnings.extend(clock.warnings)
            return clock
    warnings.append("no message carries the vehicle clock: times are log (wall-clock) times from the first record")
    e = np.zeros(0)
    return VehicleClock(e.astype(np.int64), e, e, np.array([0]), np.array([0.0]))


def params_of(sel) -> dict[str, float]:
    """PARAM_VALUE name -> last value."""
    if "PARAM_VALUE" not in sel:
        return {}
    return {str(r[0]).rstrip("\x00"): float(r[1]) for r in sel["PARAM_VALUE"][2]}


def _airspeed(streams: dict[str, Stream], warnings: list[str], params: dict[str, float],
              vehicle: dict[str, object]) -> None:
    """``airspeed`` from SCALED_PRESSURE.press_diff when it is positive over most samples, else VFR_HUD.

    EAS = sqrt(ratio * dp). ArduPilot computes its airspeed so, with the pitot calibration
    ``ARSPD_RATIO`` (AP_Airspeed; default 1.9936, the ideal value is 2 / rho0 = 1.633). The ratio is
    the logged ``ARSPD_RATIO`` when present, else the median of VFR_HUD airspeed^2 / dp above 8 m/s
    (the autopilot's own calibrated EAS), else 2 / rho0. ``vehicle["airspeed_ratio"]`` and
    ``vehicle["airspeed_ratio_source"]`` say which.
    """
    dps = streams.pop("_diff_pressure", None)
    hud = streams.get("vfr_hud")
    if dps is not None:
        dp = dps.fields["diff_pressure"]
        if np.mean(dp > 1.0) > 0.5:
            ratio, how = 2.0 / RHO0, "ideal pitot, 2 / 1.225"
            if params.get("ARSPD_RATIO", 0) > 0:
                ratio, how = params["ARSPD_RATIO"], "ARSPD_RATIO parameter"
            elif hud is not None and len(hud):
                v = np.interp(dps.t, hud.t, hud.fields["airspeed"])
                m = (v > 8.0) & (dp > 1.0)
                if m.sum() >= 10:
                    ratio, how = float(np.median(v[m] ** 2 / dp[m])), "fitted to VFR_HUD airspeed"
            vehicle["airspeed_ratio"], vehicle["airspeed_ratio_source"] = ratio, how
            eas = np.sqrt(ratio * np.maximum(dp, 0.0))
            streams["airspeed"] = Stream("airspeed", "SCALED_PRESSURE", dps.t, {"eas": eas, "diff_pressure": dp})
            return
    if hud is None:
        return
    if dps is not None:
        warnings.append("SCALED_PRESSURE.press_diff is not positive over most of the log (no pitot?): "
                        "airspeed taken from VFR_HUD (EAS)")
    eas = hud.fields["airspeed"].copy()
    if not np.any(eas > 1.0):
        warnings.append("airspeed reads 0 throughout the log (no airspeed sensor?)")
    streams["airspeed"] = Stream("airspeed", "VFR_HUD", hud.t, {"eas": eas})
