"""Impossible maneuver requests are one-line errors with exit code 2 (zero duration, beyond the surface's travel)."""

import re
from pathlib import Path

import pytest

from gcs_sysid.cli import main

DATA = Path(__file__).resolve().parents[1] / "data"

PLAN = """name = "bad"
duration_s = 20.0
[initial]
airspeed_mps = 20.0
altitude_m = 150.0
[[maneuver]]
kind = "{kind}"
control = "{control}"
start_s = 35.0
amplitude_deg = {amp}
pulse_s = {pulse}
"""


@pytest.mark.parametrize("kind, control, amp, pulse, match", [
    ("doublet", "delta_e", 30.0, 0.5, r"asks delta_e for 30.0 deg, beyond the surface's travel of 20.0 deg"),
    ("3211", "delta_r", -26.0, 0.3, r"asks delta_r for 26.0 deg, beyond the surface's travel of 25.0 deg"),
    ("doublet", "delta_a", 5.0, 0.0, r"'pulse_s' must be > 0"),
])
def test_simulate_refuses_impossible_inputs(tmp_path, capsys, kind, control, amp, pulse, match):
    plan = tmp_path / "bad.toml"
    plan.write_text(PLAN.format(kind=kind, control=control, amp=amp, pulse=pulse))
    rc = main(["simulate", "--airframe", str(DATA / "airframes" / "sim-trainer.toml"),
               "--model", str(DATA / "models" / "sim-trainer.toml"), "--maneuvers", str(plan),
               "--out", str(tmp_path / "x.tlog")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.startswith("gcs-sysid: error:") and "\n" not in err, err
    assert re.search(match, err), err
    assert not (tmp_path / "x.tlog").exists()
