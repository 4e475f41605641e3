"""Coefficient equations against a hand case and against the vector form of Euler's equations."""

import numpy as np
import pytest

from gcs_sysid.aero import REGRESSORS, aero_moments, compute_coefficients
from gcs_sysid.airframe import airframe_from_dict
from gcs_sysid.estimation.states import FlightStates


def _airframe(thrust=True):
    d = {"name": "hand", "mass": 3.0, "inertia": {"Ixx": 0.3, "Iyy": 0.35, "Izz": 0.6, "Ixz": 0.02},
         "geometry": {"S": 0.55, "b": 2.0, "c": 0.28},
         "servo": [{"name": "elevator", "channel": 2, "deflection_at_pwm_min_deg": -20.0,
                    "deflection_at_pwm_max_deg": 20.0, "mix": {"delta_e": 1.0}}],
         "throttle": {"channel": 3}}
    if thrust:
        d["thrust"] = {"T_static": 30.0, "V_zero": 40.0, "exponent": 2.0}
    return airframe_from_dict(d)


HAND = dict(p=0.5, q=0.2, r=-0.1, p_dot=2.0, q_dot=-1.0, r_dot=0.5, ax=1.0, ay=-0.5, az=-9.0, V=20.0,
            alpha=0.05, beta=0.01, qbar=0.5 * 1.225 * 400.0, delta_e=0.1, delta_a=-0.05, delta_r=0.02, delta_t=0.5)


def _states(values, n=3, valid=None):
    data = {k: np.full(n, v, float) for k, v in values.items()}
    return FlightStates(np.arange(n) * 0.02, 50.0, data, valid=np.ones(n, bool) if valid is None else valid)


def test_hand_case():
    tab = compute_coefficients(_states(HAND), _airframe())
    # worked by hand: qbar = 245 Pa, qS = 134.75 N, qSb = 269.5 N m, qSc = 37.73 N m
    # L = 0.6 - 0.02*0.6 + 0.25*(-0.02) = 0.583; M = -0.35 + (-0.3)(-0.05) + 0.02*0.24 = -0.3302
    # N = 0.3 - 0.02*2.02 + 0.05*0.1 = 0.2646; thrust = 30*0.25*0.5 = 3.75 N
    expect = {"CX": (3.0 - 3.75) / 134.75, "CY": -1.5 / 134.75, "CZ": -27.0 / 134.75,
              "Cl": 0.583 / 269.5, "Cm": -0.3302 / 37.73, "Cn": 0.2646 / 269.5}
    for k, v in expect.items():
        assert tab.y(k)[0] == pytest.approx(v, rel=1e-9), k
    assert tab.x("p_hat")[0] == pytest.approx(0.025)
    assert tab.x("q_hat")[0] == pytest.approx(0.0014)
    assert tab.x("r_hat")[0] == pytest.approx(-0.005)
    for k in ("alpha", "beta", "delta_e", "delta_a", "delta_r", "delta_t", "V"):
        assert tab.x(k)[0] == HAND[k]
    assert tab.X.shape == (3, len(REGRESSORS)) and tab.valid.all()
    assert tab.qbar[0] == pytest.approx(245.0)


def test_moments_match_the_vector_euler_equation():
    rng = np.random.default_rng(0)
    af = _airframe()
    w, wd = rng.normal(size=(100, 3)), rng.normal(size=(100, 3))
    ref = wd @ af.inertia.T + np.cross(w, w @ af.inertia.T)    # I w_dot + w x (I w)
    L, M, N = aero_moments(af, *w.T, *wd.T)
    np.testing.assert_allclose(np.stack([L, M, N], 1), ref, rtol=1e-12, atol=1e-12)


def test_without_thrust_model_cx_includes_thrust():
    tab = compute_coefficients(_states(HAND), _airframe(thrust=False))
    assert tab.y("CX")[0] == pytest.approx(3.0 / 134.75)
    assert any("CX includes thrust" in n for n in tab.notes)


def test_invalid_rows_missing_keys_and_identifiability_notes():
    vals = dict(HAND)
    del vals["delta_r"]
    st = _states(vals, valid=np.array([True, True, False]))
    st.data["qbar"][1] = 1.0                      # too small a dynamic pressure
    st.identifiability["moment_coefficients"] = (False, "gyro at 4.0 Hz")
    tab = compute_coefficients(st, _airframe())
    assert not tab.valid.any()                    # delta_r missing everywhere
    assert np.isnan(tab.x("delta_r")).all()
    assert any("no delta_r" in n for n in tab.notes)
    assert any("Cl Cm Cn not identifiable: gyro at 4.0 Hz" in n for n in tab.notes)
    st2 = _states(HAND, valid=np.array([True, True, False]))
    st2.data["qbar"][1] = 1.0
    np.testing.assert_array_equal(compute_coefficients(st2, _airframe()).valid, [True, False, False])


def test_gust_rates_make_the_hats_air_relative_and_leave_the_moments_alone():
    n = 400
    t = np.arange(n) * 0.02
    vals = dict(HAND, phi=0.0, theta=0.0, psi=0.0, wn=0.0, we=0.0)
    st = _states(vals, n)
    st.data["wd"] = 0.8 * np.sin(2 * np.pi * 0.5 * t)         # a vertical gust
    af = _airframe()
    base = compute_coefficients(st, af)
    air = compute_coefficients(st, af, gust_rates="path")
    from gcs_sysid.estimation.ekf import dcm
    from gcs_sysid.estimation.gustrates import gust_rates

    G = gust_rates(0.02, dcm(t * 0, t * 0, t * 0), np.stack([t * 0, t * 0, st.data["wd"]], 1), np.full(n, 20.0),
                   af.b, "path")
    assert np.max(np.abs(G.rates[:, 1])) > 1e-3
    np.testing.assert_allclose(air.x("q_hat"), (HAND["q"] - G.rates[:, 1]) * af.c / 40.0, rtol=1e-12)
    np.testing.assert_allclose(air.x("p_hat"), base.x("p_hat"))       # p_g is not observable: 0
    np.testing.assert_allclose(air.Y, base.Y)                         # moments use the inertial rates
    assert any("relative to the air" in n for n in air.notes)
    # without attitude or wind the hats stay inertial, and the table says why
    st2 = _states(HAND, n)
    tab = compute_coefficients(st2, af, gust_rates="path")
    np.testing.assert_allclose(tab.X, compute_coefficients(st2, af).X)
    assert any("not removed" in n and "phi" in n for n in tab.notes)
