"""`listen --can virtual:NAME`: DroneCAN frames on python-can's virtual bus are logged to DIR/can.log and
decoded beside the MAVLink link; the report says what arrived."""

import threading
import time
import uuid
from pathlib import Path
import sys

import numpy as np
import pytest

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.airframe import load_airframe  # noqa: E402
from gcs_sysid.live.session import ListenOptions, LiveSession  # noqa: E402
from gcs_sysid.telemetry.can import frames_of, read_can_log  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, free_port  # noqa: E402


def test_listen_logs_and_decodes_a_can_bus(tmp_path):
    channel = f"gcs-sysid-{uuid.uuid4().hex[:8]}"
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{free_port()}", learn=None, request=False, component=False,
                         console=False, can=f"virtual:{channel}")
    session = LiveSession(load_airframe(AIRFRAME), tmp_path, opts)
    result = {}
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    th.start()
    eq = dronecan.uavcan.equipment
    pos = 0.1 * np.sin(np.arange(30) * 0.5)
    msgs = frames_of([eq.actuator.Status(actuator_id=3, position=p, force=0, speed=0, power_rating_pct=0)
                      for p in pos] + [eq.air_data.TrueAirspeed(true_airspeed=21.0, true_airspeed_variance=0.1)])
    tx = can.Bus(interface="virtual", channel=channel)
    try:
        time.sleep(0.3)
        for m in msgs:
            tx.send(m)
        end = time.monotonic() + 5
        while session.can.received < len(msgs) and time.monotonic() < end:
            time.sleep(0.02)
    finally:
        tx.shutdown()
        session.stop()
        th.join(30)
    snap = result["snap"]
    assert snap["can"]["frames"] == len(msgs)
    assert snap["can"]["transfers"] == {"uavcan.equipment.actuator.Status": 30,
                                        "uavcan.equipment.air_data.TrueAirspeed": 1}
    streams, _ = read_can_log(tmp_path / "can.log")
    assert np.allclose(streams["actuator3"]["pos"], pos, atol=2e-4)
    assert streams["can_airspeed"]["tas"][0] == pytest.approx(21.0, abs=0.02)
    assert f"CAN: {len(msgs)} frames" in (tmp_path / "report.md").read_text()
