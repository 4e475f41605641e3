"""The batched Kalman filter / RTS smoother against filterpy, and the steady-state path against both."""

import numpy as np
import pytest
from filterpy.common import Q_continuous_white_noise
from filterpy.kalman import KalmanFilter
from scipy.linalg import solve_discrete_are

from gcs_sysid.estimation.kalman import (_dare, kalman_filter, noise_std, rts_smoother, steady_state,
                                         steady_state_smoother)

DT = 0.02
F3 = np.array([[1.0, DT, 0.5 * DT * DT], [0.0, 1.0, DT], [0.0, 0.0, 1.0]])


def _signal(T, rng, missing=True):
    t = np.arange(T) * DT
    z = np.sin(3 * t) + 0.3 * np.sin(11 * t) + rng.normal(0, 0.05, T)
    if missing:
        z[100:130] = np.nan
        z[T - 100] = np.nan
    return z


@pytest.mark.parametrize("nz", [1, 2])
def test_filter_and_rts_match_filterpy(nz):
    rng = np.random.default_rng(1)
    T = 500
    Q = Q_continuous_white_noise(3, DT, 50.0)
    z1 = _signal(T, rng)
    if nz == 1:
        H, R, z = np.array([[1.0, 0.0, 0.0]]), np.eye(1) * 0.05**2, z1[:, None]
    else:
        H, R = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.diag([0.05**2, 0.3**2])
        z = np.stack([z1, 3 * np.cos(3 * np.arange(T) * DT) + rng.normal(0, 0.3, T)], 1)
    kf = KalmanFilter(dim_x=3, dim_z=nz)
    kf.F, kf.H, kf.Q, kf.R = F3, H, Q, R
    kf.x, kf.P = np.zeros((3, 1)), np.eye(3)
    zs = [None if np.isnan(v).any() else v[:, None] for v in z]
    m, c, _, _ = kf.batch_filter(zs)
    xs_ref, Ps_ref, _, _ = kf.rts_smoother(m, c)
    res = kalman_filter(np.zeros((1, 3)), np.eye(3), F3, Q, H, R, z[:, None, :])
    xs, Ps = rts_smoother(res, F3)
    np.testing.assert_allclose(res.x[:, 0], m[:, :, 0], atol=1e-10)
    np.testing.assert_allclose(res.P[:, 0], c, atol=1e-10)
    np.testing.assert_allclose(xs[:, 0], xs_ref[:, :, 0], atol=1e-10)
    np.testing.assert_allclose(Ps[:, 0], Ps_ref, atol=1e-10)


def test_batch_of_filters_equals_separate_runs():
    rng = np.random.default_rng(2)
    T = 300
    z = np.stack([_signal(T, rng), _signal(T, rng, missing=False)], 1)[:, :, None]
    Qs = np.stack([Q_continuous_white_noise(3, DT, q) for q in (10.0, 1000.0)])
    H, R = np.array([[1.0, 0.0, 0.0]]), np.eye(1) * 0.05**2
    both = kalman_filter(np.zeros((2, 3)), np.eye(3), F3, Qs, H, R, z)
    xb, _ = rts_smoother(both, F3)
    for b in range(2):
        one = kalman_filter(np.zeros((1, 3)), np.eye(3), F3, Qs[b], H, R, z[:, b:b + 1])
        x1, _ = rts_smoother(one, F3)
        np.testing.assert_allclose(xb[:, b], x1[:, 0], atol=1e-12)
        np.testing.assert_allclose(both.loglik[b], one.loglik[0])


def test_dare_matches_scipy():
    H = np.array([[1.0, 0.0, 0.0]])
    for f in (0.5, 4.0, 13.0):
        Q = DT * (2 * np.pi * f) ** 6 * Q_continuous_white_noise(3, DT, 1.0)
        ref = solve_discrete_are(F3.T, H.T, Q, np.eye(1))
        np.testing.assert_allclose(_dare(F3.T, H.T, Q, np.eye(1)), ref, rtol=1e-9, atol=1e-14)


def test_steady_state_smoother_is_exact_from_the_fixed_point():
    rng = np.random.default_rng(3)
    T = 800
    z = _signal(T, rng, missing=False)[:, None]
    H, R = np.array([[1.0, 0.0, 0.0]]), np.eye(1) * 0.05**2
    Q = Q_continuous_white_noise(3, DT, 200.0)
    g = steady_state(F3, Q, H, R)
    x0 = np.array([z[0, 0], 0.0, 0.0])
    res = kalman_filter(x0[None], g.Pf, F3, Q, H, R, z[:, None, :])
    xs_ref, Ps_ref = rts_smoother(res, F3)
    xf, innov = steady_state_smoother(F3, g, H, z, x0, smooth=False)
    xs, _ = steady_state_smoother(F3, g, H, z, x0)
    np.testing.assert_allclose(xf, res.x[:, 0], atol=1e-9)
    np.testing.assert_allclose(innov[:, 0], z[:, 0] - res.xp[:, 0, 0], atol=1e-9)
    np.testing.assert_allclose(xs, xs_ref[:, 0], atol=1e-8)
    # the filter covariance stays at the fixed point; the smoothed one reaches Ps in the interior
    np.testing.assert_allclose(res.P[:, 0], np.broadcast_to(g.Pf, res.P[:, 0].shape), rtol=1e-6)
    np.testing.assert_allclose(Ps_ref[T // 2, 0], g.Ps, rtol=1e-6, atol=1e-12)


def test_noise_std_recovers_white_noise_under_a_slow_signal():
    rng = np.random.default_rng(4)
    t = np.arange(20000) * DT
    y = 0.5 * np.sin(2 * np.pi * 0.3 * t) + rng.normal(0, 0.01, len(t))
    assert noise_std(y) == pytest.approx(0.01, rel=0.05)
    assert noise_std(np.full(100, 1.0), floor=1e-3) == 1e-3


def test_single_filter_path_matches_batched_with_per_step_models_and_inputs():
    # B = 1 runs a separate loop on plain matrices; a batch of two copies takes the batched one
    rng = np.random.default_rng(3)
    T, nx = 200, 3
    F = F3[None] + 0.01 * rng.normal(size=(T, nx, nx))
    Q = np.stack([Q_continuous_white_noise(3, DT, q) for q in rng.uniform(5.0, 50.0, T)])[:, None]
    H, R = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.diag([0.05**2, 0.2**2])
    z = np.stack([_signal(T, rng), _signal(T, rng, missing=False)], 1)[:, None, :]
    u = 0.01 * rng.normal(size=(T, 1, nx))
    one = kalman_filter(np.zeros((1, nx)), np.eye(nx), F, Q, H, R, z, u=u)
    two = kalman_filter(np.zeros((2, nx)), np.eye(nx), F, np.repeat(Q, 2, 1), H, R, np.repeat(z, 2, 1),
                        u=np.repeat(u, 2, 1))
    for a, b in ((one.x, two.x), (one.P, two.P), (one.xp, two.xp), (one.Pp, two.Pp)):
        np.testing.assert_allclose(a[:, 0], b[:, 1], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(one.loglik[0], two.loglik[1], rtol=1e-10)
    xs1, Ps1 = rts_smoother(one, F, wrap=(0,))
    xs2, Ps2 = rts_smoother(two, F, wrap=(0,))
    np.testing.assert_allclose(xs1[:, 0], xs2[:, 1], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(Ps1[:, 0], Ps2[:, 1], rtol=1e-10, atol=1e-12)
