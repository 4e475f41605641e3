"""Gust rates from gust velocities: the MIL-F-8785C filters, Etkin's signs, the frames."""

import numpy as np
import pytest

from gcs_sysid.estimation.ekf import dcm
from gcs_sysid.estimation.gustrates import gust_rates, lag_filter

DT, V, B = 0.02, 20.0, 2.0


def _grid(n=3000):
    return np.arange(n) * DT


def _steady(amp, omega, tau, t, sign):
    """Steady-state response of sign * (s/V)/(1 + tau s) to amp*sin(omega t)."""
    g = amp * omega / V / np.sqrt(1.0 + (omega * tau) ** 2)
    return sign * g * np.cos(omega * t - np.arctan(omega * tau))


def test_lag_filter_matches_the_continuous_step_response():
    t = _grid(500)
    y = lag_filter(DT, np.ones(500) * 2.0, 0.3)
    assert y[0] == 2.0                                # started at the input: no transient
    x = np.r_[0.0, np.ones(499)]
    y = lag_filter(DT, x, 0.3)
    np.testing.assert_allclose(y[1:], 1.0 - np.exp(-t[1:] / 0.3), atol=1e-12)   # exact for a held step


def test_path_frame_vertical_gust_gives_minus_dw_dx_through_the_lag():
    t = _grid()
    om, A = 2 * np.pi * 0.3, 1.5
    wind = np.zeros((len(t), 3))
    wind[:, 0] = 4.0                                  # a steady wind changes nothing
    wind[:, 2] = A * np.sin(om * t)                   # vertical gust (down)
    C = dcm(np.zeros_like(t), np.zeros_like(t), np.zeros_like(t))
    G = gust_rates(DT, C, wind, np.full(len(t), V), B, "path")
    tau = 4 * B / (np.pi * V)
    ref = _steady(A, om, tau, t, -1.0)                # q_g = -(s/V)/(1 + 4b s/(pi V)) w_g
    s = t > 10 * tau
    assert np.max(np.abs(G.rates[s, 1] - ref[s])) < 0.03 * np.max(np.abs(ref))
    assert np.all(G.rates[:, 0] == 0.0) and np.max(np.abs(G.rates[:, 2])) < 1e-12
    assert any("p_g = 0" in n for n in G.notes)


def test_path_frame_lateral_gust_heading_east():
    t = _grid()
    om, A = 2 * np.pi * 0.2, 1.0
    wind = np.zeros((len(t), 3))
    wind[:, 0] = A * np.sin(om * t)                   # a north gust is -v_g for a body heading east
    z = np.zeros_like(t)
    G = gust_rates(DT, dcm(z, z, z + np.pi / 2), wind, np.full(len(t), V), B, "path")
    tau = 3 * B / (np.pi * V)
    ref = _steady(A, om, tau, t, -1.0)                # r_g = +(s/V)/(1 + 3b s/(pi V)) v_g, v_g = -north
    s = t > 10 * tau
    assert np.max(np.abs(G.rates[s, 2] - ref[s])) < 0.03 * np.max(np.abs(ref))
    assert np.max(np.abs(G.rates[:, 1])) < 1e-12


def test_steady_wind_seen_from_a_turning_body_is_no_gust():
    t = _grid()
    wind = np.tile([5.0, -3.0, 0.0], (len(t), 1))
    C = dcm(0.3 * np.sin(t), 0.1 * np.cos(0.5 * t), 0.4 * t)
    for frame in ("path", "mean-wind"):
        assert np.max(np.abs(gust_rates(DT, C, wind, np.full(len(t), V), B, frame).rates)) < 1e-12


def test_mean_wind_frame_puts_the_vertical_gust_term_on_the_wind_y_axis():
    t = _grid()
    om, A = 2 * np.pi * 0.3, 1.5
    wind = np.zeros((len(t), 3))
    wind[:, 0] = 6.0                                  # mean wind towards north: wind-frame y = east
    wind[:, 2] = A * np.sin(om * t)
    z = np.zeros_like(t)
    G = gust_rates(DT, dcm(z, z, z + np.pi / 2), wind, np.full(len(t), V), B, "mean-wind")   # heading east
    ref = _steady(A, om, 4 * B / (np.pi * V), t, +1.0)   # JSBSim's sign, on body x (= east)
    s = t > 5.0
    assert np.max(np.abs(G.rates[s, 0] - ref[s])) < 0.03 * np.max(np.abs(ref))
    assert np.max(np.abs(G.rates[:, 1])) < 1e-9
    np.testing.assert_allclose(G.mean_wind, [6.0, 0.0], atol=1e-9)


def test_bad_input_raises():
    t = _grid(10)
    C = dcm(t * 0, t * 0, t * 0)
    with pytest.raises(ValueError, match="frame must be one of"):
        gust_rates(DT, C, np.zeros((10, 3)), np.full(10, V), B, "body")
    with pytest.raises(ValueError, match="wind_ned"):
        gust_rates(DT, C, np.zeros((9, 3)), np.full(10, V), B)
    with pytest.raises(ValueError, match="span"):
        gust_rates(DT, C, np.zeros((10, 3)), np.full(10, V), 0.0)


def test_rows_without_airspeed_are_nan():
    t = _grid(200)
    V_ = np.full(200, V)
    V_[50:60] = np.nan
    G = gust_rates(DT, dcm(t * 0, t * 0, t * 0), np.zeros((200, 3)), V_, B)
    assert np.isnan(G.rates[50:60]).all() and np.isfinite(G.rates[:50]).all() and np.isfinite(G.rates[60:]).all()


def test_path_yaw_frame_keeps_r_g_and_leaves_q_g_at_zero():
    t = _grid()
    wind = np.zeros((len(t), 3))
    wind[:, 1] = np.sin(2 * np.pi * 0.2 * t)          # a lateral gust (east = body y heading north)
    wind[:, 2] = 1.5 * np.sin(2 * np.pi * 0.3 * t)    # and a vertical one
    C = dcm(np.zeros_like(t), np.zeros_like(t), np.zeros_like(t))
    full = gust_rates(DT, C, wind, np.full(len(t), V), B, "path")
    yaw = gust_rates(DT, C, wind, np.full(len(t), V), B, "path-yaw")
    np.testing.assert_array_equal(yaw.rates[:, 2], full.rates[:, 2])
    assert np.max(np.abs(full.rates[:, 1])) > 0.01
    assert np.all(yaw.rates[:, :2] == 0.0)
    assert any("q_g = 0" in n for n in yaw.notes)
