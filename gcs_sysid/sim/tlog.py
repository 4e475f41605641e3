"""Write a simulated flight as a telemetry log (.tlog) with ArduPlane's message set at sysid rates.

A tlog is a sequence of records: an 8-byte big-endian timestamp (microseconds
since the Unix epoch, when the ground station received the packet) followed by
one MAVLink packet (here MAVLink 2, encoded by pymavlink's ``ardupilotmega``
dialect). The log clock is ``epoch + vehicle time``; message time fields
(``time_boot_ms``, ``time_usec``) carry the vehicle time.

Messages, units as ArduPilot sends them (``GCS_Common.cpp`` / ``GCS_Plane.cpp``):
HEARTBEAT 1 Hz (fixed wing, ArduPilotMega autopilot, armed, FBWA), ATTITUDE and
RAW_IMU (accelerations in mg, rates in mrad/s, field in mgauss, integers) and
SERVO_OUTPUT_RAW (PWM of the *commanded* outputs: the autopilot logs what it
commands; actuator delay and lag act after it) at 50 Hz, SCALED_PRESSURE (hPa,
cdegC), GLOBAL_POSITION_INT (degE7, mm, cm/s, cdeg) and LOCAL_POSITION_NED at
25 Hz, VFR_HUD (airspeed = EAS, as ArduPilot), RC_CHANNELS and AOA_SSA (the
autopilot's estimate, deg) at 10 Hz, WIND (direction the wind blows *from*, deg)
at 2 Hz, NAV_CONTROLLER_OUTPUT (the autopilot's bank and pitch demands, deg, altitude error m
and airspeed error times 100, as ArduPlane sends it) at the VFR_HUD rate, PARAM_VALUE for the
stream-rate parameters and a STATUSTEXT at the start.
Rates are those of :data:`gcs_sysid.sim.sensors.STREAM_RATES_HZ`, as whole
decimations of the plan rate.
"""

from __future__ import annotations

import bisect
import math
import struct
from pathlib import Path
from typing import Mapping

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from ..airframe import Airframe
from .effects import CONTROL_NAMES
from .sensors import STREAM_RATES_HZ

__all__ = ["write_tlog", "LOG_EPOCH_S"]

#: Wall-clock time (Unix s) of vehicle time 0 in written logs.
LOG_EPOCH_S = 1714557600.0          # 2024-05-01 10:00:00 UTC
_G = 9.80665


class _Sink:
    """File wrapper given to pymavlink: each packet is preceded by its tlog timestamp."""

    def __init__(self, f):
        self.f, self.stamp = f, 0

    def write(self, buf: bytes) -> None:
        self.f.write(struct.pack(">Q", self.stamp) + bytes(buf))


def _i(x, lo=-32768, hi=32767) -> int:
    return int(min(max(round(float(x)), lo), hi))


