"""Plan files: the shipped plan, defaults, and one-line errors naming the file and key."""

import math

import pytest
from conftest import short_plan_doc

from gcs_sysid.errors import DataError, InputError
from gcs_sysid.sim import load_plan, plan_from_dict, simulate


def test_plan_fields_and_defaults():
    p = plan_from_dict(short_plan_doc(), "short.toml")
    assert p.n_ticks == 1000 and p.internal_rate_hz == 200.0 and p.start_time == 30.0
    assert p.home[2] == 50.0 and p.setpoints[0].heading == pytest.approx(math.radians(30.0))
    assert p.wind_ned[0] == pytest.approx(-3.0 * math.cos(math.radians(200.0)))       # from 200 deg
    m = p.maneuvers[0]
    assert (m.kind, m.controls, m.mode, m.end) == ("3211", ("delta_e",), "open", pytest.approx(34.1))
    assert m.amplitude[0] == pytest.approx(math.radians(2.0))
    ms = p.maneuvers[-1]
    assert ms.controls == ("delta_e", "delta_a") and ms.band == (0.4, 2.0) and ms.duration == 5.0


@pytest.mark.parametrize("change, words", [
    ({"durration_s": 5}, "unknown key 'durration_s'"),
    ({"initial": {"altitude_m": 100.0}}, "[initial] is missing 'airspeed_mps'"),
    ({"internal_rate_hz": 130.0}, "whole multiple"),
    ({"maneuver": [{"kind": "sweep", "control": "delta_e", "start_s": 31, "pulse_s": 1, "amplitude_deg": 1}]},
     "[[maneuver]] #1 kind must be one of"),
    ({"maneuver": [{"kind": "doublet", "control": "delta_e", "start_s": 49.5, "pulse_s": 1, "amplitude_deg": 1}]},
     "outside the flight 30-50 s"),
    ({"maneuver": [{"kind": "doublet", "control": "aileron", "start_s": 31, "pulse_s": 1, "amplitude_deg": 1}]},
     "needs control = one of"),
    ({"maneuver": [{"kind": "multisine", "controls": ["delta_e", "delta_a", "delta_r"], "start_s": 31,
                    "duration_s": 2.0, "band_hz": [0.6, 0.9], "amplitude_deg": 1}]}, "fewer than the 3 inputs"),
    ({"turbulence": {"intensity": "strong"}}, "intensity must be one of"),
    ({"sensors": {"gyros": 0.1}}, "[sensors] unknown key 'gyros'"),
    ({"setpoint": [{"start_s": 20.0}]}, "[[setpoint]] #1 start_s must increase"),
])
def test_plan_errors(change, words):
    with pytest.raises(InputError) as e:
        plan_from_dict(short_plan_doc(**change), "p.toml")
    assert str(e.value).startswith("p.toml:") and words in str(e.value) and "\n" not in str(e.value)


def test_untrimmable_setpoint_is_a_data_error(airframe, model):
    plan = plan_from_dict(short_plan_doc(setpoint=[{"start_s": 40.0, "airspeed_mps": 45.0}]), "fast.toml")
    with pytest.raises(DataError, match=r"fast.toml: \[\[setpoint\]\] #1 cannot trim at 45 m/s"):
        simulate(airframe, model, plan)


def test_load_plan_file_errors(tmp_path):
    with pytest.raises(InputError, match="plan file not found"):
        load_plan(tmp_path / "none.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("duration_s = = 3")
    with pytest.raises(InputError, match="not valid TOML"):
        load_plan(bad)
