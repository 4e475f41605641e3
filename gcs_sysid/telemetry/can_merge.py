"""Merge decoded DroneCAN streams (measured surface positions, airspeed) into a MAVLink flight.

A CAN log and a MAVLink log run on different clocks. python-can stamps each frame with the clock of
the machine that received it (``Message.timestamp``: Unix seconds for socketcan, the virtual bus,
``can.Logger``'s .log/.blf/.csv files); a .tlog stamps each packet with the ground station's Unix
clock (its 8-byte record stamp). When both were recorded on the same machine (``gcs-sysid listen
--can``, or candump beside MAVProxy on one laptop), the two share that host clock, and the host
clock is mapped to vehicle time through the tlog itself:

* the *track* of timed messages (``time_boot_ms``; the same track and reboot segments as the tlog
  reader's :class:`~gcs_sysid.telemetry.clock.VehicleClock`) gives pairs (host stamp, vehicle
  time); their difference is the clock offset plus the link's delay, which only ever adds;
* per segment (between vehicle reboots), the offset is the *upper envelope* of ``vehicle - host``:
  the largest difference in each 10 s bin (the least-delayed packet), fitted by a straight line
  ``vehicle = host + a + b (host - h0)``, so a drift of the two crystals (tens of ppm, ~0.1 s per
  hour) is followed;
* a CAN sample at host time ``h`` is at vehicle time ``h + a + b (h - h0)`` of the segment its
  host time falls in.

A CAN log on another clock (a relative-time .asc, a logger on the vehicle) needs the offset:
``--can-offset S`` adds ``S`` seconds to every CAN time first. With a DataFlash ``.bin`` (no host
clock in it) the offset is required and maps the CAN time to vehicle time directly.

What merges: each ``actuator<id>`` stream (``pos`` rad, the measured position) is added to the
flight as it is; the airframe's ``[[can_actuator]]`` map says which surface it measures and the
estimator prefers it to the commanded PWM (:mod:`gcs_sysid.estimation.measured`). CAN airspeed
replaces the MAVLink ``airspeed`` stream (kept as ``airspeed_mavlink``): ``eas`` from the
``IndicatedAirspeed`` (for a small UAV IAS = CAS = EAS to well under 1 %: compressibility below
0.1 % at 40 m/s; the pitot's position error is not corrected), else from ``RawAirData``'s
differential pressure, ``sqrt(2 dp / rho0)``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from .clock import VehicleClock
from .mavlink_streams import SPECS
from .tlog_scan import scan_tlog
from .types import Flight, Stream, StreamSummary

__all__ = ["HostClock", "host_clock_of_tlog", "host_clock_of_timesync", "can_host_clock", "merge_can_streams",
           "merge_can_log", "check_can_log", "RHO0", "TIMESYNC_AGREE_S"]

RHO0 = 1.225   #: ISA sea-level density, kg/m^3 (EAS definition)
_BIN_S = 10.0
TIMESYNC_AGREE_S = 1.0
"""A GlobalTimeSync master's clock is taken as the vehicle's when its map is within this of the tlog's (s)."""


@dataclass(frozen=True)
class HostClock:
    """Piecewise-linear map from the recording host's clock to vehicle time.

    Attributes:
        start: host time (Unix s) where each segment starts, shape (S,), increasing.
        h0: reference host time of each segment, shape (S,).
        a: vehicle minus host time at ``h0``, s, shape (S,).
        b: drift of the vehicle clock against the host clock (s/s), shape (S,).
        spread: RMS of the envelope points about the line, s (how well the clocks agree).
        how: one line saying how the map was made (for the report).
    """

    start: np.ndarray
    h0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    spread: float = 0.0
    how: str = "fixed offset"

    def to_vehicle(self, host: np.ndarray) -> np.ndarray:
        """Vehicle time (s) of host times ``host`` (Unix s), any shape."""
        h = np.asarray(host, float)
        k = np.maximum(np.searchsorted(self.start, h, side="right") - 1, 0)
        return h + self.a[k] + self.b[k] * (h - self.h0[k])

    @staticmethod
    def fixed(offset: float) -> "HostClock":
        """``vehicle = host + offset`` everywhere (a .bin, or a CAN log already on vehicle time)."""
        z = np.zeros(1)
        return HostClock(z, z, np.array([float(offset)]), z, 0.0, f"vehicle time = CAN time + {offset:g} s")


