"""The angle-of-attack rate from the force equations (gcs_sysid.estimation.alpharate) on an exact
kinematic trajectory: specific force, rates, attitude and ground velocity built from a known air-relative
motion, so the expected alpha_dot is the derivative of the known alpha."""

import numpy as np

from gcs_sysid.estimation.alpharate import kinematic_alpha_rate
from gcs_sysid.estimation.ekf import G0, dcm


def _trajectory(wind_ned):
    """A pitching, sideslipping glide (wings level, heading north) sampled at 1 kHz."""
    t = np.arange(0.0, 4.0, 1e-3)
    theta = 0.05 + 0.1 * np.sin(2.0 * t)
    q = 0.2 * np.cos(2.0 * t)                                   # theta_dot, phi = psi = 0
    zero = np.zeros_like(t)
    C = dcm(zero, theta, zero)
    v_air_b = np.stack([25.0 + np.sin(t), 0.5 * np.sin(t), 2.0 + 1.5 * np.sin(3.0 * t)], 1)
    vb = v_air_b + np.einsum("tji,j->ti", C, wind_ned)          # ground velocity, body axes
    vb_dot = np.gradient(vb, t, axis=0)
    omega = np.stack([zero, q, zero], 1)
    f = vb_dot + np.cross(omega, vb) - G0 * C[:, 2, :]          # specific force = dv/dt|_body + w x v - g_b
    v_ned = np.einsum("tij,tj->ti", C, vb)
    V = np.linalg.norm(v_air_b, axis=1)
    alpha = np.arctan2(v_air_b[:, 2], v_air_b[:, 0])
    beta = np.arcsin(v_air_b[:, 1] / V)
    return t, C, v_ned, f, omega, V, alpha, beta, v_air_b, vb_dot


def test_still_air_gives_the_derivative_of_alpha():
    t, C, v_ned, f, omega, V, alpha, beta, *_ = _trajectory(np.zeros(3))
    got = kinematic_alpha_rate(C, v_ned, f, omega, V, alpha, beta)
    ref = np.gradient(alpha, t)
    inner = slice(10, -10)
    assert np.sqrt(np.mean((got[inner] - ref[inner]) ** 2)) < 1e-4 * np.sqrt(np.mean(ref**2)) + 1e-6
    # gravity and the rotation terms matter: leaving out gravity is far off
    bad = kinematic_alpha_rate(C, v_ned, f, omega, V, alpha, beta, g=0.0)
    assert np.sqrt(np.mean((bad - ref) ** 2)) > 0.5 * np.sqrt(np.mean(ref**2))


def test_steady_wind_uses_the_ground_velocity_derivative():
    """With a steady wind the rate is JSBSim's form: air-relative velocity, ground-velocity derivative."""
    wind = np.array([3.0, -2.0, 0.5])
    t, C, v_ned, f, omega, V, alpha, beta, v_air_b, vb_dot = _trajectory(wind)
    got = kinematic_alpha_rate(C, v_ned, f, omega, V, alpha, beta)
    ua, wa = v_air_b[:, 0], v_air_b[:, 2]
    ref = (ua * vb_dot[:, 2] - wa * vb_dot[:, 0]) / (ua**2 + wa**2)
    inner = slice(10, -10)
    np.testing.assert_allclose(got[inner], ref[inner], atol=1e-6)


def test_slow_or_missing_inputs_give_nan():
    t, C, v_ned, f, omega, V, alpha, beta, *_ = _trajectory(np.zeros(3))
    V = V.copy()
    V[5] = 0.5
    f = f.copy()
    f[7, 2] = np.nan
    got = kinematic_alpha_rate(C, v_ned, f, omega, V, alpha, beta)
    assert np.isnan(got[5]) and np.isnan(got[7]) and np.isfinite(got[6])


def test_shape():
    T = 10
    C = np.broadcast_to(np.eye(3), (T, 3, 3)).copy()
    out = kinematic_alpha_rate(C, np.tile([20.0, 0, 1.0], (T, 1)), np.tile([0, 0, -G0], (T, 1)), np.zeros((T, 3)),
                               np.full(T, 20.0), np.full(T, 0.05), np.zeros(T))
    assert out.shape == (T,) and np.all(np.isfinite(out))
