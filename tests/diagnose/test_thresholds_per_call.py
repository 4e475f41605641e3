"""One thresholds mapping per diagnosis: a per-call override reaches the sparse search and the differential step.

Before the sixtieth session ``diagnose`` read about sixteen of the differential step's switches from the module's
``sparse.THRESHOLDS`` one by one, so only a patch of the module reached them. ``DifferentialOptions.from_thresholds``
now reads them all from one mapping, and ``diagnose(sparse_thresholds=...)`` hands the same overrides to both steps.
Synthetic flights of ``diag_synthetic`` (as ``test_differential``); a few seconds.
"""

import dataclasses

import pytest

import gcs_sysid.diagnose.differential as differential_module
from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose import sparse
from gcs_sysid.diagnose.core import diagnose
from gcs_sysid.diagnose.differential import _THRESHOLD_KEYS, DifferentialOptions, Reference

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured


def test_every_switch_is_read_from_the_thresholds_and_an_override_wins():
    fields = {f.name for f in dataclasses.fields(DifferentialOptions)}
    assert set(_THRESHOLD_KEYS) == fields and set(_THRESHOLD_KEYS.values()) <= set(sparse.THRESHOLDS)
    frozen = DifferentialOptions.from_thresholds()
    for name, key in _THRESHOLD_KEYS.items():
        want = sparse.THRESHOLDS[key]
        got = getattr(frozen, name)
        assert got == (tuple(want or ()) if isinstance(got, tuple) else want), name
    assert DifferentialOptions.from_thresholds({"delay_change_min_t": 0.0, "angle_error_along_term": None}) == \
        dataclasses.replace(frozen, delay_change_min_t=0.0, angle_error_along=())
    with pytest.raises(dataclasses.FrozenInstanceError):
        frozen.alpha_scale = False


def test_a_per_call_override_reaches_the_search_and_the_differential_step(monkeypatch):
    seen = []
    real = differential_module.differential

    def spy(*args, options=None, **kwargs):
        seen.append(options)
        return real(*args, options=options, **kwargs)

    monkeypatch.setattr(differential_module, "differential", spy)
    airframe = load_airframe(AIRFRAME)
    table, states = measured(BASE, seed=3, hidden="Cm:delta_e", value=0.4, duration=100.0)
    ref_table, ref_states = measured(BASE, seed=8, hidden=None, duration=100.0)
    frozen = dict(sparse.THRESHOLDS)
    kw = dict(output_error=False, search=True, references=[Reference(ref_table, ref_states, label="clean.tlog")])
    d = diagnose(table, airframe, BASE, states, **kw)
    assert [(f["cause"], f.get("source")) for f in d.findings] == [("Cm:delta_e", "sparse search")]
    assert seen[-1] == DifferentialOptions.from_thresholds()
    over = {"delay_change_min_t": 7.5, "force_moment_arm_max": 0.0, "min_press_drop": 0.999}
    d2 = diagnose(table, airframe, BASE, states, sparse_thresholds=over, **kw)
    assert seen[-1] == DifferentialOptions.from_thresholds(over)
    assert seen[-1].delay_change_min_t == 7.5 and seen[-1].force_moment_arm_max == 0.0
    assert d2.data["sparse"]["thresholds"]["min_press_drop"] == 0.999
    # the search's Cm:delta_e drops its coefficient's PRESS by 0.95 of itself: under the override's bar, not named
    assert d2.findings == []
    assert sparse.THRESHOLDS == frozen            # the module's frozen mapping is left as it was
