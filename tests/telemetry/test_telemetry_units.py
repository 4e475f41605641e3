"""Unit conversions of each MAVLink message, checked against hand-computed SI values."""

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink
from tlog_factory import TlogWriter, heartbeat, write_flight

from gcs_sysid.telemetry import read_log

G0 = 9.80665


def _one_of_each(path):
    w = TlogWriter()
    w.add(0.0, heartbeat())
    for i in range(5):
        ms, us, ts = 20_000 + 20 * i, (20_000 + 20 * i) * 1000, 0.01 + 0.02 * i
        for m in [
            mavlink.MAVLink_attitude_message(ms, 0.1, -0.2, 3.0, 0.01, 0.02, 0.03),
            mavlink.MAVLink_raw_imu_message(us, 100, -50, -1000, 10, 20, -30, 0, 0, 0, 0, 0),
            mavlink.MAVLink_scaled_imu2_message(ms, 200, 0, -1000, 0, 0, 5, 0, 0, 0, 0),
            mavlink.MAVLink_highres_imu_message(us, 0.5, 0.25, -9.5, 0.1, 0.2, 0.3, 0, 0, 0, 0, 0, 0, 0, 0, 0),
            mavlink.MAVLink_vfr_hud_message(18.0, 20.0, 90, 55, 100.0, 1.5),
            mavlink.MAVLink_scaled_pressure_message(ms, 1000.0, 2.0, 2150),
            mavlink.MAVLink_global_position_int_message(ms, -353632622, 1491652374, 584090, 100000,
                                                        1500, -200, 50, 9000),
            mavlink.MAVLink_local_position_ned_message(ms, 1.0, 2.0, -3.0, 4.0, 5.0, 6.0),
            mavlink.MAVLink_servo_output_raw_message(us, 0, 1500, 1400, 1100, 1600, 0, 0, 0, 0,
                                                     1000, 0, 0, 0, 0, 0, 0, 2000),
            mavlink.MAVLink_rc_channels_message(ms, 8, *([1500] * 8 + [65535] * 10), 200),
            mavlink.MAVLink_aoa_ssa_message(us, 5.0, -2.0),
            mavlink.MAVLink_wind_message(90.0, 5.0, 0.0),
            mavlink.MAVLink_simstate_message(0.1, 0.2, 0.3, 1.0, 2.0, 3.0, 0.4, 0.5, 0.6, -353632622, 1491652374),
        ]:
            w.add(ts, m)
    w.add(0.2, mavlink.MAVLink_param_value_message(b"ARSPD_RATIO", 2.0, 9, 1, 0))
    w.add(0.2, mavlink.MAVLink_statustext_message(6, b"hello world"))
    return read_log(w.write(path / "all.tlog"))


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    return _one_of_each(tmp_path_factory.mktemp("units"))


def test_imu_preference_and_scaling(flight):
    assert flight["imu"].source == "HIGHRES_IMU"  # SI already
    np.testing.assert_allclose(flight["imu"]["az"], -9.5)
    np.testing.assert_allclose(flight["imu"]["r"], 0.3, rtol=1e-6)
    raw = flight["imu2"]  # RAW_IMU on ArduPilot: milli-g and mrad/s
    assert raw.source == "RAW_IMU"
    np.testing.assert_allclose(raw["ax"], 0.1 * G0)
    np.testing.assert_allclose(raw["az"], -G0)
    np.testing.assert_allclose([raw["p"][0], raw["q"][0], raw["r"][0]], [0.01, 0.02, -0.03])
    assert flight["imu3"].source == "SCALED_IMU2"
    np.testing.assert_allclose(flight["imu3"]["r"], 0.005)


def test_attitude_time_and_rates(flight):
    att = flight["attitude"]
    np.testing.assert_allclose(att.t, 20.0 + 0.02 * np.arange(5))
    np.testing.assert_allclose(att["pitch"], -0.2, rtol=1e-6)
    np.testing.assert_allclose(att["r"], 0.03, rtol=1e-6)


