"""DroneCAN on a CAN bus (python-can) or in a CAN log: measured surface positions and air data.

DroneCAN servos report ``uavcan.equipment.actuator.Status`` (``position``: the measured surface or
servo position, rad), airspeed sensors ``uavcan.equipment.air_data.IndicatedAirspeed`` (m/s),
``TrueAirspeed`` (m/s) and ``RawAirData`` (``differential_pressure`` Pa); a time-sync master's
``uavcan.protocol.GlobalTimeSync`` gives pairs (receive time, master time) in the stream
``can_timesync`` (``master`` s; :func:`gcs_sysid.telemetry.can_merge.host_clock_of_timesync`). Frames are read with
python-can (any interface: ``socketcan``, ``slcan``, ``virtual`` ...; or a log through
``can.LogReader``: .asc, .blf, .log, .csv ...), multi-frame transfers are reassembled and decoded
with the ``dronecan`` library (``TransferManager``, ``Transfer.from_frames``: CRC and toggle checked),
and the values become :class:`~gcs_sysid.telemetry.types.Stream` objects in SI units on the bus
clock (python-can message timestamps, s).

Both libraries are in the ``can`` extra (``pip install gcs-sysid[can]``); without them the
functions here raise :class:`~gcs_sysid.errors.InputError` saying so.

References:
    DroneCAN specification, https://dronecan.github.io/Specification/ (transfer layout, 4.2);
    data types ``uavcan.equipment.actuator.Status`` (1011) and ``uavcan.equipment.air_data.*``.
"""

from __future__ import annotations

import threading
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

import numpy as np

from gcs_sysid.errors import InputError
from gcs_sysid.telemetry.types import Stream

__all__ = ["CanDecoder", "CanSamples", "read_can_log", "CanListener", "open_bus", "frames_of", "streams_of"]

TRIM_EVERY = 1000   #: transfers between trims of a bounded decoder's samples
_ACTUATOR = "uavcan.equipment.actuator.Status"
_IAS = "uavcan.equipment.air_data.IndicatedAirspeed"
_TAS = "uavcan.equipment.air_data.TrueAirspeed"
_RAW = "uavcan.equipment.air_data.RawAirData"
_SYNC = "uavcan.protocol.GlobalTimeSync"
SYNC_MAX_PERIOD_S = 1.1   #: a time-sync message pairs with the previous one only within this (spec: 1.1 s)


def _libs():
    try:
        import can
        import dronecan
    except ImportError:
        raise InputError("CAN needs python-can and dronecan: pip install 'gcs-sysid[can]'") from None
    return can, dronecan


