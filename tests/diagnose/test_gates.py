"""Between-flight allowances of the physical-cause and differential gates (issue 9, items 1-2).

Flights of one aircraft differ by near-constant coefficient offsets that are no cause (the
reconstruction's angle-of-attack offset, weight and CG within tolerance, an engine's torque). These
fast tests hold the gates on synthetic coefficient tables (``diag_synthetic``) where the truth is set
by the test:

- on a clean flight whose coefficients carry the offsets of the reconstruction's angle offsets, ``mass``
  and ``wind`` are fitted strongly enough to clear the diagnosis' thresholds, and the physical gate
  rejects them;
- the differential allowance drops a between-flight offset (``CZ:1``, an ``alpha`` term that only
  rides on the offset) and keeps a real change of the lift slope;
- slow: the whole diagnosis of a clean flight with CX/CZ offsets, differential against a clean
  reference, names nothing (it fails when the allowance is removed: ``CZ:1`` and ``CX:1`` are named).

The controls that the allowances do not blind the gates to real causes are the project's simulation
cases: a 5 m/s wind (``test_diagnose_sim.py``, ``test_diagnose_e2e.py``) and a 2 m/s pitot bias
(``test_physical.py``) are still named.
"""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose import physical
from gcs_sysid.diagnose.candidates import Scorer, fit_sensor_causes
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.core import diagnose
from gcs_sysid.diagnose.differential import Reference, _within_reference_variation, offset_allowance
from gcs_sysid.diagnose.physical import physical_gate

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured

OTHERS = ("bias:airspeed", "scale:airspeed", "bias:alpha", "bias:beta", "bias:gyro_x", "bias:gyro_y", "bias:gyro_z",
          "bias:accel_x", "bias:accel_y", "bias:accel_z", "cg_offset", "inertia:Ixx", "inertia:Iyy", "inertia:Izz",
          "inertia:Ixz")


@pytest.fixture(scope="module")
def airframe():
    return load_airframe(AIRFRAME)


def _offset_flight(seed=3, d_alpha=0.006, d_beta=0.03):
    """A clean flight whose coefficients carry the offsets of angle-of-attack and sideslip offsets (rad)
    of the reconstruction, constant over the flight."""
    table, states = measured(BASE, seed=seed, duration=80.0)
    for j, coef in enumerate(("CX", "CY", "CZ", "Cl", "Cm", "Cn")):
        table.Y[:, j] += BASE[coef].get("alpha", 0.0) * d_alpha + BASE[coef].get("beta", 0.0) * d_beta
    return table, states


def _ctx(table, states, airframe):
    return DiagContext.build(table, airframe, BASE, states, None, None)


def _fitted(ctx, R, cause):
    rest = OTHERS + tuple(c for c in ("mass", "wind") if c != cause)
    got = fit_sensor_causes(ctx, R, Scorer(ctx, R, None), exclude=rest)
    assert got and got[0].cause == cause
    return got[0]


@pytest.mark.parametrize("cause", ["mass", "wind"])
def test_a_between_flight_offset_is_no_mass_or_wind(airframe, cause):
    ctx = _ctx(*_offset_flight(), airframe)
    R = np.nan_to_num(ctx.Y - ctx.model_values())
    f = _fitted(ctx, R, cause)
    gate = physical_gate(ctx, R, f.delta, len(f.params))
    assert not gate["passed"], gate["why"]
    assert gate["offsets_allowed"]
    # a strong candidate: it clears the diagnosis' own thresholds, so only the gate stands between the
    # offset and a named cause
    assert f.score >= 30.0 and f.gain_percent >= 10.0, (f.score, f.gain_percent)


