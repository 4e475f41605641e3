"""Vehicle time: 32-bit wrap, reboot, delayed packets, duplicates and out-of-order records."""

import numpy as np
from pymavlink import mavutil
from pymavlink.dialects.v20 import ardupilotmega as mavlink
from tlog_factory import TlogWriter, write_flight

from gcs_sysid.telemetry import read_log


def _strictly_increasing(f):
    for name, s in f.streams.items():
        assert np.all(np.diff(s.t) > 0), name


def test_servo_time_usec_wrap_is_unwrapped(tmp_path):
    # boot time crosses 2**32 us = 4294.967296 s: SERVO_OUTPUT_RAW.time_usec (uint32) wraps to 0
    f = read_log(write_flight(tmp_path / "wrap.tlog", n=200, rate=50.0, boot0=4293.0))
    servo, att = f["servo"], f["attitude"]
    assert len(servo) == 200
    _strictly_increasing(f)
    np.testing.assert_allclose(servo.t, att.t, atol=1e-3)
    assert servo.t[-1] > 4294.967296 + 1.0
    assert any("wrapped 1 time" in w for w in f.warnings)


def test_reboot_starts_a_rebased_segment(tmp_path):
    w = TlogWriter()
    write_flight(tmp_path / "a.tlog", n=100, boot0=300.0, writer=w, log0=0.0)  # 2 s of flight
    write_flight(tmp_path / "b.tlog", n=100, boot0=5.0, writer=w, log0=12.0)   # 10 s later, rebooted
    f = read_log(w.write(tmp_path / "reboot.tlog"))
    _strictly_increasing(f)
    att = f["attitude"]
    assert len(att) == 200
    jump = att.t[100] - att.t[99]
    np.testing.assert_allclose(jump, 12.0 - 1.98, atol=2e-3)  # continues after the previous segment
    np.testing.assert_allclose(att.t[100:], att.t[100] + np.arange(100) / 50.0, atol=1e-6)
    msg = [x for x in f.warnings if "reboot" in x]
    assert len(msg) == 1 and "12.0 s into the log" in msg[0] and "2020-09-13" in msg[0]
    # the untimed VFR_HUD and the wrapping servo counter follow the same re-based clock
    np.testing.assert_allclose(f["vfr_hud"].t, att.t + 3e-4, atol=1e-5)
    np.testing.assert_allclose(f["servo"].t, att.t, atol=1e-5)


def test_delayed_packets_are_not_a_reboot(tmp_path):
    w = TlogWriter()
    ticks = list(range(100))
    order = ticks[:50] + ticks[55:60] + ticks[50:55] + ticks[60:]  # 5 ticks arrive 0.1 s late
    for j, i in enumerate(order):
        w.add(j / 50.0, mavlink.MAVLink_attitude_message(10_000 + 20 * i, 0, 0, 0.01 * i, 0, 0, 0))
    f = read_log(w.write(tmp_path / "late.tlog"))
    assert not any("reboot" in x for x in f.warnings)
    att = f["attitude"]
    np.testing.assert_allclose(att.t, 10.0 + 0.02 * np.arange(100))
    np.testing.assert_allclose(att["yaw"], 0.01 * np.arange(100), rtol=1e-6)


def test_duplicates_and_out_of_order_are_dropped_and_counted(tmp_path):
    w = TlogWriter()
    for i in range(20):
        rec = w.add(i / 50.0, mavlink.MAVLink_attitude_message(1000 + 20 * i, 0, 0, 0.1 * i, 0, 0, 0))
        if i in (3, 7):
            w.records.append(rec)  # byte-identical duplicate
    # the same vehicle time sent again in a new packet (a second link): out of order, dropped
    w.add(0.5, mavlink.MAVLink_attitude_message(1000 + 20 * 5, 0, 0, 0.5, 0, 0, 0))
    f = read_log(w.write(tmp_path / "dup.tlog"))
    att = f["attitude"]
    assert len(att) == 20
    np.testing.assert_allclose(att["yaw"], 0.1 * np.arange(20), rtol=1e-6)
    assert f.summaries["attitude"].dropped == 3
    assert any("duplicated or out-of-order" in x for x in f.warnings)


def test_messages_of_other_systems_are_ignored(tmp_path):
    w = TlogWriter()
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    for i in range(10):
        w.add(i * 0.02, mavlink.MAVLink_attitude_message(5000 + 20 * i, 0, 0, 0.1, 0, 0, 0))
        w.add(i * 0.02, mavlink.MAVLink_attitude_message(99 + i, 0, 0, 9.9, 0, 0, 0), mav=gcs)
    f = read_log(w.write(tmp_path / "two.tlog"))
    np.testing.assert_allclose(f["attitude"]["yaw"], 0.1, rtol=1e-6)
    assert f.messages["ATTITUDE"] == 20
    assert any("other than the vehicle" in x for x in f.warnings)


def test_matches_pymavlink_recv_match_reference(tmp_path):
    """The fast framer decodes exactly what pymavlink's own tlog reader decodes."""
    path = write_flight(tmp_path / "ref.tlog", n=120, boot0=50.0)
    f = read_log(path)
    conn = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
    rows = []
    while (m := conn.recv_match(type="RAW_IMU")) is not None:
        rows.append((m.time_usec * 1e-6, m.xacc * 9.80665e-3, m.zgyro * 1e-3))
    ref = np.array(rows)
    np.testing.assert_allclose(f["imu"].t, ref[:, 0])
    np.testing.assert_allclose(f["imu"]["ax"], ref[:, 1])
    np.testing.assert_allclose(f["imu"]["r"], ref[:, 2])


def test_mavlink1_packets(tmp_path):
    w = TlogWriter(mavlink1=True)
    f = read_log(write_flight(tmp_path / "v1.tlog", n=30, writer=w))
    assert len(f["attitude"]) == 30 and len(f["imu"]) == 30
