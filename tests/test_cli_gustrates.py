"""`--gust-rates` on replay and fit: parsed into the options, a wrong frame is a user error."""

import pytest

from gcs_sysid.cli import _replay_options, build_parser, main


def test_replay_gust_rates_reaches_the_options():
    a = build_parser().parse_args(["replay", "x.tlog", "--airframe", "a.toml", "--out", "o", "--gust-rates", "path"])
    assert _replay_options(a).gust_rates == "path"
    a = build_parser().parse_args(["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"])
    assert _replay_options(a).gust_rates is None
    a = build_parser().parse_args(["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml", "--gust-rates",
                                   "mean-wind"])
    assert a.gust_rates == "mean-wind"


def test_unknown_gust_rate_frame_is_a_user_error(capsys):
    with pytest.raises(SystemExit) as e:
        main(["replay", "x.tlog", "--airframe", "a.toml", "--out", "o", "--gust-rates", "body"], handle_signals=False)
    assert e.value.code == 2
    assert "--gust-rates" in capsys.readouterr().err


def test_stated_lift_level_flag_switches_the_aiding(monkeypatch):
    """`--stated-lift-level` on replay and fit switches on airangles.STATED_LIFT_LEVEL for the run (off without it)."""
    import gcs_sysid.cli as cli
    import gcs_sysid.diagnose as dg
    import gcs_sysid.estimation.airangles as aa
    import gcs_sysid.pipeline as pl

    seen = []
    monkeypatch.setattr(pl, "run_replay", lambda *x, **k: seen.append(aa.STATED_LIFT_LEVEL) or 1 / 0)
    monkeypatch.setattr(dg, "run_fit", lambda *x, **k: seen.append(aa.STATED_LIFT_LEVEL) or 1 / 0)
    for argv in (["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"],
                 ["replay", "x.tlog", "--airframe", "a.toml", "--out", "o", "--stated-lift-level"],
                 ["fit", "x.tlog", "--airframe", "a.toml", "--out", "m.toml", "--stated-lift-level"]):
        monkeypatch.setattr(aa, "STATED_LIFT_LEVEL", False)
        a = build_parser().parse_args(argv)
        with pytest.raises(ZeroDivisionError):
            cli.COMMANDS[a.command](a)
    assert seen == [False, True, True]
