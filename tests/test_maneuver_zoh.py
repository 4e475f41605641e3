"""The block zero-order-hold simulation equals the step-by-step recursion, alone and in the suggestions."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.maneuvers import ManeuverConfig, linear, suggest_maneuvers
from gcs_sysid.maneuvers.linear import PRIOR, linear_models, zoh_simulate, zoh_simulate_stepwise
from gcs_sysid.signals import waveform

_spec = importlib.util.spec_from_file_location("exact_gp_double", Path(__file__).parent / "exact_gp_double.py")
double = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(double)

AIRFRAME = Path(__file__).resolve().parents[1] / "data" / "airframes" / "sim-trainer.toml"


def _same(fast, slow):
    """Same NaN rows (divergence cut at the same step) and equal finite values to 1e-12 of their scale."""
    assert fast.shape == slow.shape
    np.testing.assert_array_equal(np.isnan(fast), np.isnan(slow))
    ok = ~np.isnan(slow)
    if ok.any():
        scale = np.max(np.abs(slow[ok]))
        assert np.max(np.abs(fast[ok] - slow[ok])) <= 1e-12 * scale + 1e-300


def test_block_simulation_equals_stepwise_on_random_systems():
    rng = np.random.default_rng(7)
    diverged = 0
    for i in range(120):
        n, m = ((2, 1), (4, 2), (3, 3))[i % 3]
        A = rng.normal(size=(n, n)) * rng.uniform(0.5, 8.0)
        B = rng.normal(size=(n, m))
        K = int(rng.integers(1, 700))
        U = rng.normal(size=(K, m))
        slow = zoh_simulate_stepwise(A, B, U, 0.02)
        diverged += bool(np.isnan(slow).any())
        _same(zoh_simulate(A, B, U, 0.02), slow)
        _same(zoh_simulate(A, B, U, 0.02), slow)       # second call: the cached operators
    assert 20 < diverged < 100                          # both stable and diverging models were checked


def test_block_simulation_equals_stepwise_on_the_airframe_models():
    af = load_airframe(AIRFRAME)
    d = {(c, r): PRIOR.get((c, r), 0.0) for c in ("CX", "CY", "CZ", "Cl", "Cm", "Cn")
         for r in linear.LIN}
    t = np.arange(0.0, 24.0, 0.02)
    for V in (12.0, 18.0, 30.0):
        models = linear_models(d, af, V, 1.2, 0.05)
        for kind in ("doublet", "3211", "multisine"):
            u = np.column_stack([waveform(kind, t, 1.0, 0.1, pulse_width=0.4, duration=12.0, band=(0.2, 2.0),
                                          n_inputs=2, index=i) for i in range(2)])
            for A, B, U in ((*models["lon"], u[:, :1]), (*models["lat"], u)):
                _same(zoh_simulate(A, B, U, 0.02), zoh_simulate_stepwise(A, B, U, 0.02))


def test_suggestions_are_the_same_with_the_stepwise_simulation(monkeypatch):
    tab, _, model, env, af = double.envelope_setup(AIRFRAME)
    cfg = ManeuverConfig(max_regions=8)
    fast = suggest_maneuvers(env, model, tab, af, max_suggestions=10, config=cfg)
    monkeypatch.setattr(linear, "zoh_simulate", zoh_simulate_stepwise)
    slow = suggest_maneuvers(env, model, tab, af, max_suggestions=10, config=cfg)
    assert len(fast) == len(slow) > 0
    for a, b in zip(fast, slow):
        assert (a.kind, a.controls, a.coefficients) == (b.kind, b.controls, b.coefficients)
        assert a.reason == b.reason
        assert a.priority == pytest.approx(b.priority, rel=1e-9, abs=1e-12)
        for c in a.controls:
            np.testing.assert_allclose(a.u[c], b.u[c], rtol=1e-9, atol=1e-12)
        for k, v in a.expected.items():
            assert v == pytest.approx(b.expected[k], rel=1e-9, abs=1e-12), k
