"""Independent truth harness: stock JSBSim aircraft fly system-identification maneuvers in
turbulence, and the flight is written as an ArduPilot-like .tlog plus, apart, the exact truth.

Kept outside the ``gcs_sysid`` package so that truth can never reach the pipeline. See
``docs/jsbsim.md``.

Typical use::

    from benchmarks.jsbsim_harness import FlightConfig, make_flight, load_truth
    files = make_flight(FlightConfig("c172x", duration_s=60, turbulence="light", seed=1), "out/")
    # gcs-sysid replay files.tlog --airframe files.airframe ...; compare with load_truth(files.truth)

Importing the package writes the derived models (``derived.py``: the f16 with direct surfaces) into
the installed jsbsim wheel's ``aircraft/`` folder where they are missing or stale, so that the
harness's loader finds them by name.
"""

from .derived import install_derived_models

install_derived_models()

from .aircraft import (AIRCRAFT, HELD_OUT_AIRCRAFT, TUNING_AIRCRAFT, UNTOUCHED_AIRCRAFT,  # noqa: E402
                       AircraftSpec, aircraft, canonical_name)
from .flight import TURBULENCE, FlightConfig, Recording, fly, maneuver_inputs  # noqa: E402
from .logfile import FlightFiles, make_flight, write_log  # noqa: E402
from .scoring import coefficient_errors, score_table  # noqa: E402
from .sensors import AOA_VARIANTS, SENSOR_RATES_HZ, make_sensors  # noqa: E402
from .truth import Truth, load_truth, save_truth, truth_coefficients, truth_regressors  # noqa: E402

__all__ = ["AIRCRAFT", "HELD_OUT_AIRCRAFT", "TUNING_AIRCRAFT", "UNTOUCHED_AIRCRAFT", "AircraftSpec", "aircraft",
           "canonical_name", "TURBULENCE",
           "FlightConfig", "Recording", "fly", "maneuver_inputs", "FlightFiles", "make_flight", "write_log",
           "AOA_VARIANTS", "SENSOR_RATES_HZ", "make_sensors", "Truth", "load_truth", "save_truth",
           "truth_coefficients", "truth_regressors", "score_table", "coefficient_errors"]
