"""The CLI as a user meets it: real subprocesses, real files, one-line errors, exit codes."""

import os
import struct
import subprocess
import sys
import time

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mav

from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data"

AIRFRAME = DATA / "airframes" / "sim-trainer.toml"


def run_cli(*args, timeout=300):
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-m", "gcs_sysid.cli", *map(str, args)], capture_output=True,
                          text=True, timeout=timeout, env=env)


def assert_one_line_error(proc, *fragments):
    assert proc.returncode == 2, (proc.returncode, proc.stdout, proc.stderr)
    err = proc.stderr.strip()
    assert "Traceback" not in proc.stderr
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("gcs-sysid: error: ")
    for f in fragments:
        assert f in lines[0], (f, lines[0])


def write_tlog(path, with_imu=True, with_servo=True, seconds=20.0, rate=20.0):
    """A small ArduPlane-like tlog written with pymavlink's encoder (real MAVLink 2 bytes)."""
    link = mav.MAVLink(None, srcSystem=1, srcComponent=1)
    link.robust_parsing = True
    t0 = 1_700_000_000.0
    with open(path, "wb") as f:
        def put(msg, t):
            f.write(struct.pack(">Q", int((t0 + t) * 1e6)) + msg.pack(link))
        n = int(seconds * rate)
        for k in range(n):
            t = 10.0 + k / rate
            ms = int(t * 1000)
            if k % int(rate) == 0:
                put(mav.MAVLink_heartbeat_message(1, 3, 209, 10, 4, 3), t)
            put(mav.MAVLink_attitude_message(ms, 0.01, 0.05, 1.0, 0.0, 0.0, 0.0), t)
            if with_imu:
                put(mav.MAVLink_raw_imu_message(ms * 1000, 0, 0, -1000, 0, 0, 0, 0, 0, 0), t)
            if with_servo:
                put(mav.MAVLink_servo_output_raw_message(ms * 1000, 0, 1500, 1500, 1400, 1500, 0, 0, 0, 0), t)
            put(mav.MAVLink_vfr_hud_message(18.0, 18.0, 57, 40, 100.0, 0.0), t)
            put(mav.MAVLink_global_position_int_message(ms, -353632620, 1491652370, 100000, 50000,
                                                        1000, 1500, 0, 5700), t)
            put(mav.MAVLink_scaled_pressure_message(ms, 1001.0, 1.9, 2000), t)


def test_help_lists_commands():
    p = run_cli("--help")
    assert p.returncode == 0
    for cmd in ("replay", "simulate", "fit", "diagnose"):
        assert cmd in p.stdout


def test_missing_log(tmp_path):
    p = run_cli("replay", tmp_path / "nope.tlog", "--airframe", AIRFRAME, "--out", tmp_path / "o")
    assert_one_line_error(p, "nope.tlog")


def test_empty_log(tmp_path):
    log = tmp_path / "empty.tlog"
    log.write_bytes(b"")
    p = run_cli("replay", log, "--airframe", AIRFRAME, "--out", tmp_path / "o")
    assert_one_line_error(p, "empty.tlog", "empty")


def test_non_mavlink_file(tmp_path):
    log = tmp_path / "notes.tlog"
    log.write_text("this is a text file, not a flight log\n" * 200)
    p = run_cli("replay", log, "--airframe", AIRFRAME, "--out", tmp_path / "o")
    assert_one_line_error(p, "notes.tlog")


def test_random_bytes(tmp_path):
    import numpy as np

    log = tmp_path / "noise.bin"
    log.write_bytes(np.random.default_rng(0).integers(0, 256, 50_000, dtype=np.uint8).tobytes())
    p = run_cli("replay", log, "--airframe", AIRFRAME, "--out", tmp_path / "o")
    assert_one_line_error(p, "noise.bin")


def test_malformed_airframe(tmp_path):
    log = tmp_path / "f.tlog"
    write_tlog(log, seconds=2)
    bad = tmp_path / "bad.toml"
    bad.write_text(AIRFRAME.read_text().replace("mass = 3.0", 'mass = "heavy"'))
    p = run_cli("replay", log, "--airframe", bad, "--out", tmp_path / "o")
    assert_one_line_error(p, "bad.toml", "'mass'")


def test_bad_window(tmp_path):
    log = tmp_path / "f.tlog"
    write_tlog(log, seconds=2)
    p = run_cli("replay", log, "--airframe", AIRFRAME, "--out", tmp_path / "o", "--from", "20", "--to", "10")
    assert_one_line_error(p, "--to")


