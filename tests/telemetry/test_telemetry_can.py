"""DroneCAN over python-can's virtual bus: actuator positions and airspeed decoded live, logged, and read
back from the log with can.LogReader (real multi-frame transfers built by the dronecan library)."""

import time
import uuid

import numpy as np
import pytest

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.errors import InputError  # noqa: E402
from gcs_sysid.telemetry.can import CanListener, frames_of, open_bus, read_can_log  # noqa: E402


def _payloads(n=40):
    eq = dronecan.uavcan.equipment
    out, pos = [], []
    for i in range(n):
        p = 0.2 * np.sin(0.3 * i)
        pos.append(p)
        out.append(eq.actuator.Status(actuator_id=1, position=p, force=0, speed=0, power_rating_pct=0))
        out.append(eq.actuator.Status(actuator_id=2, position=-p, force=0, speed=0, power_rating_pct=0))
        out.append(eq.air_data.IndicatedAirspeed(indicated_airspeed=18.0 + 0.1 * i, indicated_airspeed_variance=0.1))
    return out, np.array(pos)


def test_virtual_bus_decoded_live_and_from_its_log(tmp_path):
    channel = f"gcs-sysid-{uuid.uuid4().hex[:8]}"
    rx = open_bus(f"virtual:{channel}")
    tx = can.Bus(interface="virtual", channel=channel)
    listener = CanListener(rx, tmp_path / "can.log").start()
    payloads, pos = _payloads()
    msgs = frames_of(payloads)
    assert len(msgs) > len(payloads)                   # actuator Status needs two frames on CAN 2.0
    try:
        for m in msgs:
            tx.send(m)
            time.sleep(0.0005)
        end = time.monotonic() + 5
        while listener.received < len(msgs) and time.monotonic() < end:
            time.sleep(0.02)
    finally:
        listener.stop()
        tx.shutdown()
    summary = listener.summary()
    assert summary["frames"] == len(msgs) and summary["bad"] == 0
    assert summary["transfers"] == {"uavcan.equipment.actuator.Status": 80,
                                    "uavcan.equipment.air_data.IndicatedAirspeed": 40}
    live = listener.decoder.streams()
    assert np.allclose(live["actuator1"]["pos"], pos, atol=2e-4)       # float16 on the wire
    assert np.allclose(live["can_airspeed"]["ias"], 18.0 + 0.1 * np.arange(40), atol=2e-2)
    streams, dec = read_can_log(tmp_path / "can.log")
    assert dec.frames == len(msgs)
    assert np.allclose(streams["actuator1"]["pos"], live["actuator1"]["pos"])
    assert np.allclose(streams["actuator2"]["pos"], -pos, atol=2e-4)
    assert np.all(np.diff(streams["actuator1"].t) > 0)


def test_bad_can_inputs(tmp_path):
    with pytest.raises(InputError, match="INTERFACE:CHANNEL"):
        open_bus("can0")
    with pytest.raises(InputError, match="no such file"):
        read_can_log(tmp_path / "none.log")
    empty = tmp_path / "e.log"
    empty.write_text("(0.0) vcan0 123#11\n")
    with pytest.raises(InputError, match="no DroneCAN transfer"):
        read_can_log(empty)
