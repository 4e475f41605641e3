"""MAVLink messages -> canonical SI streams (the table in docs/telemetry.md).

Each entry of :data:`SPECS` names the fields collected from one message type (the first is its
clock, if any) and a converter from wire units to the canonical stream's SI fields. Units follow the
MAVLink common and ardupilotmega message definitions (https://mavlink.io/en/messages/common.html).

ArduPilot fills RAW_IMU with the same scaled values as SCALED_IMU (accelerations in milli-g, rates in
mrad/s; ArduPilot ``GCS_MAVLINK::send_raw_imu``), not ADC counts, so RAW_IMU is scaled as SCALED_IMU
when the autopilot is ArduPilot (or unknown); from other autopilots RAW_IMU is skipped with a warning.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["G0", "RHO0", "MsgSpec", "SPECS", "IMU_PREFERENCE", "TEXT_FIELDS", "wanted_fields"]

G0 = 9.80665
"""Standard gravity, m/s^2 (1 g; milli-g -> m/s^2 is G0 / 1000)."""
RHO0 = 1.225
"""Sea-level standard air density, kg/m^3 (ISA), used for equivalent airspeed."""

_D2R = np.pi / 180.0
_E7 = 1e-7 * _D2R  # degE7 -> rad


@dataclass(frozen=True)
class MsgSpec:
    """How one message type becomes (part of) a stream.

    Attributes:
        stream: canonical stream name (IMU messages are renamed imu, imu2 ... later).
        fields: message fields to collect, wire names, in order.
        clock: ``"ms"`` (time_boot_ms, first field), ``"us"`` (64-bit time_usec, first field),
            ``"us32"`` (32-bit time_usec that wraps), or None (placed by the log clock).
        convert: (N, len(fields)) float array -> dict of SI field arrays.
    """

    stream: str
    fields: tuple[str, ...]
    clock: str | None
    convert: Callable[[np.ndarray], dict[str, np.ndarray]]


def _scaled_imu(v: np.ndarray) -> dict[str, np.ndarray]:
    a, w = G0 / 1000.0, 1e-3  # milli-g -> m/s^2, mrad/s -> rad/s
    return {"ax": v[:, 1] * a, "ay": v[:, 2] * a, "az": v[:, 3] * a,
            "p": v[:, 4] * w, "q": v[:, 5] * w, "r": v[:, 6] * w}


def _highres_imu(v: np.ndarray) -> dict[str, np.ndarray]:
    return {"ax": v[:, 1], "ay": v[:, 2], "az": v[:, 3], "p": v[:, 4], "q": v[:, 5], "r": v[:, 6]}


def _attitude(v: np.ndarray) -> dict[str, np.ndarray]:
    return {"roll": v[:, 1], "pitch": v[:, 2], "yaw": v[:, 3], "p": v[:, 4], "q": v[:, 5], "r": v[:, 6]}


def _vfr_hud(v: np.ndarray) -> dict[str, np.ndarray]:
    return {"airspeed": v[:, 0], "groundspeed": v[:, 1], "alt": v[:, 2], "climb": v[:, 3],
            "throttle": v[:, 4] / 100.0, "heading": v[:, 5] * _D2R}


def _scaled_pressure(v: np.ndarray) -> dict[str, np.ndarray]:
    # hPa -> Pa, cdegC -> K
    return {"press_abs": v[:, 1] * 100.0, "diff_pressure": v[:, 2] * 100.0,
            "temperature": v[:, 3] / 100.0 + 273.15}


def _global_position(v: np.ndarray) -> dict[str, np.ndarray]:
    # degE7 -> rad, mm -> m, cm/s -> m/s (vz positive down)
    return {"lat": v[:, 1] * _E7, "lon": v[:, 2] * _E7, "alt": v[:, 3] * 1e-3,
            "relative_alt": v[:, 4] * 1e-3, "vn": v[:, 5] * 0.01, "ve": v[:, 6] * 0.01, "vd": v[:, 7] * 0.01}


def _local_position(v: np.ndarray) -> dict[str, np.ndarray]:
    return {k: v[:, i + 1] for i, k in enumerate(("x", "y", "z", "vx", "vy", "vz"))}


def _servo(v: np.ndarray) -> dict[str, np.ndarray]:
    # column 1 is port; channels of port p are servo 8p+1 .. (only port 0 carries 1..16 in MAVLink 2)
    return {f"pwm{i}": v[:, i + 1] for i in range(1, 17)}


def _rc(v: np.ndarray) -> dict[str, np.ndarray]:
    out = {}
    for i in range(1, 19):
        ch = v[:, i].copy()
        ch[ch == 65535] = np.nan  # UINT16_MAX: channel not present
        out[f"pwm{i}"] = ch
    return out


def _aoa_ssa(v: np.ndarray) -> dict[str, np.ndarray]:
    return {"alpha": v[:, 1] * _D2R, "beta": v[:, 2] * _D2R}


def _wind(v: np.ndarray) -> dict[str, np.ndarray]:
    # direction: where the wind blows FROM (deg); speed: "wind speed in ground plane" (MAVLink WIND);
    # speed_z: vertical wind, NED down (ArduPilot sends atan2(-wind.y, -wind.x), |wind|, wind.z, with
    # wind.z = 0 from its estimators, GCS_MAVLINK::send_wind). Air-mass velocity over ground:
    d = v[:, 0] * _D2R
    hs = v[:, 1]
    return {"wn": -hs * np.cos(d), "we": -hs * np.sin(d), "wd": v[:, 2]}


def _simstate(v: np.ndarray) -> dict[str, np.ndarray]:
    return {"roll": v[:, 0], "pitch": v[:, 1], "yaw": v[:, 2], "ax": v[:, 3], "ay": v[:, 4], "az": v[:, 5],
            "p": v[:, 6], "q": v[:, 7], "r": v[:, 8], "lat": v[:, 9] * _E7, "lon": v[:, 10] * _E7}


def _nav_controller(v: np.ndarray) -> dict[str, np.ndarray]:
    # deg -> rad; alt_error m (target minus current); aspd_error: ArduPlane sends the airspeed error
    # (target minus current) times 100, i.e. cm/s, although the message definition says m/s
    # (GCS_Plane.cpp send_nav_controller_output) -> m/s
    return {"roll_demand": v[:, 0] * _D2R, "pitch_demand": v[:, 1] * _D2R, "alt_error": v[:, 2],
            "aspd_error": v[:, 3] * 0.01}


def _heartbeat(v: np.ndarray) -> dict[str, np.ndarray]:
    # base_mode bit 7 (128): MAV_MODE_FLAG_SAFETY_ARMED
    return {"custom_mode": v[:, 3], "armed": ((v[:, 2].astype(np.int64) & 128) > 0).astype(float)}


_IMU_FIELDS = ("xacc", "yacc", "zacc", "xgyro", "ygyro", "zgyro")

SPECS: dict[str, MsgSpec] = {
    "HIGHRES_IMU": MsgSpec("imu", ("time_usec",) + _IMU_FIELDS, "us", _highres_imu),
    "SCALED_IMU": MsgSpec("imu", ("time_boot_ms",) + _IMU_FIELDS, "ms", _scaled_imu),
    "RAW_IMU": MsgSpec("imu", ("time_usec",) + _IMU_FIELDS, "us", _scaled_imu),
    "SCALED_IMU2": MsgSpec("imu", ("time_boot_ms",) + _IMU_FIELDS, "ms", _scaled_imu),
    "SCALED_IMU3": MsgSpec("imu", ("time_boot_ms",) + _IMU_FIELDS, "ms", _scaled_imu),
    "ATTITUDE": MsgSpec("attitude", ("time_boot_ms", "roll", "pitch", "yaw", "rollspeed", "pitchspeed",
                                     "yawspeed"), "ms", _attitude),
    "VFR_HUD": MsgSpec("vfr_hud", ("airspeed", "groundspeed", "alt", "climb", "throttle", "heading"),
                       None, _vfr_hud),
    "SCALED_PRESSURE": MsgSpec("pressure", ("time_boot_ms", "press_abs", "press_diff", "temperature"),
                               "ms", _scaled_pressure),
    "GLOBAL_POSITION_INT": MsgSpec("gps", ("time_boot_ms", "lat", "lon", "alt", "relative_alt", "vx", "vy",
                                           "vz"), "ms", _global_position),
    "LOCAL_POSITION_NED": MsgSpec("local_position", ("time_boot_ms", "x", "y", "z", "vx", "vy", "vz"),
                                  "ms", _local_position),
    "SERVO_OUTPUT_RAW": MsgSpec("servo", ("time_usec", "port") + tuple(f"servo{i}_raw" for i in range(1, 17)),
                                "us32", _servo),
    "RC_CHANNELS": MsgSpec("rc", ("time_boot_ms",) + tuple(f"chan{i}_raw" for i in range(1, 19)), "ms", _rc),
    "AOA_SSA": MsgSpec("aoa_ssa", ("time_usec", "AOA", "SSA"), "us", _aoa_ssa),
    "WIND": MsgSpec("wind", ("direction", "speed", "speed_z"), None, _wind),
    "SIMSTATE": MsgSpec("sim_truth", ("roll", "pitch", "yaw", "xacc", "yacc", "zacc", "xgyro", "ygyro",
                                      "zgyro", "lat", "lng"), None, _simstate),
    "NAV_CONTROLLER_OUTPUT": MsgSpec("nav", ("nav_roll", "nav_pitch", "alt_error", "aspd_error"), None,
                                     _nav_controller),
    "HEARTBEAT": MsgSpec("mode", ("type", "autopilot", "base_mode", "custom_mode"), None, _heartbeat),
}

IMU_PREFERENCE = ("HIGHRES_IMU", "SCALED_IMU", "RAW_IMU", "SCALED_IMU2", "SCALED_IMU3")
"""Order in which IMU messages become ``imu``, ``imu2``, ``imu3`` ..."""

TEXT_FIELDS = {"PARAM_VALUE": ("param_id", "param_value"), "STATUSTEXT": ("severity", "text")}


def wanted_fields() -> dict[str, tuple[str, ...]]:
    """Message name -> fields to collect, for :func:`gcs_sysid.telemetry.tlog_scan.scan_tlog`."""
    out = {name: spec.fields for name, spec in SPECS.items()}
    out.update(TEXT_FIELDS)
    return out
