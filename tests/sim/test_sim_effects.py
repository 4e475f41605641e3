"""Each catalogue effect changes what it should: actuators, aero terms, wind, sensors; plan [effects] parsing."""

import math

import numpy as np
import pytest
from conftest import SENSOR_EFFECTS, short_plan_doc

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.errors import InputError
from gcs_sysid.sim import Effects, control_limits, effects_from_dict, plan_from_dict, propagate, simulate, trim
from gcs_sysid.sim import state_from_measurements
from gcs_sysid.sim.dynamics import make_params
from gcs_sysid.sim.environment import RHO0

T5 = 30.0 + np.arange(250) * 0.02
STEP = 50                                      # elevator step at sample 50 (t = 31 s)


def _step_response(airframe, model, effects):
    lo, hi = control_limits(airframe)
    tr = trim(make_params(airframe, model), 20.0, 150.0, 0.3, lo, hi)
    x0 = state_from_measurements(0.0, tr.theta, 0.3, 0, 0, 0, 150.0, V=20.0, alpha=tr.alpha, beta=0.0)
    U = np.tile(tr.controls, (250, 1))
    U[STEP:, 0] -= math.radians(2.0)
    return propagate(airframe, model, x0, T5, U, effects=effects), U


def test_delay_shifts_the_response_by_the_delay(airframe, model):
    ref, U = _step_response(airframe, model, None)
    dly, _ = _step_response(airframe, model, Effects(delay=(0.06, 0.0, 0.0, 0.0)))
    assert np.allclose(dly["q"][STEP + 3:], ref["q"][STEP:-3], atol=1e-9)       # 0.06 s = 3 samples
    assert np.max(np.abs(ref["q"][STEP + 1:STEP + 3])) > 1e-3 and np.allclose(dly["q"][:STEP + 3], ref["q"][0])
    half, _ = _step_response(airframe, model, Effects(delay=(0.05, 0.0, 0.0, 0.0)))
    moved = np.nonzero(np.abs(half["delta_e"] - U[0, 0]) > 1e-9)[0][0]
    assert T5[moved] == pytest.approx(31.06)                                     # first sample at or after 31.05 s


def test_lag_is_first_order(airframe, model):
    lag, U = _step_response(airframe, model, Effects(lag=(0.1, 0.0, 0.0, 0.0)))
    frac = (lag["delta_e"] - U[0, 0]) / (U[-1, 0] - U[0, 0])
    assert frac[STEP - 1] == 0 and frac[STEP + 5] == pytest.approx(1 - math.exp(-21 * 0.005 / 0.1), rel=1e-9)
    assert frac[-1] > 0.999


def test_stuck_surface_stops_responding(airframe, model, short_plan):
    res = simulate(airframe, model, short_plan, effects=Effects(stuck=(math.inf, 37.5, math.inf, math.inf)))
    after = res.t >= 37.5 + 0.02
    assert np.ptp(res.truth["delta_a"][after]) == 0.0
    assert np.ptp(res.commands["delta_a"][after]) > math.radians(3.0)
    assert np.ptp(res.truth["delta_a"][~after]) > 0
    assert res.effects.causes() == ["stuck:delta_a"]


def test_aero_term_effect_is_added_to_the_truth_coefficients(airframe, model, short_plan):
    eff = Effects(aero=(("Cm", "alpha^2", -2.0), ("Cn", "delta_a", 0.02)))
    res = simulate(airframe, model, short_plan, effects=eff)
    d = res.Y - model.evaluate(res.X)
    assert np.allclose(d[:, COEFFICIENTS.index("Cm")], -2.0 * res.X[:, 0] ** 2, atol=1e-12)
    assert np.allclose(d[:, COEFFICIENTS.index("Cn")], 0.02 * res.X[:, 6], atol=1e-12)
    assert np.allclose(np.delete(d, [4, 5], axis=1), 0.0, atol=1e-12)
    assert res.truth_model.value("Cm", "alpha^2") == -2.0 and model.value("Cm", "alpha^2") == 0.0


