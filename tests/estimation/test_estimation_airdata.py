"""ISA, density, EAS -> TAS, wind least squares, alpha and beta."""

import numpy as np
import pytest

from gcs_sysid.estimation.airdata import RHO0, air_angles, density, estimate_wind, isa, pressure_altitude, tas_from_eas
from gcs_sysid.estimation.ekf import dcm


def test_isa_reference_values():
    p, T, rho = isa(np.array([0.0, 1000.0, 3000.0]))
    np.testing.assert_allclose(p, [101325.0, 89874.6, 70108.5], rtol=2e-5)
    np.testing.assert_allclose(T, [288.15, 281.65, 268.65])
    np.testing.assert_allclose(rho, [1.2250, 1.1117, 0.9091], rtol=3e-4)
    assert pressure_altitude(89874.6) == pytest.approx(1000.0, abs=0.5)


def test_density_from_pressure_and_temperature():
    assert density(101325.0, 288.15) == pytest.approx(1.2250, rel=1e-4)
    assert density(90000.0, 300.0) == pytest.approx(90000.0 / (287.05287 * 300.0))
    # an implausible temperature falls back to the ISA temperature at the pressure altitude
    assert density(89874.6, 0.0) == pytest.approx(1.1117, rel=3e-4)


def test_tas_from_eas():
    assert tas_from_eas(20.0, RHO0) == pytest.approx(20.0)
    assert tas_from_eas(20.0, RHO0 / 4) == pytest.approx(40.0)


def test_alpha_beta_hand_case():
    # level flight heading north, air-relative body velocity (20, 1, 2) m/s, wind 3 m/s from the west
    C = dcm(np.zeros(1), np.zeros(1), np.zeros(1))
    wind = np.array([[0.0, 3.0, 0.0]])
    vb, V, alpha, beta = air_angles(C, np.array([[20.0, 4.0, 2.0]]), wind)
    np.testing.assert_allclose(vb, [[20.0, 1.0, 2.0]])
    assert V[0] == pytest.approx(np.sqrt(405.0))
    assert alpha[0] == pytest.approx(np.arctan2(2.0, 20.0))
    assert beta[0] == pytest.approx(np.arcsin(1.0 / np.sqrt(405.0)))


def test_wind_and_pitot_scale_from_circles():
    rng = np.random.default_rng(5)
    t = np.arange(0, 240, 0.02)
    heading = 2 * np.pi * t / 40.0                   # a full circle every 40 s
    V = 20.0 + np.sin(0.1 * t)
    wind = np.array([3.0, -4.0, 0.0])
    v_ned = np.stack([V * np.cos(heading), V * np.sin(heading), 0.5 * np.sin(0.3 * t)], 1) + wind
    v_air = np.linalg.norm(v_ned - wind, axis=1)
    tas = v_air / 1.05 + rng.normal(0, 0.3, len(t))  # pitot reads 5 % low
    prior = np.tile([1.0, -1.0, 0.0], (len(t), 1))   # a poor autopilot estimate
    we = estimate_wind(t, v_ned, tas, np.ones(len(t), bool), prior=prior)
    np.testing.assert_allclose(we.wind[:, :2].mean(0), wind[:2], atol=0.05)
    assert we.scale == pytest.approx(1.05, abs=0.005)
    assert (we.sigma[:, :2] < 0.2).all()
    with pytest.raises(ValueError):
        estimate_wind(t[:5], v_ned[:5], tas[:5], np.ones(5, bool))


def test_cross_wind_on_a_straight_leg_from_the_crab_angle():
    rng = np.random.default_rng(6)
    t = np.arange(0, 90, 0.02)
    wind = np.array([0.0, 4.0, 0.0])                 # pure cross wind on a northbound leg
    V = 20.0 + 2.0 * np.sin(0.05 * t)
    crab = -np.arcsin(wind[1] / V)                   # heading into the wind, beta = 0
    C = dcm(np.zeros_like(t), np.full_like(t, 0.05), crab)
    v_air = np.einsum("tij,tj->ti", C, np.stack([V * np.cos(0.05), 0 * t, V * np.sin(0.05)], 1))
    v_ned = v_air + wind
    tas = V + rng.normal(0, 0.3, len(t))
    we = estimate_wind(t, v_ned, tas, np.ones(len(t), bool), C=C)
    np.testing.assert_allclose(we.wind[:, :2].mean(0), wind[:2], atol=0.1)
    assert we.scale == 1.0 and np.isnan(we.scale_sigma)   # no turns: the pitot scale is not estimated


def test_residual_scale_leaves_a_fit_within_pitot_noise_alone():
    """Residuals within the pitot's noise: one solve, the same wind as without ``residual_scale``."""
    rng = np.random.default_rng(6)
    t = np.arange(0, 90, 0.02)
    wind = np.array([0.0, 4.0, 0.0])
    V = 20.0 + 2.0 * np.sin(0.05 * t)
    crab = -np.arcsin(wind[1] / V)
    C = dcm(np.zeros_like(t), np.full_like(t, 0.05), crab)
    v_ned = np.einsum("tij,tj->ti", C, np.stack([V * np.cos(0.05), 0 * t, V * np.sin(0.05)], 1)) + wind
    tas = V + rng.normal(0, 0.3, len(t))
    a = estimate_wind(t, v_ned, tas, np.ones(len(t), bool), C=C)
    b = estimate_wind(t, v_ned, tas, np.ones(len(t), bool), C=C, residual_scale=True)
    assert b.fits == 1 and b.sigma_airspeed == 0.5
    np.testing.assert_array_equal(a.wind, b.wind)


def test_residual_scale_weights_gusty_airspeed_residuals_with_their_rms():
    """A gust along the flight path the wind model cannot hold (2 m/s, 3-s correlation): the airspeed residuals'
    weight becomes their RMS, and the refit settles within a few solves."""
    rng = np.random.default_rng(7)
    t = np.arange(0, 120, 0.02)
    wind = np.array([2.0, -3.0, 0.0])
    V = 30.0 + 3.0 * np.sin(0.07 * t)
    crab = -np.arcsin(wind[1] / V)
    C = dcm(np.zeros_like(t), np.zeros_like(t), crab)
    v_ned = np.einsum("tij,tj->ti", C, np.stack([V, 0 * t, 0 * t], 1)) + wind
    g = np.zeros(len(t))
    a = np.exp(-0.02 / 3.0)
    for i in range(1, len(t)):
        g[i] = a * g[i - 1] + np.sqrt(1 - a * a) * 2.0 * rng.normal()
    tas = V + g + rng.normal(0, 0.3, len(t))
    we = estimate_wind(t, v_ned, tas, np.ones(len(t), bool), C=C, residual_scale=True)
    # the weight is the residuals' RMS after the fit: the gust and the noise of this draw less the share the 30-s
    # windows' wind absorbs (0.89-0.95 of it over seeds 7-11); one refit from 0.5 m/s settles it within 5 %
    drawn = float(np.sqrt(np.mean(g ** 2) + 0.3 ** 2))
    assert 0.85 * drawn < we.sigma_airspeed <= drawn and we.fits == 2
    np.testing.assert_allclose(we.wind[:, :2].mean(0), wind[:2], atol=0.6)
