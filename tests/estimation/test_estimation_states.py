"""estimate_states on synthetic flights with known truth: accuracy, partial logs, low rates."""

from dataclasses import replace

import numpy as np
import pytest
from synthetic_flight import flight_from_truth, truth

from gcs_sysid.airframe import airframe_from_dict
from gcs_sysid.errors import DataError
from gcs_sysid.estimation import estimate_states
from gcs_sysid.estimation.ekf import smooth_attitude
from gcs_sysid.estimation.rates import smooth_rates

LEVER = (0.05, 0.0, -0.02)


@pytest.fixture(scope="module")
def airframe():
    servo = lambda name, ch, mix, sign=1.0: {  # noqa: E731
        "name": name, "channel": ch, "pwm_min": 1100, "pwm_trim": 1500, "pwm_max": 1900,
        "deflection_at_pwm_min_deg": -20.0 * sign, "deflection_at_pwm_max_deg": 20.0 * sign, "mix": mix}
    return airframe_from_dict({
        "name": "synthetic", "mass": 3.0, "inertia": {"Ixx": 0.3, "Iyy": 0.35, "Izz": 0.6, "Ixz": 0.02},
        "geometry": {"S": 0.55, "b": 2.0, "c": 0.28}, "imu_lever_arm": list(LEVER),
        "servo": [servo("aileron", 1, {"delta_a": 1.0}), servo("elevator", 2, {"delta_e": 1.0}, -1.0),
                  servo("rudder", 4, {"delta_r": 1.0})],
        "throttle": {"channel": 3}})


@pytest.fixture(scope="module")
def tr():
    return truth(60.0, lever=LEVER)


@pytest.fixture(scope="module")
def full(tr, airframe):
    return estimate_states(flight_from_truth(tr, seed=1), airframe)


def _rms(x):
    return float(np.sqrt(np.nanmean(np.asarray(x) ** 2)))


def _err(st, tr, key):
    m = st.valid.copy()
    m[:50] = m[-50:] = False           # smoother ends
    e = st[key] - tr.at(key, st.t)
    if key == "psi":
        e = np.mod(e + np.pi, 2 * np.pi) - np.pi
    return _rms(e[m]), _rms(tr.at(key, st.t)[m])


def test_full_flight_recovers_the_truth(full, tr):
    st = full
    assert st.rate_hz == 50.0 and st.valid.mean() > 0.95 and not st.missing
    for k, tol_rel in (("p_dot", 0.05), ("q_dot", 0.06), ("r_dot", 0.08)):
        e, ref = _err(st, tr, k)
        assert e < tol_rel * ref, (k, e, ref)
    for k, tol in (("phi", 2e-3), ("theta", 2e-3), ("psi", 3e-3), ("p", 5e-3), ("q", 5e-3), ("r", 5e-3),
                   ("alpha", 3e-3), ("beta", 3e-3), ("V", 0.1), ("wn", 0.15), ("we", 0.15),
                   ("u", 0.1), ("v", 0.1), ("w", 0.1), ("ax", 0.08), ("ay", 0.08), ("az", 0.08)):
        e, _ = _err(st, tr, k)
        assert e < tol, (k, e)
    # qbar consistent with rho and V; controls decoded from PWM (elevator servo reversed)
    np.testing.assert_allclose(st["qbar"], 0.5 * st["rho"] * st["V"] ** 2)
    assert set(np.round(np.degrees(st["delta_a"][st.valid]), 6)) == {-5.0, 5.0}
    assert set(np.round(np.degrees(st["delta_e"][st.valid]), 6)) == {-4.0, 4.0}
    np.testing.assert_allclose(st["delta_t"][st.valid], 0.6)
    assert st.identifiability["moment_coefficients"][0] and st.identifiability["beta"][0]
    assert "autopilot" in st.sources["wind"] and "prior" in st.sources["wind"]


def test_gyro_bias_and_attitude_from_the_ekf(tr):
    fl = flight_from_truth(tr, seed=2, gyro_bias=(0.02, -0.03, 0.01))
    from gcs_sysid.estimation.align import events, make_grid, resample
    t, rate = make_grid(fl, 50.0)
    gyro = np.stack([resample(fl["imu"].t, fl["imu"][k], t)[0] for k in "pqr"], 1)
    att = events(fl["attitude"], ("roll", "pitch", "yaw"), t, angles=("roll", "pitch", "yaw"))
    A = smooth_attitude(1 / rate, gyro, att, 0.003)
    np.testing.assert_allclose(A.gyro_bias[100:-100].mean(0), [0.02, -0.03, 0.01], atol=1e-3)
    assert _rms(A.euler[100:-100, 0] - tr.at("phi", t)[100:-100]) < 2e-3


