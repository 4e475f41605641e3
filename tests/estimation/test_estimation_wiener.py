"""The residual's Wiener correction (estimation/wiener.py) and its use in smooth_rates."""

import numpy as np
import pytest
from scipy.signal import butter, lfilter

from gcs_sysid.estimation.rates import smooth_rates
from gcs_sysid.estimation.wiener import residual_wiener

DT = 0.02          # 50 Hz, the harness's and ArduPilot's usual SCALED_IMU rate
GYRO_NOISE = 0.005  # rad/s white, the JSBSim harness's SCALED_IMU gyro


def _gust_axis(T: int = 3000, seed: int = 2, lf_rms: float = 0.15, hf_rms: float = 0.05):
    """One axis: angular acceleration = slow part (white noise through a 0.5 Hz 2nd-order low-pass) plus a
    3-4 Hz band (white noise through a 3-4 Hz band-pass: a gust-driven mode above the smoother's
    bandwidth), integrated exactly at 10x the grid rate; gyro = rate + white noise. Returns (p_dot, z)."""
    rng = np.random.default_rng(seed)
    sub = 10
    h = DT / sub
    n = T * sub
    b, a = butter(2, 0.5 * 2 * h)
    lf = lfilter(b, a, rng.normal(size=n))
    lf *= lf_rms / lf.std()
    b, a = butter(2, [3.0 * 2 * h, 4.0 * 2 * h], btype="band")
    hf = lfilter(b, a, rng.normal(size=n))
    hf *= hf_rms / hf.std()
    acc = lf + hf
    rate = np.concatenate([[0.0], np.cumsum(0.5 * (acc[1:] + acc[:-1]) * h)])
    return acc[::sub], rate[::sub] + rng.normal(0.0, GYRO_NOISE, T)


def _err(x, ref):
    m = slice(100, -100)
    return float(np.sqrt(np.mean((x[m] - ref[m]) ** 2) / np.mean(ref[m] ** 2)))


def test_content_above_the_smoother_bandwidth_is_recovered():
    pd, z = _gust_axis()
    Z = np.stack([z] * 3, 1)
    plain = smooth_rates(DT, Z, residual_correction=False)
    R = smooth_rates(DT, Z)
    # the setting this is about: the likelihood's bandwidth lies below the 3-4 Hz content
    assert plain.bandwidth_hz[0] <= 2.5, plain.bandwidth_hz
    e_plain, e = _err(plain.accel[:, 0], pd), _err(R.accel[:, 0], pd)
    # measured: 32 % without the correction, 18 % with it
    assert e < 0.25 and e < 0.7 * e_plain, (e, e_plain)
    lo, hi = R.correction_band_hz[0]
    assert lo <= 3.5 <= hi, R.correction_band_hz
    # the rate itself gets no worse (the correction adds the missed rate, not noise)
    m = slice(100, -100)
    assert np.std(R.rate[m, 0] - plain.rate[m, 0]) < 0.01
    # the uncertainty grows by the correction's own error
    assert np.all(R.accel_sigma[m, 0] >= plain.accel_sigma[m, 0])


def test_no_content_above_the_bandwidth_changes_nothing():
    pd, z = _gust_axis(seed=3, hf_rms=0.0, lf_rms=0.15)
    Z = np.stack([z] * 3, 1)
    plain = smooth_rates(DT, Z, residual_correction=False)
    R = smooth_rates(DT, Z)
    assert _err(R.accel[:, 0], pd) <= _err(plain.accel[:, 0], pd) + 1e-9


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_white_residual_gets_no_gain(seed):
    # a residual that is gyro noise only: no frequency passes the significance test
    r = np.random.default_rng(seed).normal(0.0, GYRO_NOISE, 4500)
    c = residual_wiener(DT, r)
    assert c is not None
    assert not (c.gain > 0).any(), c.freq[c.gain > 0]
    assert c.accel_var == 0.0 and not c.accel.any()
    # the floor is the white noise's one-sided PSD, 2 sigma^2 dt
    assert c.noise_psd == pytest.approx(2 * GYRO_NOISE**2 * DT, rel=0.1)


def test_a_band_over_the_floor_is_found_and_differentiated():
    rng = np.random.default_rng(7)
    t = np.arange(4500) * DT
    sig = 0.004 * np.sin(2 * np.pi * 3.3 * t + 0.4)        # a 3.3 Hz rate left in the residual, rad/s
    c = residual_wiener(DT, sig + rng.normal(0.0, GYRO_NOISE, len(t)))
    lo, hi = c.band_hz
    assert lo <= 3.3 <= hi and hi - lo < 1.5, (lo, hi)
    m = slice(200, -200)
    truth_acc = 0.004 * 2 * np.pi * 3.3 * np.cos(2 * np.pi * 3.3 * t + 0.4)
    err = np.sqrt(np.mean((c.accel[m] - truth_acc[m]) ** 2) / np.mean(truth_acc[m] ** 2))
    assert err < 0.3, err


def test_short_or_gappy_pieces_are_left_alone():
    assert residual_wiener(DT, np.zeros(100)) is None           # shorter than four windows
    r = np.random.default_rng(0).normal(0.0, GYRO_NOISE, 2000)
    r[5] = np.nan
    assert residual_wiener(DT, r) is None


def test_slow_grids_are_left_alone():
    # at 10 Hz the band where the floor would be read (above 3 Hz) still holds flight dynamics
    r = np.random.default_rng(0).normal(0.0, GYRO_NOISE, 1000)
    assert residual_wiener(0.1, r) is None
    assert residual_wiener(1 / 25.0, np.random.default_rng(0).normal(0.0, GYRO_NOISE, 2500)) is None
    assert residual_wiener(1 / 30.0, np.random.default_rng(0).normal(0.0, GYRO_NOISE, 3000)) is not None
