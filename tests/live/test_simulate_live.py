"""`gcs-sysid simulate --live`: the project's simulation streamed onto UDP as a stand-in vehicle."""

import subprocess
import sys
from pathlib import Path

import pytest
import tomli_w
from pymavlink import mavutil

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, REPO, free_port  # noqa: E402


@pytest.mark.slow   # the simulation's start-up (JAX, SciPy) costs ~20 s of wall time on a shared 2-core machine
def test_simulate_live_streams_the_simulated_flight(tmp_path):
    plan = tmp_path / "plan.toml"
    plan.write_text(tomli_w.dumps({   # a 4 s trimmed flight from vehicle time 30 s (docs/sim.md)
        "name": "live", "duration_s": 4.0, "rate_hz": 50.0, "internal_rate_hz": 200.0, "start_time_s": 30.0,
        "seed": 5, "initial": {"airspeed_mps": 20.0, "altitude_m": 150.0, "heading_deg": 30.0},
        "home": {"alt_m": 50.0}}))
    port = free_port()
    rx = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", dialect="ardupilotmega")
    out = tmp_path / "sim.tlog"
    proc = subprocess.Popen([sys.executable, "-m", "gcs_sysid", "simulate", "--airframe", str(AIRFRAME), "--model",
                             str(REPO / "data" / "models" / "sim-trainer.toml"), "--maneuvers", str(plan),
                             "--out", str(out), "--live", f"udpout:127.0.0.1:{port}", "--speed", "4"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    got = []
    try:
        while proc.poll() is None or (m := rx.recv_match(blocking=False)) is not None:
            m = rx.recv_match(blocking=True, timeout=0.2)
            if m is not None and m.get_type() != "BAD_DATA":
                got.append(m)
        sout, serr = proc.communicate(timeout=60)
    finally:
        rx.close()
    assert proc.returncode == 0, serr
    n = int(sout.split("streamed ")[1].split()[0])
    assert n > 500 and len(got) >= 0.95 * n
    att = [m for m in got if m.get_type() == "ATTITUDE"]
    assert len(att) >= 150 and att[0].time_boot_ms >= 30_000     # 4 s at 50 Hz from vehicle time 30 s
