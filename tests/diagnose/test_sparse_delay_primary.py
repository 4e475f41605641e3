"""A delay is named only when the coefficient the surface controls sees it (``delay_primary_agreement``).

A servo delay moves the surface, so every coefficient the surface acts on follows it late by the same time, and above
all the one it controls (the rudder's Cn). On the project's synthetic flights a lag that only CY shows (CY's own model
response to a 0.1-s late rudder, Cn and Cl untouched) is refused with the reason; the same delay in every coefficient
is named. The JSBSim Eternity's clean flight s15 named ``delay:delta_a`` 0.110 +- 0.006 s
on CY while Cl read 0.000 +- 0.006 s (docs/benchmarks.md, "Thirty-eighth session").

Nor is a lead (``delay_lead_max_t``): a response ahead of its logged command reads as a negative delay of the flight
itself, which no servo has (the JSBSim Eternity's clean flight s118, ``delay:delta_a`` -0.035 s as a change, the
flight's own -0.045 +- 0.007 s; docs/benchmarks.md, "Seventy-fourth session").
"""

import numpy as np
import pytest

from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.sparse import THRESHOLDS, sparse_search

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured

K_R = REGRESSORS.index("delta_r")


@pytest.fixture(scope="module")
def airframe():
    return load_airframe(AIRFRAME)


def _flight(airframe, seed, columns=None, lag_s=0.1):
    """A synthetic flight; with ``columns``, those coefficients get the model's response to the rudder ``lag_s`` late
    (negative: early, the response ahead of the logged command)."""
    table, states = measured(BASE, seed=seed, hidden=None, duration=90.0)
    if columns is not None:
        c0 = DiagContext.build(table, airframe, BASE, states)
        X = c0.X.copy()
        X[:, K_R] = np.interp(c0.t - lag_s, c0.t, np.nan_to_num(c0.X[:, K_R]))
        D = np.nan_to_num(c0.model_values(X) - c0.model_values())
        table.Y[:, columns] += D[:, columns]
    ctx = DiagContext.build(table, airframe, BASE, states)
    return ctx, ctx.Y - ctx.model_values()


def _refused(ctx, R, ref, check: str) -> tuple[dict, str]:
    """The search with the check ``check`` off (its result) and at the default 3.0 (the refusal's reason), asserting
    that the default names no delay and lists ``delay:delta_r`` under ``not_named``."""
    off = sparse_search(ctx, R, reference=ref, thresholds=dict(THRESHOLDS, **{check: 0.0}))
    on = sparse_search(ctx, R, reference=ref)
    assert THRESHOLDS[check] == 3.0
    assert not any(f["cause"].startswith("delay:") for f in on["findings"])
    refused = [n for n in on["not_named"] if n["cause"] == "delay:delta_r"]
    assert refused
    return off, refused[0]["why"]


def test_a_lag_in_a_weaker_coefficient_alone_is_not_a_delay(airframe):
    ref = _flight(airframe, 4)
    ctx, R = _flight(airframe, 5, columns=[1])                                    # CY alone
    off, why = _refused(ctx, R, ref, "delay_primary_agreement")
    assert [f["cause"] for f in off["findings"]] == ["delay:delta_r"]           # the check off: named on CY
    assert "Cn (the coefficient delta_r controls)" in why


def test_a_delay_in_every_coefficient_is_named(airframe):
    ref = _flight(airframe, 4)
    ctx, R = _flight(airframe, 5, columns=slice(None))
    res = sparse_search(ctx, R, reference=ref)
    f = next(f for f in res["findings"] if f["cause"] == "delay:delta_r")
    assert f["estimate"] == pytest.approx(0.1, abs=0.015)
    check = f["evidence"]["primary_coefficient"]
    assert check["agrees"] and check["primary"] == "Cn"
    lead = f["evidence"]["lead"]                                                 # its own delay: a lag, not a lead
    assert lead["lead"] is False and lead["flight_s"] > 0


def test_a_surface_that_leads_its_command_is_not_a_delay(airframe):
    # a servo moves after its command: a response 0.08 s ahead of the log reads as a negative delay, named with the
    # check off and refused with the reading when it is on (delay_lead_max_t; the JSBSim Eternity's clean s118)
    ref = _flight(airframe, 4)
    ctx, R = _flight(airframe, 5, columns=slice(None), lag_s=-0.08)
    off, why = _refused(ctx, R, ref, "delay_lead_max_t")
    f = next(f for f in off["findings"] if f["cause"] == "delay:delta_r")
    assert f["evidence"]["delay_differential"]["flight_s"] == pytest.approx(-0.08, abs=0.015)
    assert f["evidence"]["lead"]["lead"] is False and f["evidence"]["lead"]["why"] is None
    assert "delta_r leads its logged command by 0.0" in why
