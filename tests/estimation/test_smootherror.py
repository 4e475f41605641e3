"""The rate smoother's angular-acceleration error split (gcs_sysid.estimation.smootherror)."""

import numpy as np
import pytest

from gcs_sysid.estimation.kalman import steady_state, steady_state_smoother
from gcs_sysid.estimation.rates import _nominal_model
from gcs_sysid.estimation.smootherror import accel_error_split, model_response


@pytest.mark.parametrize("bw", [0.5, 1.5, 4.0])
def test_parts_sum_to_the_stated_variance(bw):
    dt, sd = 0.02, 0.005
    noise, dist = accel_error_split(dt, bw, sd)
    F, Q, H = _nominal_model(dt, bw)
    total = sd**2 * steady_state(F, Q, H, np.eye(1)).Ps[1, 1]
    assert noise > 0 and dist > 0
    assert noise + dist == pytest.approx(total, rel=1e-5)


def test_noise_part_is_the_smoothed_white_noise():
    """Pure gyro noise through the smoother: the derivative's variance is the noise part alone."""
    dt, sd, bw = 0.02, 0.005, 1.5
    rng = np.random.default_rng(3)
    z = rng.normal(0.0, sd, 40000)[:, None]
    F, Q, H = _nominal_model(dt, bw)
    g = steady_state(F, Q, H, np.eye(1))
    xs, _ = steady_state_smoother(F, g, H, z, np.zeros(3))
    measured = np.var(xs[2000:-2000, 1])
    noise, _ = accel_error_split(dt, bw, sd)
    assert measured == pytest.approx(noise, rel=0.05)


def test_response_passes_low_frequencies_as_a_derivative():
    dt, bw = 0.02, 2.5
    F, Q, H = _nominal_model(dt, bw)
    om = np.array([2 * np.pi * 0.05 * dt])          # 0.05 Hz, far below the bandwidth
    D = model_response(F, Q, H, om)
    assert D[0] == pytest.approx(1j * 2 * np.pi * 0.05, rel=1e-3)


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="bandwidth_hz"):
        accel_error_split(0.02, 0.0, 0.005)
    with pytest.raises(ValueError, match="noise_std"):
        accel_error_split(0.02, 1.0, float("nan"))
