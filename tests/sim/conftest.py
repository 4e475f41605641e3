"""Shared fixtures of the simulation tests: the sample airframe and model, and one short plan.

Every simulated flight in these tests uses the same plan shape (20 s at 50 Hz, 4 RK4
sub-steps), so the compiled simulation loop is reused across tests.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.sim import load_model, plan_from_dict, simulate

ROOT = Path(__file__).resolve().parents[2]


def short_plan_doc(**over) -> dict:
    """A 20 s plan from vehicle time 30 s: elevator 3-2-1-1, aileron and rudder doublets, light turbulence."""
    doc = {
        "name": "short", "duration_s": 20.0, "rate_hz": 50.0, "internal_rate_hz": 200.0, "start_time_s": 30.0,
        "seed": 11,
        "initial": {"airspeed_mps": 20.0, "altitude_m": 150.0, "heading_deg": 30.0},
        "home": {"alt_m": 50.0},
        "maneuver": [
            {"kind": "3211", "control": "delta_e", "start_s": 32.0, "pulse_s": 0.3, "amplitude_deg": 2.0,
             "mode": "open"},
            {"kind": "doublet", "control": "delta_a", "start_s": 38.0, "pulse_s": 0.4, "amplitude_deg": 4.0},
            {"kind": "doublet", "control": "delta_r", "start_s": 42.0, "pulse_s": 0.5, "amplitude_deg": 5.0},
            {"kind": "multisine", "controls": ["delta_e", "delta_a"], "start_s": 44.0, "duration_s": 5.0,
             "band_hz": [0.4, 2.0], "amplitude_deg": [1.5, 3.0]},
        ],
        "wind": {"speed_mps": 3.0, "from_deg": 200.0},
        "turbulence": {"w20_mps": 4.0},
    }
    doc.update(over)
    return doc


@pytest.fixture(scope="session")
def airframe():
    return load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml")


@pytest.fixture(scope="session")
def model():
    return load_model(ROOT / "data" / "models" / "sim-trainer.toml")


@pytest.fixture(scope="session")
def short_plan():
    return plan_from_dict(short_plan_doc(), "short.toml")


@pytest.fixture(scope="session")
def short_flight(airframe, model, short_plan):
    """The short plan flown without effects."""
    return simulate(airframe, model, short_plan)


#: Sensor effects of the ``biased_flight`` fixture.
SENSOR_EFFECTS = dict(gyro_bias=(0.01, -0.02, 0.005), accel_bias=(0.15, 0.0, -0.25), airspeed_bias=1.5,
                      airspeed_scale=1.1, alpha_bias=0.05, beta_bias=-0.03)


@pytest.fixture(scope="session")
def biased_flight(airframe, model, short_plan):
    """The short plan flown with sensor biases and an airspeed scale error."""
    from gcs_sysid.sim import Effects

    return simulate(airframe, model, short_plan, effects=Effects(**SENSOR_EFFECTS))
