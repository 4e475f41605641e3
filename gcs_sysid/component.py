"""gcs-sysid as a component on the MAVLink network: it speaks back.

* Its own system and component id. By default the *vehicle's* system id with component
  ``MAV_COMP_ID_ONBOARD_COMPUTER`` (191): ground stations (QGroundControl, Mission Planner) show the
  STATUSTEXT and NAMED_VALUE_FLOAT of the components of the vehicle they are connected to, and
  would ignore a second "ground station" system. Both ids are settable (``--sysid``/``--compid``).
* ``HEARTBEAT`` at 1 Hz as ``MAV_TYPE_ONBOARD_CONTROLLER`` with ``MAV_AUTOPILOT_INVALID``: a helper
  component, not a vehicle (so no ground station mistakes it for an autopilot) and not a GCS
  (a GCS heartbeat would make an autopilot believe an operator is connected, which changes its
  failsafe behaviour).
* ``STATUSTEXT`` for suggestions and alerts, split into 50-character chunks with the MAVLink 2
  ``id``/``chunk_seq`` fields, severity set.
* ``NAMED_VALUE_FLOAT`` for per-coefficient confidence (names of at most 10 characters, e.g.
  ``SID_CONF_Cm``... shortened to ``CONF_Cm``).
* Its settings are MAVLink parameters (REAL32), served by MAVSDK's parameter server (PyPI ``mavsdk``,
  which since 3.x ships the C++ core as a library: the server runs in this process on a ``raw://``
  connection fed with the link's bytes). Without mavsdk the same parameters are served by
  :class:`ParamTable`, the MAVLink parameter protocol written with pymavlink.

References:
    MAVLink parameter protocol, https://mavlink.io/en/services/parameter.html
    STATUSTEXT chunking, https://mavlink.io/en/messages/common.html#STATUSTEXT
    MAVSDK ParamServer, https://mavsdk.mavlink.io/main/en/cpp/api_reference/classmavsdk_1_1_param_server.html
"""

from __future__ import annotations

import threading
import time
from typing import Callable

__all__ = ["DEFAULT_PARAMS", "COMP_ID", "SysidComponent", "ParamTable", "chunk_text", "conf_name", "targets"]

COMP_ID = 191   #: MAV_COMP_ID_ONBOARD_COMPUTER
_MAV_TYPE_ONBOARD_CONTROLLER = 18
_MAV_AUTOPILOT_INVALID = 8
_MAV_STATE_ACTIVE = 4
_REAL32 = 9
_PARAM_MSGS = {"PARAM_REQUEST_LIST", "PARAM_REQUEST_READ", "PARAM_SET", "PARAM_EXT_REQUEST_LIST",
               "PARAM_EXT_REQUEST_READ", "PARAM_EXT_SET", "HEARTBEAT"}

#: Settings served as parameters: name (<= 16 chars) -> (default, meaning).
DEFAULT_PARAMS: dict[str, tuple[float, str]] = {
    "SID_IMU_HZ": (50.0, "IMU (RAW_IMU/SCALED_IMU/HIGHRES_IMU) rate asked of the vehicle, Hz"),
    "SID_ATT_HZ": (50.0, "ATTITUDE rate asked, Hz"),
    "SID_SERVO_HZ": (50.0, "SERVO_OUTPUT_RAW rate asked, Hz"),
    "SID_AIR_HZ": (25.0, "SCALED_PRESSURE, GLOBAL_POSITION_INT, LOCAL_POSITION_NED rate asked, Hz"),
    "SID_SLOW_HZ": (10.0, "VFR_HUD, RC_CHANNELS, AOA_SSA rate asked, Hz"),
    "SID_CONF_MIN": (0.5, "confidence score below which a coefficient is reported (alert), 0..1"),
    "SID_TARGETS": (63.0, "bit mask of the coefficients reported (confidence values, alerts): "
                           "1 CX, 2 CY, 4 CZ, 8 Cl, 16 Cm, 32 Cn"),
}


def targets(mask: float) -> tuple[str, ...]:
    """Coefficient names selected by the ``SID_TARGETS`` bit mask (1 CX, 2 CY, 4 CZ, 8 Cl, 16 Cm, 32 Cn)."""
    names = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")
    m = int(mask)
    return tuple(n for i, n in enumerate(names) if m & (1 << i))


def conf_name(coefficient: str) -> str:
    """NAMED_VALUE_FLOAT name of a coefficient's confidence (<= 10 chars): ``CONF_Cm``."""
    return f"CONF_{coefficient}"[:10]