def _envelope_line(host: np.ndarray, d: np.ndarray) -> tuple[float, float, float, float]:
    """``(h0, a, b, rms)``: line through the per-bin maxima of ``d`` against ``host``."""
    h0 = float(host[0])
    bins = np.floor((host - h0) / _BIN_S).astype(np.int64)
    edges = np.flatnonzero(np.diff(bins)) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [len(host)]])
    hs = np.array([host[s + int(np.argmax(d[s:e]))] for s, e in zip(starts, ends)])
    ds = np.array([float(np.max(d[s:e])) for s, e in zip(starts, ends)])
    if len(hs) >= 3 and np.ptp(hs) > 0:
        b, a = np.polyfit(hs - h0, ds, 1)
    else:
        b, a = 0.0, float(np.max(ds))
    rms = float(np.sqrt(np.mean((ds - (a + b * (hs - h0))) ** 2)))
    return h0, float(a), float(b), rms


def host_clock_of_tlog(path: str | Path, data: bytes | None = None) -> HostClock:
    """The host-clock -> vehicle-time map of a tlog (module docstring).

    Args:
        path: the .tlog.
        data: its bytes, when already read.

    Raises:
        InputError: no message carrying ``time_boot_ms`` in the log.
    """
    data = Path(path).read_bytes() if data is None else data
    wanted = {n: (s.fields[0],) for n, s in SPECS.items() if s.clock == "ms"}
    scan = scan_tlog(data, wanted)
    seq, raw, stamp = [], [], []
    for c in scan.collected.values():
        seq += c.seq
        raw += [(r[0] if isinstance(r, tuple) else r) * 1e-3 for r in c.rows]
        stamp += [s * 1e-6 for s in c.stamp_us]
    if not seq:
        raise InputError(f"{path}: no message with time_boot_ms: the CAN log cannot be put on vehicle time "
                         "(give --can-offset to place it by hand)")
    clock = VehicleClock.from_track(np.array(seq), np.array(raw), np.array(stamp))
    seg = np.searchsorted(clock.seg_start, clock.seq, side="right") - 1
    starts, h0s, As, Bs, spreads = [], [], [], [], []
    for k in np.unique(seg):
        m = seg == k
        order = np.argsort(clock.stamp[m], kind="stable")
        h = clock.stamp[m][order]
        d = clock.t[m][order] - h
        h0, a, b, rms = _envelope_line(h, d)
        starts.append(h[0] if k > 0 else -np.inf)
        h0s.append(h0), As.append(a), Bs.append(b), spreads.append(rms)
    spread = float(max(spreads))
    how = (f"host clock mapped to vehicle time through the tlog's time_boot_ms ({len(starts)} segment(s), upper "
           f"envelope of the offset per {_BIN_S:g} s, drift {Bs[0] * 1e6:+.0f} ppm, spread {spread * 1e3:.1f} ms)")
    return HostClock(np.array(starts), np.array(h0s), np.array(As), np.array(Bs), spread, how)


def host_clock_of_timesync(st: Stream | None) -> HostClock | None:
    """The host-clock -> vehicle-time map from DroneCAN time sync, when the master's clock is the vehicle's.

    ``st`` is the decoder's ``can_timesync`` stream: at each receive time ``t`` (host s) of a master's
    ``uavcan.protocol.GlobalTimeSync`` message, ``master`` its transmission time on the master's clock
    (s; ArduPilot's flight controller sends its time since boot, the clock of ``time_boot_ms``). The
    offset ``master - host`` is the clock offset minus the reception delay, so as with the tlog its
    upper envelope per 10 s bin is fitted by a line; the master's time going back (a reboot) starts a
    new segment. Against the tlog's map this one has no telemetry-link delay in it (a radio's tens of ms
    that the envelope cannot remove when they are constant), only the CAN bus's and the host's reception.

    Returns:
        The map, or None when ``st`` is None or has fewer than two pairs.
    """
    if st is None or len(st) < 2 or "master" not in st:
        return None
    h, m = np.asarray(st.t, float), np.asarray(st["master"], float)
    cut = np.flatnonzero(np.diff(m) < -1.0) + 1          # the master's clock went back: rebooted
    starts, h0s, As, Bs, spreads = [], [], [], [], []
    for k, (i, j) in enumerate(zip(np.concatenate([[0], cut]), np.concatenate([cut, [len(h)]]))):
        if j - i < 1:
            continue
        h0, a, b, rms = _envelope_line(h[i:j], m[i:j] - h[i:j])
        starts.append(h[i] if k > 0 else -np.inf)
        h0s.append(h0), As.append(a), Bs.append(b), spreads.append(rms)
    spread = float(max(spreads))
    how = (f"host clock mapped to vehicle time through DroneCAN GlobalTimeSync ({len(h)} pairs, {len(starts)} "
           f"segment(s), drift {Bs[-1] * 1e6:+.0f} ppm, spread {spread * 1e3:.1f} ms)")
    return HostClock(np.array(starts), np.array(h0s), np.array(As), np.array(Bs), spread, how)


