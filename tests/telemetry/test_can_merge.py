"""CAN streams on the vehicle time axis: the host-clock map of a tlog (link delay, crystal drift, a reboot),
the merge of a real CAN log written by python-can's logger, the airframe's [[can_actuator]] map, and the
errors of ``replay --can-log``."""

from __future__ import annotations

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.airframe import airframe_from_dict, airframe_to_dict, load_airframe  # noqa: E402
from gcs_sysid.errors import InputError  # noqa: E402
from gcs_sysid.telemetry import read_log  # noqa: E402
from gcs_sysid.telemetry.can import frames_of  # noqa: E402
from gcs_sysid.telemetry.can_merge import check_can_log, host_clock_of_tlog, merge_can_log  # noqa: E402
from gcs_sysid.tomlfile import read_toml  # noqa: E402

from tlog_factory import T0_US, TlogWriter  # noqa: E402

T0 = T0_US * 1e-6


def _flight_tlog(path, drift=40e-6, reboot_at=None, seed=3):
    """ATTITUDE + RAW_IMU at 50 Hz for 60 s; host stamp = T0 + 5 + (1 + drift) t + link delay (>= 0)."""
    rng = np.random.default_rng(seed)
    w = TlogWriter()
    truth = []
    for k in range(3000):
        tv = 0.02 * k + 10.0
        boot = tv if reboot_at is None or tv < reboot_at else tv - reboot_at + 0.5
        host = 5.0 + (1 + drift) * (tv - 10.0) + rng.exponential(0.008) + (0.05 if k % 97 == 0 else 0.0)
        ms = int(round(boot * 1000))
        w.add(host, mavlink.MAVLink_attitude_message(ms, 0.01, 0.02, 0.3, 0.0, 0.0, 0.0))
        w.add(host + 1e-4, mavlink.MAVLink_raw_imu_message(ms * 1000, 0, 0, -1000, 0, 0, 0, 0, 0, 0))
        truth.append((T0 + 5.0 + (1 + drift) * (tv - 10.0), boot))
    return w.write(path), np.array(truth)


def test_host_clock_follows_drift_despite_link_delay(tmp_path):
    path, truth = _flight_tlog(tmp_path / "f.tlog")
    clock = host_clock_of_tlog(path)
    est = clock.to_vehicle(truth[:, 0])
    err = est - truth[:, 1]
    # the least-delayed packets set the envelope: within 3 ms everywhere (delays average 8 ms, spikes 50 ms)
    assert np.max(np.abs(err)) < 3e-3, np.max(np.abs(err))
    assert clock.b[0] == pytest.approx(-40e-6 / (1 + 40e-6), abs=5e-6)
    # a constant offset alone (no drift term) would be off by the drift over the minute
    assert "drift" in clock.how


def test_host_clock_after_a_reboot(tmp_path):
    path, truth = _flight_tlog(tmp_path / "r.tlog", drift=0.0, reboot_at=40.0)
    flight = read_log(path)
    assert any("reboot" in w for w in flight.warnings)
    clock = host_clock_of_tlog(path)
    assert len(clock.a) == 2
    # after the reboot the reader re-bases the vehicle clock; the map lands on the flight's own axis
    host_after = truth[truth[:, 1] < 5.0][:, 0][200:210]
    t_after = clock.to_vehicle(host_after)
    att = flight["attitude"].t
    assert np.all(np.min(np.abs(att[None, :] - t_after[:, None]), axis=1) < 3e-3)


def _can_log(path, stamps, pos, actuator_id=2):
    Status = dronecan.uavcan.equipment.actuator.Status
    IAS = dronecan.uavcan.equipment.air_data.IndicatedAirspeed
    with can.Logger(str(path)) as log:
        for h, p in zip(stamps, pos):
            for payload in (Status(actuator_id=actuator_id, position=float(p)),
                            IAS(indicated_airspeed=20.0 + p, indicated_airspeed_variance=0.1)):
                for m in frames_of([payload]):
                    m.timestamp = float(h)
                    log.on_message_received(m)
    return path