def test_sinusoidal_rate_derivative_within_two_percent():
    rng = np.random.default_rng(7)
    dt = 0.02
    t = np.arange(0, 120, dt)
    w = 0.4 * np.sin(2 * np.pi * 0.5 * t) + 0.2 * np.sin(2 * np.pi * 1.5 * t)
    wd = 0.4 * np.pi * np.cos(2 * np.pi * 0.5 * t) + 0.6 * np.pi * np.cos(2 * np.pi * 1.5 * t)
    z = np.stack([w + rng.normal(0, 0.003, len(t))] * 3, 1)
    R = smooth_rates(dt, z)
    e = R.accel[50:-50, 0] - wd[50:-50]
    assert _rms(e) < 0.02 * _rms(wd)
    assert 0.5 < _rms(e) / np.median(R.accel_sigma[:, 0]) < 2.0   # the 1-sigma is honest


def test_no_servo_gives_partial_states(tr, airframe):
    st = estimate_states(flight_from_truth(tr, omit=("servo",)), airframe)
    assert "delta_e" not in st.data and any(m.startswith("delta_e") for m in st.missing)
    assert not st.valid.any() and "p_dot" in st.data
    assert st.sources["delta_t"].startswith("VFR_HUD")


def test_no_airspeed_uses_the_autopilot_wind(tr, airframe):
    st = estimate_states(flight_from_truth(tr, omit=("airspeed", "vfr_hud")), airframe)
    assert "autopilot" in st.sources["wind"] and any("autopilot" in n for n in st.notes)
    np.testing.assert_allclose(np.mean(st["wn"]), 5.0, atol=0.2)   # the autopilot's estimate is 1 m/s off


def test_no_gps_falls_back_to_aoa_ssa(tr, airframe):
    st = estimate_states(flight_from_truth(tr, omit=("gps",)), airframe)
    assert "AOA_SSA" in st.sources["alpha"] and not st.identifiability["beta"][0]
    assert any(m.startswith("vn") for m in st.missing) and "V" in st.data


def test_attitude_only_log_and_empty_log(tr, airframe):
    st = estimate_states(flight_from_truth(tr, omit=("imu",)), airframe)
    assert "phi" in st.data and "p_dot" not in st.data and not st.valid.any()
    with pytest.raises(DataError, match="no IMU"):
        estimate_states(flight_from_truth(tr, omit=("imu", "attitude")), airframe)


def test_low_rate_log_says_what_is_not_identifiable(tr, airframe):
    fl = flight_from_truth(tr, imu_hz=4.0, att_hz=4.0, servo_hz=4.0, gps_hz=4.0, arsp_hz=4.0)
    fracs = []
    st = estimate_states(fl, airframe, progress=fracs.append)
    assert st.rate_hz == pytest.approx(4.0, rel=0.05)
    ok, why = st.identifiability["rate_derivatives"]
    assert not ok and "SRx_RAW_SENS" in why
    assert not st.identifiability["moment_coefficients"][0]
    assert not st.identifiability["Cm"][0] and st.identifiability["CZ"][0]
    assert any("not identifiable" in n for n in st.notes)
    assert fracs == sorted(fracs) and fracs[-1] == 1.0


def test_meanwhile_runs_once_while_the_force_smoother_is_pending_and_changes_nothing(tr, airframe, full):
    """``estimate_states(meanwhile=)`` (the replay's later imports overlap the worker's specific-force smoother):
    called once, after the force smoother was handed over and before its result is collected; the states are
    the same bit for bit as without it."""
    from gcs_sysid.parallel import Helper

    calls = []

    class Recording(Helper):
        def submit(self, target, *args, **kwargs):
            job = super().submit(target, *args, **kwargs)
            calls.append(("submit", target))
            result = job.result

            def collected():
                calls.append(("result", target))
                return result()
            job.result = collected
            return job

    st = estimate_states(flight_from_truth(tr, seed=1), airframe, helper=Recording(enabled=False),
                         meanwhile=lambda: calls.append(("meanwhile", None)))
    sf = "gcs_sysid.estimation.rates:smooth_specific_force"
    assert calls == [("submit", sf), ("meanwhile", None), ("result", sf)]
    assert st.data.keys() == full.data.keys()
    for k in full.data:
        np.testing.assert_array_equal(st.data[k], full.data[k], err_msg=k)
    # no accelerometer: no smoother to wait for, and meanwhile is not run
    flight = flight_from_truth(tr, seed=1)
    imu = flight.streams["imu"]
    flight.streams["imu"] = replace(imu, fields={k: v for k, v in imu.fields.items() if k not in ("ax", "ay", "az")})
    calls.clear()
    estimate_states(flight, airframe, meanwhile=lambda: calls.append(("meanwhile", None)))
    assert calls == []
