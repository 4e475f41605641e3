"""Closed-loop campaign: suggested flights teach the model more than standard ones; bad requests fail cleanly."""

import json
from pathlib import Path

import pytest

from gcs_sysid.campaign import CampaignConfig, run_campaign
from gcs_sysid.cli import main
from gcs_sysid.errors import InputError

DATA = Path(__file__).resolve().parents[1] / "data"
AIRFRAME = DATA / "airframes" / "sim-trainer.toml"
TRUTH = DATA / "models" / "sim-trainer-campaign.toml"


@pytest.mark.parametrize("args, match", [
    (["--flights", "1"], "--flights must be at least 2"),
    (["--seeds", "a,b"], "--seeds must be comma-separated"),
    (["--airframe", str(DATA / "airframes" / "arduplane-sitl-plane.toml")], "campaign needs a \\[limits\\] table"),
    (["--model", str(DATA / "plans" / "sysid-trainer.toml")], "unknown table or field"),
])
def test_impossible_requests_are_one_line_errors(args, match, tmp_path, capsys):
    base = {"--airframe": str(AIRFRAME), "--model": str(TRUTH), "--flights": "2", "--seeds": "1"}
    for k, v in zip(args[::2], args[1::2]):
        base[k] = v
    argv = ["campaign", "--out", str(tmp_path / "c")] + [x for kv in base.items() for x in kv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("gcs-sysid: error:") and "\n" not in err and "Traceback" not in err
    import re
    assert re.search(match, err), err


def test_config_rejects_impossible_settings():
    with pytest.raises(InputError, match="at least 82 s"):
        CampaignConfig(flight_s=0.0)
    with pytest.raises(InputError, match="at least one seed"):
        CampaignConfig(seeds=())


def _check(doc):
    acc = doc["acceptance"]
    for p in acc["per_seed"]:
        assert p["inside_limits"], doc["runs"]
        assert p["sigma_2x"], p   # one suggested flight cuts the target's sigma at least 2x more than a standard set
    run = doc["runs"][0]
    assert run["target"]["coefficient"] in ("Cl", "Cm", "Cn")
    s, b = run["arms"]["suggested"], run["arms"]["standard"]
    assert s[0] == b[0] and len(s) == len(b)
    assert all(r["flown"] for r in s[1:])   # suggestions were flown
    return acc


def test_campaign_fast(tmp_path):
    """One seed, two flights per arm, small GP: the first acceptance check and the limits, end to end
    (about 30 s on the 2-core machine)."""
    cfg = CampaignConfig(flights=2, seeds=(1,), max_suggestions=2, n_inducing=16, gp_steps=20, local=False)
    doc = run_campaign(AIRFRAME, TRUTH, tmp_path, cfg, progress=None)
    _check(doc)
    for name in ("campaign.json", "campaign.md", "campaign.png"):
        assert (tmp_path / name).stat().st_size > 0
    back = json.loads((tmp_path / "campaign.json").read_text())
    assert back["acceptance"]["per_seed"][0]["sigma_2x"] is True
    assert "| flight |" in (tmp_path / "campaign.md").read_text()


@pytest.mark.slow
def test_campaign_acceptance_three_seeds(tmp_path):
    """The issue's acceptance: several seeds, turbulence and noise on, three suggested vs three standard flights
    with the product's incremental update (new rows added, hyperparameters refreshed after each flight)."""
    doc = run_campaign(AIRFRAME, TRUTH, tmp_path, CampaignConfig(flights=4, seeds=(1, 2, 3)), progress=None)
    acc = _check(doc)
    assert acc["sigma_2x_all"] and acc["inside_limits_all"]
    assert acc["moments_better_all"], acc["per_seed"]
