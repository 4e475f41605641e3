"""Aliased explanations (gcs_sysid/diagnose/aliases.py) on the sparse search's real path.

A side force 1.4 times the model's is hidden in a synthetic flight. When the model's CY is a single
sideslip term (as the JSBSim T-6's), ``scale:CY`` and a change of ``CY:beta`` are one regressor: the
finding must report the other as an alias, with its own estimate. When the model's CY has a second,
independently excited term (``delta_r``), the two are told apart and nothing may be merged.
Only CY is active (the other coefficients marked not identifiable) to keep each search under 1 s.
"""

from dataclasses import replace

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.aliases import condition_index, find_aliases, partial_correlations
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.sparse import sparse_search

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured

_CY_ONLY = np.array([c == "CY" for c in ("CX", "CY", "CZ", "Cl", "Cm", "Cn")])


@pytest.fixture(scope="module")
def airframe():
    return load_airframe(AIRFRAME)


def _scaled_side_force(airframe, model, k=1.4, seed=5):
    """The sparse search's findings on a flight whose CY is ``k`` times ``model``'s (only CY searched)."""
    table, states = measured(model, seed=seed, hidden=None, duration=90.0)
    table.Y[:, 1] += (k - 1.0) * sum(v * table.x(t) for t, v in model["CY"].items())
    ctx = DiagContext.build(table, airframe, model, states)
    ctx = replace(ctx, active=_CY_ONLY.copy())
    return sparse_search(ctx, ctx.Y - ctx.model_values(), thresholds={"honest_std_error": False})["findings"]


def test_a_scale_of_a_single_term_side_force_is_reported_with_its_alias(airframe):
    model = {c: dict(v) for c, v in BASE.items()}
    model["CY"] = {"beta": -0.35}
    found = _scaled_side_force(airframe, model)
    assert len(found) == 1, [f["cause"] for f in found]
    f = found[0]
    pair = {f["cause"]} | {a["cause"] for a in f["aliases"]}
    assert pair == {"scale:CY", "CY:beta"}, (f["cause"], f["aliases"])
    a = f["aliases"][0]
    assert a["condition_index"] >= 30 and abs(a["partial_correlation"]) > 0.99
    # each reading carries its own estimate: the factor 1.4, or CY_beta changed by 0.4 x (-0.35)
    readings = {f["cause"]: f["estimate"] - (0.0 if f["cause"] == "scale:CY" else f["model_value"]),
                a["cause"]: a["estimate"] - (0.0 if a["cause"] == "scale:CY" else a["model_value"])}
    assert readings["scale:CY"] == pytest.approx(1.4, abs=0.1)
    assert readings["CY:beta"] == pytest.approx(0.4 * -0.35, rel=0.25)
    assert "cannot be told apart" in a["cannot_tell_apart"] and "second CY term" in a["separate_with"]


def test_a_side_force_with_a_second_excited_term_is_not_merged(airframe):
    found = _scaled_side_force(airframe, BASE)          # CY = beta and delta_r, both excited independently
    assert [f["cause"] for f in found] == ["scale:CY"]
    assert found[0]["aliases"] == [], found[0]["aliases"]
    assert found[0]["estimate"] == pytest.approx(1.4, abs=0.1)


def test_partial_correlation_projects_out_the_other_selected_terms():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(2, 500))
    e = 0.01 * rng.normal(size=500)
    A = np.column_stack([a + b, a + e, b])         # col 0 and col 1 differ by b, which col 2 is
    assert abs(partial_correlations(A, 0, [])[1]) < 0.8          # b keeps them apart ...
    rho = partial_correlations(A, 0, [2])                        # ... until b is in the fit
    assert rho[1] > 0.999 and condition_index(rho[1]) > 30
    assert [k for k, _, _ in find_aliases(A, 0, [2])] == [1]
    assert find_aliases(A, 0, []) == []