def test_steady_wind_effect_adds_to_the_plan_wind(airframe, model):
    calm = plan_from_dict(short_plan_doc(turbulence={"w20_mps": 0.0}), "calm.toml")
    res = simulate(airframe, model, calm, effects=Effects(wind_ned=(2.0, 1.0, 0.0)))
    w_plan = np.array(calm.wind_ned)
    for i, k in enumerate(("wn", "we", "wd")):
        assert np.allclose(res.truth[k], w_plan[i] + (2.0, 1.0, 0.0)[i], atol=1e-12)
    # ground velocity = air velocity + wind
    from gcs_sysid.sim.dynamics import dcm

    quat = np.stack([res.truth[f"quat{i}"] for i in range(4)], 1)
    tr = res.truth
    va = tr["V"][:, None] * np.stack([np.cos(tr["alpha"]) * np.cos(tr["beta"]), np.sin(tr["beta"]),
                                      np.sin(tr["alpha"]) * np.cos(tr["beta"])], 1)
    v_ned = np.einsum("nij,nj->ni", dcm(quat), va) + np.stack([tr["wn"], tr["we"], tr["wd"]], 1)
    assert np.allclose(v_ned, np.stack([tr["vn"], tr["ve"], tr["vd"]], 1), atol=1e-9)


def test_sensor_biases_and_scale_show_in_the_sensors(biased_flight, airframe):
    res, e = biased_flight, SENSOR_EFFECTS
    imu = res.sensors["imu"]
    k = np.searchsorted(res.t, imu["t"])
    tr = {key: v[k] for key, v in res.truth.items()}
    for i, key in enumerate("pqr"):
        assert np.mean(imu[key] - tr[key]) == pytest.approx(e["gyro_bias"][i], abs=4 * 0.005 / math.sqrt(len(k)))
    arm = np.asarray(airframe.imu_lever_arm)
    w = np.stack([tr["p"], tr["q"], tr["r"]], 1)
    wd = np.stack([tr["p_dot"], tr["q_dot"], tr["r_dot"]], 1)
    f = np.stack([tr["ax"], tr["ay"], tr["az"]], 1) + np.cross(wd, arm) + np.cross(w, np.cross(w, arm))
    for i, key in enumerate(("ax", "ay", "az")):
        assert np.mean(imu[key] - f[:, i]) == pytest.approx(e["accel_bias"][i], abs=4 * 0.05 / math.sqrt(len(k)))
    eas = res.truth["V"] * np.sqrt(res.truth["rho"] / RHO0)
    slope, icpt = np.polyfit(eas, res.sensors["airspeed"]["eas"], 1)
    assert slope == pytest.approx(1.1, abs=0.05) and icpt == pytest.approx(1.5, abs=1.0)
    aoa = res.sensors["aoa_ssa"]
    k = np.searchsorted(res.t, aoa["t"])
    assert np.mean(aoa["alpha"] - res.truth["alpha"][k]) == pytest.approx(0.05, abs=0.005)
    assert np.mean(aoa["beta"] - res.truth["beta"][k]) == pytest.approx(-0.03, abs=0.01)
    assert sorted(res.effects.causes()) == sorted(["bias:airspeed", "scale:airspeed", "bias:alpha", "bias:beta",
                                                   "bias:gyro_x", "bias:gyro_y", "bias:gyro_z", "bias:accel_x",
                                                   "bias:accel_z"])


def test_effects_table_round_trip_and_errors(airframe):
    doc = {"aero": {"Cl:alpha*beta": 0.1}, "delay_s": {"delta_e": 0.05}, "lag_s": {"delta_r": 0.04},
           "stuck_s": {"delta_a": 120.0}, "bias": {"airspeed": 1.0, "gyro_y": 0.01}, "scale": {"airspeed": 1.05},
           "wind_ned": [3.0, -1.0, 0.0], "mass_delta_kg": 0.2, "inertia_delta": {"Ixz": 0.01},
           "cg_offset_m": [0.02, 0.0, 0.0]}
    eff = effects_from_dict(doc, "p.toml")
    assert effects_from_dict(eff.to_dict()) == eff
    assert eff.causes() == ["Cl:alpha*beta", "delay:delta_e", "delay:delta_r", "stuck:delta_a", "bias:airspeed",
                            "scale:airspeed", "bias:gyro_y", "wind", "mass", "inertia:Ixz", "cg_offset"]
    for bad, words in (({"delay": {}}, "unknown key 'delay'"), ({"delay_s": {"elevator": 0.1}}, "'elevator'"),
                       ({"aero": {"CL:alpha": 1.0}}, "'<coef>:<term>'"),
                       ({"aero": {"Cm:beta*alpha": 1.0}}, r"write 'alpha\*beta'"),
                       ({"delay_s": {"delta_e": -0.1}}, ">= 0"), ({"wind_ned": [1, 2]}, "3 numbers")):
        with pytest.raises(InputError, match=words) as ex:
            effects_from_dict(bad, "p.toml")
        assert str(ex.value).startswith("p.toml")
    with pytest.raises(InputError, match="unphysical"):
        Effects(mass_delta=-5.0).apply_airframe(airframe)
