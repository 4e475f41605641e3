"""The hosted session behind the MAVProxy module's commands, fed messages as a host does."""

import sys
from pathlib import Path

from pymavlink import mavutil

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "telemetry"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from tlog_factory import write_flight  # noqa: E402
from live_helpers import AIRFRAME, read_records  # noqa: E402

from gcs_sysid.live.host import HostedSession  # noqa: E402


def test_feed_tick_status_report_save_close(tmp_path):
    log = write_flight(tmp_path / "f.tlog", n=60)
    sent = []
    host = HostedSession(AIRFRAME, tmp_path / "out", sent.append, learn=None, use_mavsdk=False, name="test")
    src = mavutil.mavlink_connection(str(log), dialect="ardupilotmega")
    n, last = 0, None
    while (m := src.recv_match()) is not None:
        host.feed(m)
        n, last = n + 1, m
    host._last_tick = 0.0
    host.tick()
    status = host.status()
    assert f"{n} packets" in status and "learned 0 samples" in status
    assert host.suggest().startswith("sysid: no suggestion yet")
    assert host.report().read_text().count("raw.tlog") == 1
    assert host.save() is None                      # no learner: no model
    snap = host.close()
    assert snap["raw_records"] == n == len(read_records(tmp_path / "out" / "raw.tlog"))
    # the component announced itself and the requester asked the vehicle, through the host's write
    kinds = {m.get_type() for m in mavutil.mavlink.MAVLink(None).parse_buffer(b"".join(sent)) or []}
    assert {"HEARTBEAT", "COMMAND_LONG"} <= kinds
    host.feed(last)                                 # after close: ignored, no error
    assert len(read_records(tmp_path / "out" / "raw.tlog")) == n


def test_a_consumer_error_does_not_stop_the_raw_log(tmp_path):
    from gcs_sysid.telemetry.live import LinkReceiver, RawLog

    log = write_flight(tmp_path / "f.tlog", n=10)
    raw = RawLog(tmp_path / "raw.tlog")

    def broken(stamp_us, buf, msg):
        raise ValueError("boom")

    rx = LinkReceiver(None, raw, [broken])
    src = mavutil.mavlink_connection(str(log), dialect="ardupilotmega")
    n = 0
    while (m := src.recv_match()) is not None:
        rx.handle(m, 1.0 + n)
        n += 1
    raw.close()
    assert len(read_records(tmp_path / "raw.tlog")) == n
    assert sum("boom" in e for _, e in rx.stats.events) == n
