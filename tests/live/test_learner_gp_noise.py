"""The live learner's and the campaign's GP noise option (twenty-sixth session, i8-live) reaches the GP.

The replay's GP learns the outputs' noise correlation by default since the twenty-fifth session (``learned``,
``pipeline.GP_NOISE``); the live learner does too since the twenty-sixth (``live.learner.GP_NOISE``; docs/live.md,
"The GP's noise"), so ``listen`` and ``replay`` on one flight learn the same noise. ``independent`` stays reachable by
name (``LearnOptions.gp_noise``, ``gcs-sysid listen --gp-noise``), as is the campaign's noise
(``CampaignConfig.gp_noise``, ``gcs-sysid campaign --gp-noise``). Each test fails if the option is dropped on its way
to ``fit_gp``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gcs_sysid.gp as gp
from gcs_sysid.aero.table import CoefficientTable
from gcs_sysid.airframe import load_airframe
from gcs_sysid.campaign import CampaignConfig
from gcs_sysid.campaign.flights import fit as campaign_fit
from gcs_sysid.cli import build_parser, main
from gcs_sysid.errors import InputError
from gcs_sysid.live import learner as learner_mod
from gcs_sysid.live.learner import LearnOptions, Learner, learner_gp_config

ROOT = Path(__file__).resolve().parents[2]
LEARNED = {"noise_correlation": True, "noise_posterior": "diagonal", "noise_start": "signal"}
INDEPENDENT = {"noise_correlation": False, "noise_posterior": "full", "noise_start": "signal"}


def _fields(cfg) -> dict:
    return {k: getattr(cfg, k) for k in LEARNED}


def _table(n: int, seed: int) -> CoefficientTable:
    rng = np.random.default_rng(seed)
    X = np.column_stack([rng.normal(0.05, 0.03, n), rng.normal(0, 0.02, n), rng.normal(0, 0.02, (n, 3)),
                         rng.normal(0, 0.05, (n, 3)), rng.uniform(0.3, 0.7, n), rng.normal(20, 1, n)])
    W = rng.normal(0, 1, (10, 6))
    gust = rng.standard_normal(n)[:, None] * np.array([0.0, 0.01, 0.0, 0.004, 0.0, 0.003])   # one gust, 3 outputs
    Y = (X - X.mean(0)) / X.std(0) @ W * 0.05 + 0.005 * rng.standard_normal((n, 6)) + gust
    return CoefficientTable(np.arange(n) * 0.02, X, Y, np.ones(n, bool), np.full(n, 200.0))


def test_the_live_default_is_learned_as_the_replays_and_independent_is_reachable():
    from gcs_sysid import pipeline

    assert learner_mod.GP_NOISE == "learned" == pipeline.GP_NOISE
    assert _fields(learner_gp_config(LearnOptions())) == LEARNED
    assert _fields(learner_gp_config(LearnOptions())) == _fields(pipeline.replay_gp_config())   # live = replay noise
    assert _fields(learner_gp_config(LearnOptions(gp_noise="independent"))) == _fields(gp.GPConfig())   # the old one
    cfg = learner_gp_config(LearnOptions(gp_noise="learned", gp_seed=1, n_inducing=24))
    assert _fields(cfg) == LEARNED and cfg.seed == 1 and cfg.n_inducing == 24
    assert _fields(learner_gp_config(LearnOptions(gp_noise="full"))) == {**LEARNED, "noise_posterior": "full"}
    with pytest.raises(InputError, match="--gp-noise"):
        LearnOptions(gp_noise="fixed")


def test_the_learner_fits_with_its_noise_option(monkeypatch):
    seen = []

    def fake_fit(X, Y, config, *a, **k):
        seen.append(config)
        raise RuntimeError("stop after the config")

    monkeypatch.setattr(gp, "fit_gp", fake_fit)
    af = load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml")
    for noise, want in ((None, LEARNED), ("independent", INDEPENDENT), ("learned", LEARNED)):
        lr = Learner(af, LearnOptions(min_rows=50, gp_noise=noise, gp_seed=3))
        with pytest.raises(RuntimeError, match="stop after"):
            lr._learn(_table(60, 1), np.ones(60, bool))
        assert _fields(seen[-1]) == want and seen[-1].seed == 3


def test_listen_cli_passes_gp_noise(monkeypatch, tmp_path):
    import gcs_sysid.live.session as session
    from gcs_sysid.live.cli import cmd_listen

    got = []
    monkeypatch.setattr(session, "run_listen",
                        lambda af, out, opts: got.append(opts) or {"raw_log": "r", "raw_records": 0})
    base = ["listen", "udpin:0.0.0.0:14550", "--airframe", "a.toml", "--out", str(tmp_path)]
    for extra, want in (([], None), (["--gp-noise", "learned"], "learned"),
                        (["--gp-noise", "independent"], "independent")):
        assert cmd_listen(build_parser().parse_args(base + extra)) == 0
        assert got[-1].learn.gp_noise == want
    with pytest.raises(SystemExit):
        build_parser().parse_args(base + ["--gp-noise", "fixed"])


def test_campaign_fits_with_its_noise_option(monkeypatch, tmp_path):
    import gcs_sysid.campaign.run as campaign_run

    seen = []

    def fake_fit(X, Y, config, *a, **k):
        seen.append(config)
        return None, None

    monkeypatch.setattr(gp, "fit_gp", fake_fit)
    assert CampaignConfig().gp_noise == "independent"
    for cfg, want in ((CampaignConfig(), INDEPENDENT), (CampaignConfig(gp_noise="learned"), LEARNED)):
        campaign_fit(np.zeros((5, 10)), np.zeros((5, 6)), cfg, seed=2)
        assert _fields(seen[-1]) == want and seen[-1].seed == 2
    with pytest.raises(InputError, match="--gp-noise"):
        CampaignConfig(gp_noise="fixed")
    configs = []
    acc = {k: True for k in ("sigma_2x_all", "moments_better_all", "inside_limits_all", "flown_inside_limits_all")}
    monkeypatch.setattr(campaign_run, "run_campaign", lambda af, m, out, config: configs.append(config) or
                        {"acceptance": acc})
    data = ROOT / "data"
    for k, (extra, want) in enumerate((([], "independent"), (["--gp-noise", "learned"], "learned"))):
        assert main(["campaign", "--airframe", str(data / "airframes" / "sim-trainer.toml"), "--model",
                     str(data / "models" / "sim-trainer-campaign.toml"), "--out", str(tmp_path / f"c{k}")] + extra) == 0
        assert configs[-1].gp_noise == want


@pytest.mark.slow   # two GP fits and light refreshes at the learner's settings (compiles them: ~1 min on 2 cores)
def test_learned_noise_is_learned_in_the_live_fit_and_kept_through_updates_and_a_refresh():
    af = load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml")
    models = {}
    for noise in ("independent", "learned"):
        lr = Learner(af, LearnOptions(min_rows=300, n_inducing=24, gp_noise=noise, hyper_every=150))
        lr._learn(_table(400, 1), np.ones(400, bool))
        partial = _table(160, 2)
        partial.Y[::3, 3:] = np.nan                             # moments missing on a third of the update's rows
        lr._learn(partial, np.ones(160, bool))                  # the update, then a light refresh (hyper_every)
        assert lr.n_learned == 560
        assert any("refreshed (light)" in n for n in lr.notes), lr.notes
        models[noise] = lr.model
    assert not models["independent"].config.noise_correlation
    assert models["learned"].config.noise_correlation and models["learned"].config.noise_posterior == "diagonal"
    assert models["learned"].params.noise_chol is None          # dropped before the posterior, as in the replay
    assert np.all(np.isfinite(models["learned"].predict(_table(50, 3).X)[0]))
