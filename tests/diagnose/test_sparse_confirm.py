"""The naming rules added on branch i9-top90 (gcs_sysid/diagnose/sparse.py, pitot.py): the untouched
segment's confirmation of a term, the control-free parent named first, the reference flight's share
of a differential standard error, and the pitot screen by the wind triangle alone."""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.pitot import MIN_T_SCREEN, MIN_T_SCREEN_TRIANGLE, fuse_pitot_evidence, screen
from gcs_sysid.diagnose.sparse import (THRESHOLDS, _control_parent_first, _held_out_passes, sparse_search,
                                       untouched_confirmation)

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured


def _coloured(rng, n, rho=0.97, sd=1.0):
    """AR(1) noise of standard deviation ``sd`` (correlated over ~1/(1-rho) samples, as gusts are)."""
    e = np.zeros(n)
    w = rng.normal(scale=sd * np.sqrt(1 - rho**2), size=n)
    for i in range(1, n):
        e[i] = rho * e[i - 1] + w[i]
    return e


def test_untouched_confirmation_sees_a_small_term_in_loud_coloured_noise():
    """A term with a tenth of the noise's variance gains little (about 5 %) but its slope is ~1 and
    significant; the same noise without the term gives a slope near 0; a flat prediction gives zeros."""
    rng = np.random.default_rng(2)
    n = 1200
    p = np.sin(np.linspace(0, 24 * np.pi, n))                  # the term's prediction (12 cycles)
    noise = _coloured(rng, n, sd=np.sqrt(10 * np.mean(p**2)))
    c = untouched_confirmation(noise + p, p)
    gain = 100 * (1 - np.std(noise) / np.std(noise + p))
    assert gain < 25.0
    assert c["slope"] == pytest.approx(1.0, abs=0.35) and c["t_statistic"] >= 3.0, c
    c0 = untouched_confirmation(noise, p)
    assert abs(c0["slope"]) < 0.35 and abs(c0["t_statistic"]) < 3.0, c0
    assert untouched_confirmation(noise, np.ones(n)) == {"slope": 0.0, "std_error": 0.0, "t_statistic": 0.0}
    # the coloured standard error is larger than the white one (fewer effective samples than rows)
    e = noise - c0["slope"] * p
    assert c0["std_error"] > 1.5 * np.std(e) / np.sqrt(p @ p)


@pytest.mark.parametrize("gain, slope, t, named", [
    (30.0, 0.0, 0.0, True),        # the usual floor
    (15.0, 0.95, 4.0, True),       # below it, confirmed by the untouched segment
    (15.0, 0.2, 4.0, False),       # a slope far from the fitted size
    (15.0, 1.9, 8.0, False),
    (15.0, 0.95, 2.0, False),      # not significant there
    (5.0, 1.0, 9.0, False),        # below the confirmation floor
])
def test_held_out_test_of_a_first_term(gain, slope, t, named):
    entry = {"held_out": {"percent": gain, "confirmation": {"slope": slope, "std_error": 0.1, "t_statistic": t}}}
    assert _held_out_passes(entry, THRESHOLDS) is named
    # without the confirmation thresholds, the fixed floor alone decides
    old = {k: v for k, v in THRESHOLDS.items() if not k.startswith("confirm_")}
    assert _held_out_passes(entry, old) is (gain >= THRESHOLDS["min_gain_pct"])


def _t(term, est, se):
    return {"term": term, "estimate": est, "std_error": se, "std_error_naming": se}


def test_control_product_gives_way_to_its_selected_parent():
    terms = [_t("alpha^2*delta_e", 37.7, 7.3), _t("alpha^2", -7.5, 0.73), _t("alpha*beta", -0.8, 0.17)]
    assert [x["term"] for x in _control_parent_first(terms, 5.0)] == ["alpha^2", "alpha^2*delta_e", "alpha*beta"]
    # the parent must be significant on its own
    weak = [terms[0], _t("alpha^2", -1.0, 0.5)]
    assert _control_parent_first(weak, 5.0) == weak
    # no control among the factors: a product stays (Cl:alpha*beta is no Cl:beta)
    ab = [_t("alpha*beta", 3.0, 0.1), _t("beta", 0.01, 0.001)]
    assert _control_parent_first(ab, 5.0) == ab
    # a control alone has no parent
    da = [_t("delta_a", -0.06, 0.001), _t("beta", 0.01, 0.001)]
    assert _control_parent_first(da, 5.0) == da