def test_an_offset_is_no_aero_term_and_a_slope_is():
    rng = np.random.default_rng(4)
    n = 4000
    X = np.zeros((n, 10))
    X[:, 0] = 0.06 + 0.04 * np.sin(np.arange(n) / 37.0) + 0.01 * rng.normal(size=n)
    X[:, 9] = 18.0
    t = np.arange(n) * 0.02
    test = (np.floor(t / 8.0).astype(int) % 3) == 2
    R = np.zeros((n, 6))
    R[:, 2] = 0.03 + 0.01 * rng.normal(size=n)          # CZ differs from the reference flight by a constant
    assert offset_allowance(X, R, ~test, test, "CZ", "1")["offset_only"]
    a = offset_allowance(X, R, ~test, test, "CZ", "alpha")
    assert a["offset_only"], a
    R[:, 2] += -0.8 * (X[:, 0] - 0.06)                   # a real change of the lift slope
    b = offset_allowance(X, R, ~test, test, "CZ", "alpha")
    assert not b["offset_only"] and b["estimate"] == pytest.approx(-0.8, rel=0.1), b


@pytest.mark.slow
def test_a_clean_flight_with_between_flight_offsets_gets_no_named_cause(airframe):
    """The whole diagnosis (about 20 s), differential against a clean reference flight: offsets of CX and
    CZ that no single sensor bias explains (a weight within tolerance, an engine's drag at one power
    setting) make ``CZ:1`` and ``CX:1`` the best candidates; the code before the allowance named them.
    None may be named."""
    table, states = measured(BASE, seed=3, duration=80.0)
    table.Y[:, 0] += 0.004
    table.Y[:, 2] += 0.03
    ref_table, ref_states = measured(BASE, seed=8, duration=80.0)
    d = diagnose(table, airframe, BASE, states, output_error=False,
                 references=[Reference(ref_table, ref_states, label="ref.tlog")])
    assert d.findings == [], [(f["cause"], f["estimate"], f["gain"]["percent"]) for f in d.findings]
    allowed = {a["cause"] for a in d.data["differential"]["allowance"]}
    assert "CZ:1" in allowed, d.data["differential"]


def test_a_correction_within_the_references_spread_is_an_allowance():
    refs = [{"correction": c, "std_error": 0.002} for c in (0.010, 0.030, 0.020)]
    inside = _within_reference_variation(0.035, 0.003, refs)
    assert inside is not None and inside["spread_between_references"] == pytest.approx(0.01)
    assert _within_reference_variation(0.09, 0.003, refs) is None          # far outside: a change
    assert _within_reference_variation(0.035, 0.003, refs[:1]) is None     # one reference: no spread to judge by


def test_a_wind_correction_the_reference_needs_too_is_a_calibration(monkeypatch):
    """The catalogue's wind is a correction to the estimator's wind: the same correction in the reference
    flight is a systematic air-data error, not this flight's air; a different one is named."""
    from types import SimpleNamespace

    import gcs_sysid.diagnose.differential as differential

    f = {"cause": "wind", "std_error": 0.1, "evidence": {"parameters": {"wn": 1.0, "we": -0.5}}}
    fitted = SimpleNamespace(cov=np.eye(2) * 0.01)
    ctx = SimpleNamespace(has=lambda *k: True)
    refs = [(Reference(None, label="ref.tlog"), ctx, None)]
    monkeypatch.setattr(differential, "_wind_fit", lambda c, R: (np.array([0.95, -0.45]), np.eye(2) * 0.01))
    same = differential._wind_differential(f, fitted, refs)
    assert same["verdict"] == "calibration" and same["references"][0]["same"]
    monkeypatch.setattr(differential, "_wind_fit", lambda c, R: (np.array([0.0, 0.05]), np.eye(2) * 0.01))
    changed = differential._wind_differential(f, fitted, refs)
    assert changed["verdict"] == "changed" and "estimator" in changed["why"]


