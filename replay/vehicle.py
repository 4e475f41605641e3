"""The player as a stand-in vehicle: answers a ground station's requests the way an autopilot does.

A ground station (gcs-sysid's listener, MAVProxy, QGroundControl) asks a vehicle for message rates
with ``MAV_CMD_SET_MESSAGE_INTERVAL`` (answered by ``COMMAND_ACK``) or the older
``REQUEST_DATA_STREAM`` (no answer in the protocol). A recorded log cannot send more than it holds,
so :class:`VehicleResponder`:

* lowers a message's rate by sending only packets at least the requested interval apart (log time);
* stops a message for interval -1 and restores the recorded rate for interval 0;
* refuses a rate above the recorded one: ``COMMAND_ACK`` with ``MAV_RESULT_DENIED`` and a
  ``STATUSTEXT`` (severity WARNING) naming the recorded rate (for REQUEST_DATA_STREAM only the
  STATUSTEXT, as the protocol has no acknowledgement); the message keeps its recorded rate.

Answers carry the recorded vehicle's system and component ids, so they arrive as the vehicle's.

References:
    MAVLink message interval protocol, https://mavlink.io/en/services/message_interval.html
    MAVLink command protocol (COMMAND_LONG / COMMAND_ACK), https://mavlink.io/en/services/command.html
    ArduPilot ``GCS_MAVLINK::handle_request_data_stream`` and the ``SRx_`` stream groups.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass, field
from typing import Callable, Iterable

__all__ = ["STREAM_GROUPS", "packet_source", "recorded_rates", "VehicleResponder"]

#: ArduPilot's REQUEST_DATA_STREAM groups (MAV_DATA_STREAM id -> messages), after ArduPlane's
#: ``GCS_MAVLINK_Plane`` stream tables (``STREAM_RAW_SENSORS`` ...).
STREAM_GROUPS: dict[int, tuple[str, ...]] = {
    1: ("RAW_IMU", "SCALED_IMU", "SCALED_IMU2", "SCALED_IMU3", "SCALED_PRESSURE", "HIGHRES_IMU"),
    2: ("SYS_STATUS", "MEMINFO", "GPS_RAW_INT", "NAV_CONTROLLER_OUTPUT"),
    3: ("SERVO_OUTPUT_RAW", "RC_CHANNELS", "RC_CHANNELS_RAW"),
    6: ("GLOBAL_POSITION_INT", "LOCAL_POSITION_NED"),
    10: ("ATTITUDE", "SIMSTATE", "AOA_SSA"),
    11: ("VFR_HUD",),
    12: ("WIND", "AHRS", "AHRS2", "BATTERY_STATUS"),
}
_DENIED, _ACCEPTED, _UNSUPPORTED = 2, 0, 3
_SET_MESSAGE_INTERVAL = 511
_SEVERITY_WARNING, _SEVERITY_INFO = 4, 6


def packet_source(data: bytes) -> tuple[int, int]:
    """(system id, component id) of a raw MAVLink v1 (0xFE) or v2 (0xFD) packet."""
    if data[:1] == b"\xfd":
        return data[5], data[6]
    return data[3], data[4]


def recorded_rates(packets: Iterable, source: tuple[int, int] | None = None) -> dict[str, float]:
    """Mean rate (Hz) of each message type in the log, from the log stamps.

    Args:
        packets: :class:`replay.player.Packet` objects in file order.
        source: count only this (system, component); None: all.

    Returns:
        message name -> count / (last stamp - first stamp of the log), Hz.
    """
    counts: Counter = Counter()
    t0 = t1 = None
    for pk in packets:
        t0 = pk.stamp if t0 is None else t0
        t1 = pk.stamp
        if source is None or packet_source(pk.data) == source:
            counts[pk.name] += 1
    span = (t1 - t0) if t0 is not None else 0.0
    return {k: (v / span if span > 0 else 0.0) for k, v in counts.items()}


@dataclass
class VehicleResponder:
    """Answers rate requests for one recorded vehicle and thins the stream accordingly.

    Attributes:
        mav: a pymavlink ``MAVLink`` encoder whose ``srcSystem``/``srcComponent`` are the vehicle's.
        rates: recorded rate per message name, Hz (:func:`recorded_rates`).
        send: writes raw bytes on the link.
        intervals: message name -> interval now in force, s (-1: stopped); absent: as recorded.
        log: one line per request handled (what was asked, what was answered).
    """

    mav: object
    rates: dict[str, float]
    send: Callable[[bytes], object]
    intervals: dict[str, float] = field(default_factory=dict)
    log: list[str] = field(default_factory=list)
    _last: dict[str, float] = field(default_factory=lambda: defaultdict(lambda: -1e18))

    @property
    def system(self) -> tuple[int, int]:
        return self.mav.srcSystem, self.mav.srcComponent

    def allow(self, name: str, stamp: float) -> bool:
        """Whether the packet ``name`` recorded at log time ``stamp`` (s) is sent under the requests."""
        iv = self.intervals.get(name)
        if iv is None:
            return True
        if iv < 0:
            return False
        if stamp - self._last[name] >= 0.95 * iv:   # 5 % slack: recorded spacing jitters
            self._last[name] = stamp
            return True
        return False

    def handle(self, msg) -> None:
        """Handle one received message (others than requests addressed to the vehicle are ignored)."""
        kind = msg.get_type()
        sysid, compid = self.system
        if getattr(msg, "target_system", sysid) not in (0, sysid):
            return
        if kind == "COMMAND_LONG" and getattr(msg, "target_component", 0) in (0, compid):
            if int(msg.command) != _SET_MESSAGE_INTERVAL:
                self._ack(msg, int(msg.command), _UNSUPPORTED)
                self.log.append(f"command {int(msg.command)}: unsupported by a log player")
                return
            result = self._set_interval(int(msg.param1), float(msg.param2))
            self._ack(msg, _SET_MESSAGE_INTERVAL, result)
        elif kind == "REQUEST_DATA_STREAM":
            names = self._group(int(msg.req_stream_id))
            rate = float(msg.req_message_rate)
            for name in names:
                if not msg.start_stop:
                    self._set_name(name, -1.0)
                elif rate > 0:
                    self._set_name(name, 1.0 / rate)   # interval, s

    # --- internals -------------------------------------------------------------------------

    def _group(self, stream_id: int) -> list[str]:
        if stream_id == 0:
            return sorted({n for g in STREAM_GROUPS.values() for n in g} & set(self.rates))
        return [n for n in STREAM_GROUPS.get(stream_id, ()) if n in self.rates]

    def _set_interval(self, msgid: int, interval_us: float) -> int:
        from pymavlink.dialects.v20 import ardupilotmega as mavlink

        cls = mavlink.mavlink_map.get(msgid)
        if cls is None or cls.msgname not in self.rates:
            name = cls.msgname if cls is not None else f"message {msgid}"
            self.log.append(f"SET_MESSAGE_INTERVAL {name}: not in the log, denied")
            self._text(_SEVERITY_WARNING, f"replay: {name} not in log")
            return _DENIED
        if interval_us == 0:
            return self._set_name(cls.msgname, 0.0)
        return self._set_name(cls.msgname, -1.0 if interval_us < 0 else interval_us * 1e-6)

    def _set_name(self, name: str, interval_s: float) -> int:
        rec = self.rates.get(name, 0.0)
        if interval_s == 0.0:
            self.intervals.pop(name, None)
            self.log.append(f"{name}: back to the recorded {rec:.1f} Hz")
            return _ACCEPTED
        if interval_s < 0:
            self.intervals[name] = -1.0
            self.log.append(f"{name}: stopped")
            return _ACCEPTED
        asked = 1.0 / interval_s
        if asked > 1.05 * rec:
            self.intervals.pop(name, None)
            self.log.append(f"{name}: asked {asked:.1f} Hz, recorded {rec:.1f} Hz: denied")
            self._text(_SEVERITY_WARNING, f"replay: {name} max {rec:.1f}Hz (asked {asked:.0f})")
            return _DENIED
        self.intervals[name] = interval_s
        self.log.append(f"{name}: {asked:.1f} Hz (recorded {rec:.1f} Hz)")
        return _ACCEPTED

    def _ack(self, msg, command: int, result: int) -> None:
        self.send(self.mav.command_ack_encode(command, result, 0, 0, msg.get_srcSystem(),
                                              msg.get_srcComponent()).pack(self.mav))

    def _text(self, severity: int, text: str) -> None:
        self.send(self.mav.statustext_encode(severity, text[:50].encode()).pack(self.mav))
