"""The live learner keeps a row whose moments are missing (an angular-acceleration estimate rejected) for
its forces, in the first fit and in the updates, as the replay does (``pipeline.training_rows``).

Why (docs/benchmarks.md, "Ninth session, i8-joint"): the learner's first fit is a short log. With the
moments removed from 30 % of 20 s of JSBSim rows (c172x, pa28, t37, seeds 1-2, light and moderate), the
joint GP on every row beat the same GP on the complete rows on 88 of 144 held-out flight x coefficient
pairs and was worse on 35 (forces 46 / 13, moments 42 / 22)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, CoefficientTable
from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.learner import LearnOptions, Learner

ROOT = Path(__file__).resolve().parents[2]


def _table(n: int, seed: int) -> CoefficientTable:
    rng = np.random.default_rng(seed)
    X = np.column_stack([rng.normal(0.05, 0.03, n), rng.normal(0, 0.02, n), rng.normal(0, 0.02, (n, 3)),
                         rng.normal(0, 0.05, (n, 3)), rng.uniform(0.3, 0.7, n), rng.normal(20, 1, n)])
    W = rng.normal(0, 1, (10, 6))
    Y = (X - X.mean(0)) / X.std(0) @ W * 0.05 + 0.01 * rng.standard_normal((n, 6))
    Y[rng.random(n) < 0.3, 3:] = np.nan                  # moments missing on ~30 % of the rows
    return CoefficientTable(np.arange(n) * 0.02, X, Y, np.ones(n, bool), np.full(n, 200.0))


@pytest.mark.slow   # one GP fit and one update at the default settings (compiles them: ~30-60 s on 2 cores)
def test_rows_with_missing_moments_are_learned_for_their_forces():
    learner = Learner(load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml"),
                      LearnOptions(min_rows=300, n_inducing=24))
    first, second = _table(400, 1), _table(100, 2)
    learner._learn(first, np.ones(400, bool))
    assert learner.outputs == tuple(COEFFICIENTS)
    partial = int((~np.isfinite(first.Y).all(1)).sum())
    assert partial > 80 and learner.n_learned == 400       # before: only the complete rows (~280)
    assert any("miss" in note for note in learner.model.notes)
    learner._learn(second, np.ones(100, bool))
    assert learner.n_learned == 500
    mean, _ = learner.model.predict(second.X)
    assert np.all(np.isfinite(mean))                      # every coefficient still predicted on every row
