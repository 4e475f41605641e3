"""The player as a stand-in vehicle: rate requests over real UDP, answered within the recorded rates."""

import re
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

from pymavlink import mavutil
from pymavlink.dialects.v20 import ardupilotmega as mavlink

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "telemetry"))
from tlog_factory import write_flight  # noqa: E402

from replay.player import Packet  # noqa: E402
from replay.vehicle import VehicleResponder, recorded_rates  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def _responder(rates):
    sent = []
    return VehicleResponder(mavlink.MAVLink(None, srcSystem=1, srcComponent=1), rates, sent.append), sent


def _cmd(msgid, interval_us):
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    buf = gcs.command_long_encode(1, 1, 511, 0, msgid, interval_us, 0, 0, 0, 0, 0).pack(gcs)
    return mavlink.MAVLink(None).parse_buffer(buf)[0]


def test_rates_are_lowered_refused_above_the_recording_and_restored():
    r, sent = _responder({"ATTITUDE": 50.0})
    r.handle(_cmd(mavlink.MAVLINK_MSG_ID_ATTITUDE, 100_000))   # 10 Hz: accepted, thinned
    kept = [i for i in range(100) if r.allow("ATTITUDE", 100 + i * 0.02)]   # 2 s of 50 Hz
    assert len(kept) == 20
    r.handle(_cmd(mavlink.MAVLINK_MSG_ID_ATTITUDE, 5_000))     # 200 Hz: more than recorded
    r.handle(_cmd(mavlink.MAVLINK_MSG_ID_ATTITUDE, -1))        # stop
    assert not r.allow("ATTITUDE", 200.0)
    r.handle(_cmd(mavlink.MAVLINK_MSG_ID_ATTITUDE, 0))         # default: as recorded
    assert all(r.allow("ATTITUDE", 300 + i * 0.02) for i in range(10))
    r.handle(_cmd(mavlink.MAVLINK_MSG_ID_WIND, 100_000))       # not in the log
    msgs = mavlink.MAVLink(None).parse_buffer(b"".join(sent))
    acks = [m.result for m in msgs if m.get_type() == "COMMAND_ACK"]
    assert acks == [0, 2, 0, 0, 2]
    texts = [m.text for m in msgs if m.get_type() == "STATUSTEXT"]
    assert texts[0] == "replay: ATTITUDE max 50.0Hz (asked 200)" and "WIND not in log" in texts[1]
    assert all((m.get_srcSystem(), m.get_srcComponent()) == (1, 1) for m in msgs)


def test_recorded_rates():
    pk = [Packet(i * 0.01, "A" if i % 2 else "B", b"\xfd\x00\x00\x00\x00\x01\x01") for i in range(101)]
    assert recorded_rates(pk) == {"A": 50.0, "B": 51.0}


def test_request_data_stream_over_udp_thins_the_stream(tmp_path):
    log = write_flight(tmp_path / "f.tlog", n=150)        # 3 s at 50 Hz
    rx = mavutil.mavlink_connection("udpin:127.0.0.1:0", dialect="ardupilotmega", source_system=255)
    port = rx.port.getsockname()[1]
    exe = Path(sys.executable).with_name("gcs-sysid-player")
    proc = subprocess.Popen([str(exe), str(log), "--link", f"udpout:127.0.0.1:{port}", "--speed", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    got = Counter()
    try:
        m = rx.recv_match(blocking=True, timeout=5)        # learn the player's address, then ask
        assert m is not None
        rx.mav.request_data_stream_send(1, 1, 10, 10, 1)  # EXTRA1 (ATTITUDE) at 10 Hz
        t_end = time.monotonic() + 6
        while proc.poll() is None and time.monotonic() < t_end:
            m = rx.recv_match(blocking=True, timeout=0.2)
            if m is not None:
                got[m.get_type()] += 1
        out, err = proc.communicate(timeout=10)
    finally:
        rx.close()
    assert proc.returncode == 0, err
    assert "ATTITUDE: 10.0 Hz (recorded" in err
    assert 150 * 0.9 <= got["RAW_IMU"] <= 150 and got["ATTITUDE"] <= 45   # ~3 s at 10 Hz, plus the start
    assert re.search(r"sent \d+ packets", out)
