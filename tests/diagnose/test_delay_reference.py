"""A delay sized as a difference is judged against the reference by the same fit (differential step).

``sparse._differential_delay`` sizes a named delay as this flight's delay minus the reference flight's,
both scanned through the model's response on a grid that reaches below zero. The differential step then
asks whether the delay was already there in the reference flight. With the catalogue's scan
(``candidates.fit_delays``, grid from one sample up) a delay-free reference reads one sample (0.02 s at
50 Hz) with the small standard error of a minimum on the grid's edge, and a 0.045-s change was called
"in the reference too" (the JSBSim PA-28's 0.06-s elevator delays on seeds 1 and 3, docs/benchmarks.md,
branch i9-delay). Synthetic flights of ``BASE``; a few seconds.
"""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.context import DiagContext, evaluate_model
from gcs_sysid.diagnose.differential import DifferentialOptions, Reference, _reference_delay, differential
from gcs_sysid.diagnose.sparse import _differential_delay

from diag_flights import AIRFRAME
from diag_synthetic import BASE, FakeStates, regressors, table


def _flight(airframe, seed, delay):
    t, X, qbar, st = regressors(seed, 120.0)
    Xt = X.copy()
    if delay:
        Xt[:, 5] = np.interp(t - delay, t, X[:, 5])
    tab = table(BASE, X, evaluate_model(BASE, Xt), t, qbar, seed=seed + 10)
    ctx = DiagContext.build(tab, airframe, BASE, FakeStates(t, st))
    return tab, FakeStates(t, st), ctx


def _diag(ctx, finding):
    R = ctx.Y - ctx.model_values()
    return SimpleNamespace(findings=[finding], fitted=[], residual_after=R, residual_before=R, data={},
                           X=ctx.X, train=ctx.train, test=ctx.test, model=BASE, t=ctx.t, unexplained=[])


@pytest.mark.slow
def test_a_delay_change_is_not_called_the_references_own_delay():
    af = load_airframe(AIRFRAME)
    rtab, rst, rctx = _flight(af, 4, 0.0)
    _, _, ctx = _flight(af, 5, 0.05)
    jm = COEFFICIENTS.index("Cm")
    R = np.nan_to_num(ctx.Y - ctx.model_values())
    tr = np.nonzero(ctx.train)[0]
    ref = (rctx, rctx.Y - rctx.model_values())
    change, _, se, parts = _differential_delay(ctx, R, "delta_e", tr, jm, ref)
    assert change == pytest.approx(0.05, abs=0.0075) and abs(parts["reference_s"]) <= 0.005
    # the reference's own delay by the same fit: about zero, with the log's time resolution in its error
    tau_r, se_r = _reference_delay(rctx, rctx.Y - rctx.model_values(), "delta_e", "Cm")
    assert abs(tau_r) <= 0.005 and se_r >= 0.02 / np.sqrt(12.0)

    def finding():
        return {"cause": "delay:delta_e", "coefficient": "Cm", "estimate": change,
                "std_error": float(np.hypot(se, 0.02 / np.sqrt(12.0))), "model_value": 0.0,
                "gain": {"percent": 75.0}, "evidence": {"delay_differential": parts}}

    frozen = DifferentialOptions.from_thresholds()
    assert frozen.delay_same_fit and frozen.delay_change_min_t == 3.0
    d = _diag(ctx, finding())
    doc = differential(d, [Reference(rtab, rst, label="ref")], af, options=frozen)
    assert [f["cause"] for f in d.findings] == ["delay:delta_e"], doc
    assert doc["changed"][0]["cause"] == "delay:delta_e" and not doc["model_inadequacy"]
    # the catalogue's scan on the reference: one sample, "the same delay" -> model inadequacy
    d_old = _diag(ctx, finding())
    old = differential(d_old, [Reference(rtab, rst, label="ref")], af, options=replace(frozen, delay_same_fit=False))
    assert d_old.findings == [] and old["model_inadequacy"][0]["cause"] == "delay:delta_e", old
    assert old["model_inadequacy"][0]["in_references"][0]["correction"] == pytest.approx(0.02, abs=0.005)
    # a "change" within its standard error of none (the PA-28 s1 pitot-bias flight's 0.010 +- 0.006 s beside
    # the bias) is an allowance with delay_change_min_t, a change without it
    small = dict(finding(), estimate=0.010, std_error=0.006,
                 evidence={"delay_differential": dict(parts, flight_s=parts["reference_s"] + 0.010)})
    d_small = _diag(ctx, small)
    doc_small = differential(d_small, [Reference(rtab, rst, label="ref")], af)   # options: the frozen ones
    assert d_small.findings == [] and doc_small["allowance"][0]["cause"] == "delay:delta_e", doc_small
    d_kept = _diag(ctx, dict(small, evidence={"delay_differential": small["evidence"]["delay_differential"]}))
    differential(d_kept, [Reference(rtab, rst, label="ref")], af, options=replace(frozen, delay_change_min_t=0.0))
    assert [f["cause"] for f in d_kept.findings] == ["delay:delta_e"]


@pytest.mark.parametrize("central", [True, False])
def test_a_delay_read_below_zero_keeps_its_standard_error(central):
    """``_refine_delay``'s standard error is that of the response's slope in tau at the best tau. A reference whose
    surface leads its log by a grid step reads -0.005 s on the differential grid; with the lower point of the slope's
    difference clipped at 0 (``delay_se_central`` False, the code before the fifty-seventh session) both points sat at
    about 0 and their float noise was divided by ~1e-16: the standard error came out 0 or anything (the JSBSim
    c172x's seed-3 reference: 0.018 s on one run, 0 on another whose states differed by 1e-6). Here the log's clock
    starts at 100 s, where a shift of 1e-16 s moves no sample: the clipped slope is all zeros and the fit has no
    standard error (0). Central (the default): the standard error of the same flight read at +0.005 s, within 5 %.
    The choice is the caller's (the search passes its ``delay_se_central``), not read from the module's defaults."""
    from dataclasses import replace

    from gcs_sysid.diagnose import sparse

    af = load_airframe(AIRFRAME)
    jm = COEFFICIENTS.index("Cm")
    grid = np.arange(-0.1, 0.4001, 0.005)
    se_at = {}
    for d in (-0.005, 0.005):
        _, _, ctx = _flight(af, 4, d)
        ctx = replace(ctx, t=ctx.t + 100.0)
        rows = np.nonzero(ctx.valid)[0]
        tau, _, se = sparse._refine_delay(ctx, np.nan_to_num(ctx.Y - ctx.model_values()), "delta_e", rows, jm,
                                          taus=grid, central=central)
        assert tau == pytest.approx(d, abs=0.0025)
        se_at[d] = se
    if central:
        assert np.isfinite(se_at[-0.005]) and se_at[-0.005] > 0
        # the same flight's slope a 0.01-s shift of its delay apart: measured equal to 5e-4 on seeds 4-7
        assert se_at[-0.005] == pytest.approx(se_at[0.005], rel=0.05), se_at
    else:                                   # the clipped difference: no standard error at all (0 here)
        assert not (np.isfinite(se_at[-0.005]) and se_at[-0.005] > 0) and se_at[0.005] > 0, se_at