def test_a_differential_standard_error_counts_the_reference_flight():
    """The named term's standard error is the flight's and the reference's in quadrature."""
    airframe = load_airframe(AIRFRAME)

    def ctx_of(seed, effect):
        table, states = measured(BASE, seed=seed, hidden=None, duration=90.0)
        table.Y[:, 5] += effect * table.x("delta_a")
        ctx = DiagContext.build(table, airframe, BASE, states)
        return ctx, ctx.Y - ctx.model_values()

    ref = ctx_of(4, 0.0)
    ctx, R = ctx_of(5, -0.08)
    res = sparse_search(ctx, R, reference=ref)
    f = next(f for f in res["findings"] if f["cause"] == "Cn:delta_a")
    parts = f["evidence"]["std_error_parts"]
    assert parts["reference"] > 0 and parts["flight"] > 0
    # the standard error the decisions read (item 12 of docs/diagnose.md's sparse search); the reported one is
    # the combined standard uncertainty (item 14), which holds both flights' coloured standard errors and more
    assert f["evidence"]["std_error_decision"] == pytest.approx(np.hypot(parts["flight"], parts["reference"]))
    u = f["evidence"]["uncertainty"]
    assert u["type_a"]["reference_coloured"] > 0 and f["std_error"] == pytest.approx(u["combined"])
    assert f["std_error"] >= np.hypot(u["type_a"]["flight_coloured"], u["type_a"]["reference_coloured"]) * (1 - 1e-9)
    assert f["estimate"] - f["model_value"] == pytest.approx(-0.08, rel=0.25)


def test_pitot_screen_reaches_the_refit_on_the_triangle_alone():
    """A closed-form coefficient fit too low to agree no longer stops a significant wind triangle."""
    tri = {"change_mps": 1.8, "std_error": 0.43, "t_statistic": 1.8 / 0.43}
    fused = fuse_pitot_evidence(tri, 0.2, 0.21)          # the coefficients say 0.2 +- 0.21: they disagree
    assert not fused["agree"]
    s = screen(fused, tri)
    assert s["passes"] and s["triangle_alone"] and not s["fused"] and s["linearise_at_mps"] == 1.8
    # agreeing, significant: linearised at the fused value
    ok = fuse_pitot_evidence(tri, 1.7, 0.21)
    s = screen(ok, tri)
    assert s["passes"] and s["fused"] and s["linearise_at_mps"] == pytest.approx(ok["estimate"])
    # a clean flight: neither route (triangle -0.52 +- 0.43, coefficients 0.0 +- 0.2)
    clean = {"change_mps": -0.52, "std_error": 0.43, "t_statistic": -0.52 / 0.43}
    assert abs(clean["t_statistic"]) < MIN_T_SCREEN
    assert not screen(fuse_pitot_evidence(clean, 0.0, 0.2), clean)["passes"]


def test_pitot_screen_passes_a_one_mps_triangle_and_not_a_clean_one():
    """The triangle-alone route at MIN_T_SCREEN_TRIANGLE (1.5): a 1 m/s bias's triangle (0.73 +- 0.42, the
    JSBSim c182 s1, closed-form fit 0.08) reaches the exact re-fit; the largest |t| of the 76 recorded tuning flights
    without a pitot change (-0.54 +- 0.43, j3cub s11) does not."""
    one = {"change_mps": 0.73, "std_error": 0.42, "t_statistic": 0.73 / 0.42}
    assert MIN_T_SCREEN_TRIANGLE <= abs(one["t_statistic"]) < MIN_T_SCREEN
    s = screen(fuse_pitot_evidence(one, 0.08, 0.23), one)
    assert s["passes"] and s["triangle_alone"] and s["linearise_at_mps"] == 0.73
    worst = {"change_mps": -0.54, "std_error": 0.43, "t_statistic": -0.54 / 0.43}
    assert not screen(fuse_pitot_evidence(worst, 0.0, 0.2), worst)["passes"]
