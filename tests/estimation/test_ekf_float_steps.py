"""The attitude EKF's prediction on Python floats and its per-block shortcuts give the same numbers."""

import numpy as np

from gcs_sysid.estimation.ekf import _COS_MIN, _EulerEKF, smooth_attitude


def _predict_x_numpy_scalars(self, u=0):
    """The prediction as first written: the same Euler steps on NumPy scalars."""
    import math

    x = self.x[:, 0].copy()
    bp, bq, br = x[3], x[4], x[5]
    ph, th, ps = float(x[0]), float(x[1]), float(x[2])
    for wp, wq, wr in u:
        p, q, r = wp - bp, wq - bq, wr - br
        sf, cf, ct = math.sin(ph), math.cos(ph), math.cos(th)
        ct = math.copysign(max(abs(ct), _COS_MIN), ct)
        a = sf * q + cf * r
        ph, th, ps = ph + self.dt * (p + math.sin(th) / ct * a), th + self.dt * (cf * q - sf * r), ps + self.dt * a / ct
    x[0], x[1], x[2] = ph, th, math.remainder(ps, 2 * math.pi)
    self.x = x[:, None]


def _flight(rng, T=1500, dt=0.02):
    t = np.arange(T) * dt
    w = np.column_stack([0.3 * np.sin(0.7 * t), 0.2 * np.sin(1.1 * t + 1), 0.1 * np.cos(0.4 * t)])
    gyro = w + 0.01 + 0.002 * rng.normal(size=(T, 3))
    att = np.column_stack([np.cumsum(w[:, 0]) * dt, 0.05 + np.cumsum(w[:, 1]) * dt, np.cumsum(w[:, 2]) * dt])
    att = att + 0.003 * rng.normal(size=(T, 3))
    att[rng.random(T) > 0.2] = np.nan                   # attitude at ~10 Hz
    gyro[300:307] = np.nan                              # gyro gaps: inside a block, and over whole blocks
    gyro[900:960] = np.nan
    gyro[1200] = np.nan
    return dt, gyro, att


def test_float_prediction_and_block_shortcuts_match_the_numpy_scalar_filter(monkeypatch):
    rng = np.random.default_rng(11)
    dt, gyro, att = _flight(rng)
    fast = smooth_attitude(dt, gyro, att, 0.002)
    monkeypatch.setattr(_EulerEKF, "predict_x", _predict_x_numpy_scalars)
    slow = smooth_attitude(dt, gyro, att, 0.002)
    for f in ("euler", "euler_sigma", "gyro_bias", "gyro_bias_sigma"):
        np.testing.assert_array_equal(getattr(fast, f), getattr(slow, f), err_msg=f)
    assert np.isfinite(fast.euler).all() and np.isfinite(fast.gyro_bias).all()
