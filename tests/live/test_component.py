"""The MAVLink component: status-text chunks, named values, heartbeat, and its parameters read and set
from a second process (MAVSDK's parameter client; pymavlink's PARAM protocol) over real UDP."""

import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from gcs_sysid.component import DEFAULT_PARAMS, SysidComponent, chunk_text, conf_name
from gcs_sysid.telemetry.live import open_link

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from live_helpers import free_port  # noqa: E402


def _parse(packets):
    p = mavlink.MAVLink(None)
    return [m for b in packets for m in (p.parse_buffer(b) or [])]


def test_statustext_chunks_and_named_values():
    sent = []
    comp = SysidComponent(sent.append, 7, 191, use_mavsdk=False, clock=lambda: 100.0)
    text = "sysid: " + "x" * 93          # 100 characters: two full chunks and an empty end chunk
    assert comp.statustext(text, 4) == 3
    comp.statustext("short", 6)
    comp.confidence({"Cm": 0.25, "CX": 0.9})
    comp.tick()
    msgs = _parse(sent)
    st = [m for m in msgs if m.get_type() == "STATUSTEXT"]
    assert [(m.id, m.chunk_seq, m.severity) for m in st[:3]] == [(1, 0, 4), (1, 1, 4), (1, 2, 4)]
    assert "".join(m.text for m in st[:3]) == text and st[3].id == 0 and st[3].text == "short"
    nv = {m.name: m.value for m in msgs if m.get_type() == "NAMED_VALUE_FLOAT"}
    assert nv == {"CONF_Cm": pytest.approx(0.25), "CONF_CX": pytest.approx(0.9)}
    assert all(len(conf_name(c)) <= 10 for c in ("CX", "CY", "CZ", "Cl", "Cm", "Cn"))
    hb = [m for m in msgs if m.get_type() == "HEARTBEAT"]
    assert len(hb) == 1 and (hb[0].type, hb[0].autopilot) == (18, 8)
    assert all((m.get_srcSystem(), m.get_srcComponent()) == (7, 191) for m in msgs)
    assert chunk_text("") == [b""] and len(chunk_text("a" * 50)) == 1


def _serve(use_mavsdk):
    port = free_port()
    link = open_link(f"udpin:127.0.0.1:{port}")
    comp = SysidComponent(link.write, 1, 191, use_mavsdk=use_mavsdk)
    stop = threading.Event()

    def loop():
        while not stop.is_set():
            m = link.recv_msg()
            if m is None:
                comp.tick()
                time.sleep(0.005)
            elif m.get_type() != "BAD_DATA":
                comp.handle(m)

    th = threading.Thread(target=loop, daemon=True)
    th.start()
    return port, comp, link, stop, th


def test_mavsdk_param_server_set_and_get_from_a_second_process():
    port, comp, link, stop, th = _serve(use_mavsdk=True)
    try:
        assert comp.param_backend == "mavsdk"
        r = subprocess.run([sys.executable, str(HERE / "mavsdk_param_client.py"), str(port), "1", "191",
                            "SID_IMU_HZ", "40"], capture_output=True, text=True, timeout=30)
        out = json.loads(r.stdout.strip().splitlines()[-1])
        assert out == {"before": DEFAULT_PARAMS["SID_IMU_HZ"][0], "after": 40.0}, r.stderr
        assert comp.refresh_params()["SID_IMU_HZ"] == 40.0
    finally:
        stop.set()
        th.join(5)
        comp.close()
        link.close()


def test_pymavlink_param_protocol_from_a_second_process():
    port, comp, link, stop, th = _serve(use_mavsdk=False)
    code = f"""
import json, time
from pymavlink import mavutil
c = mavutil.mavlink_connection("udpout:127.0.0.1:{port}", source_system=255, source_component=190,
                               dialect="ardupilotmega")
c.mav.heartbeat_send(6, 8, 0, 0, 0)
c.mav.param_request_list_send(1, 191)
names = {{}}
end = time.time() + 10
while len(names) < {len(DEFAULT_PARAMS)} and time.time() < end:
    m = c.recv_match(type="PARAM_VALUE", blocking=True, timeout=0.5)
    if m: names[m.param_id] = m.param_value
c.mav.param_set_send(1, 191, b"SID_CONF_MIN", 0.75, 9)
m = c.recv_match(type="PARAM_VALUE", blocking=True, timeout=5)
print(json.dumps({{"list": names, "set": [m.param_id, m.param_value] if m else None}}))
"""
    try:
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
        out = json.loads(r.stdout.strip().splitlines()[-1])
        assert set(out["list"]) == set(DEFAULT_PARAMS)
        assert out["set"] == ["SID_CONF_MIN", 0.75] and comp.params["SID_CONF_MIN"] == 0.75
    finally:
        stop.set()
        th.join(5)
        comp.close()
        link.close()


def test_rate_parameters_set_from_a_ground_station_are_asked_again(tmp_path):
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.live.session import ListenOptions, LiveSession
    from live_helpers import AIRFRAME

    port = free_port()
    s = LiveSession(load_airframe(AIRFRAME), tmp_path, ListenOptions(f"udpin:127.0.0.1:{port}", learn=None,
                                                                     component=False, console=False))
    try:
        s.requester.result["RAW_IMU"] = "accepted"
        s._params_changed(dict(s.params), dict(s.params, SID_IMU_HZ=20.0, SID_TARGETS=16.0))
        assert s.requester.rates["RAW_IMU"] == 20.0 and s.requester.result == {}
        assert s.params["SID_TARGETS"] == 16.0 and "SID_IMU_HZ=20" in s.events[-1]
    finally:
        s.close()