def can_host_clock(can_streams: dict[str, Stream], tlog_clock: HostClock) -> tuple[HostClock, str | None]:
    """The map to use for CAN samples: DroneCAN time sync when present and on the vehicle's clock, else the tlog's.

    The time-sync master need not be the flight controller (a GNSS node may serve UTC): its map is used
    only where it agrees with the tlog's (fitted on ``time_boot_ms``) within :data:`TIMESYNC_AGREE_S` at
    the time-sync pairs' host times (median); otherwise the tlog's map is used and a note says why.

    Args:
        can_streams: decoded CAN streams (:meth:`gcs_sysid.telemetry.can.CanDecoder.streams`).
        tlog_clock: the tlog's map (:func:`host_clock_of_tlog`).

    Returns:
        ``(clock, note)``: the map, and None or one line saying why time sync was not used.
    """
    sync = host_clock_of_timesync(can_streams.get("can_timesync"))
    if sync is None:
        return tlog_clock, None
    h = np.asarray(can_streams["can_timesync"].t, float)
    gap = float(np.median(np.abs(sync.to_vehicle(h) - tlog_clock.to_vehicle(h))))
    if gap > TIMESYNC_AGREE_S:
        return tlog_clock, (f"DroneCAN GlobalTimeSync not used: its master's clock differs from the vehicle's "
                            f"time_boot_ms by {gap:.3g} s (not the flight controller's); {tlog_clock.how}")
    return sync, None


def _on_vehicle_time(st: Stream, clock: HostClock, offset: float, t_lo: float, t_hi: float) -> Stream:
    t = clock.to_vehicle(st.t + offset)
    m = (t >= t_lo) & (t <= t_hi)
    t = t[m]
    order = np.argsort(t, kind="stable")
    t = t[order]
    keep = np.concatenate([[True], np.diff(t) > 0]) if len(t) else np.zeros(0, bool)
    return Stream(st.name, st.source, t[keep], {k: v[m][order][keep] for k, v in st.fields.items()})