@pytest.mark.parametrize("what", ["imu", "servo"])
def test_log_without_imu_or_servo_gives_partial_report(tmp_path, what):
    log = tmp_path / f"no_{what}.tlog"
    write_tlog(log, with_imu=(what != "imu"), with_servo=(what != "servo"))
    out = tmp_path / "o"
    p = run_cli("replay", log, "--airframe", AIRFRAME, "--out", out, "--quiet")
    if p.returncode == 2:  # a clear one-line refusal is acceptable ...
        assert_one_line_error(p, f"no_{what}.tlog")
    else:  # ... or a partial report that says what is missing
        assert p.returncode == 0, p.stderr
        summary = (out / "summary.md").read_text().lower()
        assert "missing" in summary
        assert ("imu" in summary) if what == "imu" else ("servo" in summary)


def test_truncated_log_still_decodes_or_says_so(tmp_path):
    log = tmp_path / "f.tlog"
    write_tlog(log, seconds=20)
    data = log.read_bytes()
    cut = tmp_path / "cut.tlog"
    cut.write_bytes(data[: len(data) // 2 + 7])  # ends inside a packet
    out = tmp_path / "o"
    p = run_cli("replay", cut, "--airframe", AIRFRAME, "--out", out, "--quiet")
    assert p.returncode in (0, 2), p.stderr
    assert "Traceback" not in p.stderr
    if p.returncode == 2:
        assert_one_line_error(p, "cut.tlog")
    else:
        assert (out / "report.html").exists()


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """A short flight made by ``gcs-sysid simulate`` (75 s of the sample plan, in its steady 4 m/s wind);
    (log, model it was made from)."""
    import tomllib

    import tomli_w

    tmp_path = tmp_path_factory.mktemp("chain")
    doc = tomllib.loads((DATA / "plans" / "sysid-trainer.toml").read_text())
    doc["duration_s"] = 75.0
    doc["maneuver"] = [m for m in doc["maneuver"] if m["start_s"] < 95.0]
    doc.pop("setpoint", None)
    plan = tmp_path / "plan.toml"
    plan.write_bytes(tomli_w.dumps(doc).encode())
    log = tmp_path / "f.tlog"
    model = DATA / "models" / "sim-trainer.toml"
    p = run_cli("simulate", "--airframe", AIRFRAME, "--model", model, "--maneuvers", plan, "--out", log,
                "--seed", "3")
    assert p.returncode == 0, p.stderr
    assert log.stat().st_size > 100_000
    return log, model


def test_simulate_fit_chain(simulated, tmp_path):
    """The issue-3 commands end to end as a user runs them: simulate a short flight (the fixture), fit a
    model from it; diagnose refuses a model with an unknown coefficient in one line."""
    import tomllib

    log, model = simulated
    fitted = tmp_path / "fitted.toml"
    p = run_cli("fit", log, "--airframe", AIRFRAME, "--out", fitted)
    assert p.returncode == 0, p.stderr
    fit = tomllib.loads(fitted.read_text())
    assert fit["Cm"]["delta_e"] < 0 and fit["Cl"]["p_hat"] < 0  # the damping and control signs survive

    bad = tmp_path / "bad_model.toml"
    bad.write_text(model.read_text() + '\n[Cq]\nalpha = 1.0\n')
    p = run_cli("diagnose", log, "--airframe", AIRFRAME, "--model", bad, "--out", tmp_path / "d2")
    assert_one_line_error(p, "bad_model.toml")


@pytest.mark.slow   # the same cause through a written log: tests/diagnose/test_diagnose_e2e.py, wind case
def test_simulate_diagnose_chain(simulated, tmp_path):
    """Then diagnose the shipped model against the simulated flight as a user runs it."""
    import json

    log, model = simulated
    out = tmp_path / "diag"
    p = run_cli("diagnose", log, "--airframe", AIRFRAME, "--model", model, "--out", out)
    assert p.returncode == 0, p.stderr
    diag = json.loads((out / "diagnosis.json").read_text())
    # the flight was made from this very aero model, but in the plan's steady 4 m/s wind, which the
    # model (aero terms only) does not have: that, and nothing else, is what diagnose must find
    assert [f["cause"] for f in diag["findings"]] == ["wind"], diag["findings"]
    assert 3.0 < diag["findings"][0]["estimate"] < 5.0
    assert (out / "model_extended.toml").exists() and (out / "report.html").exists()
    # the airspeed check's resolution is printed (diagnose.report.pitot_console_lines)
    res = diag["data"]["pitot"]["wind_triangle"]["resolution"]
    assert f"airspeed (pitot) check: {res['summary']}" in p.stdout
