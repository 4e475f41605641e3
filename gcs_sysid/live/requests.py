"""Ask the vehicle for the messages system identification needs, and say what is missing.

Per required message one ``MAV_CMD_SET_MESSAGE_INTERVAL`` (one at a time, as the ``COMMAND_ACK``
does not name the message; :data:`ACK_TRIES` tries of :data:`ACK_TIMEOUT_S` each, the ``confirmation``
field counting the retries, as the MAVLink command protocol asks). A message whose request is
denied, unsupported or unanswered falls back to ``REQUEST_DATA_STREAM`` for its ArduPilot stream
group. After :data:`SETTLE_S` the received rates are compared with the asked ones; a shortfall is
reported with what it costs the identification (:func:`shortfall_costs`).

References:
    https://mavlink.io/en/services/message_interval.html; https://mavlink.io/en/services/command.html
    (retries, ``confirmation``); MAVSDK's command sender retries three times
    (``MavlinkCommandSender::DEFAULT_RETRIES``); ArduPilot ``SRx_`` stream groups.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

__all__ = ["REQUIRED_RATES", "rates_from_params", "RateRequester", "shortfall_costs", "ACK_TIMEOUT_S", "ACK_TRIES",
           "SETTLE_S"]

ACK_TIMEOUT_S = 1.0
#: tries per request before it is "no answer" (a radio link or a busy router can hold an answer past one
#: timeout; two tries were too few behind MAVProxy on a loaded machine).
ACK_TRIES = 3
SETTLE_S = 5.0
_CMD = 511          # MAV_CMD_SET_MESSAGE_INTERVAL
_ACCEPTED = 0
#: message -> REQUEST_DATA_STREAM group (MAV_DATA_STREAM) it belongs to on ArduPilot.
_GROUP = {"RAW_IMU": 1, "SCALED_PRESSURE": 1, "SERVO_OUTPUT_RAW": 3, "RC_CHANNELS": 3,
          "GLOBAL_POSITION_INT": 6, "LOCAL_POSITION_NED": 6, "ATTITUDE": 10, "AOA_SSA": 10,
          "VFR_HUD": 11, "WIND": 12}

#: message -> rate (Hz) asked for system identification (docs/live.md).
REQUIRED_RATES: dict[str, float] = {
    "RAW_IMU": 50.0, "ATTITUDE": 50.0, "SERVO_OUTPUT_RAW": 50.0, "SCALED_PRESSURE": 25.0,
    "GLOBAL_POSITION_INT": 25.0, "LOCAL_POSITION_NED": 25.0, "VFR_HUD": 10.0, "RC_CHANNELS": 10.0,
    "AOA_SSA": 10.0, "WIND": 2.0,
}


def rates_from_params(p: dict[str, float]) -> dict[str, float]:
    """The asked rates from the component's parameters (``SID_*_HZ``; :data:`gcs_sysid.component.DEFAULT_PARAMS`)."""
    r = dict(REQUIRED_RATES)
    for names, key in ((("RAW_IMU",), "SID_IMU_HZ"), (("ATTITUDE",), "SID_ATT_HZ"),
                       (("SERVO_OUTPUT_RAW",), "SID_SERVO_HZ"),
                       (("SCALED_PRESSURE", "GLOBAL_POSITION_INT", "LOCAL_POSITION_NED"), "SID_AIR_HZ"),
                       (("VFR_HUD", "RC_CHANNELS", "AOA_SSA"), "SID_SLOW_HZ")):
        if key in p:
            for n in names:
                r[n] = float(p[key])
    return r


def shortfall_costs(received: dict[str, float], rate_ok_hz: float = 20.0, rate_min_hz: float = 10.0) -> list[str]:
    """What the received rates (Hz) cost the identification, one sentence each.

    Moments need angular accelerations, formed from the gyro; below ``rate_ok_hz`` (20 Hz,
    :data:`gcs_sysid.estimation.estimate.RATE_OK_HZ`) they are unreliable and below ``rate_min_hz``
    (10 Hz) not identifiable; control derivatives need the servo outputs at the same rate.
    """
    imu = max(received.get(n, 0.0) for n in ("RAW_IMU", "SCALED_IMU", "HIGHRES_IMU", "ATTITUDE"))
    servo = received.get("SERVO_OUTPUT_RAW", 0.0)
    out = []
    if imu < rate_min_hz:
        out.append(f"gyro at {imu:.1f} Hz (< {rate_min_hz:.0f} Hz): moment coefficients Cl Cm Cn are not identifiable")
    elif imu < rate_ok_hz:
        out.append(f"gyro at {imu:.1f} Hz (< {rate_ok_hz:.0f} Hz): angular accelerations are unreliable, "
                   "Cl Cm Cn poorly identified")
    if servo < rate_ok_hz:
        out.append(f"servo outputs at {servo:.1f} Hz (< {rate_ok_hz:.0f} Hz): control derivatives "
                   "(Cl_delta_a, Cm_delta_e, Cn_delta_r) are blurred; moments unidentifiable below 20 Hz")
    air = max(received.get("SCALED_PRESSURE", 0.0), received.get("VFR_HUD", 0.0))
    if air < 4.0:
        out.append(f"air data at {air:.1f} Hz (< 4 Hz): qbar lags, all coefficients are biased in fast maneuvers")
    return out


