"""Confidence map: flags regions without data, not dense ones; JSON round trip."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.envelope import EnvelopeConfig, EnvelopeMap, confidence_map
from gcs_sysid.errors import DataError, InputError

_spec = importlib.util.spec_from_file_location("exact_gp_double", Path(__file__).parent / "exact_gp_double.py")
double = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(double)


@pytest.fixture(scope="module")
def setup():
    tab = double.synthetic_table(n=500, seed=1)
    train = np.ones(len(tab.t), bool)
    train[-100:] = False
    model = double.fit_double(tab.X[train], tab.Y[train], rel_lengthscale=2.0)
    return tab, train, model


def _cell(sl, x, y):
    ix = int(np.clip(np.searchsorted(sl.x_edges, x) - 1, 0, len(sl.x_edges) - 2))
    iy = int(np.clip(np.searchsorted(sl.y_edges, y) - 1, 0, len(sl.y_edges) - 2))
    return iy, ix


def test_flags_empty_corner_not_dense_centre(setup):
    tab, train, model = setup
    env = confidence_map(model, tab, train)
    sl = next(s for s in env.slices if s.axes == ("alpha", "V"))
    ia, iv = REGRESSORS.index("alpha"), REGRESSORS.index("V")
    Xt = tab.X[train]
    # densest cell: flagged for no coefficient
    iy, ix = np.unravel_index(np.argmax(sl.counts), sl.counts.shape)
    assert sl.counts[iy, ix] >= 5
    for c in env.outputs:
        assert not sl.flagged(c)[iy, ix], c
    # the corner (high alpha, low V) lies beyond the flown range: no data, flagged for all
    cy, cx = _cell(sl, sl.x_edges[-1] - 1e-9, sl.y_edges[0] + 1e-9)
    assert sl.counts[cy, cx] == 0
    assert Xt[:, ia].max() < sl.x_centers[cx]
    for c in env.outputs:
        assert sl.flagged(c)[cy, cx], c
        assert sl.rel_sigma[c][cy, cx] > sl.rel_sigma[c][iy, ix]
    # a region covers it and says why
    regs = [r for r in env.regions_of("Cm") if r.axes == ("alpha", "V")
            and r.bounds["alpha"][1] >= sl.x_centers[cx] and r.bounds["V"][0] <= sl.y_centers[cy]]
    assert regs and "no training data" in regs[0].reason
    assert regs[0].points.shape[1] == len(REGRESSORS) and regs[0].n_cells == len(regs[0].points)
    assert regs[0].center["alpha"] > np.median(Xt[:, ia]) and regs[0].center["V"] < np.median(Xt[:, iv])
    # grid extends beyond the flown range on both ends
    lo, hi = env.flown["alpha"]
    assert env.limits["alpha"][0] < lo and env.limits["alpha"][1] > hi
    assert all(0.0 <= s <= 1.0 for s in env.scores.values())


def test_more_data_raises_score(setup):
    tab, train, model = setup
    env = confidence_map(model, tab, train)
    few = train.copy()
    few[np.arange(len(few)) % 10 != 0] = False
    sparse = double.fit_double(tab.X[few], tab.Y[few], rel_lengthscale=2.0)
    env_sparse = confidence_map(sparse, tab, few)
    for c in env.outputs:
        assert env.scores[c] > env_sparse.scores[c]


def test_json_round_trip_and_outputs_subset(setup):
    tab, train, model = setup
    sub = double.ExactGPDouble(model.X, model.Y[:, [0, 4]], model.ls, model.sf2[[0, 4]], model.sn2[[0, 4]])
    cfg = EnvelopeConfig(slices=(("alpha", "V"), ("q_hat", "delta_e")), n_grid=12,
                         limits={"V": (10.0, 30.0)})
    env = confidence_map(sub, tab, train, cfg, outputs=["CX", "Cm"])
    assert env.outputs == ("CX", "Cm") and len(env.slices) == 2
    assert env.slices[0].y_edges[0] == 10.0 and env.slices[0].y_edges[-1] == 30.0
    text = json.dumps(env.to_dict(), allow_nan=False)
    back = EnvelopeMap.from_dict(json.loads(text))
    assert [r.coefficient for r in back.regions] == [r.coefficient for r in env.regions]
    for a, b in zip(env.regions, back.regions):
        np.testing.assert_allclose(a.points, b.points, atol=1e-9)
    np.testing.assert_allclose(back.slices[1].sigma["Cm"], env.slices[1].sigma["Cm"], rtol=1e-3, atol=1e-9)


def test_bad_input(setup):
    tab, train, model = setup
    with pytest.raises(InputError, match="slice axis 'gamma'"):
        confidence_map(model, tab, train, EnvelopeConfig(slices=(("gamma", "V"),)))
    with pytest.raises(DataError, match="training rows"):
        confidence_map(model, tab, np.zeros(len(tab.t), bool))
    with pytest.raises(InputError, match="expected"):
        confidence_map(model, tab, train, outputs=["CX"])