def test_a_curvature_about_a_shifted_zero_is_judged_with_the_parent_it_entered_with():
    """``-8 (alpha_m - e)^2`` with the measured alpha 1.2 deg off the air's (the JSBSim dr1, twenty-sixth session):
    refitted alone beside a free constant, the linear part ``16 e alpha`` stays in its residual and ``alpha^2``
    is not beyond its standard error nor gains much beyond the offset (an allowance); with ``alpha`` beside it
    (``parents``, the search's ``entered_with``) it reads -8 and is more than an offset."""
    rng = np.random.default_rng(5)
    n = 6000
    X = np.zeros((n, 10))
    t = np.arange(n) * 0.02
    X[:, 0] = 0.02 * np.sin(t / 2.1) + 0.01 * np.sin(t / 0.7) + 0.002 * rng.normal(size=n)
    X[:, 9] = 30.0
    test = (np.floor(t / 8.0).astype(int) % 3) == 2
    R = np.zeros((n, 6))
    e = np.radians(1.2)
    R[:, 4] = -8.0 * (X[:, 0] - e) ** 2 + 2e-4 * rng.normal(size=n)
    alone = offset_allowance(X, R, ~test, test, "Cm", "alpha^2")
    both = offset_allowance(X, R, ~test, test, "Cm", "alpha^2", parents=("alpha",))
    assert alone["offset_only"] and alone["gain_beyond_offset_percent"] < 20.0, alone
    assert not both["offset_only"] and both["estimate"] == pytest.approx(-8.0, rel=0.05), both
    assert both["gain_beyond_offset_percent"] > 90.0 and "beside it" in both["why"]


def test_the_angle_error_along_a_product_is_judged_with_the_parent_it_entered_with():
    """``3 (alpha_m - e) beta`` with the measured alpha 1.5 deg off the air's (its flight-common offset, the mean
    vertical wind) and a sideslip error ``0.5 alpha beta`` the side force and the yawing moment see: the error along
    the term is fitted on CY and Cn, and ``Cl:alpha*beta`` judged beyond it. Without ``beta`` beside the term (the
    search's ``entered_with``) the linear part ``-3 e beta`` stays in the residual and the term reads a fraction of
    3 (on the JSBSim dr1's seed-3 flight 1.92 +- 0.17 against 2.70 with it, and no gain beyond the offset: an
    allowance; sixtieth session); with it the term reads 3."""
    from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS
    from gcs_sysid.diagnose.differential import angle_error_allowance

    rng = np.random.default_rng(7)
    n = 6000
    t = np.arange(n) * 0.02
    X = np.zeros((n, 10))
    ia, ib = REGRESSORS.index("alpha"), REGRESSORS.index("beta")
    X[:, ia] = 0.06 + 0.02 * np.sin(t / 3.1) + 0.002 * rng.normal(size=n)
    X[:, ib] = 0.05 * np.sin(t / 1.3) * np.sin(t / 9.0) + 0.003 * rng.normal(size=n)
    X[:, REGRESSORS.index("V")] = 30.0
    test = (np.floor(t / 8.0).astype(int) % 3) == 2
    model = {"CY": {"beta": -0.4}, "Cl": {"beta": -0.02}, "Cn": {"beta": 0.08}}
    R = 1e-4 * rng.normal(size=(n, 6))
    ab = X[:, ia] * X[:, ib]
    for c in ("CY", "Cl", "Cn"):        # the measured sideslip reads 0.5 alpha beta low: every C_beta sees it
        R[:, COEFFICIENTS.index(c)] += 0.5 * ab * model[c]["beta"]
    R[:, COEFFICIENTS.index("Cl")] += 3.0 * (X[:, ia] - np.radians(1.5)) * X[:, ib]
    alone = angle_error_allowance(X, R, ~test, test, model, "Cl", "alpha*beta")
    both = angle_error_allowance(X, R, ~test, test, model, "Cl", "alpha*beta", parents=("beta",))
    for out in (alone, both):
        assert out["error_along_term"] == pytest.approx(0.5, abs=0.05) and out["from"] == ["CY", "Cn"]
    assert alone["beyond_scale"]["estimate"] < 2.0, alone
    assert both["beyond_scale"]["estimate"] == pytest.approx(3.0, rel=0.03) and not both["scale_only"], both
    assert "beside it" in both["beyond_scale"]["why"]
