"""The log player in a real subprocess, sending over real UDP on 127.0.0.1 to a pymavlink receiver."""

import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from pymavlink import mavutil

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "telemetry"))
from tlog_factory import write_flight  # noqa: E402

from replay.player import Packet, play, read_packets  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def _free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _run(*args, timeout=30):
    return subprocess.run([sys.executable, "-m", "replay", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


def test_received_packets_equal_the_log(tmp_path):
    log = write_flight(tmp_path / "f.tlog", n=40)
    expected = [p.data for p in read_packets(str(log))]
    port = _free_port()
    rx = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", dialect="ardupilotmega")
    try:
        proc = subprocess.Popen([sys.executable, "-m", "replay", str(log), "--link", f"udpout:127.0.0.1:{port}",
                                 "--speed", "0"], cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        got = []
        deadline = time.monotonic() + 20
        while len(got) < len(expected) and time.monotonic() < deadline:
            m = rx.recv_match(blocking=True, timeout=0.5)
            if m is not None and m.get_type() != "BAD_DATA":
                got.append(bytes(m.get_msgbuf()))
        out, err = proc.communicate(timeout=20)
    finally:
        rx.close()
    assert proc.returncode == 0, err
    assert f"sent {len(expected)} packets" in out
    assert got == expected


def test_timing_follows_speed_and_window():
    pk = [Packet(100.0 + 0.1 * i, "X", bytes([i])) for i in range(21)]  # 2 s of log
    now = [0.0]
    sent = []
    n = play(pk, lambda b: sent.append((now[0], b[0])), speed=2.0, t_from=0.5, t_to=1.5,
             sleep=lambda s: now.__setitem__(0, now[0] + s), clock=lambda: now[0])
    assert n == 11 and sent[0][1] == 5 and sent[-1][1] == 15
    assert sent[-1][0] == pytest.approx(0.5)  # 1 s of log at speed 2


@pytest.mark.parametrize("args, needle", [
    (["{missing}"], "no such file"),
    (["{text}"], "not a MAVLink log"),
    (["{log}", "--link", "udpout:127.0.0.1:notaport"], "cannot open"),
    (["{log}", "--speed", "-1"], "--speed"),
])
def test_bad_log_or_link_exit_2(tmp_path, args, needle):
    paths = {"missing": tmp_path / "none.tlog", "text": tmp_path / "t.tlog", "log": tmp_path / "ok.tlog"}
    paths["text"].write_text("hello\n" * 20)
    write_flight(paths["log"], n=5)
    r = _run(*[a.format(**paths) for a in args])
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("replay: error:") and needle in lines[0]
