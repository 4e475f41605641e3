"""Diagnosis of flights from the project's 6-DOF simulation with one hidden effect.

Sim-truth path: the coefficient table is the simulation's truth with the *logged
commands* as control regressors plus measurement noise, turbulence on (light
Dryden); the states for output error are the truth. This isolates the diagnosis
from the estimation layer (the full log path is in ``test_diagnose_e2e.py``).
"""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.core import diagnose
from gcs_sysid.sim import load_model, plan_from_dict, simulate

from diag_flights import AIRFRAME, MODEL, TruthStates, effects, plan_doc, truth_table

CASES = {
    "none": (None, None),
    "Cm:alpha": ("Cm:alpha", 0.3),
    "delay:delta_e": ("delay:delta_e", 0.08),
    "wind": ("wind", (3.0, -4.0, 0.0)),
    "Cl:p_hat": ("Cl:p_hat", -0.2),
    "Cn:beta": ("Cn:beta", 0.1),
    "stuck:delta_a": ("stuck:delta_a", 70.0),
}
SLOW = {"Cl:p_hat", "Cn:beta", "stuck:delta_a"}


@pytest.fixture(scope="module")
def setup():
    return load_airframe(AIRFRAME), load_model(MODEL), plan_from_dict(plan_doc(duration=96.0, seed=11))


@pytest.fixture(scope="module")
def flights(setup):
    """One simulated flight per case, made on first use and shared."""
    cache = {}

    def get(name):
        if name not in cache:
            af, m, plan = setup
            cause, value = CASES[name]
            r = simulate(af, m, plan, effects=effects(cause, value))
            cache[name] = (r, diagnose(truth_table(r, seed=1), af, m, TruthStates(r)))
        return cache[name]

    return get


def _truth(model, name):
    cause, value = CASES[name]
    if cause.startswith("delay:"):
        return value
    if cause == "wind":
        return float(np.hypot(value[0], value[1]))
    if cause.startswith("stuck:"):
        return None
    coef, term = cause.split(":")
    return model.value(coef, term) + value


@pytest.mark.parametrize("name", [n if n not in SLOW else pytest.param(n, marks=pytest.mark.slow)
                                  for n in CASES if n != "none"])
def test_hidden_effect_is_named(setup, flights, name):
    r, d = flights(name)
    assert r.effects.causes() == [CASES[name][0]]
    assert d.findings, f"nothing found: {d.data['candidate_rounds'][0][:3]}"
    top = d.findings[0]
    assert top["cause"] == CASES[name][0]
    truth = _truth(setup[1], name)
    if truth is not None:
        assert top["estimate"] == pytest.approx(truth, rel=0.25)
    else:
        assert top["onset_s"] == pytest.approx(CASES[name][1], abs=0.5)
    assert top["gain"]["percent"] >= 50.0
    assert d.output_error["available"]


def test_no_effect_no_finding(flights):
    r, d = flights("none")
    assert d.findings == []
    assert not any(u["above_threshold"] for u in d.unexplained)
    oe = d.output_error
    assert oe["available"] and "rms_after" not in oe["states_rms"]["alpha"]


def test_output_error_gain_after_delay(flights):
    _, d = flights("delay:delta_e")
    q = d.output_error["states_rms"]["q"]
    assert q["rms_after"] < q["rms_before"]
