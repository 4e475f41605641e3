"""A live MAVLink link as a telemetry source: open it, keep every packet in a raw tlog, decode samples.

* :func:`open_link` opens any pymavlink connection string (``udpin:``, ``udpout:``, ``tcp:``,
  ``tcpin:``, a serial device with a baud rate) with the ardupilotmega dialect, MAVLink 2.
* :class:`RawLog` appends each received packet to ``raw.tlog`` as it arrives, in the standard tlog
  record format (8-byte big-endian microsecond wall-clock stamp, then the packet's bytes exactly as
  received: ``msg.get_msgbuf()``), flushed per packet, so a crash loses nothing already received
  and the file can be replayed by :func:`gcs_sysid.telemetry.read_log` and by the log player.
* :class:`LinkReceiver` is the reading loop (a thread): it logs each packet, counts rates, notices
  silences, vehicle reboots and corrupt bytes, and hands each record to the consumers.
* :func:`sample_of` turns one received message into the same SI fields the log decoder produces,
  through the same table (:data:`~gcs_sysid.telemetry.mavlink_streams.SPECS`); there is no second
  decoder.

References:
    tlog record layout: pymavlink ``mavutil.mavfile.recv_msg`` (``struct.pack('>Q', usec) +
    msg.get_msgbuf()``), the format MAVProxy and Mission Planner write.
"""

from __future__ import annotations

import os
import socket
import struct
import threading
import time
from collections import Counter, deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from gcs_sysid.errors import InputError
from gcs_sysid.telemetry.mavlink_streams import SPECS

__all__ = ["open_link", "RawLog", "LinkReceiver", "LinkStats", "sample_of", "RCVBUF_BYTES"]

RCVBUF_BYTES = 8 << 20
"""Socket receive buffer asked for UDP/TCP links (8 MiB: about 30 s of a 2,000 msg/s link)."""


def _mavutil():
    from pymavlink import mavutil

    if mavutil.mavlink is None or "ardupilotmega" not in mavutil.current_dialect:
        os.environ.setdefault("MAVLINK20", "1")
        mavutil.set_dialect("ardupilotmega")
    return mavutil


def open_link(connection: str, baud: int = 57600, source_system: int = 255, source_component: int = 190):
    """Open a pymavlink connection for listening (and for sending requests back).

    Args:
        connection: ``udpin:HOST:PORT``, ``udpout:HOST:PORT``, ``tcp:HOST:PORT``, ``tcpin:HOST:PORT``
            or a serial device (``/dev/ttyUSB0``; ``/dev/ttyUSB0,57600`` also sets the baud).
        baud: serial baud rate.
        source_system, source_component: ids this end sends with (requests, component messages).

    Returns:
        The ``mavutil`` connection (robust parsing: corrupt bytes come back as ``BAD_DATA``).

    Raises:
        InputError: a file instead of a link, a malformed string, or a link that cannot be opened.
    """
    mavutil = _mavutil()
    if os.path.isfile(connection) or connection.lower().endswith((".tlog", ".bin")):
        raise InputError(f"{connection}: is a log file; `listen` needs a link such as udpin:0.0.0.0:14550 "
                         "(replay a file with `gcs-sysid replay`)")
    if "," in connection and not connection.startswith(("udp", "tcp")):
        connection, b = connection.rsplit(",", 1)
        if not b.isdigit():
            raise InputError(f"{connection},{b}: baud rate must be a number, e.g. /dev/ttyUSB0,57600")
        baud = int(b)
    try:
        link = mavutil.mavlink_connection(connection, baud=baud, source_system=source_system,
                                          source_component=source_component, robust_parsing=True,
                                          dialect="ardupilotmega", autoreconnect=True)
    except Exception as exc:   # socket.gaierror, ValueError, serial.SerialException, OSError ...
        raise InputError(f"{connection}: cannot open the link ({type(exc).__name__}: {exc}); expected e.g. "
                         "udpin:0.0.0.0:14550, udpout:HOST:PORT, tcp:HOST:5760, tcpin:0.0.0.0:5760 or "
                         "/dev/ttyUSB0 with --baud") from None
    port = getattr(link, "port", None)
    if isinstance(port, socket.socket):
        try:
            port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RCVBUF_BYTES)
        except OSError:
            pass
    return link


