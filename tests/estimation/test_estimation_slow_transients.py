"""The rate smoother's slow control transients (1/s, taken per axis by a likelihood-ratio test) and the
moment equations' control terms (each control on its own axes).

Fixture: ``data/flights/jsbsim-b747-light-s3-rates.npz`` (provenance in ``data/flights/README.md``):
the JSBSim B747's roll and yaw gyro (bias removed), its logged surface deflections, the pitot's
dynamic pressure and JSBSim's exact ``p_dot`` / ``r_dot`` of eval_jsbsim's light-turbulence seed-3
flight (90 s, 50 Hz). There the yaw moment from the smoothed accelerations was 9.45 % off the truth
on the held-out last 20 % (eval_jsbsim's measured Cn 9.43 %; the issue asks 8 %) with main's smoother,
7.11 % with the slow transients, 6.57 % with the control terms as well.
"""

from pathlib import Path

import numpy as np

from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation.rates import AILERON_YAW_TIE, CONTROL_AXES, SLOW_DECAYS, smooth_rates

DATA = Path(__file__).resolve().parents[2] / "data"


def _yaw_moment_error(accel: np.ndarray, p_dot: np.ndarray, r_dot: np.ndarray, rows) -> float:
    """% error of ``Izz r_dot - Ixz p_dot`` (the yaw moment, the B747's airframe file) on ``rows``."""
    J = load_airframe(DATA / "airframes" / "jsbsim-b747.toml").inertia
    N = J[2, 2] * r_dot + J[2, 0] * p_dot          # J[2, 0] = -Ixz
    Ne = J[2, 2] * accel[:, 2] + J[2, 0] * accel[:, 0]
    return float(100 * np.sqrt(np.mean((Ne[rows] - N[rows]) ** 2) / np.mean(N[rows] ** 2)))


def _b747_flight():
    """The B747 fixture (light, seed 3): gyro ``(T, 3)`` with q NaN, ``dt`` s, controls ``(T, 3)`` rad,
    ``qbar`` Pa, the truth's ``p_dot`` and ``r_dot`` ``(T,)`` rad/s^2 and the held-out mask (the last 20 %)."""
    d = np.load(DATA / "flights" / "jsbsim-b747-light-s3-rates.npz")
    z = np.full((len(d["gyro_pr"]), 3), np.nan)
    z[:, [0, 2]] = d["gyro_pr"]
    dt, U, qbar = float(d["dt"]), d["controls"].astype(float), d["qbar_eas"].astype(float)
    p_dot, r_dot = d["p_dot"].astype(float), d["r_dot"].astype(float)
    return z, dt, U, qbar, p_dot, r_dot, np.arange(len(z)) >= int(0.8 * len(z))


def test_slow_transients_and_control_terms_bring_the_b747_yaw_moment_within_8_percent():
    """The smoother as ``estimate_states`` runs it (slow transients offered, each control on the axes of
    :data:`~gcs_sysid.estimation.rates.CONTROL_AXES`) on the B747 flight: the yaw axis takes the slow
    transients, the elevator moves neither p nor r, and the held-out yaw moment is within the issue's
    8 % (measured 6.57 %; whole flight 8.15 %). Main's smoother (neither) gives 9.45 / 13.0 % on the
    same data (eval_jsbsim's measured Cn: 9.43 %). Only p and r are given (q NaN: no pitch column)."""
    z, dt, U, qbar, p_dot, r_dot, held = _b747_flight()
    R = smooth_rates(dt, z, controls=U, scale=qbar,
                     control_axes=[CONTROL_AXES[k] for k in ("delta_e", "delta_a", "delta_r")])
    assert R.slow_transient.tolist() == [False, False, True]
    assert R.effectiveness[0, 0] == R.effectiveness[2, 0] == 0.0 and R.effectiveness[0, 1] != 0.0
    assert _yaw_moment_error(R.accel, p_dot, r_dot, held) < 7.0
    assert _yaw_moment_error(R.accel, p_dot, r_dot, slice(None)) < 9.0
    R0 = smooth_rates(dt, z, controls=U, scale=qbar, slow_decays=())      # main's smoother
    assert _yaw_moment_error(R0.accel, p_dot, r_dot, held) > 9.0


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


def test_aileron_yaw_response_through_the_roll_axis_b747():
    """The aileron's yaw response tied to its roll response (:data:`~gcs_sysid.estimation.rates.AILERON_YAW_TIE`,
    opt-in, ``I_z r_dot = N + I_xz p_dot``: on the yaw axis the roll axis' fitted response to the aileron, its rate
    and the aileron's step, one coefficient each, instead of the aileron's free columns there), on the same
    B747 flight: the BIC keeps the tied form, and the held-out yaw moment goes 6.57 -> 4.72 % and the whole
    flight's 8.15 -> 5.34 % (measured 2026-11-23; the free columns' numbers are the test above's). The B747
    has no ``Cn_delta_a``: the aileron's jump on the yaw axis is at most the ``I_xz / I_z`` share (0.020) of
    the roll axis' (here 1.7 % of it) within 3 sigma."""
    z, dt, U, qbar, p_dot, r_dot, held = _b747_flight()
    names = ("delta_e", "delta_a", "delta_r")
    R = smooth_rates(dt, z, controls=U, scale=qbar, control_axes=[CONTROL_AXES[k] for k in names],
                     coupled={names.index(k): v for k, v in AILERON_YAW_TIE.items()})
    assert _yaw_moment_error(R.accel, p_dot, r_dot, held) < 5.2
    assert _yaw_moment_error(R.accel, p_dot, r_dot, slice(None)) < 6.0
    assert R.slow_transient.tolist() == [False, False, True]
    J = load_airframe(DATA / "airframes" / "jsbsim-b747.toml").inertia
    ratio = abs(J[2, 0] / J[2, 2])                              # I_xz / I_z = 0.020
    assert abs(R.effectiveness[2, 1]) < 3 * R.effectiveness_sigma[2, 1] + ratio * abs(R.effectiveness[0, 1])


def test_aileron_yaw_response_tie_rejected_keeps_the_free_columns():
    """Where the free columns fit the yaw axis better than the BIC penalty allows (a synthetic yaw axis
    whose aileron response decays at 12/s, not shaped like the roll axis' 3/s), the estimate is the
    uncoupled one exactly."""
    rng = np.random.default_rng(5)
    dt, n, sub = 0.02, 1500, 10
    h = dt / sub
    cmd = np.repeat(rng.uniform(-0.05, 0.05, n // 40 + 1), 40 * sub)[: n * sub]
    w = np.zeros((n * sub, 2))
    for k in range(1, n * sub):       # roll: damping 3/s; yaw: its own 12/s response to the aileron
        wd = np.array([-3.0 * w[k - 1, 0] + 10.0 * cmd[k - 1], -12.0 * w[k - 1, 1] + 6.0 * cmd[k - 1]])
        w[k] = w[k - 1] + h * wd
    z = np.full((n, 3), np.nan)
    z[:, [0, 2]] = w[::sub] + 0.002 * rng.standard_normal((n, 2))
    U = cmd[::sub, None]
    kw = dict(controls=U, max_delay_s=0.0, residual_correction=False, holds=("foh",), slow_decays=(),
              control_axes=[(0, 2)])
    R = smooth_rates(dt, z, coupled={0: (0, 2)}, **kw)
    R0 = smooth_rates(dt, z, **kw)
    np.testing.assert_array_equal(R.accel[:, 2], R0.accel[:, 2])
