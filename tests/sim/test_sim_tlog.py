"""The tlog writer: real MAVLink 2 bytes decoded by pymavlink, ArduPilot rates and units, sensor biases visible."""

import math
from collections import defaultdict

import numpy as np
import pytest
import tomli_w
from conftest import ROOT, short_plan_doc
from pymavlink import mavutil

from gcs_sysid.sim import load_plan, run_simulate, write_tlog
from gcs_sysid.sim.environment import RHO0
from gcs_sysid.sim.tlog import LOG_EPOCH_S


def _decode(path):
    log = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
    msgs = defaultdict(list)
    while True:
        m = log.recv_match()
        if m is None:
            break
        msgs[m.get_type()].append((m._timestamp, m))
    return msgs


@pytest.fixture(scope="module")
def decoded(biased_flight, airframe, tmp_path_factory):
    path = tmp_path_factory.mktemp("tlog") / "flight.tlog"
    n = write_tlog(biased_flight, path, airframe)
    msgs = _decode(path)
    assert sum(len(v) for v in msgs.values()) == n and "BAD_DATA" not in msgs
    return msgs


def test_message_set_and_rates(decoded):
    expect = {"ATTITUDE": 50, "RAW_IMU": 50, "SERVO_OUTPUT_RAW": 50, "SCALED_PRESSURE": 25,
              "GLOBAL_POSITION_INT": 25, "LOCAL_POSITION_NED": 25, "VFR_HUD": 10, "RC_CHANNELS": 10,
              "AOA_SSA": 10, "WIND": 2, "HEARTBEAT": 1}
    for name, rate in expect.items():
        assert len(decoded[name]) == 20 * rate, name
        ts = np.array([t for t, _ in decoded[name]])
        assert np.median(np.diff(ts)) == pytest.approx(1.0 / rate, rel=1e-3), name
    hb = decoded["HEARTBEAT"][0][1]
    assert hb.type == mavutil.mavlink.MAV_TYPE_FIXED_WING
    assert hb.autopilot == mavutil.mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA
    assert "gcs-sysid sim" in decoded["STATUSTEXT"][0][1].text
    assert {m.param_id for _, m in decoded["PARAM_VALUE"]} >= {"SR0_RAW_SENS", "SR0_EXTRA1"}
    for name in ("ATTITUDE", "GLOBAL_POSITION_INT", "SCALED_PRESSURE"):
        for ts, m in decoded[name][:5]:
            assert ts - LOG_EPOCH_S == pytest.approx(m.time_boot_ms / 1000.0, abs=1e-6)
    t_imu = np.array([m.time_usec for _, m in decoded["RAW_IMU"]]) / 1e6
    assert t_imu[0] == pytest.approx(30.0)


def test_units_and_biases_in_the_log(decoded, biased_flight, airframe):
    res = biased_flight
    tr = res.truth
    imu = decoded["RAW_IMU"]
    p_log = np.array([m.xgyro for _, m in imu]) / 1000.0
    assert np.mean(p_log - tr["p"]) == pytest.approx(0.01, abs=0.001)          # gyro_x bias, mrad/s integers
    az = np.array([m.zacc for _, m in imu]) * 9.80665 / 1000.0
    assert np.mean(az) == pytest.approx(np.mean(res.sensors["imu"]["az"]), abs=0.01)
    assert -10.5 < np.mean(az) < -9.0                                          # ~ -1 g in mg, level flight
    att = decoded["ATTITUDE"]
    assert np.allclose([m.pitch for _, m in att], tr["theta"], atol=0.02)
    servo = {c: np.array([getattr(m, f"servo{c}_raw") for _, m in decoded["SERVO_OUTPUT_RAW"]]) for c in (1, 2, 3, 4)}
    ctl = airframe.controls_from_pwm(servo)
    for c in ("delta_e", "delta_a", "delta_r"):
        assert np.allclose(ctl[c], res.commands[c], atol=math.radians(0.032)), c  # commanded; 1 us PWM = 0.0625 deg
    assert np.allclose(ctl["delta_t"], res.commands["delta_t"], atol=0.001)
    hud = decoded["VFR_HUD"]
    k = np.arange(0, len(res.t), 5)
    assert np.allclose([m.airspeed for _, m in hud], res.sensors["airspeed"]["eas"][k], atol=1e-4)
    dp = np.array([m.press_diff for _, m in decoded["SCALED_PRESSURE"]]) * 100.0
    eas_p = np.sqrt(2 * dp / RHO0)
    assert np.allclose(eas_p, res.sensors["airspeed"]["eas"][::2], atol=1e-3)
    assert np.mean(eas_p) > np.mean(tr["V"][::2] * np.sqrt(tr["rho"][::2] / RHO0)) + 2.5   # scale 1.1 and bias 1.5
    aoa = np.radians([m.AOA for _, m in decoded["AOA_SSA"]])
    assert np.mean(aoa - tr["alpha"][::5]) == pytest.approx(0.05, abs=0.005)
    gpi = decoded["GLOBAL_POSITION_INT"]
    assert np.allclose(np.array([m.vx for _, m in gpi]) / 100.0, tr["vn"][::2], atol=0.4)
    assert np.allclose(np.array([m.alt for _, m in gpi]) / 1000.0, tr["alt"][::2], atol=2.0)
    assert np.allclose(np.array([m.relative_alt for _, m in gpi]) / 1000.0, tr["alt"][::2] - 50.0, atol=2.0)
    wind = decoded["WIND"]
    assert np.median([m.direction for _, m in wind]) == pytest.approx(200.0, abs=15.0)
    assert np.median([m.speed for _, m in wind]) == pytest.approx(3.0, abs=1.0)


def test_run_simulate_from_files(tmp_path, airframe):
    plan = tmp_path / "plan.toml"
    plan.write_text(tomli_w.dumps(short_plan_doc(effects={"delay_s": {"delta_e": 0.04}})))
    out = tmp_path / "f.tlog"
    res = run_simulate(ROOT / "data" / "airframes" / "sim-trainer.toml", ROOT / "data" / "models" / "sim-trainer.toml",
                       plan, out, seed=5, truth_path=tmp_path / "truth.npz")
    assert res.seed == 5 and res.effects.delay[0] == 0.04 and out.stat().st_size > 20_000
    z = np.load(tmp_path / "truth.npz")
    assert z["X"].shape == (1000, 10) and np.allclose(z["alpha"], res.truth["alpha"])
    assert "delay:delta_e" in str(z["meta"])


def test_shipped_plan_and_flight():
    plan = load_plan(ROOT / "data" / "plans" / "sysid-trainer.toml")
    assert 200 <= plan.duration <= 300 and len({s.airspeed for s in plan.setpoints}) >= 2
    t_test = plan.start_time + 0.8 * plan.duration
    late = {c for m in plan.maneuvers if m.start >= t_test for c in m.controls}
    assert {"delta_e", "delta_a", "delta_r"} <= late
    flight = ROOT / "data" / "flights" / "sim-trainer-sysid.tlog"
    assert flight.stat().st_size < 6_000_000
    log = mavutil.mavlink_connection(str(flight), dialect="ardupilotmega")
    first = [log.recv_match() for _ in range(20)]
    assert first[0].get_type() == "STATUSTEXT" and "sysid-trainer" in first[0].text
    assert {m.get_type() for m in first} >= {"PARAM_VALUE", "HEARTBEAT", "ATTITUDE", "RAW_IMU"}
