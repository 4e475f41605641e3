"""The listener on real UDP behind a relay that loses, corrupts, duplicates, reorders, silences and
floods packets: it keeps running, says what happened, and raw.tlog holds every intact packet received."""

import re
import sys
import threading
import time
from pathlib import Path

import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.session import ListenOptions, LiveSession
from gcs_sysid.telemetry.live import open_link
from replay.player import read_packets

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "telemetry"))
from tlog_factory import TlogWriter, write_flight  # noqa: E402

from live_helpers import AIRFRAME, FaultyRelay, free_port, player, read_records  # noqa: E402


def _listen(tmp_path, log, relay_kw, speed=4.0, silence_s=0.5, player_args=()):
    port = free_port()
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{port}", learn=None, request=False, component=False,
                         silence_s=silence_s, console=False, duration_s=60)
    session = LiveSession(load_airframe(AIRFRAME), tmp_path / "out", opts, link=open_link(opts.connection))
    result = {}
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    with FaultyRelay(port, **relay_kw) as relay:
        th.start()
        proc = player(log, f"udpout:127.0.0.1:{relay.in_port}", "--speed", speed, "--no-answer", *player_args)
        out, err = proc.communicate(timeout=60)
        assert proc.returncode == 0, err
        sent = int(re.search(r"sent (\d+) packets", out).group(1))
        deadline = time.monotonic() + 10
        while (relay.counts["received"] < sent or session.receiver.stats.records < len(relay.delivered)) \
                and time.monotonic() < deadline:
            time.sleep(0.05)
    session.stop()
    th.join(30)
    return result["snap"], relay, tmp_path / "out" / "raw.tlog"


def test_loss_corruption_duplicates_reordering_noise(tmp_path):
    log = write_flight(tmp_path / "f.tlog", n=300)
    snap, relay, raw = _listen(tmp_path, log, dict(drop=0.10, corrupt=0.03, duplicate=0.05, reorder=0.05,
                                                   noise=0.02, seed=7))
    c = relay.counts
    assert c["dropped"] > 100 and c["corrupted"] > 20 and c["duplicated"] > 30 and c["reordered"] > 30
    assert read_records(raw) == relay.delivered          # every intact packet, in arrival order
    assert snap["bad_data"] >= c["corrupted"]             # each corrupt packet seen and skipped
    assert snap["seq_lost"] > 0                           # the loss is noticed by the sequence numbers
    assert (tmp_path / "out" / "report.md").read_text().count("raw.tlog") == 1


def test_silence_then_recovery_and_flood(tmp_path):
    log = write_flight(tmp_path / "f.tlog", n=40)
    snap, relay, raw = _listen(tmp_path, log, dict(silence=(120, 40), pause_s=1.5, flood=10))
    assert len(relay.delivered) == 10 * (relay.counts["received"] - 40)
    assert read_records(raw) == relay.delivered
    text = " | ".join(snap["events"])
    assert "silent" in text and "back after" in text


def test_vehicle_reboot_is_reported(tmp_path):
    w = TlogWriter()
    write_flight(tmp_path / "a.tlog", n=100, boot0=200.0, writer=w)
    log = write_flight(tmp_path / "f.tlog", n=100, boot0=1.0, writer=w, log0=2.5)
    snap, relay, raw = _listen(tmp_path, log, {})
    assert read_records(raw) == relay.delivered
    assert any("reboot" in e and "time_boot_ms fell" in e for e in snap["events"])


def test_tcp_link_keeps_every_packet(tmp_path):
    """tcpin: listener, the player connecting with tcp: (a reliable link: all it sent is in raw.tlog)."""
    log = write_flight(tmp_path / "f.tlog", n=50)
    port = free_port()
    opts = ListenOptions(connection=f"tcpin:127.0.0.1:{port}", learn=None, request=False, component=False,
                         console=False, duration_s=60)
    session = LiveSession(load_airframe(AIRFRAME), tmp_path / "out", opts)
    result = {}
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    th.start()
    proc = player(log, f"tcp:127.0.0.1:{port}", "--speed", 4, "--no-answer")
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    sent = int(re.search(r"sent (\d+) packets", out).group(1))
    deadline = time.monotonic() + 10
    while session.receiver.stats.records < sent and time.monotonic() < deadline:
        time.sleep(0.05)
    session.stop()
    th.join(30)
    assert read_records(tmp_path / "out" / "raw.tlog") == [p.data for p in read_packets(str(log))]