class RawLog:
    """Append-only raw tlog of a live link (flushed per record; thread-safe).

    Args:
        path: the ``raw.tlog`` file (its directory is created; an existing file is appended to).
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._f = open(self.path, "ab", buffering=0)   # unbuffered: each record reaches the OS at once
        self._lock = threading.Lock()
        self.records = 0
        self.bytes = 0

    def write(self, stamp_us: int, packet: bytes) -> None:
        """Append one record: ``stamp_us`` wall-clock microseconds, ``packet`` the raw MAVLink bytes."""
        rec = struct.pack(">Q", stamp_us) + packet
        with self._lock:
            self._f.write(rec)
            self.records += 1
            self.bytes += len(rec)

    def close(self) -> None:
        with self._lock:
            if not self._f.closed:
                os.fsync(self._f.fileno())
                self._f.close()


def sample_of(msg) -> dict[str, float] | None:
    """SI fields of one received message, as the log decoder converts them, or None if not used.

    Args:
        msg: a pymavlink message.

    Returns:
        Field name -> value in SI units (e.g. ATTITUDE -> roll pitch yaw rad, p q r rad/s;
        RAW_IMU -> ax ay az m/s^2, p q r rad/s), per ``docs/telemetry.md``; None for a message
        type the telemetry layer does not decode.
    """
    spec = SPECS.get(msg.get_type())
    if spec is None:
        return None
    row = np.array([[float(getattr(msg, f)) for f in spec.fields]])
    return {k: float(v[0]) for k, v in spec.convert(row).items()}


@dataclass
class LinkStats:
    """What the receiver has seen (read by the console; written only by the receiver thread).

    Attributes:
        counts: message name -> packets received.
        bad_data: corrupt byte runs (pymavlink ``BAD_DATA``: bad CRC or framing).
        records: packets written to the raw log.
        first_s, last_s: wall-clock time of the first and the latest packet, s (0 before any).
        vehicle: (system, component) of the vehicle (the sender of an autopilot HEARTBEAT or ATTITUDE).
        events: ``(wall time s, text)`` of what happened to the link (silence, recovery, reboot).
        seq_lost: packets missed by the vehicle's sequence numbers (pymavlink ``mav_loss``).
    """

    counts: Counter = field(default_factory=Counter)
    bad_data: int = 0
    records: int = 0
    first_s: float = 0.0
    last_s: float = 0.0
    vehicle: tuple[int, int] | None = None
    events: list[tuple[float, str]] = field(default_factory=list)
    seq_lost: int = 0
    _recent: deque = field(default_factory=lambda: deque(maxlen=20000))

    def mean_rates(self) -> dict[str, float]:
        """Message name -> mean received rate over the whole session, Hz."""
        dur = self.last_s - self.first_s
        return {k: (v / dur if dur > 0 else 0.0) for k, v in sorted(self.counts.items())}

    def rates(self, now: float, span: float = 5.0) -> dict[str, float]:
        """Message name -> received rate over the last ``span`` s, Hz."""
        c: Counter = Counter()
        for t, name in list(self._recent):
            if t >= now - span:
                c[name] += 1
        dur = min(span, max(now - self.first_s, 1e-3))
        return {k: v / dur for k, v in c.items()}


class LinkReceiver:
    """Reads a link in a thread, logs every packet and hands it on.

    Args:
        link: an open ``mavutil`` connection (:func:`open_link`).
        raw: the :class:`RawLog` every received packet goes to (before anything else is done with it).
        consumers: callables ``(stamp_us, packet_bytes, msg)`` called in arrival order from the
            receiver thread; they must return fast (queue the work).
        silence_s: a gap without packets longer than this is reported as a silence (and the end of
            it as a recovery).
        clock: wall clock, s (injectable for tests).
        measure: keep the handling time of each message (s; the last 100,000) in :attr:`handle_s`,
            from the return of ``recv_msg`` to the consumers' return (benchmarks).
    """

    def __init__(self, link, raw: RawLog, consumers: list[Callable] | None = None, silence_s: float = 3.0,
                 clock: Callable[[], float] = time.time, measure: bool = False):
        self.link = link
        self.raw = raw
        self.consumers = list(consumers or [])
        self.silence_s = silence_s
        self.clock = clock
        self.stats = LinkStats()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._silent = False
        self._boot_ms: dict[tuple[int, int], float] = {}
        self.write_lock = threading.Lock()
        self.handle_s: deque | None = deque(maxlen=100_000) if measure else None

    def start(self) -> "LinkReceiver":
        self._thread = threading.Thread(target=self._run, name="gcs-sysid-link", daemon=True)
        self._thread.start()
        return self

    def stop(self, timeout: float = 5.0) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)

    def send(self, packet: bytes) -> None:
        """Write raw bytes on the link (thread-safe)."""
        with self.write_lock:
            self.link.write(packet)

    def _event(self, text: str) -> None:
        self.stats.events.append((self.clock(), text))

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self.link.recv_msg()
            except OSError as exc:   # e.g. a serial device unplugged; autoreconnect handles tcp
                self._event(f"link error: {exc}")
                time.sleep(0.2)
                continue
            now = self.clock()
            if msg is None:
                if not self._silent and self.stats.last_s and now - self.stats.last_s > self.silence_s:
                    self._silent = True
                    self._event(f"link silent for more than {self.silence_s:.0f} s")
                self._stop.wait(0.002)
                continue
            if self.handle_s is None:
                self.handle(msg, now)
            else:
                t0 = time.perf_counter()
                self.handle(msg, now)
                self.handle_s.append(time.perf_counter() - t0)

    def handle(self, msg, now: float) -> None:
        """Log and dispatch one received message (called by the thread; public for in-process hosts)."""
        st = self.stats
        if msg.get_type() == "BAD_DATA":
            st.bad_data += 1
            return
        buf = bytes(msg.get_msgbuf())
        stamp_us = int(now * 1e6)
        self.raw.write(stamp_us, buf)
        name = msg.get_type()
        st.records += 1
        st.counts[name] += 1
        st._recent.append((now, name))
        if self._silent:
            self._silent = False
            self._event(f"link back after {now - st.last_s:.1f} s of silence")
        if not st.first_s:
            st.first_s = now
        st.last_s = now
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        if st.vehicle is None and (name == "ATTITUDE" or (name == "HEARTBEAT" and msg.autopilot != 8)):
            st.vehicle = src
            self._event(f"vehicle: system {src[0]}, component {src[1]}")
        boot = getattr(msg, "time_boot_ms", None)
        if boot is not None and src == st.vehicle:
            last = self._boot_ms.get(src)
            if last is not None and boot < last - 1000 and boot < 60_000:
                self._event(f"vehicle reboot: time_boot_ms fell from {last / 1e3:.1f} s to {boot / 1e3:.1f} s")
            self._boot_ms[src] = boot if last is None or boot < last - 1000 or boot > last else last
        st.seq_lost = int(getattr(self.link, "mav_loss", 0))
        for c in self.consumers:
            try:
                c(stamp_us, buf, msg)
            except Exception as exc:   # a consumer's bug must not stop the logging of the link
                if len(st.events) < 1000:
                    self._event(f"error handling {name}: {type(exc).__name__}: {exc}")
