"""Maneuver suggestions: right surface, ranking by expected variance reduction, moments first when weakest."""

import dataclasses
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.airframe import airframe_from_dict, airframe_to_dict, load_airframe
from gcs_sysid.envelope import EnvelopeConfig, FlaggedRegion, confidence_map
from gcs_sysid.maneuvers import (SURFACE_OF, ManeuverConfig, Suggestion, derivative_estimates, linear_models,
                                 suggest_maneuvers)

_spec = importlib.util.spec_from_file_location("exact_gp_double", Path(__file__).parent / "exact_gp_double.py")
double = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(double)

AIRFRAME = Path(__file__).resolve().parents[1] / "data" / "airframes" / "sim-trainer.toml"


@pytest.fixture(scope="module")
def setup():
    return double.envelope_setup(AIRFRAME)


def _region(env, coef, axes, x_sel, y_sel, mean_rel=0.8):
    """A hand-made region of the cells (x_sel, y_sel index ranges) of a slice."""
    sl = next(s for s in env.slices if s.axes == axes)
    ref = np.array([env.reference[r] for r in REGRESSORS])
    gx, gy = np.meshgrid(sl.x_centers[x_sel], sl.y_centers[y_sel])
    P = np.tile(ref, (gx.size, 1))
    P[:, REGRESSORS.index(axes[0])] = gx.ravel()
    P[:, REGRESSORS.index(axes[1])] = gy.ravel()
    center = dict(env.reference)
    center[axes[0]], center[axes[1]] = float(gx.mean()), float(gy.mean())
    bounds = {axes[0]: (float(gx.min()), float(gx.max())), axes[1]: (float(gy.min()), float(gy.max()))}
    return FlaggedRegion(coef, axes, bounds, center, mean_rel, mean_rel, 0, len(P), 1, "test region", P)


def test_surface_per_coefficient(setup):
    tab, _, model, env, af = setup
    sug = suggest_maneuvers(env, model, tab, af, max_suggestions=30, config=ManeuverConfig(max_regions=12))
    assert sug and [s.rank for s in sug] == list(range(1, len(sug) + 1))
    assert all(a.priority >= b.priority for a, b in zip(sug, sug[1:]))
    for s in sug:
        if s.kind != "multisine":
            assert len(s.controls) == 1
            assert all(SURFACE_OF[c] == s.control for c in s.coefficients), (s.coefficients, s.controls)
        else:
            assert {SURFACE_OF[c] for c in s.coefficients} <= set(s.controls) and len(s.controls) >= 2
        assert s.kind in ("doublet", "3211", "multisine")
        assert 0.0 <= s.expected_reduction <= 1.0
        assert s.amplitude_deg == pytest.approx(np.degrees(s.amplitude_rad))
        for c, a in s.amplitudes_rad.items():   # within the 20-25 deg surface limits, at least 1 deg
            assert np.radians(1.0) - 1e-9 <= a <= np.radians(25.0)
            assert np.max(np.abs(s.u[c])) == pytest.approx(a, rel=0.02)
        assert s.coefficients[0] in s.reason and "sigma" in s.reason
        assert s.t[-1] <= s.duration_s and s.flight_condition["V"] > 5
    json.dumps([s.to_dict() for s in sug], allow_nan=False)
    back = Suggestion.from_dict(json.loads(json.dumps(sug[0].to_dict())))
    assert back.coefficients == sug[0].coefficients and np.allclose(back.u[back.control], sug[0].u[sug[0].control],
                                                                    atol=1e-6)


