"""The replay GP's default output noise (twenty-fifth session, i8-learned): ``learned``, with the old default
(``independent``, one noise variance per output) still reachable by name.

``learned`` (``GPConfig(noise_correlation=True, noise_posterior="diagonal")``) learns the outputs' noise
correlation with the hyperparameters and drops it before the posterior (docs/gp.md, "The default noise"); it
became the default under the two-GP-seed rule (docs/benchmarks.md, "Twenty-fifth session, i8-learned")."""

from dataclasses import replace

import pytest

from gcs_sysid import pipeline
from gcs_sysid.cli import _replay_options, build_parser
from gcs_sysid.errors import InputError
from gcs_sysid.pipeline import GP_NOISE_MODES, ReplayOptions, gp_noise_fields, replay_gp_config

LEARNED = {"noise_correlation": True, "noise_posterior": "diagonal", "noise_start": "signal"}
INDEPENDENT = {"noise_correlation": False, "noise_posterior": "full", "noise_start": "signal"}


def _fields(cfg):
    return {k: getattr(cfg, k) for k in LEARNED}


def test_the_replay_gp_noise_default_is_learned():
    assert pipeline.GP_NOISE == "learned"
    assert gp_noise_fields() == gp_noise_fields("learned") == LEARNED
    assert _fields(replay_gp_config()) == LEARNED
    assert _fields(replay_gp_config(ReplayOptions(), alpha_dot=True)) == LEARNED
    a = build_parser().parse_args(["replay", "f.tlog", "--airframe", "a.toml", "--out", "o"])
    assert a.gp_noise is None                                   # None: the package's default, learned
    assert _fields(replay_gp_config(_replay_options(a))) == LEARNED


def test_the_old_independent_noise_is_still_reachable():
    assert gp_noise_fields("independent") == gp_noise_fields("diagonal") == INDEPENDENT
    a = build_parser().parse_args(["replay", "f.tlog", "--airframe", "a.toml", "--out", "o",
                                   "--gp-noise", "independent"])
    cfg = replay_gp_config(_replay_options(a))
    assert _fields(cfg) == INDEPENDENT
    assert cfg.coupling_test == pipeline.GP_COUPLING_TEST      # only the noise differs from the default
    assert _fields(replay_gp_config(ReplayOptions(gp_noise="full"))) == {**LEARNED, "noise_posterior": "full"}
    assert set(GP_NOISE_MODES) == {"learned", "independent", "diagonal", "full", "full-nstart"}
    with pytest.raises(InputError, match="--gp-noise"):
        gp_noise_fields("fixed")
    with pytest.raises(SystemExit):
        build_parser().parse_args(["replay", "f.tlog", "--airframe", "a.toml", "--out", "o", "--gp-noise", "fixed"])


def test_the_replay_gp_seed_is_an_option_and_defaults_to_gpconfigs():
    """``ReplayOptions.gp_seed`` reaches the replay's ``GPConfig.seed`` (issue 8's counts are judged at GP seeds 0
    and 1, ``benchmarks/eval_jsbsim.py --gp-seed``); 0 leaves the fit as it was (``GPConfig``'s own default)."""
    from gcs_sysid.gp import GPConfig

    assert ReplayOptions().gp_seed == 0 == GPConfig().seed
    assert replay_gp_config().seed == 0
    cfg = replay_gp_config(ReplayOptions(gp_seed=1), alpha_dot=True)
    assert cfg.seed == 1
    assert cfg == replace(replay_gp_config(ReplayOptions(), alpha_dot=True), seed=1)   # nothing else moves