def chunk_text(text: str, size: int = 50) -> list[bytes]:
    """Split ``text`` into STATUSTEXT chunks of ``size`` bytes (ASCII; others replaced by '?').

    A text that fills its last chunk exactly is followed by an empty chunk, so a receiver sees the
    end (MAVLink: the last chunk is shorter than 50 characters or NUL-terminated).
    """
    raw = text.encode("ascii", "replace")
    chunks = [raw[i:i + size] for i in range(0, len(raw), size)] or [b""]
    if len(chunks) > 1 and len(chunks[-1]) == size:
        chunks.append(b"")
    return chunks


class ParamTable:
    """The MAVLink parameter protocol (PARAM_REQUEST_LIST/READ/SET -> PARAM_VALUE), REAL32 values.

    Args:
        mav: pymavlink ``MAVLink`` encoder with this component's ids.
        send: writes raw bytes.
        values: name -> value (changed in place by PARAM_SET).
        on_change: called with ``(name, value)`` after a PARAM_SET.
    """

    def __init__(self, mav, send: Callable[[bytes], object], values: dict[str, float],
                 on_change: Callable[[str, float], object] | None = None):
        self.mav, self.send, self.values, self.on_change = mav, send, values, on_change

    def _value(self, name: str) -> None:
        names = list(self.values)
        self.send(self.mav.param_value_encode(name.encode(), float(self.values[name]), _REAL32, len(names),
                                              names.index(name)).pack(self.mav))

    def handle(self, msg) -> None:
        """Answer one received parameter message addressed to this component."""
        kind = msg.get_type()
        if getattr(msg, "target_system", -1) != self.mav.srcSystem or \
                getattr(msg, "target_component", -1) not in (self.mav.srcComponent, 0):
            return
        if kind == "PARAM_REQUEST_LIST":
            for name in self.values:
                self._value(name)
        elif kind == "PARAM_REQUEST_READ":
            names = list(self.values)
            name = msg.param_id if msg.param_index < 0 else (names[msg.param_index]
                                                              if msg.param_index < len(names) else None)
            if name in self.values:
                self._value(name)
        elif kind == "PARAM_SET" and msg.param_id in self.values:
            self.values[msg.param_id] = float(msg.param_value)
            if self.on_change is not None:
                self.on_change(msg.param_id, float(msg.param_value))
            self._value(msg.param_id)


