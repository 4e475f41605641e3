"""The light hyperparameter refresh (warm start, few steps, a subset of the stored rows) on the issue's
envelope-expansion case: within 20 % of a full refit's held-out error in the new region, with fewer
optimisation steps than the full refresh, and the model's own settings kept."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gp_data import FAST, envelope_expansion_case, error_pct
from gcs_sysid.gp import fit_gp
from gcs_sysid.gp.streaming import RefreshBudget, light_refresh


@pytest.mark.slow   # ~30 s alone (a fit, 20 updates, a refresh, a refit: their compilations)
def test_light_refresh_in_a_new_region_is_within_20_percent_of_a_refit():
    X, Yt, Y, flown, test, train_new = envelope_expansion_case()
    cfg = replace(FAST, hyper_every=0)
    model, _ = fit_gp(X[flown], Y[flown], cfg)
    for a in range(0, len(train_new), 50):
        rows = train_new[a:a + 50]
        model = model.update(X[rows], Y[rows])
    streamed = error_pct(model.predict(X[test])[0], Yt[test])
    budget = RefreshBudget(steps=max(cfg.steps // 4, 10), rows=cfg.n_train_max // 2, local_steps=cfg.local_steps)
    light = light_refresh(model, budget)
    assert light.config == model.config and light.since_refresh == 0
    refreshed = error_pct(light.predict(X[test])[0], Yt[test])
    refit, _ = fit_gp(np.vstack([X[flown], X[train_new]]), np.vstack([Y[flown], Y[train_new]]), cfg)
    full = error_pct(refit.predict(X[test])[0], Yt[test])
    assert np.mean(refreshed) <= 1.2 * np.mean(full), (refreshed, full)
    assert np.mean(refreshed) < np.mean(streamed), (refreshed, streamed)   # the refresh is what gets it there
