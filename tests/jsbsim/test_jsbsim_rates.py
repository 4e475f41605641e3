"""The rate smoother's residual correction (estimation/wiener.py) on a JSBSim flight, against JSBSim's
exact angular accelerations.

Thresholds FROZEN on 2026-11-22 from the measurement on the tuning aircraft (c172x, 90 s, moderate
turbulence (severity 3: the harness's "light" since the fifteenth session, which this test flies), seed 1,
AHRS AOA_SSA; docs/benchmarks.md "Issue 8: the rate smoother's residual"):
angular-acceleration error over the flight (2 s trimmed at each end) p_dot 15.2 % without the
correction, 13.2 % with it; q_dot 20.1 / 20.1, r_dot 10.4 / 10.4 (no band found on those axes). The
test asks for a third of that gain on p_dot and nothing worse on q_dot and r_dot.
"""

import functools

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, load_truth, make_flight
from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation import estimate as estimate_module
from gcs_sysid.estimation import estimate_states
from gcs_sysid.estimation.rates import smooth_rates
from gcs_sysid.telemetry import read_log


def _accel_errors(states, truth) -> dict[str, float]:
    out = {}
    for k in ("p_dot", "q_dot", "r_dot"):
        ref = np.interp(states.t, truth.t, truth.fields[k])
        m = np.isfinite(states.data[k]) & (states.t > states.t[0] + 2.0) & (states.t < states.t[-1] - 2.0)
        out[k] = float(100 * np.sqrt(np.mean((states.data[k][m] - ref[m]) ** 2) / np.mean(ref[m] ** 2)))
    return out


@pytest.mark.slow
def test_residual_correction_follows_the_gusts_on_jsbsim(tmp_path, monkeypatch):
    # "light" is the frozen flight: the old "moderate" (severity 3, 30 kt at 20 ft) is the new "light"
    # (severity 3, 15 kt) above 2000 ft, where the 20-ft wind is not used (c172x at 6000 ft; turb15)
    files = make_flight(FlightConfig("c172x", duration_s=90.0, turbulence="light", seed=1), tmp_path, aoa="ahrs")
    truth, af = load_truth(files.truth), load_airframe(files.airframe)
    flight = read_log(files.tlog)
    with_corr = _accel_errors(estimate_states(flight, af), truth)
    monkeypatch.setattr(estimate_module, "smooth_rates", functools.partial(smooth_rates, residual_correction=False))
    without = _accel_errors(estimate_states(flight, af), truth)
    assert with_corr["p_dot"] < without["p_dot"] - 0.7, (with_corr, without)
    for k in ("q_dot", "r_dot"):
        assert with_corr[k] <= without[k] + 0.2, (k, with_corr, without)
