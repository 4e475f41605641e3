"""DroneCAN GlobalTimeSync puts CAN samples on vehicle time without the telemetry link's delay: frames built
by the dronecan library (a master on the vehicle's boot clock at 1 Hz, received with a small bus delay),
decoded to pairs (receive time, master time), fitted to a host-clock map; merged in place of the tlog's map
when the master's clock is the vehicle's, and not used (with a note) when it is another clock."""

from __future__ import annotations

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.telemetry import read_log  # noqa: E402
from gcs_sysid.telemetry.can import CanDecoder, frames_of, read_can_log  # noqa: E402
from gcs_sysid.telemetry.can_merge import (  # noqa: E402
    can_host_clock, host_clock_of_timesync, host_clock_of_tlog, merge_can_log)

from tlog_factory import T0_US, TlogWriter  # noqa: E402

T0 = T0_US * 1e-6
DRIFT = 30e-6      # the host's crystal against the vehicle's
LINK_S = 0.120     # constant telemetry-link delay (a radio): the tlog's envelope cannot see it


def _host(tv):
    """Host clock (s) at vehicle time ``tv`` (s)."""
    return T0 + 5.0 + (1 + DRIFT) * (np.asarray(tv) - 10.0)


def _tlog(path, seed=4):
    """ATTITUDE at 50 Hz for 60 s (vehicle 10..70 s), arriving LINK_S late plus a small jitter."""
    rng = np.random.default_rng(seed)
    w = TlogWriter()
    for k in range(3000):
        tv = 10.0 + 0.02 * k
        w.add(_host(tv) - T0 + LINK_S + rng.exponential(0.002),
              mavlink.MAVLink_attitude_message(int(round(tv * 1000)), 0.01, 0.02, 0.3, 0.0, 0.0, 0.0))
    return w.write(path)


def _sync_messages(master_t, drop=(), node=10, seed=5, vehicle_t=None):
    """python-can messages of a GlobalTimeSync master: message k sent at master time ``master_t[k]`` carries the
    exact send time of message k-1 (0 in the first); stamped with the host's receive time (bus delay 0.2-1 ms).
    Messages whose index is in ``drop`` are lost on the bus (their transfer id is spent). ``vehicle_t``: the
    vehicle times they are sent at, when the master's clock is another one."""
    vehicle_t = master_t if vehicle_t is None else vehicle_t
    rng = np.random.default_rng(seed)
    GTS = dronecan.uavcan.protocol.GlobalTimeSync
    payloads = [GTS(previous_transmission_timestamp_usec=int(round(master_t[k - 1] * 1e6)) if k else 0)
                for k in range(len(master_t))]
    out = []
    for k, m in enumerate(frames_of(payloads, source_node_id=node)):   # one frame per transfer
        if k in drop:
            continue
        m.timestamp = float(_host(vehicle_t[k]) + rng.uniform(0.0002, 0.001))
        out.append(m)
    return out


def test_time_sync_pairs_give_the_vehicle_clock():
    master = 10.0 + np.arange(60) * 1.0 + np.random.default_rng(1).uniform(0, 0.01, 60)
    dec = CanDecoder()
    for m in _sync_messages(master, drop={20}):
        dec.feed(m)
    st = dec.streams()["can_timesync"]
    # a pair per message after the first, except the one after the loss (ids not consecutive) and the lost one
    assert len(st) == 60 - 1 - 2
    assert np.allclose(st["master"], np.delete(master[:-1], [19, 20]), atol=1e-6)
    clock = host_clock_of_timesync(st)
    tv = np.linspace(10.0, 70.0, 301)
    assert np.max(np.abs(clock.to_vehicle(_host(tv)) - tv)) < 1.5e-3      # the bus delay only
    assert clock.b[0] == pytest.approx(-DRIFT / (1 + DRIFT), abs=5e-6)
    assert "GlobalTimeSync" in clock.how
    assert host_clock_of_timesync(None) is None


def _can_log(path, master_t, samples_tv, pos):
    Status = dronecan.uavcan.equipment.actuator.Status
    msgs = _sync_messages(master_t)
    for tv, p in zip(samples_tv, pos):
        for m in frames_of([Status(actuator_id=2, position=float(p))], source_node_id=20):
            m.timestamp = float(_host(tv) + 0.0005)
            msgs.append(m)
    msgs.sort(key=lambda m: m.timestamp)
    with can.Logger(str(path)) as log:
        for m in msgs:
            log.on_message_received(m)
    return path


def test_merge_uses_time_sync_and_not_the_delayed_link(tmp_path):
    tlog = _tlog(tmp_path / "f.tlog")
    tv = 12.0 + 0.04 * np.arange(1200)                          # 25 Hz actuator reports, vehicle time
    pos = 0.2 * np.sin(tv)
    can_path = _can_log(tmp_path / "can.log", 10.0 + np.arange(60) * 1.0, tv, pos)
    # the tlog's own map is late by the link's constant delay
    tlog_err = host_clock_of_tlog(tlog).to_vehicle(_host(tv)) - tv
    assert np.all(np.abs(tlog_err + LINK_S) < 5e-3), tlog_err
    merged = merge_can_log(read_log(tlog), tlog, can_path)
    st = merged["actuator2"]
    assert len(st) == len(tv)
    assert np.allclose(st.t, tv, atol=2e-3)                      # on vehicle time: no link delay in it
    assert np.allclose(st["pos"], pos, atol=3e-4)
    assert "DroneCAN GlobalTimeSync" in merged.warnings[-1]
    # with the time sync stripped from the log, today's fit (and its link delay) is what is left
    streams, _ = read_can_log(can_path)
    clock, note = can_host_clock({k: v for k, v in streams.items() if k != "can_timesync"}, host_clock_of_tlog(tlog))
    assert note is None and "time_boot_ms" in clock.how


def test_time_sync_on_another_clock_is_not_used(tmp_path):
    tlog = _tlog(tmp_path / "f.tlog")
    tv = 10.0 + np.arange(60) * 1.0
    dec = CanDecoder()
    for m in _sync_messages(1.7e9 + tv, vehicle_t=tv):          # a GNSS node serving UTC, not the vehicle's clock
        dec.feed(m)
    streams = dec.streams()
    assert len(streams["can_timesync"]) == 59
    clock, note = can_host_clock(streams, host_clock_of_tlog(tlog))
    assert "time_boot_ms" in clock.how
    assert note.startswith("DroneCAN GlobalTimeSync not used") and "not the flight controller" in note
