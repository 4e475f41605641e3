"""`gcs-sysid listen` as a user runs it: one-line errors with exit 2, Ctrl-C ends cleanly with the report;
the player runs from outside the repository as an installed command and as `python -m replay`."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT, free_port, player, read_records  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "telemetry"))
from tlog_factory import write_flight  # noqa: E402

GCS = [sys.executable, "-m", "gcs_sysid"]


@pytest.mark.parametrize("args, needle", [
    (["udpin:127.0.0.1:{port}", "--airframe", "{missing}"], "no such file"),
    (["{flight}", "--airframe", "{airframe}"], "is a log file"),
    (["udpin:127.0.0.1:notaport", "--airframe", "{airframe}"], "cannot open the link"),
    (["udpin:127.0.0.1:{port}", "--airframe", "{airframe}", "--window", "5", "--step", "10"], "--window"),
    (["udpin:127.0.0.1:{port}", "--airframe", "{airframe}", "--sysid", "300"], "--sysid"),
])
def test_listen_user_errors_exit_2(tmp_path, args, needle):
    vals = dict(port=free_port(), missing=tmp_path / "none.toml", flight=FLIGHT, airframe=AIRFRAME)
    r = subprocess.run(GCS + ["listen"] + [a.format(**vals) for a in args] + ["--out", str(tmp_path / "o"),
                                                                             "--quiet", "--duration", "1"],
                       capture_output=True, text=True, timeout=60, cwd=tmp_path)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1 and lines[0].startswith("gcs-sysid: error:"), r.stderr
    assert needle in lines[0]


def test_ctrl_c_ends_cleanly_and_writes_the_report(tmp_path):
    port = free_port()
    out = tmp_path / "session"
    exe = Path(sys.executable).with_name("gcs-sysid")
    lis = subprocess.Popen([str(exe), "listen", f"udpin:127.0.0.1:{port}", "--airframe", str(AIRFRAME),
                            "--out", str(out), "--no-learn", "--no-component"], cwd=tmp_path,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           env={**os.environ, "PYTHONFAULTHANDLER": "1"})   # SIGABRT dumps every thread's stack
    log = write_flight(tmp_path / "f.tlog", n=100)
    end = time.monotonic() + 20
    while not (out / "raw.tlog").exists() and time.monotonic() < end:   # the socket is bound before it
        time.sleep(0.05)
    pl = player(log, f"udpout:127.0.0.1:{port}", "--speed", 2, cwd=tmp_path)
    pout, perr = pl.communicate(timeout=30)
    time.sleep(0.5)
    lis.send_signal(signal.SIGINT)
    try:
        sout, serr = lis.communicate(timeout=30)
    except subprocess.TimeoutExpired:   # seen once under CI's load (eighteenth session): say where it hangs
        lis.send_signal(signal.SIGABRT)
        sout, serr = lis.communicate(timeout=30)
        pytest.fail(f"listen still running 30 s after SIGINT; its threads at SIGABRT:\n{serr[-6000:]}")
    assert lis.returncode == 0, serr
    snap = json.loads((out / "session.json").read_text())
    assert snap["interrupted"] is True and "Ctrl-C" in (out / "report.md").read_text()
    sent = int(pout.split("sent ")[1].split()[0])
    assert snap["raw_records"] == len(read_records(out / "raw.tlog")) >= sent
    assert "raw log:" in sout


def test_player_runs_from_outside_the_repository(tmp_path):
    for cmd in ([sys.executable, "-m", "replay", "--help"], [str(Path(sys.executable).with_name("gcs-sysid-player")),
                                                           "--help"]):
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=30, cwd=tmp_path)
        assert r.returncode == 0 and "--speed" in r.stdout