@pytest.mark.parametrize("ext", ["log", "blf"])
def test_merge_can_log_on_vehicle_time(tmp_path, ext):
    path, truth = _flight_tlog(tmp_path / "f.tlog")
    sel = truth[::2][100:1000]                  # 25 Hz over the middle of the flight
    pos = 0.2 * np.sin(sel[:, 1])
    can_path = _can_log(tmp_path / f"can.{ext}", sel[:, 0], pos)
    flight = read_log(path)
    merged = merge_can_log(flight, path, can_path)
    st = merged["actuator2"]
    assert len(st) == len(sel)
    assert np.allclose(st.t, sel[:, 1], atol=3e-3)
    assert np.allclose(st["pos"], pos, atol=3e-4)                    # float16 on the wire
    assert merged["airspeed"].source.startswith("DroneCAN")
    assert np.allclose(merged["airspeed"]["eas"], 20.0 + pos, atol=2e-2)
    assert "merged actuator2" in merged.warnings[-1] and "time_boot_ms" in merged.warnings[-1]
    assert "actuator2" not in flight.streams                          # the input flight is left as it was


def test_merge_errors(tmp_path):
    path, truth = _flight_tlog(tmp_path / "f.tlog")
    flight = read_log(path)
    far = _can_log(tmp_path / "far.log", truth[:50, 0] - 1e6, np.zeros(50))
    with pytest.raises(InputError, match="--can-offset"):
        merge_can_log(flight, path, far)
    merged = merge_can_log(flight, path, far, offset=1e6)              # the offset puts it back
    assert len(merged["actuator2"]) == 50
    with pytest.raises(InputError, match="no such file"):
        check_can_log(tmp_path / "none.log", path, None)
    bad = tmp_path / "bad.log"
    bad.write_text("(0.0) vcan0 123#11\n")
    with pytest.raises(InputError, match="no DroneCAN transfer"):
        merge_can_log(flight, path, bad)


def test_airframe_can_actuator_map(tmp_path):
    doc = read_toml("data/airframes/sim-trainer.toml", "airframe")
    doc["can_actuator"] = [{"id": 2, "servo": "elevator", "sign": -1, "scale": 1.5, "zero_deg": 2.0}]
    af = airframe_from_dict(doc, "a.toml")
    (act,) = af.can_actuators
    assert act.deflection(np.radians(4.0)) == pytest.approx(-1.5 * np.radians(2.0))
    assert airframe_from_dict(airframe_to_dict(af), "b.toml").can_actuators == af.can_actuators
    assert load_airframe("data/airframes/sim-trainer.toml").can_actuators == ()
    for bad, msg in (({"id": 300, "servo": "elevator"}, "actuator id 0..255"),
                     ({"id": 2, "servo": "flap"}, "must name a \\[\\[servo\\]\\]"),
                     ({"id": 2, "servo": "elevator", "sign": 2}, "'sign' must be 1 or -1"),
                     ({"id": 2, "servo": "elevator", "scale": -1}, "'scale' must be > 0"),
                     ({"id": 2, "servo": "elevator", "gain": 1}, "unknown field 'gain'")):
        doc["can_actuator"] = [bad]
        with pytest.raises(InputError, match=msg):
            airframe_from_dict(doc, "a.toml")
    doc["can_actuator"] = [{"id": 2, "servo": "elevator"}, {"id": 2, "servo": "rudder"}]
    with pytest.raises(InputError, match="listed twice"):
        airframe_from_dict(doc, "a.toml")


def test_bounded_decoder_keeps_the_recent_samples():
    from gcs_sysid.telemetry.can import TRIM_EVERY, CanDecoder

    Status = dronecan.uavcan.equipment.actuator.Status
    dec = CanDecoder(keep_s=10.0)
    n = 3 * TRIM_EVERY
    for i in range(n):
        for m in frames_of([Status(actuator_id=1, position=0.0)], source_node_id=20 + i % 2):
            m.timestamp = 0.1 * i
            dec.feed(m)
    t = dec.streams()["actuator1"].t
    assert dec.counts["uavcan.equipment.actuator.Status"] == n
    assert len(t) < TRIM_EVERY + 120 and t[-1] == pytest.approx(0.1 * (n - 1))
    assert t[0] >= 0.1 * (n - 1) - 10.0 - 0.1 * TRIM_EVERY
