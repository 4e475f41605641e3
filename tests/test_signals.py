"""Maneuver waveforms: shapes, durations, orthogonal multisines with a low peak factor."""

import numpy as np
import pytest

from gcs_sysid.errors import InputError
from gcs_sysid.signals import (doublet, duration_of, multisine, multisine_frequencies, multisine_phases,
                               relative_peak_factor, three_two_one_one, waveform)

T = np.arange(0.0, 30.0, 0.01)


def test_doublet_and_3211_levels_and_durations():
    u = doublet(T, 2.0, 0.5, 0.1)
    assert np.allclose(u[(T >= 2.0) & (T < 2.5)], 0.1) and np.allclose(u[(T >= 2.5) & (T < 3.0)], -0.1)
    assert np.all(u[(T < 2.0) | (T >= 3.0 + 1e-9)] == 0)
    v = three_two_one_one(T, 1.0, 0.3, 0.05)
    expect = np.zeros_like(T)
    for a, b, lvl in ((1.0, 1.9, 1), (1.9, 2.5, -1), (2.5, 2.8, 1), (2.8, 3.1, -1)):
        expect[(T >= a - 1e-9) & (T < b - 1e-9)] = 0.05 * lvl
    assert np.mean(np.isclose(v, expect)) > 0.99        # edges may fall one sample either way
    assert duration_of("3211", 0.3) == pytest.approx(2.1) and duration_of("doublet", 0.5) == 1.0
    assert duration_of("multisine", 12.0) == 12.0
    with pytest.raises(InputError, match="unknown maneuver kind"):
        duration_of("sweep", 1.0)
    with pytest.raises(InputError, match="pulse width"):
        doublet(T, 0.0, 0.0, 1.0)


def test_multisines_are_orthogonal_and_scaled():
    dur, band = 12.0, (0.2, 2.0)
    t = np.arange(0.0, dur, 0.005)
    U = np.stack([multisine(t, 0.0, dur, band, 0.07, n_inputs=3, index=i) for i in range(3)])
    G = U @ U.T
    assert np.all(np.abs(G - np.diag(np.diag(G))) < 1e-6 * np.diag(G).min())
    assert np.allclose(np.abs(U).max(1), 0.07, rtol=2e-3)
    assert np.all(np.abs(U[:, 0]) < 0.02)                   # starts near zero (shifted to a zero crossing)
    fs = [set(np.round(multisine_frequencies(dur, band, 3, i) * dur).astype(int)) for i in range(3)]
    assert not (fs[0] & fs[1]) and not (fs[1] & fs[2])
    f = multisine_frequencies(dur, band, 1, 0)
    tau = np.linspace(0, dur, 4000, endpoint=False)
    rpf = [relative_peak_factor(np.cos(2 * np.pi * np.outer(tau, f) + multisine_phases(f, dur, o)).sum(1))
           for o in (False, True)]
    assert rpf[1] <= rpf[0] and rpf[1] < 1.3
    assert np.all(multisine(T, 5.0, dur, band, 1.0)[(T < 5.0) | (T >= 17.0)] == 0)


def test_waveform_dispatch_and_errors():
    assert np.allclose(waveform("doublet", T, 1.0, 0.2, pulse_width=0.5), doublet(T, 1.0, 0.5, 0.2))
    with pytest.raises(InputError, match="band"):
        waveform("multisine", T, 1.0, 0.2, duration=10.0)
    with pytest.raises(InputError, match="fewer than"):
        multisine_frequencies(2.0, (0.6, 0.9), 3, 0)