def merge_can_streams(flight: Flight, can_streams: dict[str, Stream], clock: HostClock, offset: float = 0.0,
                      source: str = "CAN log") -> Flight:
    """A copy of ``flight`` with the CAN streams on its vehicle time (module docstring).

    Args:
        flight: the decoded MAVLink flight.
        can_streams: :func:`gcs_sysid.telemetry.can.read_can_log`'s streams (CAN clock, s).
        clock: host clock -> vehicle time (:func:`host_clock_of_tlog`, or :meth:`HostClock.fixed`).
        offset: s added to every CAN time before the map (``--can-offset``).
        source: name of the CAN source, for messages.

    Returns:
        The flight with ``actuator<id>`` streams added and, when the CAN log has airspeed, its
        ``airspeed`` stream from CAN (the MAVLink one kept as ``airspeed_mavlink``); a line in
        ``warnings`` says what was merged and how the clocks were aligned.

    Raises:
        InputError: no CAN sample falls inside the flight's time span (the clocks do not match).
    """
    t_lo, t_hi = flight.t_range
    streams = dict(flight.streams)
    summaries = dict(flight.summaries)
    merged = []
    for name, st in can_streams.items():
        if not (name.startswith("actuator") or name == "can_airspeed") or not len(st):
            continue
        v = _on_vehicle_time(st, clock, offset, t_lo - 0.5, t_hi + 0.5)
        if len(v) < 2:
            continue
        if name == "can_airspeed":
            if "ias" in v:
                eas, how = v["ias"], "IndicatedAirspeed as EAS"
            elif "diff_pressure" in v:
                eas, how = np.sqrt(2.0 * np.maximum(v["diff_pressure"], 0.0) / RHO0), "RawAirData sqrt(2 dp / rho0)"
            else:
                continue   # TAS alone needs the density: left to the MAVLink airspeed
            if "airspeed" in streams:
                streams["airspeed_mavlink"] = replace(streams["airspeed"], name="airspeed_mavlink")
            fields = {"eas": eas}
            if "diff_pressure" in v:
                fields["diff_pressure"] = v["diff_pressure"]
            v = Stream("airspeed", f"DroneCAN ({how})", v.t, fields)
            name = "airspeed"
        streams[name] = v
        summaries[name] = StreamSummary.of(v)
        merged.append(f"{name} ({len(v)} samples, {summaries[name].rate_hz:.0f} Hz)")
    if not merged:
        spans = [(float(s.t[0]), float(s.t[-1])) for s in can_streams.values() if len(s)]
        lo = min(a for a, _ in spans) if spans else float("nan")
        hi = max(b for _, b in spans) if spans else float("nan")
        raise InputError(f"{source}: no CAN sample falls inside the flight (CAN clock {lo:.3f}..{hi:.3f} s maps to "
                         f"vehicle {float(clock.to_vehicle(np.array([lo + offset]))[0]):.1f}..."
                         f"{float(clock.to_vehicle(np.array([hi + offset]))[0]):.1f} s, the flight spans "
                         f"{t_lo:.1f}..{t_hi:.1f} s); if the CAN log was recorded on another clock give "
                         "--can-offset SECONDS (CAN time + offset = the tlog's host time, or vehicle time for a .bin)")
    warnings = list(flight.warnings) + [f"{source}: merged {', '.join(merged)}; CAN clock + {offset:g} s, "
                                        f"{clock.how}"]
    return replace(flight, streams=streams, summaries=summaries, warnings=warnings)


def check_can_log(can_path: str | Path, log_path: str | Path, offset: float | None) -> None:
    """Check ``--can-log``/``--can-offset`` before any decoding (file exists, libraries, a .bin has an offset).

    Raises:
        InputError: one line naming the option and what was expected.
    """
    from . import detect_format
    from .can import _libs

    _libs()
    p = Path(can_path)
    if not p.is_file():
        raise InputError(f"--can-log {p}: no such file; expected a CAN log (.log, .asc, .blf, .csv)")
    if offset is not None and not np.isfinite(offset):
        raise InputError(f"--can-offset must be a finite number of seconds, got {offset!r}")
    if offset is None and detect_format(log_path) == "bin":
        raise InputError(f"--can-log {p}: a DataFlash .bin has no host clock to align the CAN log with; give "
                         "--can-offset SECONDS (CAN time + offset = vehicle time since boot)")


def merge_can_log(flight: Flight, log_path: str | Path, can_path: str | Path, offset: float | None = None) -> Flight:
    """Decode a CAN log and merge it into the flight decoded from ``log_path``.

    Args:
        flight: the flight read from ``log_path``.
        log_path: the .tlog (its host stamps align the clocks) or .bin (then ``offset`` is required).
        can_path: a CAN log ``can.LogReader`` reads (.asc, .blf, .log, .csv ...).
        offset: s added to the CAN times (None: 0 for a tlog).

    Raises:
        InputError: unreadable CAN log, no DroneCAN data, a .bin without ``offset``, or clocks that
            do not overlap.
    """
    from .can import read_can_log

    streams, _ = read_can_log(can_path)
    note = None
    if flight.format == "tlog" and offset is None:
        clock, note = can_host_clock(streams, host_clock_of_tlog(log_path))
    elif flight.format == "tlog":   # a CAN log on another clock, placed by hand: its time sync is not compared
        clock = host_clock_of_tlog(log_path)
    elif offset is None:
        raise InputError(f"--can-log {can_path}: a {flight.format} log has no host clock to align the CAN log "
                         "with; give --can-offset SECONDS (CAN time + offset = vehicle time)")
    else:
        clock = HostClock.fixed(0.0)
    merged = merge_can_streams(flight, streams, clock, 0.0 if offset is None else float(offset),
                               f"--can-log {can_path}")
    return replace(merged, warnings=merged.warnings + [note]) if note else merged
