"""Limits: the airframe's [limits] table, defaults from the flown envelope, no suggestion outside them,
out-of-reach regions moved to the nearest safe condition, quality gate, targeting, plan file."""

import dataclasses
import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
from gcs_sysid.airframe import airframe_from_dict, airframe_to_dict, load_airframe
from gcs_sysid.envelope import FlaggedRegion
from gcs_sysid.errors import InputError
from gcs_sysid.maneuvers import (ManeuverConfig, check_peaks, effective_limits, plan_document, quality_gate,
                                 suggest_maneuvers)

_spec = importlib.util.spec_from_file_location("exact_gp_double", Path(__file__).parent / "exact_gp_double.py")
double = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(double)

DATA = Path(__file__).resolve().parents[1] / "data"
AIRFRAME = DATA / "airframes" / "sim-trainer.toml"


@pytest.fixture(scope="module")
def setup():
    return double.envelope_setup(AIRFRAME)


@pytest.fixture(scope="module")
def full(setup):
    """Suggestions over the whole map (one design-and-rank run shared by several tests)."""
    tab, train, model, env, af = setup
    return suggest_maneuvers(env, model, tab, af, max_suggestions=30, config=ManeuverConfig(max_regions=12))


def _doc(**limits):
    doc = airframe_to_dict(load_airframe(AIRFRAME))
    doc["limits"] = limits
    return doc


def test_limits_table_parsed_and_round_trips():
    af = load_airframe(AIRFRAME)
    lim = af.limits
    assert lim.V_min == 12.0 and lim.V_max == 25.0 and lim.n_max == 3.0
    assert lim.alpha_max == pytest.approx(math.radians(12.0))
    assert (lim.throw["delta_r"] == pytest.approx(math.radians(20.0))
            and lim.rate["delta_e"] == pytest.approx(math.radians(300)))
    back = airframe_from_dict(airframe_to_dict(af)).limits
    assert dataclasses.replace(back, alpha_max=lim.alpha_max) == lim and back.alpha_max == pytest.approx(lim.alpha_max)
    assert load_airframe(DATA / "airframes" / "carbon-z-t28.toml").limits.V_min == 14.0


@pytest.mark.parametrize("limits, match", [
    ({"V_min_mps": 20.0, "V_max_mps": 15.0}, "V_min_mps .20. must be below V_max_mps"),
    ({"n_max": 0.8}, r"n_max must lie in \(1, 15\]"),
    ({"alpha_max_deg": 0.0}, "alpha_max_deg' must be > 0"),
    ({"throw_deg": {"delta_e": 30.0}}, "throw_deg.delta_e = 30 deg exceeds the servos' travel .20.0 deg"),
    ({"throw_deg": {"delta_x": 3.0}}, "key 'delta_x' is not one of"),
    ({"rate_dps": {"delta_a": -5.0}}, "must be > 0"),
    ({"V_max": 30.0}, "unknown field 'V_max'"),
])
def test_contradictory_or_impossible_limits_are_one_line_errors(limits, match):
    with pytest.raises(InputError, match=match) as e:
        airframe_from_dict(_doc(**limits), "t.toml")
    assert "\n" not in str(e.value) and str(e.value).startswith("t.toml: [limits]")


def test_limits_default_from_flown_envelope_and_say_so(setup):
    tab, train, _, _, af = setup
    doc = airframe_to_dict(af)
    del doc["limits"]
    bare = airframe_from_dict(doc)
    lim = effective_limits(bare, tab, train)
    V = tab.x("V")[train]
    assert lim.V_min == pytest.approx(np.quantile(V, 0.01)) and lim.V_max == pytest.approx(1.05 * np.quantile(V, 0.99))
    assert lim.alpha_max == pytest.approx(np.quantile(tab.x("alpha")[train], 0.995) + math.radians(1))
    assert all("flown envelope" in lim.source[k] for k in ("V_min", "V_max", "alpha_max", "n_max", "throw.delta_e"))
    assert lim.throw["delta_e"] == pytest.approx(0.75 * math.radians(20.0))
    partial = airframe_from_dict(_doc(V_min_mps=11.0))
    lp = effective_limits(partial, tab, train)
    assert lp.V_min == 11.0 and lp.source["V_min"] == "airframe file" and "V_max" in lp.defaulted
    with pytest.raises(InputError, match="no flown envelope"):
        effective_limits(bare)
    with pytest.raises(InputError, match="contradict"):   # given V_min above the flown V_max default
        effective_limits(airframe_from_dict(_doc(V_min_mps=60.0)), tab, train)