@dataclass
class RateRequester:
    """The request state machine (driven by :meth:`tick` and :meth:`handle`; not thread-safe).

    Args:
        mav: pymavlink ``MAVLink`` encoder with the listener's ids.
        send: writes raw bytes.
        rates: message -> asked rate, Hz.
        clock: wall clock, s.

    Attributes:
        target: (system, component) of the vehicle, set by the caller when known.
        result: message -> ``"accepted"``, ``"denied"``, ``"unsupported"``, ``"no answer"`` or
            ``"stream"`` (asked with REQUEST_DATA_STREAM).
        shortfalls: message -> (asked Hz, received Hz) below 80 % of the asked rate, after settling.
        costs: :func:`shortfall_costs` of the received rates.
        log: what was done, in order.
    """

    mav: object
    send: Callable[[bytes], object]
    rates: dict[str, float] = field(default_factory=lambda: dict(REQUIRED_RATES))
    clock: Callable[[], float] = time.time
    target: tuple[int, int] | None = None
    result: dict[str, str] = field(default_factory=dict)
    shortfalls: dict[str, tuple[float, float]] = field(default_factory=dict)
    costs: list[str] = field(default_factory=list)
    log: list[str] = field(default_factory=list)
    checked: bool = False

    def __post_init__(self):
        self._queue = list(self.rates)
        self._current: str | None = None
        self._sent_at = 0.0
        self._tries = 0
        self._done_at: float | None = None

    @property
    def done(self) -> bool:
        return self._done_at is not None

    def restart(self) -> None:
        """Ask again (after a vehicle reboot or a long silence, when the vehicle forgot the rates)."""
        self.__post_init__()
        self.result.clear()
        self.checked = False

    def handle(self, msg) -> None:
        """Take a COMMAND_ACK for the pending request."""
        if msg.get_type() != "COMMAND_ACK" or int(msg.command) != _CMD or self._current is None:
            return
        if self.target is not None and (msg.get_srcSystem(), msg.get_srcComponent()) != self.target:
            return
        name = self._current
        res = int(msg.result)
        if res == _ACCEPTED:
            self.result[name] = "accepted"
        else:
            self.result[name] = {2: "denied", 3: "unsupported"}.get(res, f"refused ({res})")
            self._fallback(name)
        self.log.append(f"SET_MESSAGE_INTERVAL {name} {self.rates[name]:g} Hz: {self.result[name]}")
        self._current = None

    def _fallback(self, name: str) -> None:
        group = _GROUP.get(name)
        if group is None or self.target is None:
            return
        rate = max(self.rates[n] for n, g in _GROUP.items() if g == group and n in self.rates)
        self.send(self.mav.request_data_stream_encode(self.target[0], self.target[1], group, int(round(rate)),
                                                      1).pack(self.mav))
        self.log.append(f"REQUEST_DATA_STREAM group {group} at {rate:g} Hz (for {name})")

    def tick(self, received: Callable[[], dict[str, float]]) -> None:
        """Send the next request or retry; after settling compare ``received()`` rates with the asked."""
        if self.target is None:
            return
        now = self.clock()
        if self._current is not None and now - self._sent_at > ACK_TIMEOUT_S:
            if self._tries < ACK_TRIES:
                self._request(self._current)
            else:
                self.result[self._current] = "no answer"
                self.log.append(f"SET_MESSAGE_INTERVAL {self._current}: no answer")
                self._fallback(self._current)
                self._current = None
        if self._current is None:
            if self._queue:
                self._tries = 0
                self._request(self._queue.pop(0))
            elif self._done_at is None:
                self._done_at = now
        if self._done_at is not None and not self.checked and now - self._done_at >= SETTLE_S:
            got = received()
            self.shortfalls = {n: (r, got.get(n, 0.0)) for n, r in self.rates.items() if got.get(n, 0.0) < 0.8 * r}
            self.costs = shortfall_costs(got)
            self.checked = True
            for n, (r, g) in self.shortfalls.items():
                self.log.append(f"{n}: asked {r:g} Hz, receiving {g:.1f} Hz")
            self.log.extend(self.costs)

    def _request(self, name: str) -> None:
        self._current, self._sent_at = name, self.clock()
        self._tries += 1
        from pymavlink.dialects.v20 import ardupilotmega as mavlink

        msgid = next(i for i, c in mavlink.mavlink_map.items() if c.msgname == name)
        self.send(self.mav.command_long_encode(self.target[0], self.target[1], _CMD, self._tries - 1, msgid,
                                               1e6 / self.rates[name], 0, 0, 0, 0, 0).pack(self.mav))
