"""The velocity filter's Earth model: WGS-84 normal gravity, Coriolis and transport rate.

Without them the accelerometer bias that the filter estimates takes the Coriolis acceleration and the
gravity difference, and the bias-corrected specific force (the force coefficients' input) is off by
as much (docs/estimation.md). The trajectory below is built on a rotating, ellipsoidal Earth, so the
accelerometer measures what a real one would; the filter must return the accelerometer's own bias.
"""

import numpy as np
import pytest

from gcs_sysid.estimation.ekf import G0, dcm
from gcs_sysid.estimation.smoothers import OMEGA_IE, earth_acceleration, normal_gravity, smooth_velocity


def test_normal_gravity_against_published_values():
    """WGS-84 normal gravity: 9.7803253 m/s^2 at the equator, 9.8321849 at the poles (NIMA TR8350.2,
    table 3.4), and the free-air gradient of about -3.086e-6 s^-2 at mid latitude."""
    assert normal_gravity(np.array(0.0), np.array(0.0)) == pytest.approx(9.7803253, abs=1e-6)
    assert normal_gravity(np.array(np.pi / 2), np.array(0.0)) == pytest.approx(9.8321849, abs=1e-6)
    lat = np.radians(45.0)
    grad = (normal_gravity(lat, 1000.0) - normal_gravity(lat, 0.0)) / 1000.0
    assert grad == pytest.approx(-3.086e-6, rel=0.01)


def test_coriolis_term_by_hand():
    """Flying east at 40 m/s at latitude 30 deg: Coriolis 2 Omega v sin(lat) to the south and
    2 Omega v cos(lat) upwards (Eotvos), plus the transport rate's v^2 tan(lat) / R southwards and
    v^2 / R upwards, by hand."""
    lat, v = np.radians(30.0), 40.0
    a = earth_acceleration(np.array([lat]), np.array([0.0]), np.array([[0.0, v, 0.0]]))[0]
    RE = 6378137.0 / np.sqrt(1 - 6.69437999014e-3 * np.sin(lat) ** 2)
    assert a[0] == pytest.approx(-2 * OMEGA_IE * v * np.sin(lat) - v**2 * np.tan(lat) / RE, rel=1e-9)
    assert a[1] == pytest.approx(0.0, abs=1e-12)
    assert a[2] == pytest.approx(normal_gravity(lat, 0.0) - 2 * OMEGA_IE * v * np.cos(lat) - v**2 / RE, rel=1e-9)


def _rotating_earth_flight(seed=0, T=4500, dt=0.02):
    """90 s straight glide over the rotating Earth at 47.4 deg N, 1.8 km: a heading-30-deg ground track
    with a slow lateral weave, body axes banked with the weave. Returns C, measured f, GPS velocity
    samples (25 Hz), lat, alt and the accelerometer's true bias."""
    rng = np.random.default_rng(seed)
    t = np.arange(T) * dt
    psi = np.radians(30.0) + 0.15 * np.sin(2 * np.pi * t / 30.0)
    V = 40.0
    v = np.stack([V * np.cos(psi), V * np.sin(psi), np.full(T, 2.0)], 1)
    vdot = np.gradient(v, dt, axis=0)
    lat = np.radians(47.4) + np.cumsum(v[:, 0]) * dt / 6.37e6
    alt = 1800.0 - np.cumsum(v[:, 2]) * dt
    phi = np.arctan(V * np.gradient(psi, dt) / G0)
    C = dcm(phi, np.full(T, 0.05), psi)
    f_ned = vdot - earth_acceleration(lat, alt, v)          # v_dot = C f + g - (2 w_ie + w_en) x v
    bias = np.array([0.03, -0.02, 0.04])
    f = np.einsum("tji,tj->ti", C, f_ned) + bias + rng.normal(0, 0.05, (T, 3))
    vm = np.full((T, 3), np.nan)
    vm[::2] = v[::2] + rng.normal(0, 0.07, (len(v[::2]), 3))
    return C, f, vm, lat, alt, bias


def test_velocity_filter_returns_the_accelerometer_bias_on_a_rotating_earth():
    C, f, vm, lat, alt, bias = _rotating_earth_flight()
    est = smooth_velocity(0.02, C, f, vm, 0.05, lat=lat, alt=alt)
    err = est.accel_bias[500:-500].mean(0) - bias
    assert np.all(np.abs(err) < 2e-3), err
    # the flat non-rotating Earth puts the Coriolis acceleration (about 0.006 m/s^2 across the track)
    # and the gravity difference (-0.003 m/s^2) into the bias: the same test fails without the model
    flat = smooth_velocity(0.02, C, f, vm, 0.05)
    err_flat = flat.accel_bias[500:-500].mean(0) - bias
    assert np.abs(err_flat[1]) > 3.5e-3 and np.abs(err_flat[2]) > 4e-3, err_flat


def test_latitude_of_the_wrong_length_is_refused():
    C, f, vm, lat, alt, _ = _rotating_earth_flight(T=200)
    with pytest.raises(ValueError, match="lat has 199 samples, expected 200"):
        smooth_velocity(0.02, C, f, vm, 0.05, lat=lat[:-1], alt=alt)
    # all-NaN latitude: the flat Earth, no error
    est = smooth_velocity(0.02, C, f, vm, 0.05, lat=np.full(200, np.nan), alt=alt)
    assert np.isfinite(est.v_ned).all()


def test_unknown_earth_is_refused():
    from gcs_sysid.estimation import estimate_states

    with pytest.raises(ValueError, match="earth must be 'wgs84' or 'flat', got 'round'"):
        estimate_states(None, None, earth="round")
