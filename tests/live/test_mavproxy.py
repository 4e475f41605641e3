"""Through MAVProxy from PyPI, started headless as a subprocess: as a router in front of `listen`, and
with gcs-sysid's MAVProxy module loaded. Real UDP on 127.0.0.1; the far end is the log player."""

import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

import pytest
from pymavlink import mavutil

from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.session import ListenOptions, LiveSession
from gcs_sysid.telemetry.live import open_link
from replay.player import read_packets

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT, free_port, player, read_records  # noqa: E402

MAVPROXY = Path(sys.executable).with_name("mavproxy.py")
pytestmark = pytest.mark.skipif(not MAVPROXY.exists(), reason="MAVProxy (test extra) not installed")


def _sources(path):
    log = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
    c = Counter()
    while (m := log.recv_match()) is not None:
        c[(m.get_type(), m.get_srcSystem(), m.get_srcComponent())] += 1
    return c


def _wait_for(path, text, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if path.exists() and text in path.read_text(errors="replace"):
            return True
        time.sleep(0.1)
    return False


def test_listen_behind_mavproxy_router_with_the_module_loaded(tmp_path):
    master, out_port = free_port(), free_port()
    module_out = tmp_path / "module"
    kwargs = f'{{"airframe":"{AIRFRAME}","out":"{module_out}","learn":false}}'
    mp_log = tmp_path / "mavproxy.out"
    with open(mp_log, "w") as log:
        mp = subprocess.Popen([sys.executable, str(MAVPROXY), f"--master=udpin:127.0.0.1:{master}",
                               f"--out=udpout:127.0.0.1:{out_port}", "--daemon", f"--state-basedir={tmp_path}",
                               f"--cmd=module load gcs_sysid.mavproxy_sysid:{kwargs}; sysid status; sysid save"],
                              cwd=tmp_path, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                              env=dict(os.environ, PYTHONUNBUFFERED="1"))
    try:
        assert _wait_for(mp_log, "sysid: listening", 30), mp_log.read_text()
        opts = ListenOptions(connection=f"udpin:127.0.0.1:{out_port}", learn=None, component_id=192,
                             console=False, duration_s=60, use_mavsdk=False)
        session = LiveSession(load_airframe(AIRFRAME), tmp_path / "listen", opts, link=open_link(opts.connection))
        result = {}
        th = threading.Thread(target=lambda: result.update(snap=session.run()))
        th.start()
        far = tmp_path / "far_end.tlog"
        pl = player(FLIGHT, f"udpout:127.0.0.1:{master}", "--speed", 4, "--to", 14, "--received", far,
                    "--linger", 1.5)
        out, err = pl.communicate(timeout=60)
        assert pl.returncode == 0, err
        time.sleep(0.5)
        session.stop()
        th.join(30)
    finally:
        mp.send_signal(signal.SIGINT)
        try:
            mp.wait(20)
        except subprocess.TimeoutExpired:
            mp.kill()
            mp.wait(5)
    sent = int(re.search(r"sent (\d+) packets", out).group(1))
    recorded = {p.data for p in read_packets(str(FLIGHT))}
    # MAVProxy's own log holds what it received from the vehicle (on a busy machine it may itself miss
    # some at its master socket); the router delivers all of it, unchanged, to the listener ...
    routed = [p for p in read_records(tmp_path / "mav.tlog") if p in recorded]
    assert len(routed) > 0.3 * sent
    # (MAVProxy's log may lose its last few writes when it is stopped: once 6 of 3633 packets that the listener and
    # the module both received; so the listener's record starts with MAVProxy's and may hold a few more at its end)
    got = [p for p in read_records(tmp_path / "listen" / "raw.tlog") if p in recorded]
    assert got[:len(routed)] == routed and len(got) - len(routed) <= max(50, 0.02 * len(routed))
    # ... and hands the module every packet from the moment the vehicle is detected (the first
    # records, before its first HEARTBEAT, are not given to modules)
    in_module = [p for p in read_records(module_out / "raw.tlog") if p in recorded]
    assert len(in_module) >= len(got) - 20 and in_module == got[len(got) - len(in_module):]
    # both components speak back to the vehicle side: the module's directly, the listener's through the router
    far_end = _sources(far)
    for comp in (191, 192):
        assert far_end[("HEARTBEAT", 1, comp)] >= 2 and far_end[("STATUSTEXT", 1, comp)] >= 1, far_end
    # rate requests reached the stand-in vehicle through MAVProxy and were answered
    assert set(result["snap"]["requests"].values()) == {"accepted"}
    # the module's commands answered (given at start-up: no data, no model yet)
    text = mp_log.read_text()
    assert "sysid: no data yet, 0 packets" in text and "sysid: no model yet" in text
    # the module wrote its report when MAVProxy shut down
    assert "packets received and kept" in (module_out / "report.md").read_text()