def test_air_data_and_position(flight):
    p = flight["pressure"]
    np.testing.assert_allclose(p["press_abs"], 100000.0)
    np.testing.assert_allclose(p["temperature"], 21.5 + 273.15)
    a = flight["airspeed"]
    np.testing.assert_allclose(a["diff_pressure"], 200.0)
    np.testing.assert_allclose(a["eas"], np.sqrt(2.0 * 200.0))  # ARSPD_RATIO = 2.0 in the log
    assert flight.vehicle["airspeed_ratio_source"] == "ARSPD_RATIO parameter"
    g = flight["gps"]
    np.testing.assert_allclose(g["lat"], np.radians(-35.3632622))
    np.testing.assert_allclose(g["lon"], np.radians(149.1652374))
    np.testing.assert_allclose(g["alt"], 584.09)
    np.testing.assert_allclose([g["vn"][0], g["ve"][0], g["vd"][0]], [15.0, -2.0, 0.5])
    lp = flight["local_position"]
    np.testing.assert_allclose([lp["z"][0], lp["vz"][0]], [-3.0, 6.0])
    hud = flight["vfr_hud"]
    np.testing.assert_allclose([hud["airspeed"][0], hud["throttle"][0], hud["heading"][0]],
                               [18.0, 0.55, np.pi / 2])


def test_controls_aoa_wind_truth(flight):
    s = flight["servo"]
    assert s["pwm1"][0] == 1500 and s["pwm9"][0] == 1000 and s["pwm16"][0] == 2000
    rc = flight["rc"]
    assert rc["pwm8"][0] == 1500 and np.isnan(rc["pwm9"][0])
    np.testing.assert_allclose([flight["aoa_ssa"]["alpha"][0], flight["aoa_ssa"]["beta"][0]],
                               np.radians([5.0, -2.0]), rtol=1e-6)
    w = flight["wind"]  # from the east (90 deg) at 5 m/s: air mass moves west
    np.testing.assert_allclose([w["wn"][0], w["we"][0]], [0.0, -5.0], atol=1e-9)
    st = flight["sim_truth"]
    np.testing.assert_allclose([st["yaw"][0], st["az"][0], st["lat"][0]], [0.3, 3.0, np.radians(-35.3632622)],
                               rtol=1e-6)


def test_params_text_vehicle_summaries(flight):
    assert flight.params["ARSPD_RATIO"] == 2.0
    assert flight.statustext[0][1] == "hello world"
    assert 20.0 < flight.statustext[0][0] < 20.2  # placed on the vehicle clock
    assert flight.vehicle["mav_type"] == "MAV_TYPE_FIXED_WING"
    assert flight.vehicle["autopilot"] == "MAV_AUTOPILOT_ARDUPILOTMEGA"
    assert flight.summaries["attitude"].count == 5
    np.testing.assert_allclose(flight.summaries["attitude"].rate_hz, 50.0)
    assert flight.messages["ATTITUDE"] == 5 and flight.format == "tlog"


def test_untimed_messages_follow_the_vehicle_clock(tmp_path):
    f = read_log(write_flight(tmp_path / "f.tlog", n=50, boot0=100.0, log0=7.0))
    # VFR_HUD has no clock: placed through the offset between log clock and the latest timed message
    np.testing.assert_allclose(f["vfr_hud"].t, f["attitude"].t + 3e-4, atol=1e-6)
    assert f["airspeed"].source == "SCALED_PRESSURE"
    assert f.vehicle["airspeed_ratio_source"] == "fitted to VFR_HUD airspeed"
    np.testing.assert_allclose(f["airspeed"]["eas"], 18.0, rtol=1e-6)


def test_pixhawk_raw_imu_is_not_scaled(tmp_path):
    w = TlogWriter()
    w.add(0.0, heartbeat(autopilot=mavlink.MAV_AUTOPILOT_PX4))
    for i in range(3):
        w.add(0.01 * i, mavlink.MAVLink_raw_imu_message(1000 * i, 100, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0))
        w.add(0.01 * i, mavlink.MAVLink_attitude_message(i, 0, 0, 0, 0, 0, 0))
    f = read_log(w.write(tmp_path / "px4.tlog"))
    assert "imu" not in f.streams
    assert any("RAW_IMU" in x and "skipped" in x for x in f.warnings)