def test_every_suggestion_inside_limits_and_peaks_checked(setup):
    tab, train, model, env, af = setup
    tight = airframe_from_dict(_doc(V_min_mps=14.0, V_max_mps=22.0, n_max=1.4, alpha_max_deg=9.0,
                                    throw_deg={"delta_e": 10.0, "delta_a": 10.0, "delta_r": 12.0},
                                    rate_dps={"delta_e": 80.0, "delta_a": 120.0, "delta_r": 120.0}))
    sug = suggest_maneuvers(env, model, tab, tight, max_suggestions=30,
                            config=ManeuverConfig(max_regions=12, min_reduction=0.0, min_relative_reduction=0.0))
    assert sug
    lim = effective_limits(tight, tab, train)
    kinds = set()
    for s in sug:
        kinds.add(s.kind)
        assert check_peaks(s.expected, lim) == [], s.reason
        assert 14.0 - 1e-9 <= s.flight_condition["V"] <= 22.0 + 1e-9
        assert s.expected["alpha_max_deg"] <= 9.0 + 1e-6 and 2 - 1.4 - 1e-6 <= s.expected["n_min"]
        assert s.expected["n_max"] <= 1.4 + 1e-6
        for c, a in s.amplitudes_rad.items():   # trim + input within the throw
            base = s.flight_condition["delta_e_trim"] if c == "delta_e" else env.reference[c]
            assert abs(base) + a <= lim.throw[c] + 1e-9
            assert np.max(np.abs(np.diff(s.u[c]))) / np.diff(s.t)[0] <= lim.rate[c] * 1.05 or s.kind != "multisine"
        if s.kind != "multisine":   # a step's edge at the rate limit takes at most 20 % of the pulse
            assert 2 * s.amplitude_rad / lim.rate[s.control] <= 0.2 * s.pulse_width_s + 1e-9
    assert "multisine" in kinds
    # the check itself fails on a peak beyond a limit
    bad = dict(sug[0].expected, n_max=lim.n_max + 0.5)
    assert any("load factor" in b for b in check_peaks(bad, lim))
    assert sug.context["limits"]["V_min_mps"] == 14.0


def _region(env, coef, axes, center_vals, n=6):
    ref = np.array([env.reference[r] for r in REGRESSORS])
    P = np.tile(ref, (n, 1))
    for k, v in center_vals.items():
        P[:, REGRESSORS.index(k)] = v + np.linspace(-0.01, 0.01, n) * (1 if k != "V" else 50)
    center = dict(env.reference)
    center.update(center_vals)
    bounds = {k: (float(P[:, REGRESSORS.index(k)].min()), float(P[:, REGRESSORS.index(k)].max())) for k in axes}
    return FlaggedRegion(coef, axes, bounds, center, 0.9, 0.9, 0, n, 1, "test", P)


def test_out_of_reach_region_offers_nearest_safe_condition(setup):
    tab, train, model, env, af = setup
    slow = _region(env, "Cm", ("alpha", "V"), {"alpha": math.radians(16.0), "V": 8.0})
    e2 = dataclasses.replace(env, regions=[slow])
    sug = suggest_maneuvers(e2, model, tab, af, config=ManeuverConfig(min_reduction=0.0))
    assert sug
    for s in sug:
        assert s.flight_condition["V"] >= 12.0 and s.flight_condition["alpha_deg"] <= 12.0 - 3.0 + 1e-6
        assert "out of reach" in s.reason and "nearest safe condition" in s.reason
    assert sug.context["out_of_reach"] and "below V_min 12.0" in sug.context["out_of_reach"][0]


