"""What the reconstructed alpha's mean error is made of, on the fast JSBSim flight (c172x, 40 s, "calm" (the old light)
Milspec turbulence, seed 1, AHRS AOA_SSA), against JSBSim's exact alpha and wind (slow: two more
estimate_states runs).

The mean error must be the flight-mean vertical wind over the airspeed (out of reach of every channel
of the log: ``gcs_sysid/estimation/angleerrors.py``) and nothing else: an attitude, accelerometer,
wind-model or aiding offset coming back fails the first test. The alpha sigma must carry it.
The instrumented slope (``instrument_slopes``) must keep the scale error below the least-squares one.

Thresholds FROZEN 2026-11-22 03:01 UTC, before the held-out runs (pa28, seed 3), from the 90-s tuning
flights (c172x, sgs seeds 1-2: mean error minus mean(w_d)/V within 0.01 deg on the c172x, 0.07 deg on
the SGS, whose aiding moves the mean by up to 0.07 deg; |mean| / bias sigma 0.36-0.90) and this flight's
first measurement: mean error +0.111 deg against mean(w_d)/V +0.106 deg, smallest alpha sigma 0.17 deg;
alpha scale error +0.064 with least squares, +0.033 with the instrumented slope. Do not retune them to pass.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import load_truth
from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation import estimate_states
from gcs_sysid.telemetry import read_log

pytestmark = pytest.mark.slow


def _truth_on(states, truth, k):
    return np.interp(states.t, truth.t, truth.fields[k], left=np.nan, right=np.nan)


@pytest.fixture(scope="module")
def flight(fast_flight):
    return read_log(fast_flight.tlog), load_airframe(fast_flight.airframe), load_truth(fast_flight.truth)


def test_mean_alpha_error_is_the_mean_vertical_wind_and_sigma_carries_it(flight):
    fl, af, truth = flight
    st = estimate_states(fl, af)
    a_true, wd, V = (_truth_on(st, truth, k) for k in ("alpha", "wd", "V"))
    m = st.valid & np.isfinite(a_true)
    mean_err = float(np.degrees(np.mean(st.data["alpha"][m] - a_true[m])))
    wind_part = float(np.degrees(np.mean(wd[m]) / np.mean(V[m])))
    assert abs(mean_err - wind_part) < 0.05, (mean_err, wind_part)
    sig = st.sigma["alpha"][m]
    assert np.isfinite(sig).all()
    assert abs(mean_err) < 2.5 * np.degrees(sig.min()), (mean_err, np.degrees(sig.min()))
    assert any("mean vertical wind" in n for n in st.notes)


def test_instrumented_slope_keeps_alpha_scale_below_least_squares(flight, monkeypatch):
    import gcs_sysid.estimation.airangles as airangles

    fl, af, truth = flight
    scales = {}
    for on in (False, True):
        monkeypatch.setattr(airangles, "INSTRUMENTED_SLOPES", on)
        st = estimate_states(fl, af)
        a_true = _truth_on(st, truth, "alpha")
        m = st.valid & np.isfinite(a_true)
        e, r = st.data["alpha"][m] - a_true[m], a_true[m] - a_true[m].mean()
        scales[on] = float(np.dot(e - e.mean(), r) / np.dot(r, r))
    assert abs(scales[True]) < 0.06 and abs(scales[True]) < abs(scales[False]), scales