class SysidComponent:
    """The gcs-sysid component: heartbeat, status texts, confidence values and parameters.

    Args:
        send: writes raw bytes on the link (thread-safe).
        system_id, component_id: this component's ids.
        params: initial parameter values (default :data:`DEFAULT_PARAMS`).
        use_mavsdk: serve parameters with MAVSDK's ParamServer when mavsdk imports (else
            :class:`ParamTable`).
        clock: wall clock, s.

    Attributes:
        params: current parameter values (updated when a ground station sets one).
        param_backend: ``"mavsdk"`` or ``"pymavlink"``.
        sent: count of messages sent by kind.
        sdk_log: MAVSDK's warnings and errors (kept here rather than printed).
    """

    def __init__(self, send: Callable[[bytes], object], system_id: int = 1, component_id: int = COMP_ID,
                 params: dict[str, float] | None = None, use_mavsdk: bool = True,
                 clock: Callable[[], float] = time.time):
        from pymavlink.dialects.v20 import ardupilotmega as mavlink

        self.send = send
        self.mav = mavlink.MAVLink(None, srcSystem=system_id, srcComponent=component_id)
        self.params = dict(params) if params is not None else {k: v for k, (v, _) in DEFAULT_PARAMS.items()}
        self.clock = clock
        self.sent: dict[str, int] = {}
        self._t0 = clock()
        self._last_hb = -1e9
        self._text_id = 0
        self._lock = threading.Lock()
        self._sdk = self._ps = None
        self.sdk_log: list[str] = []
        self.param_backend = "pymavlink"
        if use_mavsdk:
            self._start_mavsdk(system_id, component_id)
        self._table = ParamTable(self.mav, self._send, self.params) if self._sdk is None else None

    # --- parameters ---------------------------------------------------------------------------

    def _start_mavsdk(self, system_id: int, component_id: int) -> None:
        try:
            from mavsdk import Configuration, Mavsdk
            from mavsdk.plugins.param_server import ParamServer
        except Exception:   # not installed, or its library does not load on this platform
            return
        from pymavlink.dialects.v20 import ardupilotmega as mavlink

        from mavsdk import LogLevel, log_subscribe

        def keep_log(level, message, _file, _line) -> bool:   # MAVSDK's log goes to sdk_log, not stdout
            if level >= LogLevel.WARN and len(self.sdk_log) < 200:
                self.sdk_log.append(f"{level.name}: {message}")
            return True

        log_subscribe(keep_log)
        sdk = Mavsdk(Configuration.create_manual(system_id, component_id, False))
        parser = mavlink.MAVLink(None)
        parser.robust_parsing = True

        def out(data: bytes) -> None:   # MAVSDK's own heartbeat is dropped: this component sends one
            for m in parser.parse_buffer(bytes(data)) or []:
                if m.get_type() not in ("HEARTBEAT", "BAD_DATA"):
                    self._send(m.get_msgbuf(), m.get_type())

        self._sub = sdk.subscribe_raw_bytes_to_be_sent(out)
        if int(sdk.add_any_connection("raw://")) != 0:
            sdk.destroy()
            return
        ps = ParamServer(sdk.server_component_by_id(component_id))
        for name, value in self.params.items():
            ps.provide_param_float(name, float(value))
        self._sdk, self._ps, self.param_backend = sdk, ps, "mavsdk"

    def refresh_params(self) -> dict[str, float]:
        """Read back the parameter values (MAVSDK holds them when it serves them); returns them."""
        if self._ps is not None:
            for name in list(self.params):
                try:
                    self.params[name] = float(self._ps.retrieve_param_float(name))
                except Exception:
                    pass
        return self.params

    # --- sending ------------------------------------------------------------------------------

    def _send(self, packet: bytes, kind: str = "") -> None:
        with self._lock:
            self.send(bytes(packet))
            self.sent[kind] = self.sent.get(kind, 0) + 1

    def _boot_ms(self) -> int:
        return int((self.clock() - self._t0) * 1000) & 0xFFFFFFFF

    def heartbeat(self) -> None:
        """Send one HEARTBEAT (MAV_TYPE_ONBOARD_CONTROLLER, MAV_AUTOPILOT_INVALID, active)."""
        self._send(self.mav.heartbeat_encode(_MAV_TYPE_ONBOARD_CONTROLLER, _MAV_AUTOPILOT_INVALID, 0, 0,
                                             _MAV_STATE_ACTIVE).pack(self.mav), "HEARTBEAT")

    def statustext(self, text: str, severity: int = 6) -> int:
        """Send ``text`` as STATUSTEXT chunks; returns the number of chunks.

        Args:
            text: any length (ASCII).
            severity: MAV_SEVERITY (0 emergency .. 4 warning .. 6 info .. 7 debug).
        """
        chunks = chunk_text(text)
        tid = 0
        if len(chunks) > 1:
            self._text_id = self._text_id % 65535 + 1
            tid = self._text_id
        for seq, c in enumerate(chunks):
            self._send(self.mav.statustext_encode(severity, c, tid, seq).pack(self.mav), "STATUSTEXT")
        return len(chunks)

    def named_float(self, name: str, value: float) -> None:
        """Send one NAMED_VALUE_FLOAT (``name`` at most 10 characters)."""
        if len(name) > 10:
            raise ValueError(f"NAMED_VALUE_FLOAT name '{name}' is longer than 10 characters")
        self._send(self.mav.named_value_float_encode(self._boot_ms(), name.encode(), float(value)).pack(self.mav),
                   "NAMED_VALUE_FLOAT")

    def confidence(self, scores: dict[str, float]) -> None:
        """Send each coefficient's confidence score (0..1) as ``CONF_<coef>``."""
        for coef, v in scores.items():
            self.named_float(conf_name(coef), v)

    # --- receiving and schedule ---------------------------------------------------------------

    def handle(self, msg) -> None:
        """Hand one received message to the parameter server (others are ignored)."""
        kind = msg.get_type()
        if kind not in _PARAM_MSGS:
            return
        if kind == "HEARTBEAT" and msg.autopilot != _MAV_AUTOPILOT_INVALID:
            return   # only ground stations' heartbeats: MAVSDK would otherwise query the autopilot
        if self._sdk is not None:
            self._sdk.pass_received_raw_bytes(bytes(msg.get_msgbuf()))
        elif kind != "HEARTBEAT":
            self._table.handle(msg)

    def tick(self) -> None:
        """Periodic work: the 1 Hz heartbeat."""
        now = self.clock()
        if now - self._last_hb >= 1.0:
            self._last_hb = now
            self.heartbeat()

    def close(self) -> None:
        if self._sdk is not None:
            self.refresh_params()
            self._sdk.destroy()
            self._sdk = self._ps = None
