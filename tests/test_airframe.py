import math

import numpy as np
import pytest

from gcs_sysid.airframe import airframe_from_dict, airframe_to_dict, load_airframe
from gcs_sysid.errors import InputError


def _doc():
    return {
        "name": "t", "mass": 2.0,
        "inertia": {"Ixx": 0.2, "Iyy": 0.3, "Izz": 0.45, "Ixz": 0.01},
        "geometry": {"S": 0.5, "b": 2.0, "c": 0.25},
        "servo": [
            {"name": "elevon_left", "channel": 1, "deflection_at_pwm_min_deg": -20, "deflection_at_pwm_max_deg": 20,
             "mix": {"delta_e": 0.5, "delta_a": -0.5}},
            {"name": "elevon_right", "channel": 2, "deflection_at_pwm_min_deg": 20, "deflection_at_pwm_max_deg": -20,
             "mix": {"delta_e": 0.5, "delta_a": 0.5}},
        ],
        "throttle": {"channel": 3},
        "thrust": {"T_static": 20.0, "V_zero": 30.0},
    }


def test_shipped_airframes_load(data_dir):
    for p in sorted((data_dir / "airframes").glob("*.toml")):
        a = load_airframe(p)
        assert a.mass > 0 and a.S > 0 and a.servos


def test_pwm_map_piecewise_linear_and_inverse():
    a = airframe_from_dict(_doc())
    s = a.servos[0]
    assert s.deflection(np.array([1500.0]))[0] == 0.0
    assert math.isclose(s.deflection(np.array([1900.0]))[0], math.radians(20))
    assert math.isclose(s.deflection(np.array([1300.0]))[0], math.radians(-10))
    assert np.isnan(s.deflection(np.array([0.0]))[0])  # unpowered output
    d = np.radians([-15.0, -3.0, 0.0, 7.0, 20.0])
    assert np.allclose(s.deflection(s.pwm(d)), d)


def test_elevon_mixing_round_trip():
    a = airframe_from_dict(_doc())
    # both elevons trailing edge down by 10 deg -> pure delta_e
    pwm = {1: a.servos[0].pwm(np.radians([10.0])), 2: a.servos[1].pwm(np.radians([10.0])), 3: np.array([1500.0])}
    c = a.controls_from_pwm(pwm)
    assert np.allclose(c["delta_e"], np.radians(10)) and np.allclose(c["delta_a"], 0)
    assert np.allclose(c["delta_t"], 0.5)
    u = {"delta_e": np.array([0.05]), "delta_a": np.array([-0.08]), "delta_r": np.array([0.0]),
         "delta_t": np.array([0.3])}
    back = a.controls_from_pwm(a.pwm_from_controls(u))
    for k in ("delta_e", "delta_a", "delta_t"):
        assert np.allclose(back[k], u[k])
    assert "delta_r" not in back  # no servo drives the rudder: the control is absent, not zero


def test_thrust_model():
    a = airframe_from_dict(_doc())
    assert math.isclose(float(a.thrust.thrust(1.0, 0.0)), 20.0)
    assert math.isclose(float(a.thrust.thrust(0.5, 15.0)), 20.0 * 0.25 * 0.5)
    assert float(a.thrust.thrust(1.0, 40.0)) == 0.0


def test_to_dict_round_trip():
    a = airframe_from_dict(_doc())
    b = airframe_from_dict(airframe_to_dict(a))
    assert a == b


@pytest.mark.parametrize("mutate, fragment", [
    (lambda d: d.pop("mass"), "missing required field 'mass'"),
    (lambda d: d.update(mass=-1), "'mass' must be > 0"),
    (lambda d: d["inertia"].update(Izz=5.0), "triangle inequality"),
    (lambda d: d["servo"][0].update(pwm_trim=2100), "pwm_min < pwm_trim < pwm_max"),
    (lambda d: d["servo"][1].update(channel=1), "channel 1 is already used"),
    (lambda d: d["servo"][0].update(mix={"delta_x": 1}), "mix key 'delta_x'"),
    (lambda d: d["servo"][0].update(deflection_at_pwm_max_deg=-20), "opposite sign"),
    (lambda d: d.update(wing=1), "unknown top-level field 'wing'"),
    (lambda d: d.pop("throttle"), "no [throttle] channel"),
    (lambda d: d.update(imu_lever_arm=[0, 1]), "imu_lever_arm"),
])
def test_validation_names_the_field(mutate, fragment):
    d = _doc()
    mutate(d)
    with pytest.raises(InputError, match=None) as e:
        airframe_from_dict(d, "x.toml")
    assert fragment in str(e.value) and str(e.value).startswith("x.toml: ")