def test_unexplored_region_ranks_above_explored(setup):
    tab, _, model, env, af = setup
    n = len(env.slices[0].x_centers)
    explored = _region(env, "Cm", ("alpha", "V"), slice(n // 2 - 2, n // 2 + 2), slice(n // 2 - 2, n // 2 + 2))
    unexplored = _region(env, "Cm", ("alpha", "V"), slice(n - 4, n), slice(0, 4))
    e2 = dataclasses.replace(env, regions=[explored, unexplored])
    sug = suggest_maneuvers(e2, model, tab, af)
    assert sug[0].region["center"]["alpha"] == pytest.approx(unexplored.center["alpha"])
    ex = [s for s in sug if s.region["center"]["alpha"] == pytest.approx(explored.center["alpha"])]
    assert ex and sug[0].expected_reduction > ex[0].expected_reduction
    # the unexplored corner is at high alpha and low V: the flight condition follows
    assert sug[0].flight_condition["alpha"] > env.reference["alpha"]
    assert sug[0].control == "delta_e"


@pytest.mark.parametrize("weak, strong", [(("Cl", "Cm", "Cn"), ("CX", "CY", "CZ")),
                                          (("CX", "CY", "CZ"), ("Cl", "Cm", "Cn"))])
def test_weakest_coefficients_first(setup, weak, strong):
    tab, _, model, env, af = setup
    n = len(env.slices[0].x_centers)
    regs = [_region(env, c, ("alpha", "V"), slice(n - 4, n), slice(0, 4)) for c in weak + strong]
    scores = {**{c: 0.1 for c in weak}, **{c: 0.9 for c in strong}}
    e2 = dataclasses.replace(env, regions=regs, scores=scores)
    sug = suggest_maneuvers(e2, model, tab, af, config=ManeuverConfig(targets=("CX", "CY", "CZ", "Cl", "Cm", "Cn")))
    assert sug[0].coefficients[0] in weak
    top_weak = sum(c in weak for c in sug[0].coefficients)
    assert top_weak >= 1 and sug[0].priority > sug[-1].priority
    # by default the moment coefficients lead even when the forces are weaker
    default = suggest_maneuvers(e2, model, tab, af)
    assert default[0].coefficients[0] in ("Cl", "Cm", "Cn")


def test_mode_frequency_sets_pulse_width(setup):
    tab, train, model, env, af = setup
    d, _, assumed = derivative_estimates(tab, train)
    assert d[("Cm", "alpha")] == pytest.approx(double.SYNTH_DERIVATIVES[4, 1], rel=0.1)
    assert d[("Cl", "p_hat")] == pytest.approx(double.SYNTH_DERIVATIVES[3, 3], rel=0.15)
    assert not [a for a in assumed if a.startswith("Cm")]
    lon = linear_models(d, af, 18.0, 1.2, 0.05)["lon"][0]
    w_sp = np.max(np.abs(np.linalg.eigvals(lon)))
    # short-period approximation w^2 = Za Mq / V - Ma (Etkin and Reid 1996, eq. 6.3,6)
    qS = 0.5 * 1.2 * 18.0**2 * af.S
    Za = qS * d[("CZ", "alpha")] / af.mass
    Ma = qS * af.c * d[("Cm", "alpha")] / af.Iyy
    Mq = qS * af.c * d[("Cm", "q_hat")] * af.c / 36.0 / af.Iyy
    assert w_sp == pytest.approx(np.sqrt(Za * Mq / 18.0 - Ma), rel=0.05)
    n = len(env.slices[0].x_centers)
    e2 = dataclasses.replace(env, regions=[_region(env, "Cm", ("alpha", "V"), slice(n - 4, n), slice(0, 4))])
    s = [x for x in suggest_maneuvers(e2, model, tab, af) if x.kind == "doublet"]
    if s:
        w = 2 * np.pi * s[0].mode_hz["delta_e"]
        assert s[0].pulse_width_s == pytest.approx(np.clip(2.3 / w, 0.15, 3.0), rel=1e-6)


def test_no_rudder_uses_aileron_for_yaw(setup):
    tab, _, model, env, af = setup
    doc = airframe_to_dict(af)
    doc["servo"] = [s for s in doc["servo"] if s["name"] != "rudder"]
    for k in ("throw_deg", "rate_dps"):
        doc["limits"][k].pop("delta_r")
    flying_wing = airframe_from_dict(doc)
    n = len(env.slices[0].x_centers)
    e2 = dataclasses.replace(env, regions=[_region(env, "Cn", ("beta", "delta_r"), slice(n - 4, n), slice(n - 4, n))])
    sug = suggest_maneuvers(e2, model, tab, flying_wing)
    assert sug and all("delta_a" in s.controls and "delta_r" not in s.controls for s in sug)
    assert any(s.controls == ("delta_a",) for s in sug)


def test_batched_ranking_of_the_package_gp_equals_one_update_per_candidate():
    """The package's GP ranks all candidates in one closed-form call; the same numbers come from
    refitting its global layer with each candidate's rows (the generic variance_after path)."""
    from gcs_sysid.gp import GPConfig, fit_gp

    tab = double.synthetic_table(n=300, seed=4)
    train = np.ones(len(tab.t), bool)
    cfg = GPConfig(n_inducing=16, n_train_max=200, steps=40, mi_pool=200, local=False, batch_size=128)
    model, _ = fit_gp(tab.X[train], tab.Y[train], cfg)
    env = confidence_map(model, tab, train, EnvelopeConfig(n_grid=10))
    af = load_airframe(AIRFRAME)

    class GlobalOnly:   # the same model seen through the generic interface only
        def predict(self, X, include_noise=True):
            return model.predict_global(X, include_noise)

        def variance_after(self, X_extra, X_query, include_noise=True):
            return model.update(X_extra, np.zeros((len(X_extra), 6))).predict_global(X_query, include_noise)[1]

    mcfg = ManeuverConfig(max_regions=4)
    fast = suggest_maneuvers(env, model, tab, af, max_suggestions=5, config=mcfg)
    slow = suggest_maneuvers(env, GlobalOnly(), tab, af, max_suggestions=5, config=mcfg)
    assert fast and [(s.kind, s.controls, s.coefficients) for s in fast] == \
        [(s.kind, s.controls, s.coefficients) for s in slow]
    for a, b in zip(fast, slow):
        assert a.reductions == pytest.approx(b.reductions, rel=1e-6, abs=1e-9)
