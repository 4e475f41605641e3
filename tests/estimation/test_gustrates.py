"""Gust rates from gust velocities: the MIL-F-8785C filters, Etkin's signs, the frames."""

import numpy as np
import pytest

from gcs_sysid.estimation.ekf import dcm
from gcs_sysid.estimation.gustrates import (DRYDEN_L, DRYDEN_RATE_FACTORS, dryden_rate_sigma, gust_intensity,
                                             gust_rates, lag_filter)

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


def _dryden_field(sigma, L, dx, n, rng):
    """A frozen Dryden transverse gust along the path, ``(n,)`` m/s at spacing ``dx`` m: random phases on MIL-F-8785C's
    one-sided spectrum ``sigma^2 L/pi (1 + 3 L^2 W^2) / (1 + L^2 W^2)^2`` (rad/m), so its variance is ``sigma^2``."""
    W = 2 * np.pi * np.fft.rfftfreq(n, dx)
    dW = W[1]
    phi = sigma**2 * L / np.pi * (1 + 3 * (L * W) ** 2) / (1 + (L * W) ** 2) ** 2
    amp = np.sqrt(2 * phi * dW) * n / 2
    amp[0] = 0.0
    spec = amp * np.exp(1j * rng.uniform(0, 2 * np.pi, len(W)))
    return np.fft.irfft(spec, n), W, spec


def test_gust_intensity_recovers_a_dryden_fields_sigma_and_hardly_depends_on_the_scale_length():
    rng = np.random.default_rng(3)
    sigma, L, Vg, dt = 1.8, 533.4, 25.0, 0.02
    n = 2**16                                          # 1311 s at 25 m/s, 50 Hz
    north = _dryden_field(sigma, L, Vg * dt, n, rng)[0]
    east = _dryden_field(sigma, L, Vg * dt, n, rng)[0]
    wind = np.c_[north + 3.0, east - 2.0, np.zeros(n)]     # a steady wind changes nothing
    s = gust_intensity(dt, wind, np.full(n, Vg))
    assert abs(s / sigma - 1) < 0.1
    # sigma^2 / L (what the rates need) from a short lag barely moves with the L assumed
    s_half = gust_intensity(dt, wind, np.full(n, Vg), L=L / 2)
    assert abs((s_half**2 / (L / 2)) / (s**2 / L) - 1) < 0.15
    assert np.isnan(gust_intensity(dt, wind[:5], np.full(5, Vg)))
    with pytest.raises(ValueError):
        gust_intensity(dt, wind[:, :1], np.full(n, Vg))


def test_dryden_rate_sigma_matches_the_standards_gradient_filters_on_a_synthetic_field():
    rng = np.random.default_rng(5)
    sigma, L, b, dx = 2.0, 533.4, 10.0, 0.25
    n = 2**19                                          # 131 km of path
    _, W, spec = _dryden_field(sigma, L, dx, n, rng)
    sp, sq, sr = dryden_rate_sigma(sigma, b, L)
    for tau_b, s_formula in ((4.0, sq), (3.0, sr)):    # (s/V)/(1 + k b s/(pi V)) = d/dx / (1 + (k b / pi) d/dx)
        rate = np.fft.irfft(spec * 1j * W / (1 + 1j * tau_b * b * W / np.pi), n)
        assert abs(np.std(rate) / s_formula - 1) < 0.1, (tau_b, np.std(rate), s_formula)
    assert sp == pytest.approx(1.9 * sigma / np.sqrt(L * b))
    assert np.allclose(dryden_rate_sigma(sigma, b) * np.sqrt(DRYDEN_L * b) / sigma, DRYDEN_RATE_FACTORS)
    with pytest.raises(ValueError):
        dryden_rate_sigma(sigma, 0.0)