def write_tlog(result, path: str | Path, airframe: Airframe | None = None, system_id: int = 1,
               rates_hz: Mapping[str, float] | None = None) -> int:
    """Write ``result`` (a :class:`gcs_sysid.sim.flight.SimResult`) as a .tlog.

    Args:
        result: the simulated flight.
        path: output file.
        airframe: airframe whose servo map turns commands into PWM (default ``result.airframe``).
        system_id: MAVLink system id.
        rates_hz: stream -> rate overriding :data:`~gcs_sysid.sim.sensors.STREAM_RATES_HZ` (the
            sensor streams of ``result`` must have been sampled at the same decimations; the
            JSBSim harness in ``benchmarks/`` sends AOA_SSA at 50 Hz this way).

    Returns:
        number of packets written.
    """
    rates = {**STREAM_RATES_HZ, **(rates_hz or {})}

    def decimation(rate_hz: float, stream: str) -> int:
        return max(1, int(round(rate_hz / rates[stream])))

    af = airframe or result.airframe
    t = result.t
    T = len(t)
    rate = result.rate_hz
    sen = result.sensors
    pwm = af.pwm_from_controls({c: result.commands[c] for c in CONTROL_NAMES})
    thr_ch = af.throttle.channel if af.throttle else None
    events: list[tuple[float, int, str, int]] = []

    def add(name: str, stream: str, prio: int) -> None:
        for j, k in enumerate(range(0, T, decimation(rate, stream))):
            events.append((float(t[k]), prio, name, j if stream not in ("servo", "rc", "vfr_hud", "heartbeat") else k))

    add("HEARTBEAT", "heartbeat", 0)
    add("ATTITUDE", "attitude", 1)
    add("RAW_IMU", "imu", 2)
    add("SERVO_OUTPUT_RAW", "servo", 3)
    add("SCALED_PRESSURE", "pressure", 4)
    add("GLOBAL_POSITION_INT", "gps", 5)
    add("LOCAL_POSITION_NED", "gps", 6)
    add("VFR_HUD", "vfr_hud", 7)
    add("RC_CHANNELS", "rc", 8)
    add("AOA_SSA", "aoa_ssa", 9)
    add("WIND", "wind", 10)
    if result.demand:
        add("NAV_CONTROLLER_OUTPUT", "vfr_hud", 11)
    events.sort()

    att, imu, prs, gps, lpn, aoa, wnd = (sen[k] for k in ("attitude", "imu", "pressure", "gps", "local_position",
                                                           "aoa_ssa", "wind"))
    eas = sen["airspeed"]["eas"]
    gps_dec = decimation(rate, "gps")
    sp_start = [sp.start for sp in result.plan.setpoints] if result.demand else []   # for NAV_CONTROLLER_OUTPUT
    n = 0
    with open(path, "wb") as f:
        sink = _Sink(f)
        mav = mavlink.MAVLink(sink, srcSystem=system_id, srcComponent=1)

        def send(ts: float, msg) -> None:
            nonlocal n
            sink.stamp = int(round((LOG_EPOCH_S + ts) * 1e6))
            mav.send(msg)
            n += 1

        t0 = float(t[0])
        base_mode = (mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | mavlink.MAV_MODE_FLAG_SAFETY_ARMED
                     | mavlink.MAV_MODE_FLAG_STABILIZE_ENABLED)        # custom mode 5 = FBWA
        send(t0, mav.statustext_encode(mavlink.MAV_SEVERITY_INFO,
                                       f"gcs-sysid sim: {result.plan.name} seed {result.seed}"[:50].encode()))
        params = {"SCHED_LOOP_RATE": 300.0, "SR0_RAW_SENS": 50.0, "SR0_EXTRA1": 50.0, "SR0_EXTRA2": 10.0,
                  "SR0_EXTRA3": 2.0, "SR0_POSITION": 25.0, "SR0_RC_CHAN": 10.0, "ARSPD_USE": 1.0,
                  "AIRSPEED_CRUISE": float(result.plan.setpoints[0].airspeed)}
        for i, (k, v) in enumerate(params.items()):
            send(t0, mav.param_value_encode(k.encode(), v, mavlink.MAV_PARAM_TYPE_REAL32, len(params), i))
        for ts, _, name, j in events:
            ms = int(round(ts * 1000))
            us = int(round(ts * 1e6))
            if name == "HEARTBEAT":
                msg = mav.heartbeat_encode(mavlink.MAV_TYPE_FIXED_WING, mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA, base_mode,
                                           5, mavlink.MAV_STATE_ACTIVE)
            elif name == "ATTITUDE":
                msg = mav.attitude_encode(ms, att["roll"][j], att["pitch"][j], att["yaw"][j],
                                          att["p"][j], att["q"][j], att["r"][j])
            elif name == "RAW_IMU":
                msg = mav.raw_imu_encode(us, _i(imu["ax"][j] * 1000 / _G), _i(imu["ay"][j] * 1000 / _G),
                                         _i(imu["az"][j] * 1000 / _G), _i(imu["p"][j] * 1000), _i(imu["q"][j] * 1000),
                                         _i(imu["r"][j] * 1000), _i(imu["mx"][j] * 1000), _i(imu["my"][j] * 1000),
                                         _i(imu["mz"][j] * 1000), 0, 3500)
            elif name == "SERVO_OUTPUT_RAW":
                s = [_i(pwm[c][j], 0, 65535) if c in pwm else 0 for c in range(1, 17)]
                msg = mav.servo_output_raw_encode(us % (1 << 32), 0, *s)
            elif name == "SCALED_PRESSURE":
                msg = mav.scaled_pressure_encode(ms, prs["press_abs"][j] / 100.0, prs["diff_pressure"][j] / 100.0,
                                                 _i((prs["temperature"][j] - 273.15) * 100), 0)
            elif name == "GLOBAL_POSITION_INT":
                hdg = math.degrees(math.atan2(gps["ve"][j], gps["vn"][j])) % 360.0
                i32 = (-2**31, 2**31 - 1)
                msg = mav.global_position_int_encode(
                    ms, _i(math.degrees(gps["lat"][j]) * 1e7, *i32), _i(math.degrees(gps["lon"][j]) * 1e7, *i32),
                    _i(gps["alt"][j] * 1000, *i32), _i(gps["relative_alt"][j] * 1000, *i32), _i(gps["vn"][j] * 100),
                    _i(gps["ve"][j] * 100), _i(gps["vd"][j] * 100), _i(hdg * 100, 0, 35999))
            elif name == "LOCAL_POSITION_NED":
                msg = mav.local_position_ned_encode(ms, lpn["x"][j], lpn["y"][j], lpn["z"][j], lpn["vx"][j],
                                                    lpn["vy"][j], lpn["vz"][j])
            elif name == "VFR_HUD":
                g = min(j // gps_dec, len(gps["t"]) - 1)
                yaw = math.degrees(result.truth["psi"][j]) % 360.0
                msg = mav.vfr_hud_encode(float(eas[j]), float(math.hypot(gps["vn"][g], gps["ve"][g])), _i(yaw, 0, 359),
                                         _i(100 * result.commands["delta_t"][j], 0, 100), float(gps["alt"][g]),
                                         float(-gps["vd"][g]))
            elif name == "RC_CHANNELS":
                ch = [1500] * 18
                ch[7] = 1800
                if thr_ch:
                    ch[thr_ch - 1] = _i(pwm[thr_ch][j], 0, 65535)
                msg = mav.rc_channels_encode(ms, 16, *ch, 255)
            elif name == "NAV_CONTROLLER_OUTPUT":
                dem = result.demand
                sp = result.plan.setpoints[max(0, bisect.bisect_right(sp_start, ts) - 1)]
                hdg = _i(math.degrees(sp.heading) % 360.0, 0, 359)
                msg = mav.nav_controller_output_encode(math.degrees(dem["roll"][j]), math.degrees(dem["pitch"][j]),
                                                       hdg, hdg, 0, float(dem["alt_error"][j]),
                                                       float(100.0 * dem["aspd_error"][j]), 0.0)
            elif name == "AOA_SSA":
                msg = mav.aoa_ssa_encode(us, math.degrees(aoa["alpha"][j]), math.degrees(aoa["beta"][j]))
            else:  # WIND
                wn, we = float(wnd["wn"][j]), float(wnd["we"][j])
                msg = mav.wind_encode(math.degrees(math.atan2(-we, -wn)) % 360.0, math.hypot(wn, we),
                                      float(wnd["wd"][j]))
            send(ts, msg)
    return n