@dataclass
class CanDecoder:
    """Reassembles and decodes DroneCAN transfers from python-can messages.

    Attributes:
        samples: stream name -> field -> list of (t s, value) (SI).
        counts: DroneCAN type name -> transfers decoded; ``bad`` transfers failing their checks;
        frames: CAN frames seen (extended ids only: DroneCAN uses 29-bit ids).
        keep_s: samples older than this (s, bus clock) behind the newest are dropped (checked every
            :data:`TRIM_EVERY` transfers), so a live session's memory stays bounded; None keeps all
            (reading a log).
        new: None, or a list that every decoded sample is also appended to as
            ``(stream, field, t s, value)`` until :meth:`drain` takes them.
    """

    samples: dict = field(default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    counts: Counter = field(default_factory=Counter)
    bad: int = 0
    frames: int = 0
    keep_s: float | None = None
    new: list | None = None

    def __post_init__(self):
        _, dronecan = _libs()
        self._dc = dronecan
        self._tm = dronecan.transport.TransferManager()
        self._since_trim = 0
        self._newest = -np.inf
        self._sync_last: dict[int, tuple[int, float]] = {}   # master node -> (transfer id, receive time)

    def _trim(self) -> None:
        horizon = self._newest - self.keep_s
        for fields in self.samples.values():
            for k, lst in fields.items():
                if lst and lst[0][0] < horizon:
                    fields[k] = [x for x in lst if x[0] >= horizon]

    def feed(self, msg) -> None:
        """One python-can ``Message``."""
        if not msg.is_extended_id or msg.is_error_frame or msg.is_remote_frame:
            return
        self.frames += 1
        dc = self._dc
        frame = dc.transport.Frame(msg.arbitration_id, bytes(msg.data), msg.timestamp, msg.timestamp,
                                   getattr(msg, "is_fd", False))
        try:
            frames = self._tm.receive_frame(frame)
            if not frames:
                return
            tr = dc.transport.Transfer()
            tr.from_frames(frames)
        except Exception:   # TransferError, CRC or a type this dialect does not know
            self.bad += 1
            return
        payload = tr.payload
        kind = dc.get_dronecan_data_type(payload).full_name if payload is not None else "unknown"
        self.counts[kind] += 1
        t = float(frames[0].ts_monotonic)
        s = self.samples
        if self.keep_s is not None:
            self._newest = max(self._newest, t)
            self._since_trim += 1
            if self._since_trim >= TRIM_EVERY:
                self._since_trim = 0
                self._trim()
        if kind == _ACTUATOR:
            sample = (f"actuator{int(payload.actuator_id)}", "pos", t, float(payload.position))
        elif kind == _IAS:
            sample = ("can_airspeed", "ias", t, float(payload.indicated_airspeed))
        elif kind == _TAS:
            sample = ("can_airspeed", "tas", t, float(payload.true_airspeed))
        elif kind == _RAW:
            sample = ("can_airspeed", "diff_pressure", t, float(payload.differential_pressure))
        elif kind == _SYNC:
            sample = self._time_sync(int(tr.source_node_id), int(tr.transfer_id), t,
                                     int(payload.previous_transmission_timestamp_usec))
            if sample is None:
                return
        else:
            return
        s[sample[0]][sample[1]].append(sample[2:])
        if self.new is not None:
            self.new.append(sample)

    def _time_sync(self, node: int, tid: int, t: float, prev_usec: int):
        """A ``uavcan.protocol.GlobalTimeSync`` from master ``node`` received at ``t``: the pair (receive time of
        the master's previous sync message, the master's time when it sent it), or None.

        DroneCAN specification, "Time synchronization" (``uavcan.protocol.GlobalTimeSync``): each message
        carries the master's exact transmission time of the *previous* one; it pairs with the receive time
        of that one if the transfer ids are consecutive and it came within 1.1 s (else it only starts a pair).
        """
        last = self._sync_last.get(node)
        self._sync_last[node] = (tid, t)
        if last is None or prev_usec == 0 or (last[0] + 1) % 32 != tid or not 0 < t - last[1] <= SYNC_MAX_PERIOD_S:
            return None
        return ("can_timesync", "master", last[1], prev_usec * 1e-6)

    def drain(self) -> list[tuple[str, str, float, float]]:
        """The samples decoded since the last call, as ``(stream, field, t s, value)`` (SI), in decoding
        order; empty unless ``new`` was set to a list. For a consumer in another process
        (:class:`CanSamples`), so that only what is new crosses the pipe."""
        if self.new is None:
            return []
        out, self.new = self.new, []
        return out

    def streams(self) -> dict[str, Stream]:
        """The decoded samples as streams (:func:`streams_of`)."""
        return streams_of(self.samples)


def streams_of(samples: dict) -> dict[str, Stream]:
    """Decoded samples as streams: ``actuator<id>`` (``pos`` rad, one stream per actuator id, on its own
    report times) and ``can_airspeed`` (``ias``/``tas`` m/s, ``diff_pressure`` Pa).

    Args:
        samples: stream name -> field -> list of ``(t s, value)`` (:attr:`CanDecoder.samples`).

    Fields of one stream share the times of its first field (sorted by name); the others (from
    other messages) are linearly interpolated onto them.
    """
    out = {}
    for name, fields in samples.items():
        keys = sorted(k for k in fields if fields[k])
        if not keys:
            continue
        t0 = np.array([t for t, _ in fields[keys[0]]])
        order = np.argsort(t0, kind="stable")
        t = t0[order]
        vals = {}
        for k in keys:
            tk = np.array([x for x, _ in fields[k]])
            vk = np.array([v for _, v in fields[k]])
            o = np.argsort(tk, kind="stable")
            vals[k] = np.interp(t, tk[o], vk[o]) if k != keys[0] else vk[order]
        out[name] = Stream(name, "DroneCAN", t, vals)
    return out


@dataclass
class CanSamples:
    """Decoded DroneCAN samples gathered from :meth:`CanDecoder.drain` (e.g. in the learner's process),
    bounded like a live decoder's.

    Attributes:
        keep_s: samples older than this (s, bus clock) behind the newest are dropped at each
            :meth:`add`; None keeps all.
        samples: stream name -> field -> list of ``(t s, value)``, as :attr:`CanDecoder.samples`.
    """

    keep_s: float | None = None
    samples: dict = field(default_factory=lambda: defaultdict(lambda: defaultdict(list)))

    def add(self, new: Iterable[tuple[str, str, float, float]]) -> None:
        """Add ``(stream, field, t s, value)`` samples (:meth:`CanDecoder.drain`), then drop old ones."""
        newest = -np.inf
        for name, key, t, v in new:
            self.samples[name][key].append((t, v))
            newest = max(newest, t)
        if self.keep_s is not None and np.isfinite(newest):
            horizon = newest - self.keep_s
            for fields in self.samples.values():
                for k, lst in fields.items():
                    if lst and lst[0][0] < horizon:
                        fields[k] = [x for x in lst if x[0] >= horizon]

    def streams(self) -> dict[str, Stream]:
        """The samples as streams (:func:`streams_of`)."""
        return streams_of(self.samples)


def read_can_log(path: str | Path) -> tuple[dict[str, Stream], CanDecoder]:
    """Decode a CAN log (any format ``can.LogReader`` reads) into streams.

    Raises:
        InputError: missing file, unreadable format, or no DroneCAN transfer in it.
    """
    can, _ = _libs()
    p = Path(path)
    if not p.exists():
        raise InputError(f"{p}: no such file; expected a CAN log (.asc, .blf, .log, .csv)")
    dec = CanDecoder()
    try:
        for msg in can.LogReader(str(p)):
            dec.feed(msg)
    except (ValueError, OSError, NotImplementedError) as exc:
        raise InputError(f"{p}: cannot be read as a CAN log ({exc})") from None
    if not dec.counts:
        raise InputError(f"{p}: {dec.frames} CAN frames but no DroneCAN transfer decoded; expected "
                         "actuator Status or air-data messages")
    return dec.streams(), dec


def open_bus(spec: str):
    """Open a python-can bus from ``INTERFACE:CHANNEL`` (e.g. ``socketcan:can0``, ``virtual:sim``).

    Raises:
        InputError: malformed spec or a bus that cannot be opened.
    """
    can, _ = _libs()
    if ":" not in spec:
        raise InputError(f"--can {spec}: expected INTERFACE:CHANNEL, e.g. socketcan:can0 or slcan:/dev/ttyACM0")
    interface, channel = spec.split(":", 1)
    try:
        return can.Bus(interface=interface, channel=channel, receive_own_messages=False)
    except Exception as exc:
        raise InputError(f"--can {spec}: cannot open the CAN bus ({type(exc).__name__}: {exc})") from None


class CanListener:
    """Reads a CAN bus in a thread: every frame to ``log_path`` (python-can's logger, format by
    extension, e.g. ``can.log``), DroneCAN transfers decoded into :attr:`decoder`.

    Args:
        bus: an open python-can bus (:func:`open_bus`).
        log_path: where every received frame is written.
        keep_s: decoded samples kept in memory, s of bus time (None: all); the log keeps every frame.
    """

    def __init__(self, bus, log_path: str | Path, keep_s: float | None = None):
        can, _ = _libs()
        self.bus = bus
        self.log_path = Path(log_path)
        self._writer = can.Logger(str(self.log_path))
        self.decoder = CanDecoder(keep_s=keep_s)
        self.received = 0
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._t = threading.Thread(target=self._run, name="gcs-sysid-can", daemon=True)

    def start(self) -> "CanListener":
        self._t.start()
        return self

    def _run(self) -> None:
        while not self._stop.is_set():
            msg = self.bus.recv(timeout=0.1)
            if msg is None:
                continue
            with self._lock:
                self._writer.on_message_received(msg)
                self.received += 1
                self.decoder.feed(msg)

    def streams(self) -> dict[str, Stream]:
        """A snapshot of the decoded streams (bus clock; :meth:`CanDecoder.streams`), thread-safe."""
        with self._lock:
            return self.decoder.streams()

    def drain(self) -> list[tuple[str, str, float, float]]:
        """The samples decoded since the last call (:meth:`CanDecoder.drain`; the first call switches
        the collection on and returns what the decoder holds), thread-safe."""
        with self._lock:
            dec = self.decoder
            if dec.new is None:
                dec.new = []
                return [(n, k, t, v) for n, fields in dec.samples.items() for k, lst in fields.items()
                        for t, v in lst]
            return dec.drain()

    def summary(self) -> dict:
        """Frames received, transfers decoded by type, failed transfers."""
        with self._lock:
            return {"frames": self.received, "transfers": dict(self.decoder.counts), "bad": self.decoder.bad,
                    "log": str(self.log_path)}

    def stop(self) -> None:
        self._stop.set()
        self._t.join(5)
        with self._lock:
            self._writer.stop()
        self.bus.shutdown()


def frames_of(payloads: Iterable, source_node_id: int = 20):
    """python-can messages carrying DroneCAN ``payloads`` (for tests and simulators): each payload
    one transfer (transfer ids counting up), split into frames by ``dronecan``."""
    can, dronecan = _libs()
    out = []
    for i, p in enumerate(payloads):
        tr = dronecan.transport.Transfer(payload=p, source_node_id=source_node_id, transfer_id=i % 32,
                                         service_not_message=False)
        for f in tr.to_frames():
            out.append(can.Message(arbitration_id=f.message_id, data=bytes(f.bytes), is_extended_id=True))
    return out
