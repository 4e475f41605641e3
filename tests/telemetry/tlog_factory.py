"""Builds small real tlogs with pymavlink's encoder (ardupilotmega dialect) for the tests.

A record is ``struct.pack('>Q', stamp_usec) + packet``; packets come from ``msg.pack(mav)`` with
the sequence number advancing as a real sender's would.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink

T0_US = 1_600_000_000_000_000  # log wall clock of the first record (2020-09-13)


class TlogWriter:
    """Accumulates tlog records in memory."""

    def __init__(self, sysid: int = 1, compid: int = 1, mavlink1: bool = False):
        self.mav = mavlink.MAVLink(None, srcSystem=sysid, srcComponent=compid)
        self.mavlink1 = mavlink1
        self.records: list[bytes] = []

    def packet(self, msg, mav=None) -> bytes:
        mav = mav or self.mav
        buf = msg.pack(mav, force_mavlink1=self.mavlink1)
        mav.seq = (mav.seq + 1) % 256
        return bytes(buf)

    def add(self, stamp_s: float, msg, mav=None) -> bytes:
        """Append ``msg`` at log time ``stamp_s`` (s after T0); returns the record bytes."""
        rec = struct.pack(">Q", T0_US + int(round(stamp_s * 1e6))) + self.packet(msg, mav)
        self.records.append(rec)
        return rec

    def add_raw(self, stamp_s: float, packet: bytes) -> bytes:
        rec = struct.pack(">Q", T0_US + int(round(stamp_s * 1e6))) + packet
        self.records.append(rec)
        return rec

    def data(self) -> bytes:
        return b"".join(self.records)

    def write(self, path: Path) -> Path:
        Path(path).write_bytes(self.data())
        return Path(path)


def heartbeat(autopilot=mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA, armed=True):
    return mavlink.MAVLink_heartbeat_message(mavlink.MAV_TYPE_FIXED_WING, autopilot,
                                             128 if armed else 0, 10, 4, 3)


def flight_messages(boot_s: float, i: int):
    """One 'tick' of an ArduPlane-like stream set at vehicle time ``boot_s`` (s since boot)."""
    ms = int(round(boot_s * 1000)) % 2 ** 32
    us = int(round(boot_s * 1e6))
    ph = 0.1 * i
    return [
        mavlink.MAVLink_attitude_message(ms, 0.1 * np.sin(ph), 0.05, 1.0 + 0.01 * i, 0.01, 0.02, 0.03),
        mavlink.MAVLink_raw_imu_message(us, 100, -50, -1000, 10, 20, -30, 0, 0, 0, 0, 0),
        mavlink.MAVLink_servo_output_raw_message(us % 2 ** 32, 0, 1500 + i % 100, 1400, 1100, 1600,
                                                 0, 0, 0, 0),
        mavlink.MAVLink_vfr_hud_message(18.0, 20.0, 120, 55, 100.0, 1.5),
        mavlink.MAVLink_scaled_pressure_message(ms, 1000.0, 2.0, 2150),
        mavlink.MAVLink_global_position_int_message(ms, -353632622, 1491652374, 584090, 100000,
                                                    1500, -200, 50, 9000),
    ]


def write_flight(path: Path, n: int = 100, rate: float = 50.0, boot0: float = 10.0,
                 writer: TlogWriter | None = None, log0: float = 0.0) -> Path:
    """A plain flight of ``n`` ticks at ``rate`` Hz, with a HEARTBEAT every second."""
    w = writer or TlogWriter()
    for i in range(n):
        tb = boot0 + i / rate
        ts = log0 + i / rate
        if i % int(rate) == 0:
            w.add(ts, heartbeat())
        for k, m in enumerate(flight_messages(tb, i)):
            w.add(ts + 1e-4 * k, m)
    return w.write(path)
