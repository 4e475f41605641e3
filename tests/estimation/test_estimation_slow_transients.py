"""The rate smoother's slow control transients (1/s), taken per axis by a likelihood-ratio test.

Fixture: ``data/flights/jsbsim-b747-light-s3-rates.npz`` (provenance in ``data/flights/README.md``):
the JSBSim B747's roll and yaw gyro (bias removed), its logged surface deflections, the pitot's
dynamic pressure and JSBSim's exact ``p_dot`` / ``r_dot`` of eval_jsbsim's light-turbulence seed-3
flight (90 s, 50 Hz). There the yaw moment from the smoothed accelerations was 9.45 % off the truth
on the held-out last 20 % (eval_jsbsim's measured Cn 9.43 %; the issue asks 8 %) without the slow
transients, 7.11 % with them.
"""

from pathlib import Path

import numpy as np

from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation.rates import SLOW_DECAYS, smooth_rates

DATA = Path(__file__).resolve().parents[2] / "data"


def _yaw_moment_error(accel: np.ndarray, p_dot: np.ndarray, r_dot: np.ndarray, rows) -> float:
    """% error of ``Izz r_dot - Ixz p_dot`` (the yaw moment, the B747's airframe file) on ``rows``."""
    J = load_airframe(DATA / "airframes" / "jsbsim-b747.toml").inertia
    N = J[2, 2] * r_dot + J[2, 0] * p_dot          # J[2, 0] = -Ixz
    Ne = J[2, 2] * accel[:, 2] + J[2, 0] * accel[:, 0]
    return float(100 * np.sqrt(np.mean((Ne[rows] - N[rows]) ** 2) / np.mean(N[rows] ** 2)))


def test_slow_transients_bring_the_b747_yaw_moment_within_8_percent():
    """Default smoother on the B747 flight: the yaw axis takes the slow transients and the held-out
    yaw moment is within the issue's 8 % (measured 7.11 %; 9.45 % without them, 9.43 % in main's
    eval_jsbsim); over the whole flight 10.1 % (13.0 % without). Only p and r are given (q NaN: no
    pitch column, which keeps the test under a second)."""
    d = np.load(DATA / "flights" / "jsbsim-b747-light-s3-rates.npz")
    z = np.full((len(d["gyro_pr"]), 3), np.nan)
    z[:, [0, 2]] = d["gyro_pr"]
    R = smooth_rates(float(d["dt"]), z, controls=d["controls"].astype(float), scale=d["qbar_eas"].astype(float))
    assert R.slow_transient.tolist() == [False, False, True]
    p_dot, r_dot = d["p_dot"].astype(float), d["r_dot"].astype(float)
    held = np.arange(len(z)) >= int(0.8 * len(z))
    assert _yaw_moment_error(R.accel, p_dot, r_dot, held) < 8.0
    assert _yaw_moment_error(R.accel, p_dot, r_dot, slice(None)) < 11.5


def test_slow_transients_left_out_change_nothing():
    """Where the test rejects them (a synthetic roll axis whose steps decay at 8/s, within
    :data:`~gcs_sysid.estimation.rates.DECAYS`), the estimate is the one without them (to rounding)."""
    rng = np.random.default_rng(3)
    dt, n, sub = 0.02, 1500, 10
    h = dt / sub
    cmd = np.repeat(rng.uniform(-0.05, 0.05, n // 40 + 1), 40 * sub)[: n * sub]
    pos, w, wd = np.zeros(n * sub), np.zeros(n * sub), np.zeros(n * sub)
    for k in range(1, n * sub):       # 0.04 s servo lag, roll damping 8/s
        pos[k] = pos[k - 1] + h / 0.04 * (cmd[k - 1] - pos[k - 1])
        wd[k - 1] = -8.0 * w[k - 1] + 10.0 * pos[k - 1]
        w[k] = w[k - 1] + h * wd[k - 1]
    z = np.full((n, 3), np.nan)
    z[:, 0] = w[::sub] + 0.005 * rng.standard_normal(n)
    U = pos[::sub, None]
    R = smooth_rates(dt, z, controls=U, max_delay_s=0.0, residual_correction=False)
    R0 = smooth_rates(dt, z, controls=U, max_delay_s=0.0, residual_correction=False, slow_decays=())
    assert SLOW_DECAYS and not R.slow_transient.any()
    np.testing.assert_allclose(R.accel[:, 0], R0.accel[:, 0], rtol=0, atol=1e-12 * np.abs(R0.accel[:, 0]).max())
