"""benchmarks/imu_noise.py: its estimators give back a known white-noise level under motion."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.imu_noise import (diff_sigma, flight_noise, independent_sigma, pair_sigma,  # noqa: E402
                                  psd_sigma)
from gcs_sysid.errors import InputError  # noqa: E402

FS = 50.0


def _motion(t: np.ndarray, f_max: float) -> np.ndarray:
    """A rigid-body-like signal: 1 m/s^2 RMS of sinusoids from 0.1 Hz to ``f_max``."""
    f = np.linspace(0.1, f_max, 8)
    ph = np.random.default_rng(7).uniform(0, 2 * np.pi, len(f))
    return np.sin(2 * np.pi * f[:, None] * t + ph[:, None]).sum(0) / 2.0


def test_white_noise_level_is_given_back_under_motion_at_50_and_10_hz():
    t = np.arange(0, 300, 1 / FS)
    noise = np.random.default_rng(1).normal(0, 0.05, len(t))
    x = _motion(t, 2.0) + noise
    assert np.std(x) > 10 * 0.05                      # the motion dominates the raw samples
    assert diff_sigma(x) == pytest.approx(0.05, rel=0.05)
    assert psd_sigma(x, 1 / FS) == pytest.approx(0.05, rel=0.1)
    # point-sampled at 10 Hz (the ALFA logs' rate) the per-sample level is the same, motion under fs/10
    y = _motion(t, 0.5) + noise
    assert diff_sigma(y[::5]) == pytest.approx(0.05, rel=0.08)
    # a masked-out stretch of a larger noise is not counted
    z = x.copy()
    z[:3000] += np.random.default_rng(2).normal(0, 0.5, 3000)
    ok = np.ones(len(z) - 2, bool)
    ok[:3000] = False
    assert diff_sigma(z, ok) == pytest.approx(0.05, rel=0.06)
    assert diff_sigma(z) > 0.1


def test_two_imus_separate_their_own_noise_from_a_shared_signal():
    rng = np.random.default_rng(3)
    n = 20000
    shared = rng.normal(0, 0.3, n)                     # vibration/motion both chips see: white, large
    x1, x2 = shared + rng.normal(0, 0.03, n), shared + rng.normal(0, 0.08, n)
    assert diff_sigma(x1) > 0.25                       # the one-channel estimators cannot separate it
    s1, s2 = independent_sigma(x1, x2)
    assert s1 == pytest.approx(0.03, rel=0.25)
    assert s2 == pytest.approx(0.08, rel=0.1)
    assert pair_sigma(x1, x2) == pytest.approx(np.sqrt((0.03 ** 2 + 0.08 ** 2) / 2), rel=0.05)


def test_a_file_that_is_not_a_log_is_an_input_error(tmp_path):
    p = tmp_path / "notes.tlog"
    p.write_text("not a log\n" * 50)
    with pytest.raises(InputError, match="not a MAVLink log"):
        flight_noise(p)
