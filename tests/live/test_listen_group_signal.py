"""`gcs-sysid listen` with the learner in its worker process, stopped by a signal to its whole process group (what
timeout(1), a service manager or a terminal's Ctrl-C send): it ends cleanly with the learner's model, the worker
having held on until the session collected it (slow: the worker imports JAX and fits the GP cold, ~40-60 s each)."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT, free_port, player  # noqa: E402


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_to_the_group_ends_with_the_model(tmp_path, sig):
    port, out = free_port(), tmp_path / "s"
    exe = Path(sys.executable).with_name("gcs-sysid")
    lis = subprocess.Popen([str(exe), "listen", f"udpin:127.0.0.1:{port}", "--airframe", str(AIRFRAME),
                            "--out", str(out), "--window", "4", "--step", "2", "--lag", "1", "--min-rows", "300",
                            "--inducing", "24", "--quiet", "--no-mavsdk"], start_new_session=True, cwd=tmp_path,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        end = time.monotonic() + 60
        while not (out / "raw.tlog").exists() and time.monotonic() < end:
            time.sleep(0.1)
        pl = player(FLIGHT, f"udpout:127.0.0.1:{port}", "--speed", 4, "--from", 30, "--to", 70, "--no-answer")
        pl.communicate(timeout=60)
        time.sleep(1.0)
        os.killpg(lis.pid, sig)
        sout, serr = lis.communicate(timeout=240)
    finally:
        if lis.poll() is None:
            os.killpg(lis.pid, signal.SIGKILL)
            lis.communicate()
    assert lis.returncode == 0, serr
    snap = json.loads((out / "session.json").read_text())
    assert snap["interrupted"] is True and snap["learner_in"] == "worker process"
    assert snap["model"] and Path(snap["model"]).with_suffix(".npz").exists() and snap["samples_learned"] > 1000
    assert not any(n.startswith("learning stopped") for n in snap["learner_notes"]), snap["learner_notes"]
