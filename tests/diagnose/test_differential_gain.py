"""The held-out gain of a finding is measured on the change since the reference flight (branch i9-pitot).

With a reference flight and the search, ``diagnose`` reports every coefficient-domain finding's gain on
the residual against the model *minus the reference flight's own inadequacy* (the search's ridge
prediction), the residual on which the search's terms have always been measured
(:func:`gcs_sysid.diagnose.core._differential_gains`). Here, on a synthetic coefficient table
(``diag_synthetic``, truth set by the test), the residual holds a model inadequacy the reference has
too (``0.02 alpha^2``-like in CZ), a change (a CZ offset-and-slope with the shape of a pitot bias's qbar
scaling) and noise; the pitot-like finding's gain on the residual against the model is limited by the
inadequacy it cannot explain, and on the differential residual it is what the change is against the noise.
Sensor findings judged by data compatibility and the search's own terms keep their gain.
"""

from __future__ import annotations

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.candidates import Fitted
from gcs_sysid.diagnose.context import DiagContext
from gcs_sysid.diagnose.core import _differential_gains
from gcs_sysid.diagnose.physical import split_held_out

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured


@pytest.fixture(scope="module")
def case():
    table, states = measured(BASE, seed=5, duration=80.0)
    ctx = DiagContext.build(table, load_airframe(AIRFRAME), BASE, states, None, None)
    rng = np.random.default_rng(1)
    a = ctx.x("alpha")
    T = len(ctx.t)
    inad = np.zeros((T, 6))
    inad[:, 2] = 3.0 * (a - a.mean()) ** 2 * 40 + 0.004 * np.sin(0.7 * ctx.t)   # the reference has it too
    change = np.zeros((T, 6))
    change[:, 2] = -0.01 * (1 + 2 * (a - a.mean()))                               # what changed
    noise = np.zeros((T, 6))
    noise[:, 2] = 0.001 * rng.standard_normal(T)
    R0 = inad + change + noise
    return ctx, R0, inad, change


def test_the_gain_is_measured_on_what_changed_and_the_former_one_is_kept(case):
    ctx, R0, inad, change = case
    j = 2
    acc, gain_rows = split_held_out(ctx.t, ctx.test)
    g = gain_rows & ctx.valid
    raw = 100 * (1 - np.sqrt(np.mean((R0 - change)[g, j] ** 2)) / np.sqrt(np.mean(R0[g, j] ** 2)))
    pitot_finding = {"cause": "bias:airspeed", "coefficient": "CZ", "gain": {"percent": raw, "rows": "untouched"},
                     "evidence": {"domain": "data compatibility"}}
    compat = {"cause": "bias:alpha", "coefficient": "alpha", "gain": {"percent": 33.0},
              "evidence": {"domain": "data compatibility"}}
    term = {"cause": "Cm:alpha^2", "coefficient": "Cm", "gain": {"percent": 61.0}, "source": "sparse search",
            "evidence": {"domain": "sparse search"}}
    d_cat = np.zeros_like(R0)
    d_cat[:, j] = -change[:, j]
    cat = Fitted("CZ:alpha", "aero", np.array([0.02]), np.eye(1), ["alpha"], d_cat)
    cat_finding = {"cause": "CZ:alpha", "coefficient": "CZ", "gain": {"percent": 5.0}, "evidence": {}}
    findings = [pitot_finding, compat, term, cat_finding]
    _differential_gains(ctx, R0, None, inad, [cat], {"finding": pitot_finding, "delta": -change}, findings)
    # the pitot-like finding: on the residual against the model the inadequacy caps it; on the change, the noise
    assert raw < 50.0
    assert pitot_finding["gain"]["percent"] > 80.0
    assert pitot_finding["gain"]["coefficient"] == "CZ" and pitot_finding["gain"]["rows"] == "untouched"
    assert pitot_finding["evidence"]["gain_against_model"]["percent"] == pytest.approx(raw)
    # a catalogue cause is measured on the same residual, on its own held-out rows
    assert cat_finding["gain"]["percent"] > 80.0
    assert cat_finding["evidence"]["gain_against_model"]["percent"] == 5.0
    # sensor causes (gains in their own units) and the search's terms keep theirs
    assert compat["gain"] == {"percent": 33.0} and "gain_against_model" not in compat["evidence"]
    assert term["gain"] == {"percent": 61.0}


def test_with_no_change_the_differential_gain_is_not_inflated(case):
    ctx, R0, inad, change = case
    R = R0 - change                              # nothing changed: inadequacy and noise only
    wrong = np.zeros_like(R0)
    wrong[:, 2] = -change[:, 2]                  # a correction for a change that is not there
    f = {"cause": "bias:airspeed", "coefficient": "CZ", "gain": {"percent": 0.0}, "evidence": {}}
    _differential_gains(ctx, R, None, inad, [], {"finding": f, "delta": wrong}, [f])
    assert f["gain"]["percent"] < 0.0