def test_lateral_axes_and_moment_first_weighting(setup, full):
    tab, train, model, env, af = setup
    sug = full
    surfaces = {c for s in sug for c in s.controls}
    best = max(s.expected_reduction for s in sug)   # nothing suggested that teaches next to nothing
    assert all(s.expected_reduction >= 0.1 * best - 1e-12 for s in sug)
    assert {"delta_a", "delta_r"} <= surfaces
    assert any(s.kind == "multisine" and s.controls == ("delta_e", "delta_a", "delta_r") for s in sug)
    assert sug[0].coefficients[0] in ("Cl", "Cm", "Cn")
    w = sug.context["weights"]
    assert max(w[c] for c in ("CX", "CY", "CZ")) <= 0.35 + 1e-9 and max(w[c] for c in ("Cl", "Cm", "Cn")) == 1.0
    # rates in deg/s, not q_hat, in the words
    assert all("_hat" not in s.reason for s in sug)
    # regions grouped by fix: far fewer groups than regions
    g = sug.context["groups"]
    assert g and sum(x["regions"] for x in g) > len(g)
    assert all(x["fix"].split()[0] in ("elevator", "aileron", "rudder") for x in g)
    # the user can target any coefficient (a force here)
    only = suggest_maneuvers(env, model, tab, af, config=ManeuverConfig(targets=("CY",), max_regions=4))
    assert only and all(s.coefficients == ("CY",) for s in only)
    with pytest.raises(InputError, match="target coefficients"):
        suggest_maneuvers(env, model, tab, af, config=ManeuverConfig(targets=("Cq",)))


def test_quality_gate_keeps_failing_coefficients_out(setup):
    tab, train, model, env, af = setup
    gate = quality_gate({"Cn": 330.0, "Cl": 80.0, "Cm": 12.0}, {"CY": (False, "IMU at 4 Hz")})
    assert set(gate) == {"Cn", "Cl", "CY"}
    assert "330 %" in gate["Cn"]["why"] and "airframe file" in gate["Cn"]["fix"]
    assert "excitation" in gate["Cl"]["fix"] and "not identified" in gate["CY"]["why"]
    err = {c: 10.0 for c in COEFFICIENTS}
    err["Cl"] = 330.0
    sug = suggest_maneuvers(env, model, tab, af, max_suggestions=30, heldout_error_pct=err,
                            config=ManeuverConfig(max_regions=6))
    assert sug and all("Cl" not in s.coefficients for s in sug)
    assert "Cl" in sug.context["gated"] and sug.context["weights"]["Cl"] == 0.0


def test_plan_file_flies_the_suggestions_exactly(full):
    from gcs_sysid.signals import waveform
    from gcs_sysid.sim import plan_from_dict

    sug = full
    doc = plan_document(sug[:4])
    plan = plan_from_dict(doc, "fly.toml")
    assert len(plan.maneuvers) == 4
    for s, m in zip(sug, plan.maneuvers):
        assert m.kind == s.kind and m.controls == s.controls
        assert all(a <= s.amplitudes_rad[c] + 1e-12 for a, c in zip(m.amplitude, m.controls))
        # the simulator builds the suggestion's own input: same waveform from the plan's parameters
        i = 0
        tt = m.start + (s.t - s.lead_s)
        u = waveform(m.kind, tt, m.start, m.amplitude[i], m.pulse, m.duration, m.band, len(m.controls), i)
        off = np.abs(u - s.u[s.controls[0]]) > 2e-4   # a sample exactly on a pulse edge may fall either side
        assert off.sum() <= {"doublet": 3, "3211": 5, "multisine": 1}[s.kind], (s.kind, off.sum())
        sp = [p for p in plan.setpoints if p.start <= m.start][-1]
        assert sp.airspeed == pytest.approx(s.flight_condition["V"], abs=0.01)
    with pytest.raises(InputError, match="no suggestions"):
        plan_document([])
    zero = dataclasses.replace(sug[0], input_s=0.0)
    with pytest.raises(InputError, match="zero duration"):
        plan_document([zero])
    with pytest.raises(InputError, match="more than the 5 s"):
        plan_document(sug[:2], duration_s=5.0)


@pytest.mark.slow   # tests/test_pipeline_parallel.py replays the sample flight with targets=("Cn",) too
def test_replay_targets_only_the_coefficients_asked_for(tmp_path):
    """``replay --target Cn`` (ReplayOptions.targets): every suggestion of the sample flight aims at Cn."""
    from gcs_sysid.pipeline import ReplayOptions, run_replay

    data = Path(__file__).resolve().parents[1] / "data"
    r = run_replay(data / "flights" / "sim-trainer-sysid.tlog", data / "airframes" / "sim-trainer.toml", tmp_path,
                   ReplayOptions(progress=False, write=False, parallel=False, t_from=40.0, t_to=160.0,
                                 targets=("Cn",)))
    assert r.suggestions, "no suggestion for Cn"
    assert all(set(s.coefficients) == {"Cn"} for s in r.suggestions), [s.coefficients for s in r.suggestions]
