"""Air angles aided by the specific force (estimation/airangles.py) on the fast JSBSim flight
(c172x, 40 s, "calm" Milspec turbulence (the harness's light until the fifteenth session), seed 1, AOA_SSA = ArduPilot's
AHRS estimate), against JSBSim's exact alpha and beta; the same flight with the aiding switched off is the reference.

Thresholds FROZEN on 2026-11-21 from the first measurement (aided alpha / beta RMS error 0.116 / 0.079
deg, kinematic 0.236 / 0.207 deg), with a margin of about a third; the final method (slopes above
0.3 Hz instead of 0.15, CY0 ~ 0 prior) measured 0.116 / 0.081 deg, thresholds unchanged. Method tuned
on c172x and sgs only (pa28 held out). Do not retune them to pass.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import load_truth
from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation import estimate_states
from gcs_sysid.telemetry import read_log

MEASURED_AIDED = (0.116, 0.081)
MEASURED_KIN = (0.236, 0.207)
AIDED_MAX_DEG = (0.16, 0.11)        #: alpha, beta, deg RMS


def _errors(states, truth):
    X, _ = truth.at(states.t)
    m = states.valid & np.isfinite(X[:, 0])
    return tuple(float(np.degrees(np.sqrt(np.mean((states.data[k][m] - X[m, i]) ** 2))))
                 for i, k in ((0, "alpha"), (1, "beta")))


@pytest.fixture(scope="module")
def both(fast_flight):
    flight, af = read_log(fast_flight.tlog), load_airframe(fast_flight.airframe)
    return (estimate_states(flight, af), estimate_states(flight, af, aid_air_angles=False),
            load_truth(fast_flight.truth))


def test_specific_force_aiding_beats_the_kinematic_angles(both):
    aided, kin, truth = both
    ea, ek = _errors(aided, truth), _errors(kin, truth)
    assert ea[0] <= AIDED_MAX_DEG[0] and ea[1] <= AIDED_MAX_DEG[1], (ea, ek)
    assert ea[1] < 0.5 * ek[1], (ea, ek)          # the sideslip gusts come from the side force
    assert all("aided by the specific force" in n for n in aided.notes if n.startswith(("alpha aided", "beta aided")))
    assert "gusts from the specific force" in aided.sources["beta"]
    assert "gusts from the specific force" not in kin.sources["beta"]
