"""The live learner's per-window CAN merge uses DroneCAN time sync when its master is the vehicle (no telemetry-link
delay in the map), and says so when it is not; the offline merge is tested in tests/telemetry/test_can_timesync.py
with the same synthetic flight and CAN log."""

import sys
from pathlib import Path

import numpy as np
import pytest

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.airframe import load_airframe  # noqa: E402
from gcs_sysid.live.learner import LearnOptions, Learner, iter_tlog_records  # noqa: E402
from gcs_sysid.telemetry.can import read_can_log  # noqa: E402
from gcs_sysid.telemetry.tlog_reader import read_tlog  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "telemetry"))
from live_helpers import AIRFRAME  # noqa: E402
import test_can_timesync as T  # noqa: E402


def _window_merge(tmp_path, master_t, vehicle_t=None):
    tlog = T._tlog(tmp_path / "f.tlog")
    tv = 12.0 + 0.04 * np.arange(1200)
    can_path = T._can_log(tmp_path / "can.log", master_t, tv, 0.2 * np.sin(tv))
    if vehicle_t is not None:   # the same log, its time-sync master on another clock
        can_path = tmp_path / "can_other.log"
        msgs = [m for m in can.LogReader(str(tmp_path / "can.log")) if (m.arbitration_id & 0x7F) != 10]
        msgs += T._sync_messages(master_t, vehicle_t=vehicle_t)
        with can.Logger(str(can_path)) as log:
            for m in sorted(msgs, key=lambda m: m.timestamp):
                log.on_message_received(m)
    streams, _ = read_can_log(can_path)
    learner = Learner(load_airframe(AIRFRAME), LearnOptions(window_s=8.0, step_s=4.0))
    learner.can_source = lambda: streams
    learner._window.extend(iter_tlog_records(tlog))   # the window: the whole synthetic flight
    data = tlog.read_bytes()
    return learner, learner._merge_can(read_tlog("live window", data), data), tv


def test_the_window_merge_takes_the_time_sync(tmp_path):
    learner, merged, tv = _window_merge(tmp_path, 10.0 + np.arange(60) * 1.0)
    assert np.allclose(merged["actuator2"].t, tv, atol=2e-3)           # the tlog's map alone: 120 ms late
    assert not any("GlobalTimeSync" in n for n in learner.notes)


def test_a_master_on_another_clock_is_noted_and_the_tlog_map_used(tmp_path):
    tv_sync = 10.0 + np.arange(60) * 1.0
    learner, merged, tv = _window_merge(tmp_path, 1.7e9 + tv_sync, vehicle_t=tv_sync)
    assert np.allclose(merged["actuator2"].t, tv - T.LINK_S, atol=5e-3)
    assert sum(n.startswith("DroneCAN GlobalTimeSync not used") for n in learner.notes) == 1
