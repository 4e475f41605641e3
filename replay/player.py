"""Read a tlog's raw packets and send them on a pymavlink link with the recorded timing.

Packets are read with pymavlink's ``mavutil.mavlogfile`` and sent as their original bytes
(``msg.get_msgbuf()``: header, sequence number, ids and CRC unchanged), so a receiver sees exactly
what the vehicle sent. Corrupt records (pymavlink's ``BAD_DATA``) are skipped and counted.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Callable, Iterable, Iterator

from gcs_sysid.errors import InputError

__all__ = ["Packet", "read_packets", "open_link", "play", "POLL_S"]

POLL_S = 0.01
"""Longest wait (s) between two looks at what the far end sent."""


@dataclass(frozen=True)
class Packet:
    """One recorded packet: ``stamp`` log time (s, the tlog's wall clock), ``name``, raw ``data``."""

    stamp: float
    name: str
    data: bytes


def _mavutil():
    from pymavlink import mavutil

    if mavutil.mavlink is None or "ardupilotmega" not in mavutil.current_dialect:
        os.environ.setdefault("MAVLINK20", "1")  # v2 parser (it reads v1 packets too)
        mavutil.set_dialect("ardupilotmega")
    return mavutil


def read_packets(path: str, bad: list[int] | None = None) -> Iterator[Packet]:
    """Yield the packets of a tlog in file order.

    Args:
        path: the .tlog file.
        bad: if given, a one-element list whose count of skipped BAD_DATA records is updated.

    Raises:
        InputError: the file is missing, empty, not a tlog (a DataFlash .bin cannot be replayed as
            MAVLink) or holds no MAVLink packet.
    """
    from gcs_sysid.telemetry import detect_format

    fmt = detect_format(path)
    if fmt != "tlog":
        raise InputError(f"{path}: is a DataFlash .bin log; replay needs a MAVLink telemetry log (.tlog)")
    mavutil = _mavutil()
    log = mavutil.mavlogfile(str(path), robust_parsing=True)
    n = 0
    try:
        while True:
            msg = log.recv_msg()
            if msg is None:
                break
            name = msg.get_type()
            if name == "BAD_DATA":
                if bad is not None:
                    bad[0] += 1
                continue
            n += 1
            yield Packet(float(msg._timestamp), name, bytes(msg.get_msgbuf()))
    finally:
        log.close()
    if n == 0:
        raise InputError(f"{path}: no MAVLink packets could be read; expected a MAVLink telemetry log (.tlog)")


def open_link(link: str, baud: int = 115200):
    """Open the output link with ``mavutil.mavlink_connection`` (udpout:, udpin:, tcp:, tcpin:, serial).

    Raises:
        InputError: the link string is malformed or the link cannot be opened.
    """
    mavutil = _mavutil()
    if os.path.isfile(link) or link.lower().endswith((".tlog", ".bin", ".log")):
        raise InputError(f"--link {link}: is a file; expected a link such as udpout:127.0.0.1:14550, "
                         "tcp:HOST:PORT or a serial device")
    try:
        return mavutil.mavlink_connection(link, baud=baud, input=False, source_system=255, robust_parsing=True)
    except Exception as exc:  # socket.gaierror, ValueError, serial.SerialException ...
        raise InputError(f"--link {link}: cannot open ({type(exc).__name__}: {exc}); expected e.g. "
                         "udpout:127.0.0.1:14550, tcp:HOST:PORT or /dev/ttyUSB0") from None


def play(packets: Iterable[Packet], send: Callable[[bytes], object], speed: float = 1.0,
         t_from: float | None = None, t_to: float | None = None,
         sleep: Callable[[float], None] = time.sleep, clock: Callable[[], float] = time.monotonic,
         poll: Callable[[], object] | None = None, allow: Callable[[str, float], bool] | None = None) -> int:
    """Send packets with their recorded spacing divided by ``speed``.

    Args:
        packets: in file order.
        send: called with each packet's bytes.
        speed: 1.0 real time, 2.0 twice as fast, 0 as fast as possible.
        t_from, t_to: window in s from the log's first record (None: open end).
        sleep, clock: injectable for tests.
        poll: called while waiting (at least every :data:`POLL_S`) and every 64 packets when
            sending as fast as possible: handles what the far end sends (requests).
        allow: ``allow(name, stamp)`` says whether a packet is sent (rate requests); None: all.

    Returns:
        The number of packets sent.
    """
    if speed < 0:
        raise InputError(f"--speed {speed}: must be >= 0 (0 = as fast as possible)")
    sent = 0
    first = None
    start_stamp = start_wall = None
    for i, pk in enumerate(packets):
        if first is None:
            first = pk.stamp
        rel = pk.stamp - first
        if t_from is not None and rel < t_from:
            continue
        if t_to is not None and rel > t_to:
            break
        if speed > 0:
            if start_stamp is None:
                start_stamp, start_wall = pk.stamp, clock()
            # a stamp going backwards (a merged log) is sent at once, not waited for
            due = start_wall + max(pk.stamp - start_stamp, 0.0) / speed
            wait = due - clock()
            while wait > 0:
                sleep(min(wait, POLL_S) if poll is not None else wait)
                if poll is not None:
                    poll()
                wait = due - clock()
        elif poll is not None and i % 64 == 0:
            poll()
        if allow is not None and not allow(pk.name, pk.stamp):
            continue
        send(pk.data)
        sent += 1
    return sent
