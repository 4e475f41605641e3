"""Alignment on the grid: gaps, angles, zero-order hold, anti-alias averaging, events."""

import numpy as np
import pytest

from gcs_sysid.estimation.align import align_flight, events, make_grid, resample
from gcs_sysid.telemetry.types import Flight, Stream


def _flight(**rates):
    streams = {}
    for name, hz in rates.items():
        t = np.arange(0.0, 10.0, 1.0 / hz) + 0.003
        streams[name] = Stream(name, name.upper(), t, {"x": np.sin(t)})
    return Flight("mem", "test", streams)


def test_grid_rate_is_capped_by_the_imu_rate():
    t, rate = make_grid(_flight(imu=10.0, attitude=50.0), 50.0)
    assert rate == pytest.approx(10.0)
    assert np.allclose(np.diff(t), 0.1)
    t, rate = make_grid(_flight(imu=100.0), 50.0)
    assert rate == 50.0 and t[0] >= 0.003 and t[-1] <= 10.0
    with pytest.raises(ValueError):
        make_grid(_flight(gps=5.0), 50.0)


def test_linear_interpolation_leaves_gaps_empty():
    ts = np.concatenate([np.arange(0, 5, 0.1), np.arange(7, 10, 0.1)])
    t = np.arange(0, 10, 0.02)
    y, ok = resample(ts, 2 * ts, t)
    gap = (t > 5.0) & (t < 6.95)
    assert not ok[gap].any() and np.isnan(y[gap]).all()
    assert ok[(t < 4.9) | ((t > 7.05) & (t < 9.9))].all()
    assert not ok[t > 9.96].any()  # no extrapolation past the last sample
    inside = ok & (t <= ts[-1])
    np.testing.assert_allclose(y[inside], 2 * t[inside], atol=1e-9)


def test_angles_interpolate_across_pi():
    ts = np.array([0.0, 1.0])
    y, ok = resample(ts, np.array([np.pi - 0.1, -np.pi + 0.1]), np.array([0.5]), mode="angle")
    assert abs(abs(y[0]) - np.pi) < 1e-9  # through +-180 deg, not through 0


def test_hold_keeps_the_last_command():
    ts = np.array([0.0, 1.0, 2.0, 3.0])
    pwm = np.array([1500.0, 1900.0, 1100.0, 1500.0])
    y, ok = resample(ts, pwm, np.array([0.5, 0.99, 1.0, 1.5, 2.7]), mode="hold")
    np.testing.assert_array_equal(y, [1500, 1500, 1900, 1900, 1100])


def test_fast_source_is_averaged_not_picked():
    rng = np.random.default_rng(0)
    ts = np.arange(0, 60, 0.005)          # 200 Hz
    t = np.arange(1, 59, 0.02)            # 50 Hz grid
    y, ok = resample(ts, rng.normal(0, 1.0, len(ts)), t)
    assert ok.all()
    assert np.std(y) == pytest.approx(0.5, rel=0.1)  # 4 samples per cell


def test_events_land_on_nearest_grid_points():
    st = Stream("gps", "GPS", np.array([0.101, 0.299, 0.305]), {"v": np.array([1.0, 2.0, 4.0])})
    ev = events(st, ("v",), np.arange(0, 1, 0.02))
    assert ev[5, 0] == 1.0 and ev[15, 0] == 3.0  # 0.299 and 0.305 share grid point 0.30
    assert np.isfinite(ev[:, 0]).sum() == 2


def test_align_flight_uses_hold_for_servo():
    fl = _flight(imu=50.0)
    fl.streams["servo"] = Stream("servo", "SERVO_OUTPUT_RAW", np.array([0.0, 5.0]),
                                 {"pwm1": np.array([1000.0, 2000.0])})
    al = align_flight(fl, 50.0)
    v = al.values["servo"]["pwm1"]
    assert set(np.unique(v[np.isfinite(v)])) <= {1000.0, 2000.0}
    assert al.rates["imu"] == pytest.approx(50.0)
