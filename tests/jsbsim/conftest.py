"""Fixtures of the JSBSim truth tests: one short flight shared by the module tests.

The harness lives in ``benchmarks/jsbsim_harness`` (outside the package, so truth cannot reach the
pipeline); the repository root is put on the import path for it.
"""

import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))
# this directory's helpers (truth_fits, static_checks, model_checks)
sys.path.insert(0, str(Path(__file__).resolve().parent))

from benchmarks.jsbsim_harness import FlightConfig, make_flight  # noqa: E402

#: The fast flight: c172x gliding, 40 s logged, "calm" Milspec turbulence (severity 1, what the harness
#: called light until the fifteenth session; docs/jsbsim.md, "Turbulence levels"), seed 1, AHRS AOA_SSA.
#: The thresholds of the tests that share it were frozen on this flight; they check mechanisms (the
#: Earth model, the lever arm, the aiding, the side-force floor, predict), not a level of turbulence.
FAST = FlightConfig("c172x", duration_s=40.0, turbulence="calm", seed=1)


@pytest.fixture(scope="session")
def fast_flight(tmp_path_factory):
    """(FlightFiles) of the fast flight: .tlog, truth .npz, airframe, recording."""
    return make_flight(FAST, tmp_path_factory.mktemp("jsbsim"))
