"""The rate smoother's opt-in local bandwidth (estimation/rates.py ``_local_blend``, issue 8, branch i8-meas): where the
motion is weaker than over the whole record (calm air after turbulence, a quiet leg between manoeuvres) a
narrower bandwidth, chosen per window by the candidates' own innovations, lets less of the gyro's noise into the
angular acceleration; where the whole-record bandwidth is already the narrowest the smoother is unchanged."""

import numpy as np
from scipy.signal import butter, filtfilt

from gcs_sysid.estimation.rates import LOCAL_WINDOW_S, smooth_rates

DT = 0.02          # 50 Hz gyro
GYRO_NOISE = 0.005  # rad/s white per sample, the JSBSim harness's gyro


def _rate(T: int, seed: int, active_until: int, active_rms: float = 0.3, calm_rms: float = 0.02):
    """Angular acceleration: filtered noise (2 Hz) of ``active_rms`` rad/s^2 up to ``active_until``, then
    ``calm_rms`` (0.4 Hz); the rate is its integral, measured with white noise. Returns (rate, accel, z)."""
    rng = np.random.default_rng(seed)
    b2, a2 = butter(2, 2.0 * 2 * DT)
    b0, a0 = butter(2, 0.4 * 2 * DT)
    hi = filtfilt(b2, a2, rng.normal(size=T))
    lo = filtfilt(b0, a0, rng.normal(size=T))
    acc = np.where(np.arange(T) < active_until, active_rms * hi / hi.std(), calm_rms * lo / lo.std())
    w = np.cumsum(acc) * DT
    return w, acc, w + rng.normal(0.0, GYRO_NOISE, T)


def _err(x, ref, m):
    return float(np.sqrt(np.mean((x[m] - ref[m]) ** 2)))


def test_calm_part_gets_a_narrower_bandwidth():
    T, half = 2000, 1000
    w, acc, z = _rate(T, 5, half)
    Z = np.stack([z, z, z], 1)
    loc = smooth_rates(DT, Z, residual_correction=False, local_window_s=LOCAL_WINDOW_S)
    one = smooth_rates(DT, Z, residual_correction=False)          # the default: one bandwidth per axis
    assert LOCAL_WINDOW_S == 5.0
    calm, active = slice(half + 300, T - 100), slice(100, half - 300)
    e_one, e_loc = _err(one.accel[:, 0], acc, calm), _err(loc.accel[:, 0], acc, calm)
    assert e_loc < 0.7 * e_one, (e_one, e_loc)        # measured 0.026 -> 0.0030 rad/s^2 (4 Hz whole-record)
    # the active part keeps the whole-record bandwidth (its windows' weights stay on it)
    assert _err(loc.accel[:, 0], acc, active) < 1.05 * _err(one.accel[:, 0], acc, active)
    lo, hi = loc.local_bandwidth_hz[0]
    assert lo < hi == one.bandwidth_hz[0]              # only narrower candidates are offered
    assert one.local_bandwidth_hz is None
    assert np.isfinite(loc.accel_sigma).all() and (loc.accel_sigma > 0).all()


def test_narrowest_whole_record_bandwidth_is_the_plain_smoother():
    # a record calm throughout: the whole-record choice is the ladder's narrowest, nothing narrower to offer
    T = 1500
    w, acc, z = _rate(T, 7, 0)
    Z = np.stack([z, z, z], 1)
    ladder = (1.0, 2.5, 4.0)
    loc = smooth_rates(DT, Z, residual_correction=False, bandwidths_hz=ladder, local_window_s=LOCAL_WINDOW_S)
    one = smooth_rates(DT, Z, residual_correction=False, bandwidths_hz=ladder)
    assert (one.bandwidth_hz == 1.0).all() and loc.local_bandwidth_hz is None
    np.testing.assert_array_equal(loc.accel, one.accel)
    np.testing.assert_array_equal(loc.accel_sigma, one.accel_sigma)