def test_load_errors(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_airframe(tmp_path / "nope.toml")
    p = tmp_path / "bad.toml"
    p.write_text("name = [unclosed\n")
    with pytest.raises(InputError, match="not valid TOML"):
        load_airframe(p)


def _aiding_sees(monkeypatch, a, flag: str, key: str) -> list:
    """What the aiding (``aided_air_angles``) is handed as its keyword ``key`` when ``est._aid_angles`` runs on the
    airframe ``a`` with the opt-in ``airangles.<flag>`` off, then on (the aiding is stubbed to record and raise)."""
    import gcs_sysid.estimation.airangles as aa
    import gcs_sysid.estimation.estimate as est

    seen = []
    monkeypatch.setattr(est, "aided_air_angles", lambda *x, **k: seen.append(k[key]) or 1 / 0)
    for on in (False, True):
        monkeypatch.setattr(aa, flag, on)
        with pytest.raises(ZeroDivisionError):
            z = np.zeros(1)
            est._aid_angles(0.02, z, z, z + 1.0, 1.2, np.zeros((1, 3)), 0.0, np.zeros((1, 3)),
                            {"delta_e": 0, "delta_a": 0, "delta_r": 0}, a, np.ones(1, bool), None, None, {}, {}, [])
    return seen


def test_stated_lift_derivatives(monkeypatch):
    """``[aero] CL_alpha``, ``CL_q`` (the aided alpha's stated lift-slope floor) are read, written back, checked, and
    reach the aiding only with the opt-in ``STATED_LIFT_SLOPE``."""
    d = _doc()
    assert airframe_from_dict(d).CL_alpha is None and "aero" not in airframe_to_dict(airframe_from_dict(d))
    d["aero"] = {"CL_alpha": 5.5, "CL_q": 7.1}
    a = airframe_from_dict(d)
    assert (a.CL_alpha, a.CL_q) == (5.5, 7.1)
    assert airframe_from_dict(airframe_to_dict(a)) == a
    for bad, frag in (({"CL_alpha": -5.5}, "CL_alpha"), ({"CL_q": 7.0}, "only with CL_alpha"),
                      ({"CL_alpha": 5.5, "CL_q": -1.0}, "CL_q"), ({"CL_alpha": 5.5, "Cm_q": 1.0}, "[aero]")):
        d["aero"] = bad
        with pytest.raises(InputError, match=frag.replace("[", r"\[")):
            airframe_from_dict(d)
    assert _aiding_sees(monkeypatch, a, "STATED_LIFT_SLOPE", "stated_slopes") == [None, (5.5, 7.1)]


def test_stated_lift_line(monkeypatch):
    """``[aero] CL0``, ``CL_delta_e``, ``CL0_sigma`` (the stated lift line that sets the aided alpha's flight mean) are
    read, written back, checked, and reach the aiding only with the opt-in ``STATED_LIFT_LEVEL``."""
    d = _doc()
    d["aero"] = {"CL_alpha": 3.57, "CL_q": 1.05, "CL0": 0.252, "CL_delta_e": 0.16, "CL0_sigma": 0.01}
    a = airframe_from_dict(d)
    assert (a.CL0, a.CL_delta_e, a.CL0_sigma) == (0.252, 0.16, 0.01)
    assert airframe_from_dict(airframe_to_dict(a)) == a
    assert airframe_from_dict(_doc()).CL0 is None
    for bad, frag in (({"CL0": 0.2}, "only with CL_alpha"), ({"CL_alpha": 5.0, "CL_delta_e": 0.3}, "only with CL0"),
                      ({"CL_alpha": 5.0, "CL0": 0.2, "CL0_sigma": 0.0}, "CL0_sigma"),
                      ({"CL_alpha": 5.0, "CL0": "x"}, "CL0")):
        d["aero"] = bad
        with pytest.raises(InputError, match=frag):
            airframe_from_dict(d)
    assert _aiding_sees(monkeypatch, a, "STATED_LIFT_LEVEL", "stated_level") == [
        None, {"CL0": 0.252, "CL_alpha": 3.57, "CL_q": 1.05, "CL_delta_e": 0.16, "CL0_sigma": 0.01}]
