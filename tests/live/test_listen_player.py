"""`listen` against the log player over real UDP on 127.0.0.1 (slow: ~65 s, mostly compiling the GP cold): rate
requests answered, the component
speaks back to the far end, and the live model equals the model learned again from the session's raw.tlog."""

import re
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from pymavlink import mavutil

from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.learner import LearnOptions, learn_from_tlog
from gcs_sysid.live.session import ListenOptions, LiveSession
from gcs_sysid.parallel import default_enabled
from gcs_sysid.telemetry.live import open_link
from replay.player import read_packets

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT, free_port, player, read_records  # noqa: E402

LEARN = LearnOptions(window_s=3.0, step_s=2.0, lag_s=1.0, min_rows=300, refresh_every=100, n_inducing=24)


def _messages(path):
    log = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
    out = []
    while (m := log.recv_match()) is not None:
        out.append(m)
    return out


@pytest.mark.slow
def test_listen_matches_replay_and_speaks_back(tmp_path):
    port = free_port()
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{port}", learn=LEARN, console=False, duration_s=120,
                         use_mavsdk=False)
    airframe = load_airframe(AIRFRAME)
    session = LiveSession(airframe, tmp_path / "live", opts, link=open_link(opts.connection))
    result = {}
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    th.start()
    received = tmp_path / "far_end.tlog"
    proc = player(FLIGHT, f"udpout:127.0.0.1:{port}", "--speed", 6, "--from", 30, "--to", 66,
                  "--received", received, "--linger", 3)
    out, err = proc.communicate(timeout=90)
    session.stop()
    th.join(120)
    assert proc.returncode == 0, err
    snap = result["snap"]

    # every packet the player sent is in raw.tlog, in order (plus the player's answers to requests)
    sent = int(re.search(r"sent (\d+) packets", out).group(1))
    raw = read_records(tmp_path / "live" / "raw.tlog")
    recorded = {p.data for p in read_packets(str(FLIGHT))}
    assert len([p for p in raw if p in recorded]) == sent
    # requests: SET_MESSAGE_INTERVAL answered by the stand-in vehicle within its recorded rates
    assert snap["requests"] and set(snap["requests"].values()) == {"accepted"}
    assert "RAW_IMU: 50.0 Hz (recorded 50.0 Hz)" in err

    # the far end (the player) received the component's heartbeat, status texts and confidence values
    msgs = [m for m in _messages(received) if (m.get_srcSystem(), m.get_srcComponent()) == (1, 191)]
    kinds = {m.get_type() for m in msgs}
    assert {"HEARTBEAT", "STATUSTEXT"} <= kinds
    assert all(m.type == 18 and m.autopilot == 8 for m in msgs if m.get_type() == "HEARTBEAT")
    texts = [m.text for m in msgs if m.get_type() == "STATUSTEXT"]
    assert any(t.startswith("vehicle: system 1") for t in texts)

    # the live model = the model learned again from raw.tlog (same windows, rows, fit, updates), the live
    # one learned in the worker process (gcs_sysid.live.remote) where there is one
    assert snap["learner_in"] == ("worker process" if default_enabled() else "this process")
    live = session.learner
    assert live.model is not None and snap["samples_learned"] > 1000 and live.steps >= 3
    again = learn_from_tlog(tmp_path / "live" / "raw.tlog", airframe, LEARN,
                            coalesced_at=snap["coalesced_at_us"])   # steps merged while behind, if any
    assert again.n_learned == live.n_learned and again.outputs == live.outputs
    m1, v1 = live.model.predict(live.X)
    m2, v2 = again.model.predict(live.X)
    assert np.allclose(np.asarray(m1), np.asarray(m2), rtol=1e-9, atol=1e-12)
    assert np.allclose(np.asarray(v1), np.asarray(v2), rtol=1e-9, atol=1e-12)
    # and the report was written with the model
    assert Path(snap["model"]).with_suffix(".npz").exists()
    assert "samples learned" in (tmp_path / "live" / "report.md").read_text()
    assert snap["top_suggestion"] and snap["confidence"]
